// SPDX-License-Identifier: Apache-2.0
// Runs a helper program (the C preprocessor, an allowed @S command) without a shell,
// bounded in time, output and memory, and never outliving an interrupted cambium.
#pragma once

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

}  // namespace cambium
