// SPDX-License-Identifier: Apache-2.0
// Runs a helper program (the C preprocessor, an allowed @S command) without a shell,
// bounded in time, output and memory, and never outliving an interrupted cambium.
#include "base/subprocess.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <mutex>
#include <utility>

namespace cambium {

Interrupted::Interrupted(int signal)
    : Error("interrupted (signal " + std::to_string(signal) + ")"), m_signal(signal)
{
}

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::array<int, 3> forwarded_signals{SIGINT, SIGTERM, SIGHUP};

/// The self-pipe the signal handler writes to: the waiting loop polls it, whichever
/// thread the signal lands on.
int g_signal_pipe[2] = {-1, -1};
volatile sig_atomic_t g_signal = 0;

extern "C" void note_signal(int signal)
{
    int saved = errno;
    g_signal = signal;
    char byte = 1;
    [[maybe_unused]] auto ignored = ::write(g_signal_pipe[1], &byte, 1);
    errno = saved;
}

/// A file descriptor closed on destruction.
class Fd {
public:
    Fd() = default;
    explicit Fd(int fd) : m_fd(fd) {}
    Fd(Fd&& o) noexcept : m_fd(o.release()) {}
    Fd& operator=(Fd&& o) noexcept
    {
        reset(o.release());
        return *this;
    }
    ~Fd() { reset(); }
    int get() const { return m_fd; }
    int release() { return std::exchange(m_fd, -1); }
    void reset(int fd = -1)
    {
        if (m_fd >= 0)
            ::close(m_fd);
        m_fd = fd;
    }

private:
    int m_fd = -1;
};

struct Pipe {
    Fd read, write;
};

Pipe make_pipe()
{
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0)
        throw Error(std::string("cannot create a pipe: ") + std::strerror(errno));
    return {Fd(fds[0]), Fd(fds[1])};
}

/// While any is alive: SIGINT/SIGTERM/SIGHUP are noted (not fatal) and SIGPIPE is
/// ignored (a child program that stops reading its input must not kill cambium). The first
/// installs the handlers, the last restores them, so scopes may overlap across threads.
class SignalScope {
public:
    SignalScope()
    {
        std::lock_guard lock(mutex());
        if (s_users++ > 0)
            return;
        Pipe p = make_pipe();
        ::fcntl(p.read.get(), F_SETFL, O_NONBLOCK);
        ::fcntl(p.write.get(), F_SETFL, O_NONBLOCK);
        s_pipe = std::move(p);
        g_signal_pipe[0] = s_pipe.read.get();
        g_signal_pipe[1] = s_pipe.write.get();
        g_signal = 0;
        struct sigaction note {};
        note.sa_handler = note_signal;
        sigemptyset(&note.sa_mask);
        for (std::size_t i = 0; i < forwarded_signals.size(); ++i)
            ::sigaction(forwarded_signals[i], &note, &s_saved[i]);
        struct sigaction ignore {};
        ignore.sa_handler = SIG_IGN;
        sigemptyset(&ignore.sa_mask);
        ::sigaction(SIGPIPE, &ignore, &s_saved_pipe);
    }
    ~SignalScope()
    {
        std::lock_guard lock(mutex());
        if (--s_users > 0)
            return;
        for (std::size_t i = 0; i < forwarded_signals.size(); ++i)
            ::sigaction(forwarded_signals[i], &s_saved[i], nullptr);
        ::sigaction(SIGPIPE, &s_saved_pipe, nullptr);
        g_signal_pipe[0] = g_signal_pipe[1] = -1;
        s_pipe = Pipe{};
    }
    SignalScope(const SignalScope&) = delete;
    SignalScope& operator=(const SignalScope&) = delete;
    int fd() const { return g_signal_pipe[0]; }

private:
    static std::mutex& mutex()
    {
        static std::mutex m;
        return m;
    }
    static inline int s_users = 0;
    static inline Pipe s_pipe;
    static inline std::array<struct sigaction, forwarded_signals.size()> s_saved{};
    static inline struct sigaction s_saved_pipe {};
};

