// SPDX-License-Identifier: Apache-2.0
// Geom tests write their strings as cpfg string text ("F(2) @Gs ?P(0,0,0)") and read
// them with lsys's own reader, which groups names as the L-system lexer does.
#pragma once

#include <sstream>
#include <string>

#include "lsys/module_string.h"
#include "lsys/string_io.h"

namespace cambium::geom {

inline lsys::ModuleString text_modules(lsys::SymbolTable& symbols, const std::string& text)
{
    std::istringstream in(text);
    return lsys::read_string_text(in, symbols, "test string");
}

}  // namespace cambium::geom
