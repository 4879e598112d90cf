// SPDX-License-Identifier: Apache-2.0
// Derivation benchmark: derives the corpus bench/ models and prints one JSON line each.
//
// Usage: derive [--cambium PATH] [model...]   (default: koch-L6 koch-L7 birch-225k birch-2250k)
// Each model runs in a fresh child process (this program re-executed with --one), so
// the peak RSS it reports belongs to that model alone. With --cambium, the command at
// PATH also runs on each model with -str alone and with -vv alone (whole process: start-up,
// load, derive, and interpretation where it is needed), one JSON line each with its wall
// time, CPU time and peak RSS.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <ostream>
#include <streambuf>
#include <string>
#include <system_error>
#include <vector>

#include "lsys/lsystem.h"
#include "lsys/string_io.h"

namespace fs = std::filesystem;

namespace {

fs::path bench_dir()
{
    if (const char* env = std::getenv("CAMBIUM_CORPUS"))
        return fs::path(env) / "bench";
    return fs::path(CAMBIUM_CORPUS_DEFAULT) / "bench";
}

/// The model's .l file: the only *.l in its folder (bench models have no model.json);
/// empty when there is no such folder or file.
fs::path lsystem_file(const fs::path& folder)
{
    std::error_code error;
    if (!fs::is_directory(folder, error))
        return {};
    for (const auto& e : fs::directory_iterator(folder, error))
        if (e.path().extension() == ".l")
            return e.path();
    return {};
}

double seconds(const timeval& t) { return double(t.tv_sec) + double(t.tv_usec) * 1e-6; }

/// CPU time (user + system) of this process so far, in seconds, with that of the child
/// processes it waited for (cpp while loading), and its own minor page faults.
struct CpuMark {
    double cpu_s = 0;
    long faults = 0;
};

CpuMark cpu_mark()
{
    rusage usage{}, children{};
    getrusage(RUSAGE_SELF, &usage);
    getrusage(RUSAGE_CHILDREN, &children);
    return {seconds(usage.ru_utime) + seconds(usage.ru_stime) + seconds(children.ru_utime) +
                seconds(children.ru_stime),
            usage.ru_minflt};
}

double peak_rss_mb()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
}

/// A stream buffer that counts and drops what is written: string output without disk I/O.
class NullBuffer : public std::streambuf {
protected:
    std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
    int_type overflow(int_type c) override { return traits_type::not_eof(c); }
};

/// Loads, derives and reports one model (runs in the child process).
int run_one(const std::string& model)
{
    using clock = std::chrono::steady_clock;
    fs::path file = lsystem_file(bench_dir() / model);
    if (file.empty()) {
        std::printf("{\"model\":\"%s\",\"error\":\"no .l file\"}\n", model.c_str());
        return 1;
    }
    try {
        auto t0 = clock::now();
        CpuMark c0 = cpu_mark();
        cambium::lsys::LSystem ls = cambium::lsys::LSystem::load(file);
        auto t1 = clock::now();
        CpuMark c1 = cpu_mark();
        cambium::lsys::ModuleString s = ls.derive();
        auto t2 = clock::now();
        CpuMark c2 = cpu_mark();
        double derive_peak = peak_rss_mb();
        // cpfg's -str text output of the same string, written to a sink (no disk)
        NullBuffer sink;
        std::ostream null_stream(&sink);
        auto t3 = clock::now();
        CpuMark c3 = cpu_mark();
        cambium::lsys::write_string_text(s, ls.symbols(), null_stream);
        auto t4 = clock::now();
        CpuMark c4 = cpu_mark();
        double load_s = std::chrono::duration<double>(t1 - t0).count();
        double derive_s = std::chrono::duration<double>(t2 - t1).count();
        double str_s = std::chrono::duration<double>(t4 - t3).count();
        double wall_s = load_s + derive_s;
        std::printf("{\"model\":\"%s\",\"modules\":%zu,\"wall_s\":%.3f,\"load_s\":%.3f,"
                    "\"derive_s\":%.3f,\"modules_per_s\":%.0f,\"peak_rss_mb\":%.1f,"
                    "\"str_text_s\":%.3f,\"peak_rss_after_str_mb\":%.1f,"
                    "\"load_cpu_s\":%.3f,\"derive_cpu_s\":%.3f,\"str_text_cpu_s\":%.3f,"
                    "\"derive_page_faults\":%ld}\n",
                    model.c_str(), s.size(), wall_s, load_s, derive_s,
                    static_cast<double>(s.size()) / derive_s, derive_peak, str_s, peak_rss_mb(),
                    c1.cpu_s - c0.cpu_s, c2.cpu_s - c1.cpu_s, c4.cpu_s - c3.cpu_s,
                    c2.faults - c1.faults);
    } catch (const std::exception& e) {
        std::printf("{\"model\":\"%s\",\"error\":\"%s\"}\n", model.c_str(), e.what());
        return 1;
    }
    return 0;
}