/// The process groups of the coprocesses alive now. Between their waits (which note
/// SIGINT, SIGTERM and SIGHUP themselves) such a signal ends cambium: a guard handler
/// kills the groups first, since only the program itself would die with cambium
/// (PR_SET_PDEATHSIG), not what it started. Slots hold 0 when free.
class LiveGroups {
public:
    static void add(pid_t group)
    {
        std::lock_guard lock(mutex());
        for (auto& slot : s_groups) {
            pid_t free = 0;
            if (slot.compare_exchange_strong(free, group))
                break;
        }
        if (s_users++ == 0)
            install();
    }
    static void remove(pid_t group)
    {
        std::lock_guard lock(mutex());
        for (auto& slot : s_groups) {
            pid_t held = group;
            if (slot.compare_exchange_strong(held, 0))
                break;
        }
        if (--s_users == 0)
            restore();
    }

private:
    static void install()
    {
        struct sigaction guard {};
        guard.sa_handler = guard_signal;
        sigemptyset(&guard.sa_mask);
        for (std::size_t i = 0; i < forwarded_signals.size(); ++i)
            ::sigaction(forwarded_signals[i], &guard, &s_before[i]);
    }
    static void restore()
    {
        for (std::size_t i = 0; i < forwarded_signals.size(); ++i)
            ::sigaction(forwarded_signals[i], &s_before[i], nullptr);
    }
    /// Async-signal-safe: kill, sigaction and raise only.
    static void guard_signal(int signal)
    {
        for (auto& slot : s_groups)
            if (const pid_t group = slot.load(); group > 0)
                ::kill(-group, SIGKILL);
        for (std::size_t i = 0; i < forwarded_signals.size(); ++i) {
            if (forwarded_signals[i] != signal)
                continue;
            const struct sigaction& before = s_before[i];
            if (before.sa_handler == SIG_IGN)
                return;
            if (before.sa_handler != SIG_DFL && !(before.sa_flags & SA_SIGINFO)) {
                before.sa_handler(signal);  // whoever handled it before (a cleanup) still does
                return;
            }
            ::sigaction(signal, &before, nullptr);
            ::raise(signal);  // delivered when this handler returns: ends cambium as before
        }
    }
    static std::mutex& mutex()
    {
        static std::mutex m;
        return m;
    }
    static constexpr std::size_t max_groups = 256;
    static inline std::array<std::atomic<pid_t>, max_groups> s_groups{};
    static inline int s_users = 0;
    static inline std::array<struct sigaction, forwarded_signals.size()> s_before{};
};

/// The started child: its whole process group is killed and the child reaped on
/// destruction, whatever way the caller leaves.
class Child {
public:
    explicit Child(pid_t pid) : m_pid(pid) {}
    ~Child() { finish(); }
    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;

    /// Non-blocking: whether it has ended. The zombie is left for finish() so its
    /// process group id cannot be reused before the group is killed.
    bool ended()
    {
        siginfo_t info{};
        if (::waitid(P_PID, id_t(m_pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0)
            return errno == ECHILD;
        return info.si_pid == m_pid;
    }
    /// Kills the group (also what it left behind: cc1, background jobs) and reaps the
    /// child. Idempotent.
    void finish()
    {
        if (m_reaped)
            return;
        ::kill(-m_pid, SIGKILL);
        for (;;) {
            pid_t r = ::waitpid(m_pid, &m_status, 0);
            if (r == m_pid || (r < 0 && errno != EINTR))
                break;
        }
        m_reaped = true;
    }
    int status() const { return m_status; }

private:
    pid_t m_pid;
    int m_status = 0;
    bool m_reaped = false;
};

/// In the forked child: tells the parent why the program could not start.
[[noreturn]] void fail_to_start(int report, int error)
{
    [[maybe_unused]] auto ignored = ::write(report, &error, sizeof error);
    ::_exit(127);
}

/// In the forked child: only async-signal-safe calls until exec.
[[noreturn]] void exec_child(char* const* argv, const char* folder, int in, int out, int err,
                             int report, pid_t parent, const ProcessLimits& limits)
{
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent)
        ::_exit(127);
    ::setpgid(0, 0);
    struct sigaction deflt {};
    deflt.sa_handler = SIG_DFL;
    for (int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE})
        ::sigaction(s, &deflt, nullptr);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    if (::dup2(in, 0) < 0 || (out >= 0 && ::dup2(out, 1) < 0) || (err >= 0 && ::dup2(err, 2) < 0))
        fail_to_start(report, errno);
    if (::chdir(folder) != 0)
        fail_to_start(report, errno);
    if (limits.max_memory_bytes > 0) {
        struct rlimit memory {limits.max_memory_bytes, limits.max_memory_bytes};
        ::setrlimit(RLIMIT_AS, &memory);
    }
    ::execvp(argv[0], argv);
    fail_to_start(report, errno);
}

