// SPDX-License-Identifier: Apache-2.0
// The one rule for every input file Cambium opens: regular files only, size known and
// checked against a limit before anything is read or allocated.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace cambium {

/// The size of `file` when it is a regular file of at most `max_bytes`, for readers that
/// stream a file instead of holding it. A FIFO or device would block or never end, so
/// only regular files pass. Error naming the file (and `what` it is) when it is missing,
/// not a regular file, unreadable or too large.
std::uintmax_t regular_file_size(const std::filesystem::path& file, const char* what,
                                 std::uintmax_t max_bytes);

/// The whole file, at most `max_bytes` (regular_file_size's checks first).
std::string read_file(const std::filesystem::path& file, const char* what,
                      std::uintmax_t max_bytes);

/// The whole binary file, at most `max_bytes` (regular_file_size's checks first).
std::vector<unsigned char> read_binary_file(const std::filesystem::path& file, const char* what,
                                            std::uintmax_t max_bytes);

}  // namespace cambium
