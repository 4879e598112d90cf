// SPDX-License-Identifier: Apache-2.0
// Runs an L-system file through the system C preprocessor, keeping cpfg's tab and `#(` lines.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cambium::lsys {

/// How to run the preprocessor. cpp runs without a shell in the model's folder with
/// the protected text on a pipe as its input (never a temporary file, never the
/// user's standard input), so `#include "x"` is looked up from the model's folder,
/// then in `include_dirs`; system folders are not searched (-nostdinc).
struct PreprocessOptions {
    std::vector<std::string> defines;         ///< NAME or NAME=VALUE, passed as -D
    std::filesystem::path folder;             ///< the model's folder ("" = the current one)
    std::vector<std::filesystem::path> include_dirs;  ///< searched after `folder`; empty ones skipped
    std::string preprocessor = "cpp";         ///< the program to run
    std::size_t max_input_bytes = 16u << 20;  ///< larger inputs are refused
    std::size_t max_output_bytes = 64u << 20;  ///< larger preprocessed text stops cpp
    double max_seconds = 20;                  ///< cpp is stopped after this long
    std::size_t max_memory_bytes = 1u << 30;  ///< cpp's address space
    /// When set, every file cpp includes must lie in this folder or below once `..` and
    /// links are resolved (the model's folder: a model file reads nothing outside it,
    /// docs/security.md). Unset (--allow-file-access): includes may name any file.
    std::optional<std::filesystem::path> confine_to;
};

/// Preprocesses `source`, read from `file_name`. The result keeps cpp's line markers
/// (`# 12 "plant.l"`) naming `file_name`, a leading tab on every line that had one, and
/// every line whose first non-blank characters are `#(`. Throws cambium::Error (at the
/// line of the directive where known) when the preprocessor is missing, reports an
/// error, runs past a limit, or an `#include` names a device, FIFO or folder, or a file
/// outside options.confine_to.
std::string preprocess(std::string_view source, std::string_view file_name,
                       const PreprocessOptions& options);

/// The protection applied before cpp: a leading tab and a leading `#(` become marker
/// words that cpp passes through. Exposed for tests.
std::string protect_cpfg_lines(std::string_view source);
/// Undoes protect_cpfg_lines on cpp's output.
std::string restore_cpfg_lines(std::string_view text);

}  // namespace cambium::lsys