/// Appends what is readable on `fd` to `into`, keeping at most `keep` bytes; returns
/// false at end of file. `total` counts everything read.
bool drain(int fd, std::string& into, std::size_t keep, std::size_t& total)
{
    std::array<char, 65536> buffer;
    for (;;) {
        ssize_t n = ::read(fd, buffer.data(), buffer.size());
        if (n > 0) {
            total += std::size_t(n);
            if (keep == 0 || into.size() < keep)
                into.append(buffer.data(),
                            keep == 0 ? std::size_t(n) : std::min(std::size_t(n), keep - into.size()));
            continue;
        }
        if (n == 0)
            return false;
        return errno == EAGAIN || errno == EINTR;
    }
}

}  // namespace

ProcessResult run_process(const std::vector<std::string>& argv, const std::filesystem::path& folder,
                          const ProcessIo& io, const ProcessLimits& limits)
{
    if (argv.empty() || argv[0].empty())
        throw Error("no program to run");
    static std::mutex one_at_a_time;  // the signal pipe is process-wide
    std::lock_guard lock(one_at_a_time);

    std::vector<char*> args;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    std::string where = folder.empty() ? std::string(".") : folder.string();

    Fd input;
    Pipe in_pipe;
    if (io.input) {
        in_pipe = make_pipe();
    } else {
        input = Fd(::open("/dev/null", O_RDONLY | O_CLOEXEC));
        if (input.get() < 0)
            throw Error(std::string("cannot open /dev/null: ") + std::strerror(errno));
    }
    Pipe out_pipe, err_pipe;
    if (io.capture) {
        out_pipe = make_pipe();
        err_pipe = make_pipe();
    }
    Pipe report = make_pipe();
    SignalScope signals;

    pid_t parent = ::getpid();
    pid_t pid = ::fork();
    if (pid < 0)
        throw Error(std::string("cannot start ") + argv[0] + ": " + std::strerror(errno));
    if (pid == 0)
        exec_child(args.data(), where.c_str(), io.input ? in_pipe.read.get() : input.get(),
                   out_pipe.write.get(), err_pipe.write.get(), report.write.get(), parent, limits);
    ::setpgid(pid, pid);  // also here: no race with a kill before the child's own call
    Child child(pid);
    in_pipe.read.reset();
    out_pipe.write.reset();
    err_pipe.write.reset();
    report.write.reset();

    ProcessResult result;
    int exec_error = 0;
    ssize_t got;
    do
        got = ::read(report.read.get(), &exec_error, sizeof exec_error);
    while (got < 0 && errno == EINTR);
    if (got == sizeof exec_error) {
        child.finish();
        result.end = ProcessResult::End::not_found;
        result.exit_code = 127;
        result.messages = argv[0] + ": " + std::strerror(exec_error);
        return result;
    }

    for (int fd : {in_pipe.write.get(), out_pipe.read.get(), err_pipe.read.get()})
        if (fd >= 0)
            ::fcntl(fd, F_SETFL, O_NONBLOCK);
    std::string_view pending = io.input.value_or(std::string_view{});
    if (pending.empty())
        in_pipe.write.reset();
    std::size_t output_total = 0, message_total = 0;
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(limits.wall_seconds > 0 ? limits.wall_seconds : 1e9));
    for (;;) {
        if (g_signal != 0) {
            int signal = g_signal;
            child.finish();
            throw Interrupted(signal);
        }
        bool streams_open = in_pipe.write.get() >= 0 || out_pipe.read.get() >= 0 || err_pipe.read.get() >= 0;
        if (!streams_open && child.ended())
            break;
        auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        if (left.count() <= 0) {
            child.finish();
            result.end = ProcessResult::End::timed_out;
            return result;
        }
        std::array<pollfd, 4> polled{};
        nfds_t n = 0;
        polled[n++] = {signals.fd(), POLLIN, 0};
        if (in_pipe.write.get() >= 0)
            polled[n++] = {in_pipe.write.get(), POLLOUT, 0};
        if (out_pipe.read.get() >= 0)
            polled[n++] = {out_pipe.read.get(), POLLIN, 0};
        if (err_pipe.read.get() >= 0)
            polled[n++] = {err_pipe.read.get(), POLLIN, 0};
        // Without streams, the child's end is polled for every 10 ms.
        int timeout = streams_open ? int(std::min<long long>(left.count(), 1000)) : 10;
        if (::poll(polled.data(), n, timeout) < 0 && errno != EINTR)
            throw Error(std::string("cannot wait for ") + argv[0] + ": " + std::strerror(errno));
        for (nfds_t i = 1; i < n; ++i) {
            if (polled[i].revents == 0)
                continue;
            int fd = polled[i].fd;
            if (fd == in_pipe.write.get()) {
                ssize_t w = ::write(fd, pending.data(), pending.size());
                if (w > 0)
                    pending.remove_prefix(std::size_t(w));
                if (pending.empty() || (w < 0 && errno != EAGAIN && errno != EINTR))
                    in_pipe.write.reset();  // end of input (or the helper stopped reading)
            } else if (fd == out_pipe.read.get()) {
                if (!drain(fd, result.output, limits.max_output_bytes, output_total))
                    out_pipe.read.reset();
                if (limits.max_output_bytes > 0 && output_total > limits.max_output_bytes) {
                    child.finish();
                    result.end = ProcessResult::End::output_too_large;
                    return result;
                }
            } else if (fd == err_pipe.read.get()) {
                if (!drain(fd, result.messages, limits.max_message_bytes, message_total))
                    err_pipe.read.reset();
            }
        }
    }
    child.finish();
    if (g_signal != 0)
        throw Interrupted(g_signal);
    int status = child.status();
    if (WIFSIGNALED(status)) {
        result.end = ProcessResult::End::signalled;
        result.exit_code = 128 + WTERMSIG(status);
    } else {
        result.exit_code = WEXITSTATUS(status);
    }
    return result;
}

