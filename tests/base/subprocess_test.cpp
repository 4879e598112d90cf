// SPDX-License-Identifier: Apache-2.0
// Helper programs: no shell, limits, standard input, interrupts, process groups.
#include "base/subprocess.h"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "scratch.h"

namespace cambium {
namespace {

namespace fs = std::filesystem;

using testing::scratch;

/// Whether `pid` is gone or a zombie within a few seconds (SIGKILL is asynchronous, and
/// an orphan's zombie may wait for a reaper).
bool dies_soon(pid_t pid)
{
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (std::chrono::steady_clock::now() < deadline) {
        std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
        std::string id, name, state;
        if (!(stat >> id >> name >> state) || state == "Z")
            return true;
        std::this_thread::yield();
    }
    return false;
}

TEST(Subprocess, RunsWithoutAShellInTheFolderGivenAndFeedsItsInput)
{
    fs::path dir = scratch("folder");
    ProcessIo io;
    io.input = "a;b $(x)\n";
    // `cat` copies its input: no shell interprets the words.
    ProcessResult r = run_process({"cat"}, dir, io, {});
    EXPECT_EQ(r.end, ProcessResult::End::exited);
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_EQ(r.output, "a;b $(x)\n");
    r = run_process({"pwd"}, dir, {}, {});
    EXPECT_EQ(r.output, fs::canonical(dir).string() + "\n");
}

TEST(Subprocess, StandardInputIsDevNullWithoutInput)
{
    ProcessResult r = run_process({"sh", "-c", "wc -c; readlink /proc/self/fd/0"}, ".", {}, {});
    EXPECT_EQ(r.output, "0\n/dev/null\n");
}

TEST(Subprocess, MissingProgramIsReported)
{
    ProcessResult r = run_process({"/nonexistent/cambium-helper"}, ".", {}, {});
    EXPECT_EQ(r.end, ProcessResult::End::not_found);
    EXPECT_NE(r.messages.find("No such file"), std::string::npos) << r.messages;
}

TEST(Subprocess, WallTimeLimitKillsTheWholeGroup)
{
    fs::path dir = scratch("time");
    ProcessLimits limits;
    limits.wall_seconds = 0.3;
    auto start = std::chrono::steady_clock::now();
    // The grandchild `sleep` must die too (cpp leaves cc1 running otherwise).
    ProcessResult r =
        run_process({"sh", "-c", "sleep 60 & echo $! > grandchild; wait"}, dir, {}, limits);
    EXPECT_EQ(r.end, ProcessResult::End::timed_out);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
    pid_t grandchild = 0;
    std::ifstream(dir / "grandchild") >> grandchild;
    ASSERT_GT(grandchild, 0);
    EXPECT_TRUE(dies_soon(grandchild));
}

TEST(Subprocess, OutputLimitStopsIt)
{
    ProcessLimits limits;
    limits.max_output_bytes = 1u << 20;
    ProcessResult r = run_process({"yes"}, ".", {}, limits);
    EXPECT_EQ(r.end, ProcessResult::End::output_too_large);
    EXPECT_LE(r.output.size(), limits.max_output_bytes);
}

TEST(Subprocess, MemoryLimitApplies)
{
    // awk builds a 32 MiB string: fine without a limit, impossible within 24 MiB.
    std::vector<std::string> hungry{
        "awk", "BEGIN { s = \"x\"; for (i = 0; i < 25; i++) s = s s; print length(s) }"};
    ProcessLimits limits;
    limits.max_memory_bytes = 0;
    EXPECT_EQ(run_process(hungry, ".", {}, limits).output, "33554432\n");
    limits.max_memory_bytes = 24u << 20;
    ProcessResult r = run_process(hungry, ".", {}, limits);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(r.output, "");
    EXPECT_NE(r.messages.find("out of memory"), std::string::npos) << r.messages;
}

// Ctrl-C while a helper runs: it and its children are killed and reaped, and the
// caller gets Interrupted (main exits 130) instead of dying with files left behind.
TEST(Subprocess, InterruptKillsTheHelperAndThrows)
{
    fs::path dir = scratch("interrupt");
    auto start = std::chrono::steady_clock::now();
    try {
        run_process({"sh", "-c", "echo $$ > helper; kill -INT $PPID; exec sleep 60"}, dir, {}, {});
        FAIL() << "expected Interrupted";
    } catch (const Interrupted& e) {
        EXPECT_EQ(e.signal(), SIGINT);
        EXPECT_NE(std::string(e.what()).find("interrupted"), std::string::npos);
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
    pid_t helper = 0;
    std::ifstream(dir / "helper") >> helper;
    ASSERT_GT(helper, 0);
    EXPECT_NE(::kill(helper, 0), 0);
    // The default disposition is back afterwards.
    struct sigaction now {};
    ::sigaction(SIGINT, nullptr, &now);
    EXPECT_EQ(now.sa_handler, SIG_DFL);
}

/// Reads from `c` until `want` bytes or its end, waiting at most 10 s in all.
std::string read_from(Coprocess& c, std::size_t want)
{
    std::string got;
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    char buffer[256];
    while (got.size() < want && std::chrono::steady_clock::now() < deadline) {
        if (!c.wait(false, true, std::chrono::milliseconds(1000)).output)
            continue;
        std::ptrdiff_t n = c.read_some(buffer, sizeof buffer);
        if (n == 0)
            break;
        if (n > 0)
            got.append(buffer, std::size_t(n));
    }
    return got;
}

TEST(Coprocess, TalksThroughTwoPipesInTheFolderGiven)
{
    fs::path dir = scratch("coprocess");
    Coprocess c({"sh", "-c", "pwd; while read line; do echo \"got $line\"; done; exit 4"}, dir, {});
    const std::string folder = fs::canonical(dir).string() + "\n";
    EXPECT_EQ(read_from(c, folder.size()), folder);
    ASSERT_TRUE(c.wait(true, false, std::chrono::milliseconds(10000)).input);
    EXPECT_EQ(c.write_some("a b\n"), 4);
    EXPECT_EQ(read_from(c, 8), "got a b\n");
    c.close_input();
    EXPECT_EQ(read_from(c, 1), "");  // its end: the loop read end of file
    EXPECT_EQ(c.end_description(std::chrono::milliseconds(10000)), "exited with status 4");
}

TEST(Coprocess, AProgramThatStopsReadingIsNoSigpipe)
{
    Coprocess c({"sh", "-c", "exec 0<&-; echo closed"}, ".", {});
    EXPECT_EQ(read_from(c, 7), "closed\n");
    EXPECT_EQ(read_from(c, 1), "");
    EXPECT_EQ(c.write_some("more\n"), -1);
    EXPECT_THROW(Coprocess({"no-such-program-anywhere"}, ".", {}), Error);
}

TEST(Coprocess, DestructionKillsItsWholeGroup)
{
    pid_t background = 0;
    {
        Coprocess c({"sh", "-c", "sleep 60 & echo $!; wait"}, ".", {});
        std::string line;
        for (std::string more; line.find('\n') == std::string::npos && !(more = read_from(c, 1)).empty();)
            line += more;
        std::istringstream(line) >> background;
        ASSERT_GT(background, 0);
    }
    EXPECT_TRUE(dies_soon(background));
}

// Ctrl-C between waits ends cambium as it would, and kills the program's whole group
// first: only the program itself would die with cambium (PR_SET_PDEATHSIG), not the
// background job it started.
TEST(Coprocess, AnInterruptBetweenWaitsKillsItsWholeGroup)
{
    int report[2];
    ASSERT_EQ(::pipe(report), 0);
    const pid_t plant = ::fork();
    ASSERT_GE(plant, 0);
    if (plant == 0) {
        ::close(report[0]);
        Coprocess c({"sh", "-c", "sleep 60 & echo $!; read x"}, ".", {});
        std::string line;
        for (std::string more; line.find('\n') == std::string::npos && !(more = read_from(c, 1)).empty();)
            line += more;
        [[maybe_unused]] auto written = ::write(report[1], line.data(), line.size());
        ::close(report[1]);
        ::raise(SIGINT);
        ::_exit(0);  // not reached: SIGINT ends it
    }
    ::close(report[1]);
    std::string line(64, '\0');
    const ssize_t got = ::read(report[0], line.data(), line.size());
    ::close(report[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(plant, &status, 0), plant);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT);
    pid_t background = 0;
    std::istringstream(line.substr(0, std::size_t(std::max<ssize_t>(got, 0)))) >> background;
    ASSERT_GT(background, 0);
    EXPECT_TRUE(dies_soon(background));
}

volatile sig_atomic_t g_stray_interrupts = 0;
extern "C" void note_stray_interrupt(int)
{
    g_stray_interrupts = g_stray_interrupts + 1;
}

// Ctrl-C during a wait: the program's group is killed and Interrupted thrown. The program
// sends SIGINT until it is killed, so one lands inside the wait; the test's own handler
// takes any that arrive outside it.
TEST(Coprocess, InterruptWhileWaitingKillsItAndThrows)
{
    struct sigaction stray {}, saved{};
    stray.sa_handler = note_stray_interrupt;
    sigemptyset(&stray.sa_mask);
    ::sigaction(SIGINT, &stray, &saved);
    pid_t pid = 0;
    try {
        Coprocess c({"sh", "-c", "read go; while kill -INT $PPID; do :; done"}, ".", {});
        pid = c.pid();
        EXPECT_EQ(c.write_some("go\n"), 3);
        for (int i = 0; i < 100; ++i)
            c.wait(false, true, std::chrono::milliseconds(100));
        FAIL() << "expected Interrupted";
    } catch (const Interrupted& e) {
        EXPECT_EQ(e.signal(), SIGINT);
    }
    ::sigaction(SIGINT, &saved, nullptr);
    ASSERT_GT(pid, 0);
    EXPECT_NE(::kill(pid, 0), 0);  // killed and reaped
}

}  // namespace
}  // namespace cambium
