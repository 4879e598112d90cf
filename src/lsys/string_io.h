// SPDX-License-Identifier: Apache-2.0
// Reading and writing L-system strings in cpfg's text (-str) and binary (-strb) formats.
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>

#include "lsys/module_string.h"

namespace cambium::lsys {

/// Limits on what a string file may make (malformed or hostile input stops with an Error).
struct StringReadLimits {
    std::size_t max_modules = 100'000'000;
};

/// cpfg's text string output (manual section 6.3, cpfg's SaveTextModule): every module
/// name character by character, parameters as "(%g,%g)", and a line break before a
/// character once 70 or more are on the line. cpfg counts the symbol characters, the
/// parentheses and the printed numbers but not the commas; the file ends with a newline.
void write_string_text(const ModuleString& string, const SymbolTable& symbols, std::ostream& out);

/// cpfg's binary string dump (-strb): "L-system string:" then "<bytes> <step>\n", then
/// cpfg's own string bytes: each name character, and after a module's last character
/// '(' p1 ',' p2 ... ')' with every parameter as a 4-byte native (little-endian) float.
void write_string_binary(const ModuleString& string, const SymbolTable& symbols,
                         std::ostream& out, int step = 0);

/// Reads a text string: blanks and line breaks are skipped, characters become modules
/// grouped into names as the L-system lexer groups them (@Gs, ~l, ?P), parameters are
/// read as floats. `source` names the input in error messages.
ModuleString read_string_text(std::istream& in, SymbolTable& symbols,
                              std::string_view source = "<string>",
                              const StringReadLimits& limits = {});
ModuleString read_string_text(const std::filesystem::path& file, SymbolTable& symbols,
                              const StringReadLimits& limits = {});

/// Reads a binary string dump; `step` (when given) receives the derivation step stored.
ModuleString read_string_binary(std::istream& in, SymbolTable& symbols,
                                std::string_view source = "<string>", int* step = nullptr,
                                const StringReadLimits& limits = {});
ModuleString read_string_binary(const std::filesystem::path& file, SymbolTable& symbols,
                                int* step = nullptr, const StringReadLimits& limits = {});

/// An output name for frame `frame` from a printf-style pattern such as "plant%03d.str".
/// The pattern may hold at most one integer conversion (%d %i %u %o %x %X with flags,
/// width and precision) and any number of "%%"; anything else throws cambium::Error.
/// A pattern without a conversion is returned as is (with "%%" made "%").
std::string format_frame_name(std::string_view pattern, int frame);

/// Whether `pattern` holds an integer conversion (the name changes with the frame).
bool is_frame_pattern(std::string_view pattern);

}  // namespace cambium::lsys
