// SPDX-License-Identifier: Apache-2.0
// Derivation benchmark: derives the corpus bench/ models and prints one JSON line each.
//
// Usage: derive [model...]   (default: koch-L6 koch-L7 birch-225k birch-2250k)
// Each model runs in a fresh child process (this program re-executed with --one), so
// the peak RSS it reports belongs to that model alone.
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

/// The model's .l file: the only *.l in its folder (bench models have no model.json).
fs::path lsystem_file(const fs::path& folder)
{
    for (const auto& e : fs::directory_iterator(folder))
        if (e.path().extension() == ".l")
            return e.path();
    return {};
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
        cambium::lsys::LSystem ls = cambium::lsys::LSystem::load(file);
        auto t1 = clock::now();
        cambium::lsys::ModuleString s = ls.derive();
        auto t2 = clock::now();
        double peak = peak_rss_mb();
        // cpfg's -str text output of the same string, written to a sink (no disk)
        NullBuffer sink;
        std::ostream null_stream(&sink);
        auto t3 = clock::now();
        cambium::lsys::write_string_text(s, ls.symbols(), null_stream);
        auto t4 = clock::now();
        double load_s = std::chrono::duration<double>(t1 - t0).count();
        double derive_s = std::chrono::duration<double>(t2 - t1).count();
        double str_s = std::chrono::duration<double>(t4 - t3).count();
        double wall_s = load_s + derive_s;
        std::printf("{\"model\":\"%s\",\"modules\":%zu,\"wall_s\":%.3f,\"load_s\":%.3f,"
                    "\"derive_s\":%.3f,\"modules_per_s\":%.0f,\"peak_rss_mb\":%.1f,"
                    "\"str_text_s\":%.3f}\n",
                    model.c_str(), s.size(), wall_s, load_s, derive_s,
                    static_cast<double>(s.size()) / derive_s, peak, str_s);
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

}  // namespace

int main(int argc, char** argv)
{
    if (argc == 3 && std::string(argv[1]) == "--one")
        return run_one(argv[2]);
    if (!fs::is_directory(bench_dir())) {
        std::printf("{\"note\":\"corpus bench folder not found at %s; nothing measured\"}\n",
                    bench_dir().string().c_str());
        return 0;
    }
    std::vector<std::string> models = {"koch-L6", "koch-L7", "birch-225k", "birch-2250k"};
    if (argc > 1)
        models.assign(argv + 1, argv + argc);
    int failures = 0;
    for (const auto& m : models)
        failures += run_child("/proc/self/exe", m) != 0 ? 1 : 0;
    return failures == 0 ? 0 : 1;
}
