// SPDX-License-Identifier: Apache-2.0
// cpfg's view-volume file (-vv): the bounding box of the interpreted geometry, in the
// syntax of the view file's `box:` command (manual 3.4 and 5.2.2).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "geom/vec.h"

namespace cambium::geom {

/// "box: x: xmin,xmax y: ymin,ymax z: zmin,zmax" with C's %g, as cpfg writes it.
std::string format_view_volume(const Bounds3& box);

/// Writes format_view_volume(box) and a newline to `file` (through a temporary name).
/// Throws cambium::Error when the file cannot be written.
void write_view_volume(const Bounds3& box, const std::filesystem::path& file);

/// Reads a line written by cpfg's -vv back. Throws cambium::Error naming the file.
Bounds3 parse_view_volume(std::string_view text, const std::string& file_name);

}  // namespace cambium::geom
