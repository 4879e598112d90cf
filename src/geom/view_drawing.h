// SPDX-License-Identifier: Apache-2.0
// The view file's drawing commands (render mode, generalized cylinders, surfaces,
// functions, curves, background scenes, labels, colour-index lighting, rayshade output)
// and the ones that only concern cpfg's OpenGL window: the half of view_file.cpp's
// reader that does not place the turtle, the camera or the lights.
#pragma once

#include <string>

#include "geom/text_input.h"
#include "geom/view_file.h"

namespace cambium::geom {

/// Whether `name` is a drawing command or one of cpfg's window-only commands.
bool is_drawing_command(const std::string& name);

/// Applies the drawing command `name` (is_drawing_command) whose value `in` reads; a
/// malformed value is an Error at its column.
void apply_drawing_command(ViewFile& v, const std::string& name, ValueReader& in);

}  // namespace cambium::geom
