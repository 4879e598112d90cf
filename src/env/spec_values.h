// SPDX-License-Identifier: Apache-2.0
// Values of specification-file lines, read as vlab's programs read them: the value is
// cut into tokens at blanks, commas, semicolons, colons and the letter 'x' ("32x32x32").
#pragma once

#include <cmath>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "env/environment.h"

namespace cambium::env {

/// The value's tokens, cut at " \t,;:x".
std::vector<std::string> value_tokens(const SpecLine& line);

/// The first `count` tokens as numbers; Error naming the line when one is missing or is
/// not a number.
std::vector<double> numbers_value(const SpecLine& line, std::size_t count);

/// The first `at_most` numbers of the value (fewer when fewer tokens are written: the
/// programs keep their defaults for the rest).
std::vector<double> leading_numbers(const SpecLine& line, std::size_t at_most);

/// The first token as a number (numbers_value(line, 1)[0]).
double number_value(const SpecLine& line);

/// Whether the first token is one of `words` ("on", "yes": each program has its own).
bool switch_value(const SpecLine& line, std::initializer_list<const char*> words);

/// A text file's lines that hold more than blanks, numbered from 1, without a trailing
/// carriage return: how `.e` and specification files are read.
std::vector<std::pair<int, std::string>> non_blank_lines(const std::string& text);

/// The group a ?E parameter names, as the programs' int conversion of it: the value
/// truncated toward zero, kept as a double so that a value no int holds (which C's
/// conversion leaves undefined) names a group of its own and NaN names none (it equals
/// nothing).
inline double group_of(float parameter) { return std::trunc(static_cast<double>(parameter)); }

/// The specification file named by a program's arguments: the first argument that is
/// not an option. Error naming the program when there is none.
std::string spec_argument(const std::string& program, const std::vector<std::string>& args);

}  // namespace cambium::env
