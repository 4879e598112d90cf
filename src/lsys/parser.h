// SPDX-License-Identifier: Apache-2.0
// Recursive-descent parser of preprocessed cpfg L-system text into a compiled Program.
#pragma once

#include <string_view>

#include "lsys/program.h"

namespace cambium::lsys {

/// Parses preprocessed text (with cpp line markers naming the original file) into
/// `program`. Throws cambium::Error "file:line:col: error: expected ..." on bad input.
/// After an error in a production or a one-line header item (or the axiom) the parser
/// goes on at the next line; every error is reported (ErrorList) and one Error listing
/// them all ("file: error: 3 errors:" and one a line) is thrown at the end.
void parse_program(std::string_view preprocessed, const std::string& file_name, Program& program);

}  // namespace cambium::lsys
