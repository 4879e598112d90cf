// SPDX-License-Identifier: Apache-2.0
#include "geom/flatten.h"

#include <limits>

#include "geom/background_scene.h"
#include "geom/placed_geometry.h"
#include "geom/primitives.h"

namespace cambium::geom {

namespace {

/// Whether the prototype is triangles alone, few enough to draw in place.
bool small_mesh(const Prototype& p, const FlattenLimits& limits)
{
    const Geometry& g = p.geometry;
    return g.mesh.size() > 0 && primitive_count(g) == g.mesh.size() &&
           g.mesh.size() <= limits.max_prototype_triangles;
}

/// What a copy of the mesh takes in the scene's arrays.
std::uint64_t mesh_bytes(const TriangleMesh& m)
{
    return m.positions.size() * sizeof(Float3) + m.normals.size() * sizeof(Float3) +
           m.uvs.size() * sizeof(Float2) + m.triangles.size() * sizeof(m.triangles[0]) +
           m.size() * (sizeof(std::uint16_t) * 2 + sizeof(std::int16_t));
}

}  // namespace

std::size_t flatten_small_instances(Scene& scene, const FlattenLimits& limits)
{
    std::vector<bool> small(scene.prototypes.size());
    for (std::size_t p = 0; p < scene.prototypes.size(); ++p)
        small[p] = small_mesh(scene.prototypes[p], limits);
    std::size_t total = 0, flattened = 0;
    std::uint64_t bytes = 0;
    for (const Instance& in : scene.instances)
        if (in.prototype < small.size() && small[in.prototype]) {
            const TriangleMesh& m = scene.prototypes[in.prototype].geometry.mesh;
            total += m.size();
            bytes += mesh_bytes(m);
            ++flattened;
        }
    if (flattened == 0 || total > limits.max_total_triangles || bytes > limits.max_bytes)
        return 0;

    // The kept instances, their prototypes renumbered in order of first use.
    constexpr std::uint32_t unused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> renumbered(scene.prototypes.size(), unused);
    std::vector<Prototype> kept_prototypes;
    std::vector<Instance> kept;
    for (const Instance& in : scene.instances) {
        if (in.prototype < small.size() && small[in.prototype]) {
            Geometry copy;
            copy.mesh = scene.prototypes[in.prototype].geometry.mesh;
            if (in.module != no_module)  // provenance: the copies are the placing module's
                copy.mesh.module.assign(copy.mesh.size(), in.module);
            place_geometry(copy, in);
            append_geometry(scene.geometry, copy);
            continue;
        }
        Instance moved = in;
        if (in.prototype < renumbered.size()) {
            if (renumbered[in.prototype] == unused) {
                renumbered[in.prototype] = static_cast<std::uint32_t>(kept_prototypes.size());
                kept_prototypes.push_back(std::move(scene.prototypes[in.prototype]));
            }
            moved.prototype = renumbered[in.prototype];
        }
        kept.push_back(moved);
    }
    scene.prototypes = std::move(kept_prototypes);
    scene.instances = std::move(kept);
    return flattened;
}

}  // namespace cambium::geom
