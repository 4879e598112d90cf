// SPDX-License-Identifier: Apache-2.0
// User-facing diagnostics: source locations, errors that name them, and warnings.
#pragma once

#include <stdexcept>
#include <string>

namespace cambium {

/// A position in a user's input file (1-based line and column; 0 = unknown).
struct FileLoc {
    std::string file;
    int line = 0;
    int column = 0;

    /// "file:line:col", "file:line" or "file", as much as is known.
    std::string to_string() const;
};

/// An error in user input or in the environment that ends the command.
/// what() is the complete message, e.g. "plant.l:12:7: error: expected '-->'".
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message);
    Error(const FileLoc& loc, const std::string& message);

    const FileLoc& loc() const { return m_loc; }

private:
    FileLoc m_loc;
};

/// Prints "loc: warning: message" to stderr (the same message at most once).
void warn(const FileLoc& loc, const std::string& message);
void warn(const std::string& message);

/// Silences or restores warnings (tests and -q use it).
void set_warnings_enabled(bool enabled);

}  // namespace cambium
