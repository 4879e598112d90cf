// SPDX-License-Identifier: Apache-2.0
// Reading cpfg's small text formats: bounded file reads, comment removal, value tokens.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "base/input_file.h"

namespace cambium::geom {

/// Largest text input file read (view files, surfaces, contours...): 64 MiB.
constexpr std::uintmax_t max_text_file_bytes = 64u << 20;

/// read_file with the text files' limit (max_text_file_bytes).
std::string read_text_file(const std::filesystem::path& file, const char* what);

struct SourceLine {
    int number;        ///< 1-based
    std::string text;  ///< the line with C comments blanked out (columns are kept)
};

/// Splits text into lines, replacing /* ... */ and // ... comments with spaces.
std::vector<SourceLine> split_lines_without_comments(std::string_view text);

/// "  Initial   Color " -> "initial color"
std::string normalize_command_name(std::string_view name);

/// Reads whitespace- or comma-separated values from one line, knowing their columns.
class ValueReader {
public:
    /// Reads `line` from byte `start`; `line_loc` gives file and line (column unused).
    ValueReader(std::string_view line, std::size_t start, FileLoc line_loc);

    bool at_end();
    double number();
    int integer();
    /// A word of letters, digits, '.', '_', '-', lower-cased; `what` names it in errors.
    std::string word(const char* what);
    /// `on` or `off`.
    bool on_off();
    /// A run of characters other than blanks and ',', case kept (a file or font name).
    std::string name(const char* what);
    /// The rest of the line, consumed, without leading or trailing blanks.
    std::string rest();
    /// A one-letter subcommand such as "O:" or "D" (the colon is optional); upper-cased.
    char subcommand(const char* what);
    /// Expects `label` followed by an optional ':' (as in "x: 0,1").
    void expect_label(const std::string& label);

    /// The location of the next token.
    FileLoc loc();
    Error error(const std::string& message);

private:
    void skip_separators();

    std::string_view m_line;
    std::size_t m_pos;
    FileLoc m_loc;
};

}  // namespace cambium::geom
