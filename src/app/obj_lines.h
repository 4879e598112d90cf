// SPDX-License-Identifier: Apache-2.0
// An OBJ file's statements, read within the scene limits: what the ground mesh and the
// meshes entry both read (app/placement.cpp, app/obj_model.cpp).
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/scene_file.h"
#include "base/diagnostics.h"
#include "base/input_file.h"

namespace cambium::app {

/// Reads `file` (at most limits.max_mesh_bytes) line by line, handing each statement's
/// keyword, the rest of its words, its text and its location to `each`; a line is read
/// into a buffer of limits.max_mesh_line_bytes, never grown; comments are skipped.
template <typename Each>
void for_each_obj_line(const std::filesystem::path& file, const char* what, const SceneLimits& limits, Each each)
{
    regular_file_size(file, what, limits.max_mesh_bytes);
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw Error(FileLoc{file.string()}, std::string("cannot read ") + what);
    std::vector<char> buffer(limits.max_mesh_line_bytes + 1);
    int line = 0;
    while (in.getline(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0) {
        ++line;
        FileLoc loc{file.string(), line, 1};
        if (in.fail() && !in.eof()) {
            loc.column = int(limits.max_mesh_line_bytes) + 1;
            throw Error(loc, "the line is longer than " +
                                 std::to_string(limits.max_mesh_line_bytes) + " bytes");
        }
        std::string text(buffer.data());
        if (!text.empty() && text.back() == '\r')
            text.pop_back();
        std::istringstream words(text);
        std::string kind;
        words >> kind;
        if (!kind.empty() && kind[0] != '#')
            each(kind, words, text, loc);
    }
}

}  // namespace cambium::app
