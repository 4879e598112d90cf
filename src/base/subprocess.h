// SPDX-License-Identifier: Apache-2.0
// Runs a helper program (the C preprocessor, an allowed @S command) without a shell,
// bounded in time, output and memory, and never outliving an interrupted cambium.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"

namespace cambium {

/// What a helper program may use. Zero means "no limit" for every field.
struct ProcessLimits {
    double wall_seconds = 30;                   ///< killed after this long
    std::size_t max_output_bytes = 64u << 20;   ///< standard output kept; more kills it
    std::size_t max_message_bytes = 64u << 10;  ///< standard error kept (the rest dropped)
    std::size_t max_memory_bytes = 1u << 30;    ///< address space (RLIMIT_AS)
};

/// How a helper program ended.
struct ProcessResult {
    enum class End {
        exited,            ///< on its own; see exit_code
        signalled,         ///< killed by a signal it did not get from us
        timed_out,         ///< ran past ProcessLimits::wall_seconds
        output_too_large,  ///< wrote more than ProcessLimits::max_output_bytes
        not_found,         ///< the program could not be started (see messages)
    };
    End end = End::exited;
    int exit_code = 0;
    std::string output;    ///< standard output (when captured)
    std::string messages;  ///< standard error (when captured)
};

/// Where a helper program's standard streams go.
struct ProcessIo {
    /// Given: written to its standard input through a pipe. Not given: /dev/null.
    std::optional<std::string_view> input;
    /// True: standard output and error are captured into ProcessResult. False: they
    /// are cambium's own (an @S command talks to the user as under cpfg).
    bool capture = true;
};

/// Thrown when SIGINT, SIGTERM or SIGHUP arrives while a helper runs: the helper and
/// everything it started are killed and reaped first. main() exits with 128 + signal.
class Interrupted : public Error {
public:
    explicit Interrupted(int signal);
    int signal() const { return m_signal; }

private:
    int m_signal;
};

/// Runs `argv` (argv[0] found through PATH, no shell) in `folder`, in a process group
/// of its own so a time-out or an interrupt kills its children too (cpp runs cc1).
/// It dies with cambium (PR_SET_PDEATHSIG) even if cambium is killed. Throws
/// Interrupted; other failures are reported in the result.
ProcessResult run_process(const std::vector<std::string>& argv, const std::filesystem::path& folder,
                          const ProcessIo& io, const ProcessLimits& limits);

/// A child program that runs beside cambium for a long time and talks to it through
/// two pipes (its standard input and output; standard error stays cambium's). Started
/// as run_process starts one: no shell, in `folder`, in a process group of its own,
/// dying with cambium. The whole group is killed and the program reaped on destruction.
class Coprocess {
public:
    /// Starts `argv` (argv[0] found through PATH); Error naming it when it cannot start.
    /// Only `limits.max_memory_bytes` applies: the caller bounds time and output.
    Coprocess(const std::vector<std::string>& argv, const std::filesystem::path& folder,
              const ProcessLimits& limits);
    ~Coprocess();
    Coprocess(const Coprocess&) = delete;
    Coprocess& operator=(const Coprocess&) = delete;

    /// What poll found: its input takes bytes, its output has bytes (or ended).
    struct Ready {
        bool input = false, output = false;
    };
    /// Waits at most `timeout` for its input to take bytes (`writing`) or its output to
    /// have some (`reading`). When SIGINT, SIGTERM or SIGHUP arrives meanwhile, the
    /// program's group is killed and Interrupted thrown.
    Ready wait(bool writing, bool reading, std::chrono::milliseconds timeout);
    /// Writes what its input takes now: the bytes written, 0 when the pipe is full, -1
    /// when the program no longer reads (never SIGPIPE).
    std::ptrdiff_t write_some(std::string_view bytes);
    /// Reads what its output has now: the bytes read, 0 at its end, -1 when none yet.
    std::ptrdiff_t read_some(char* buffer, std::size_t size);
    /// Closes its standard input (the program reads end of file).
    void close_input();
    /// How it ended ("exited with status 3", "was killed by signal 11 (Segmentation
    /// fault)"), waiting at most `grace` for it; "is still running" otherwise.
    std::string end_description(std::chrono::milliseconds grace);
    /// Kills its group and reaps it. Idempotent.
    void kill();
    pid_t pid() const { return m_pid; }

private:
    pid_t m_pid = -1;
    int m_input = -1, m_output = -1;
    bool m_reaped = false;
};

}  // namespace cambium
