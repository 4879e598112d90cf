// SPDX-License-Identifier: Apache-2.0
// A VectorDrawing as PostScript (cpfg's -ps, manual 6.2), SVG or PDF, drawn once through
// cairo onto the format's surface.
#pragma once

#include <filesystem>

#include "base/output_format.h"
#include "render/vector_drawing.h"

namespace cambium::render {

/// Writes `drawing` as `file` in `format`: one page of the window's size (a pixel is a
/// point), the background filled, then each shape in the drawing's order (triangles
/// filled, lines stroked with round caps). The file appears whole or not at all; throws
/// cambium::Error naming it.
void write_vector(const VectorDrawing& drawing, const std::filesystem::path& file,
                  VectorFormat format);

}  // namespace cambium::render
