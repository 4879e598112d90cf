// SPDX-License-Identifier: Apache-2.0
// External environmental programs (manual 7.4): a program started once for a derivation
// run, speaking cpfg's text protocol through its standard input and output.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>

#include "env/comm_spec.h"
#include "env/environment.h"

namespace cambium::env {

/// What an external program may take; a program past any of them ends the run.
struct ExternalLimits {
    /// Seconds for the start (its confirmation byte), each pass, and the goodbye.
    double seconds_per_pass = 60;
    /// Longest line it may write (an answer, a `Control:` line).
    std::size_t max_line_bytes = 64u << 10;
    /// Bytes it may write in one pass.
    std::size_t max_pass_bytes = 64u << 20;
    /// Address space of the program (RLIMIT_AS); 0: no limit.
    std::size_t max_memory_bytes = 0;
    /// Not empty: a folder made by prepare_message_folder, where each pass's messages
    /// are written as text (`step003.to`, `step003.from`).
    std::filesystem::path message_folder;
};

/// Starts the program a `.e` file names (`-e <file.e>` inserted after the program's
/// name, as cpfg does) in the model folder, and waits for its start-up byte. Pipes are
/// spoken whatever the `communication type:`: for files, memory or sockets the program
/// is given a private copy of the `.e` saying pipes. With `interpreted modules:`, a query
/// whose following module is named carries its polygons between `Dbegin` and `Dend`
/// lines, as vlab's library reads them. Errors name the program.
std::unique_ptr<Environment> make_external_program(const CommSpec& spec, const Context& context,
                                                   const ExternalLimits& limits);

/// Makes `folder` private (0700) for message logs: created when missing; an existing one
/// must be an empty real directory (not a link). Error otherwise.
void prepare_message_folder(const std::filesystem::path& folder);

}  // namespace cambium::env
