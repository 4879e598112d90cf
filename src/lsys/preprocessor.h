// SPDX-License-Identifier: Apache-2.0
// Runs an L-system file through the system C preprocessor, keeping cpfg's tab and `#(` lines.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace cambium::lsys {

/// How to run the preprocessor.
struct PreprocessOptions {
    std::vector<std::string> defines;         ///< NAME or NAME=VALUE, passed as -D
    std::vector<std::filesystem::path> include_dirs;  ///< passed as -I
    std::string preprocessor = "cpp";         ///< the program to run
    std::size_t max_input_bytes = 16u << 20;  ///< larger inputs are refused
};

/// Preprocesses `source`, read from `file_name`. The result keeps cpp's line markers
/// (`# 12 "plant.l"`) naming `file_name`, a leading tab on every line that had one, and
/// every line whose first non-blank characters are `#(`. Throws cambium::Error when
/// the preprocessor is missing or reports an error.
std::string preprocess(std::string_view source, std::string_view file_name,
                       const PreprocessOptions& options);

/// The protection applied before cpp: a leading tab and a leading `#(` become marker
/// words that cpp passes through. Exposed for tests.
std::string protect_cpfg_lines(std::string_view source);
/// Undoes protect_cpfg_lines on cpp's output.
std::string restore_cpfg_lines(std::string_view text);

}  // namespace cambium::lsys