/// Runs `self --one model` in a child process and waits for it.
int run_child(const char* self, const std::string& model)
{
    std::fflush(stdout);
    pid_t pid = fork();
    if (pid < 0)
        return 1;
    if (pid == 0) {
        execl(self, self, "--one", model.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

/// Runs the cambium command at `cambium` on a bench model with `output_option` (-str or
/// -vv) into a scratch file, and prints its wall time, CPU time and peak RSS.
int run_command(const std::string& cambium, const std::string& model,
                const std::string& output_option)
{
    fs::path folder = bench_dir() / model;
    fs::path lsystem = lsystem_file(folder);
    if (lsystem.empty())
        return 1;
    fs::path view = fs::path(lsystem).replace_extension(".v");
    fs::path output = fs::temp_directory_path() /
                      ("cambium_derive_bench_" + std::to_string(::getpid()) + ".out");
    std::fflush(stdout);
    auto start = std::chrono::steady_clock::now();
    pid_t pid = fork();
    if (pid < 0)
        return 1;
    if (pid == 0) {
        if (chdir(folder.c_str()) != 0)
            _exit(127);
        execl(cambium.c_str(), cambium.c_str(), "-q", output_option.c_str(), output.c_str(),
              lsystem.c_str(), view.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fs::remove(output);
    bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    std::printf("{\"model\":\"%s\",\"command\":\"cambium %s\",\"ok\":%s,\"wall_s\":%.3f,"
                "\"cpu_s\":%.3f,\"peak_rss_mb\":%.1f}\n",
                model.c_str(), output_option.c_str(), ok ? "true" : "false", wall,
                seconds(usage.ru_utime) + seconds(usage.ru_stime),
                static_cast<double>(usage.ru_maxrss) / 1024.0);
    return ok ? 0 : 1;
}

constexpr const char* usage =
    "usage: derive [--cambium PATH] [model...]\n"
    "Derives each corpus bench/ model (default: koch-L6 koch-L7 birch-225k birch-2250k) in\n"
    "a child process and prints one JSON line per model: load, derive and -str text output\n"
    "times (wall and CPU), page faults while deriving and peak RSS. With --cambium, the\n"
    "command at PATH also runs on each model with -str alone and with -vv alone.\n"
    "The corpus is $CAMBIUM_CORPUS, else " CAMBIUM_CORPUS_DEFAULT ".\n";

}  // namespace

int main(int argc, char** argv)
{
    if (argc == 3 && std::string(argv[1]) == "--one")
        return run_one(argv[2]);
    if (argc >= 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
        std::fputs(usage, stdout);
        return 0;
    }
    std::string cambium;
    if (argc >= 2 && std::string(argv[1]) == "--cambium") {
        if (argc < 3) {
            std::fprintf(stderr, "derive: --cambium needs the path of the cambium command\n%s",
                         usage);
            return 2;
        }
        cambium = fs::absolute(argv[2]).string();
        argv += 2;
        argc -= 2;
    }
    for (int i = 1; i < argc; ++i)
        if (argv[i][0] == '-') {
            std::fprintf(stderr, "derive: unknown option %s\n%s", argv[i], usage);
            return 2;
        }
    if (!fs::is_directory(bench_dir())) {
        std::printf("{\"note\":\"corpus bench folder not found at %s; nothing measured\"}\n",
                    bench_dir().string().c_str());
        return 0;
    }
    std::vector<std::string> models = {"koch-L6", "koch-L7", "birch-225k", "birch-2250k"};
    if (argc > 1)
        models.assign(argv + 1, argv + argc);
    int failures = 0;
    for (const auto& m : models) {
        if (lsystem_file(bench_dir() / m).empty()) {
            std::printf("{\"model\":\"%s\",\"error\":\"no such model: no .l file in %s\"}\n",
                        m.c_str(), (bench_dir() / m).string().c_str());
            ++failures;
            continue;
        }
        failures += run_child("/proc/self/exe", m) != 0 ? 1 : 0;
        if (!cambium.empty())
            for (const char* option : {"-str", "-vv"})
                failures += run_command(cambium, m, option) != 0 ? 1 : 0;
    }
    return failures == 0 ? 0 : 1;
}
