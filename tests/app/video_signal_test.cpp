// SPDX-License-Identifier: Apache-2.0
// A video's frames go to a private folder beside it (app/video.h); a run ended by
// SIGTERM, SIGINT or SIGHUP while it renders removes that folder too. The cambium command
// runs in a child process; the test waits for the folder through inotify and for the end
// through waitpid (no sleeping).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace {

void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

/// What happened to a cambium run signalled once its video folder appeared.
struct Signalled {
    bool folder_seen = false;  ///< the private folder appeared before the signal
    int status = 0;            ///< waitpid's
};

/// Starts `args` (cambium's arguments) in `dir` with `bin` first on PATH, waits for a
/// folder to appear in `dir` (the video's private one), sends `signal` and waits for the
/// end. A child that ends first, or a folder that does not appear in a minute, is
/// reported as not seen.
Signalled run_and_signal(const fs::path& dir, const fs::path& bin,
                         const std::vector<std::string>& args, int signal)
{
    Signalled out;
    int watch = ::inotify_init1(IN_CLOEXEC);
    if (watch < 0 || ::inotify_add_watch(watch, dir.c_str(), IN_CREATE) < 0)
        return out;
    // The child holds `alive`'s write end: its end closes it, which poll sees.
    int alive[2];
    if (::pipe(alive) != 0)
        return out;
    ::fcntl(alive[0], F_SETFD, FD_CLOEXEC);
    const std::string path = bin.string() + ":" + (std::getenv("PATH") ? std::getenv("PATH") : "");
    pid_t pid = ::fork();
    if (pid == 0) {
        ::setenv("PATH", path.c_str(), 1);
        if (::chdir(dir.c_str()) != 0)
            ::_exit(126);
        int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1);
        ::dup2(null, 2);
        std::vector<char*> argv{const_cast<char*>(CAMBIUM_EXE)};
        for (const std::string& a : args)
            argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(CAMBIUM_EXE, argv.data());
        ::_exit(127);
    }
    ::close(alive[1]);
    std::array<pollfd, 2> fds{{{watch, POLLIN, 0}, {alive[0], POLLIN, 0}}};
    while (!out.folder_seen && ::poll(fds.data(), fds.size(), 60'000) > 0) {
        if (fds[0].revents & POLLIN) {
            alignas(inotify_event) char buffer[4096];
            ssize_t n = ::read(watch, buffer, sizeof buffer);
            for (ssize_t at = 0; at < n;) {
                auto* event = reinterpret_cast<inotify_event*>(buffer + at);
                out.folder_seen |= (event->mask & IN_ISDIR) != 0;
                at += ssize_t(sizeof(inotify_event) + event->len);
            }
        } else if (fds[1].revents) {
            break;  // the child ended first
        }
    }
    ::kill(pid, signal);
    ::waitpid(pid, &out.status, 0);
    ::close(alive[0]);
    ::close(watch);
    return out;
}

}  // namespace

TEST(VideoSignals, ASignalledRenderLeavesNoPrivateFolder)
{
    const fs::path dir = fs::temp_directory_path() /
                         ("cambium_video_signal_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "bin");
    write(dir / "g.l", "lsystem: 1\nderivation length: 3\naxiom: A\nA --> F[+F]A\nendlsystem\n");
    write(dir / "g.v", "line style: cylinder\ninitial line width: 0.2\n");
    // a stand-in ffmpeg: the run is stopped before it would encode
    write(dir / "bin" / "ffmpeg", "#!/bin/sh\nexit 1\n");
    fs::permissions(dir / "bin" / "ffmpeg", fs::perms::owner_all);
    // a turntable, and an animation (cpfg's frames 1 to 3), rendered far longer than the
    // test lasts: only the signal ends them
    const std::vector<std::string> turntable{"--turntable", "2"}, animation{"-a"};
    for (auto [signal, sequence] : {std::pair{SIGTERM, turntable}, {SIGINT, turntable},
                                    {SIGHUP, turntable}, {SIGTERM, animation}}) {
        std::vector<std::string> args{"-q", "-w", "64", "48", "--spp", "1048576"};
        args.insert(args.end(), sequence.begin(), sequence.end());
        args.insert(args.end(), {"-o", "t.mp4", "g.l", "g.v"});
        Signalled r = run_and_signal(dir, dir / "bin", args, signal);
        EXPECT_TRUE(r.folder_seen) << "signal " << signal;
        for (const auto& entry : fs::directory_iterator(dir))  // no .t.cambium-XXXXXX
            EXPECT_TRUE(entry.path().filename() == "bin" || !entry.is_directory())
                << "signal " << signal << " left " << entry.path();
        // ended by the normal path, with 128 + the signal (as a shell reports a signal's end)
        EXPECT_TRUE(WIFEXITED(r.status)) << "signal " << signal << ": killed by signal "
                                         << (WIFSIGNALED(r.status) ? WTERMSIG(r.status) : 0);
        EXPECT_EQ(WEXITSTATUS(r.status), 128 + signal);
        EXPECT_FALSE(fs::exists(dir / "t.mp4"));
    }
    fs::remove_all(dir);
}