Coprocess::Coprocess(const std::vector<std::string>& argv, const std::filesystem::path& folder,
                     const ProcessLimits& limits)
{
    if (argv.empty() || argv[0].empty())
        throw Error("no program to run");
    std::vector<char*> args;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const std::string where = folder.empty() ? std::string(".") : folder.string();
    Pipe in_pipe = make_pipe(), out_pipe = make_pipe(), report = make_pipe();
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0)
        throw Error("cannot start " + argv[0] + ": " + std::strerror(errno));
    if (pid == 0)
        exec_child(args.data(), where.c_str(), in_pipe.read.get(), out_pipe.write.get(), -1,
                   report.write.get(), parent, limits);
    ::setpgid(pid, pid);  // also here: no race with a kill before the child's own call
    m_pid = pid;
    LiveGroups::add(pid);
    in_pipe.read.reset();
    out_pipe.write.reset();
    report.write.reset();
    int exec_error = 0;
    ssize_t got;
    do
        got = ::read(report.read.get(), &exec_error, sizeof exec_error);
    while (got < 0 && errno == EINTR);
    if (got == sizeof exec_error) {
        kill();
        throw Error("cannot start " + argv[0] + ": " + std::strerror(exec_error));
    }
    ::fcntl(in_pipe.write.get(), F_SETFL, O_NONBLOCK);
    ::fcntl(out_pipe.read.get(), F_SETFL, O_NONBLOCK);
    m_input = in_pipe.write.release();
    m_output = out_pipe.read.release();
}

