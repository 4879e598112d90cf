// SPDX-License-Identifier: Apache-2.0
// Geometry moved into place by an instance's transform: what flattening an instance
// (drawing its prototype's primitives directly in the parent's frame) takes.
#pragma once

#include <cstdint>

#include "geom/scene.h"

namespace cambium::geom {

/// Moves `geometry` (a prototype's) by `instance`: points by its 3x4 transform, normals
/// by the inverse transpose, curve and sphere radii by the transform's mean scale (the
/// cube root of its determinant; exact for the rigid and uniformly scaled transforms of
/// objects and scene placements, approximate for radii under non-uniform scale), and
/// replaces inherit_material and untextured primitives by the instance's material and
/// texture, as the renderer does for instances.
void place_geometry(Geometry& geometry, const Instance& instance);

/// Adds `offset` to every texture index other than no_texture.
void offset_textures(Geometry& geometry, std::int16_t offset);

}  // namespace cambium::geom
