// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the geom tests: strings written as cpfg string text, vector checks,
// the corpus, scratch folders and a unit-square surface file.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "geom/interpreter.h"
#include "geom/scene.h"
#include "geom/vec.h"
#include "geom/view_file.h"
#include "lsys/module_string.h"
#include "lsys/string_io.h"

namespace cambium::geom {

/// Geom tests write their strings as cpfg string text ("F(2) @Gs ?P(0,0,0)") and read
/// them with lsys's own reader, which groups names as the L-system lexer does.
inline lsys::ModuleString text_modules(lsys::SymbolTable& symbols, const std::string& text)
{
    std::istringstream in(text);
    return lsys::read_string_text(in, symbols, "test string");
}

/// The Scene of string text `text` under a view file's text (its folder: the current one),
/// `@L` labels taking their texts from `strings`.
inline Scene interpret_text(const std::string& text, const std::string& view_text = "",
                            std::vector<std::string> strings = {})
{
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, text);
    InterpretOptions options;
    options.strings = strings;
    return interpret(s, symbols, parse_view_file(view_text, "t.v"), options);
}

inline Vec3 v3(const Float3& f) { return {f[0], f[1], f[2]}; }

inline void expect_near(const Vec3& a, const Vec3& b, double eps = 1e-5)
{
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

/// The corpus of cpfg models: $CAMBIUM_CORPUS, or ../shared/corpus beside the project.
inline std::filesystem::path corpus()
{
    const char* env = std::getenv("CAMBIUM_CORPUS");
    return env ? env : CAMBIUM_CORPUS_DEFAULT;
}

/// A scratch folder of this test process (`name` keeps test binaries apart).
inline std::filesystem::path temp_dir(const std::string& name)
{
    auto dir = std::filesystem::temp_directory_path() / ("cambium_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return dir;
}

/// One Bézier patch whose control point (i, j) is (j/3, i/3, 0): the unit square.
/// Contact (0,0,0), end (0,1,0), heading +y, up +z, SIZE 1: the prototype frame equals
/// the file's, times the view file's scale.
inline std::string unit_square_surface()
{
    std::string s = "0 1 0 1 0 0\nCONTACT POINT X: 0 Y: 0 Z: 0\nEND POINT X: 0 Y: 1 Z: 0\n"
                    "HEADING X: 0 Y: 1 Z: 0\nUP X: 0 Y: 0 Z: 1\nSIZE: 1\n"
                    "square\nTOP COLOR: 0 DIFFUSE: 0.00 BOTTOM COLOR: 0 DIFFUSE: 0.00\n"
                    "AL: ~ A: ~ AR: ~\nL: ~ R: ~\nBL: ~ B: ~ BR: ~\n";
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j)
            s += std::to_string(j / 3.0) + " " + std::to_string(i / 3.0) + " 0  ";
        s += "\n";
    }
    return s;
}

}  // namespace cambium::geom
