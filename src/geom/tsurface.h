// SPDX-License-Identifier: Apache-2.0
// Tsurfaces (CPFG manual 5.4.6): surfaces given as triangles in rayshade-like text.
#pragma once

#include <string>
#include <string_view>

#include "geom/surface.h"

namespace cambium::geom {

/// Most triangles one tsurface file may hold.
inline constexpr std::size_t max_tsurface_triangles = 4u << 20;

/// Reads tsurface text as cpfg does: only lines whose first token starts with
/// `triangle` open a triangle; the next lines give its 3 vertices, 6 or 8 numbers each
/// (x y z nx ny nz [u v]; tokens separated by blanks, tabs, ',' or ':'; numbers after
/// the eighth are ignored; a vertex ends with the line on which it reached 3 numbers,
/// missing normal or uv values are 0). Positions are multiplied by command.scale; the
/// prototype frame is the turtle frame (x = L, y = H, z = U), as for `.s` surfaces.
/// Triangles carry inherit_material and the command's fixed texture or no_texture; the
/// vertex order and normals are the file's (a zero normal is replaced by the face
/// normal). A triangle left unfinished at the end of the text is an Error naming the
/// line of its `triangle`; a token that is not a number is an Error at its column.
SurfaceDef parse_tsurface_text(std::string_view text, const std::string& file_name,
                               const SurfaceCommand& command);

}  // namespace cambium::geom