Coprocess::~Coprocess()
{
    kill();
}

void Coprocess::close_input()
{
    if (m_input >= 0)
        ::close(m_input);
    m_input = -1;
}

void Coprocess::kill()
{
    close_input();
    if (m_output >= 0)
        ::close(m_output);
    m_output = -1;
    if (m_reaped || m_pid < 0)
        return;
    ::kill(-m_pid, SIGKILL);
    LiveGroups::remove(m_pid);  // before the reaping, after which the id may be reused
    int status = 0;
    for (;;) {
        pid_t r = ::waitpid(m_pid, &status, 0);
        if (r == m_pid || (r < 0 && errno != EINTR))
            break;
    }
    m_reaped = true;
}

Coprocess::Ready Coprocess::wait(bool writing, bool reading, std::chrono::milliseconds timeout)
{
    SignalScope signals;
    std::array<pollfd, 3> polled{};
    nfds_t n = 0;
    polled[n++] = {signals.fd(), POLLIN, 0};
    if (writing && m_input >= 0)
        polled[n++] = {m_input, POLLOUT, 0};
    if (reading && m_output >= 0)
        polled[n++] = {m_output, POLLIN, 0};
    const int ms = int(std::clamp<long long>(timeout.count(), 0, 1 << 30));
    if (g_signal == 0 && ::poll(polled.data(), n, ms) < 0 && errno != EINTR)
        throw Error(std::string("cannot wait for a child program: ") + std::strerror(errno));
    if (g_signal != 0) {
        const int signal = g_signal;
        kill();
        throw Interrupted(signal);
    }
    Ready ready;
    for (nfds_t i = 1; i < n; ++i) {
        if (polled[i].revents == 0)
            continue;
        if (polled[i].fd == m_input)
            ready.input = true;
        else
            ready.output = true;
    }
    return ready;
}

std::ptrdiff_t Coprocess::write_some(std::string_view bytes)
{
    if (m_input < 0)
        return -1;
    // SIGPIPE is blocked for this write and a pending one discarded: EPIPE tells the same
    sigset_t pipe_signal, saved;
    sigemptyset(&pipe_signal);
    sigaddset(&pipe_signal, SIGPIPE);
    ::pthread_sigmask(SIG_BLOCK, &pipe_signal, &saved);
    ssize_t w;
    do
        w = ::write(m_input, bytes.data(), bytes.size());
    while (w < 0 && errno == EINTR);
    const int error = errno;
    if (w < 0 && error == EPIPE) {
        const timespec zero{};
        ::sigtimedwait(&pipe_signal, nullptr, &zero);
    }
    ::pthread_sigmask(SIG_SETMASK, &saved, nullptr);
    if (w >= 0)
        return w;
    return error == EAGAIN || error == EWOULDBLOCK ? 0 : -1;
}

std::ptrdiff_t Coprocess::read_some(char* buffer, std::size_t size)
{
    if (m_output < 0)
        return 0;
    ssize_t r;
    do
        r = ::read(m_output, buffer, size);
    while (r < 0 && errno == EINTR);
    if (r >= 0)
        return r;
    return errno == EAGAIN || errno == EWOULDBLOCK ? -1 : 0;
}

std::string Coprocess::end_description(std::chrono::milliseconds grace)
{
    if (m_reaped)
        return "was stopped";
    const auto deadline = Clock::now() + grace;
    for (;;) {
        siginfo_t info{};
        // WNOWAIT leaves the zombie, so the group id stays ours until kill()
        if (::waitid(P_PID, id_t(m_pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
            info.si_pid == m_pid) {
            if (info.si_code == CLD_EXITED)
                return "exited with status " + std::to_string(info.si_status);
            return "was killed by signal " + std::to_string(info.si_status) + " (" +
                   ::strsignal(info.si_status) + ")";
        }
        if (Clock::now() >= deadline)
            return "is still running";
        ::poll(nullptr, 0, 5);
    }
}

}  // namespace cambium
