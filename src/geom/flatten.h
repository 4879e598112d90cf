// SPDX-License-Identifier: Apache-2.0
// Small instanced surfaces drawn in place: a ray through a plant of many small
// instances (Lilac's 3 090 petals of 80 triangles) otherwise walks a BVH of instance
// boxes and then, for each box it enters, the prototype's own BVH.
#pragma once

#include <cstddef>
#include <cstdint>

#include "geom/scene.h"

namespace cambium::geom {

/// How far flatten_small_instances goes: only prototypes of triangles alone, each of at
/// most `max_prototype_triangles`, and only when all their placed copies together have
/// at most `max_total_triangles` (the memory instancing saves stays saved for large
/// scenes: meadows and forests place thousands of larger prototypes).
struct FlattenLimits {
    std::size_t max_prototype_triangles = 4096;
    std::size_t max_total_triangles = std::size_t{1} << 19;
    /// What the placed copies may add to the scene's arrays (their vertices and
    /// triangles as stored): a run's --max-memory budget bounds them too.
    std::uint64_t max_bytes = std::uint64_t{1} << 28;
};

/// Places a copy of every small prototype's mesh at each of its instances in the scene's
/// own mesh (geom::place_geometry: the same materials, textures and faces as the
/// instance shows) and drops those instances and the prototypes no instance uses any
/// more; nothing changes when the copies would pass the limits. Returns how many
/// instances were drawn in place.
std::size_t flatten_small_instances(Scene& scene, const FlattenLimits& limits = {});

}  // namespace cambium::geom
