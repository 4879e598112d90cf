// SPDX-License-Identifier: Apache-2.0
// The numbers a Scene may hold: what Embree's float BVH and rays can take.
//
// Embree asserts (and aborts the process) on a ray whose origin or direction is beyond
// 1.844e18 or not finite, also for the rays it moves into an instance's frame, and a BVH
// over non-finite bounds is garbage. The limits below keep every ray within that:
// geometry within max_coordinate of the origin, camera rays starting within
// max_ray_origin (a ray moved to a front clipping plane may start farther: beyond
// max_ray_start it has passed all geometry and render skips it), instances scaling by at
// least min_instance_scale (an instance's inverse grows a world ray by at most
// 1 / min_instance_scale: 1e6 x (4e11 + 1e10) < 1.8e18).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "geom/scene.h"

namespace cambium::geom {

/// Largest coordinate, radius or tangent kept in a scene (docs/security.md).
inline constexpr double max_coordinate = 1e10;
/// Farthest from the origin that a camera ray may start (render checks its camera).
inline constexpr double max_ray_origin = 1e11;
/// Farthest from the origin that any traced ray starts; rays beyond are skipped.
inline constexpr double max_ray_start = 4 * max_ray_origin;
/// Smallest and largest scale of an instance's placement.
inline constexpr double min_instance_scale = 1e-6;
inline constexpr double max_instance_scale = 1e6;

/// Whether |v| <= max_coordinate (false for NaN and infinities).
inline bool in_range(double v) { return v >= -max_coordinate && v <= max_coordinate; }

/// The integer a module parameter or a file's number stands for, truncated toward zero
/// as cpfg's C casts do; nothing when it is not finite or beyond +-1e9 (where a cast to
/// int would be undefined behaviour). Every float-to-int of user data goes through it.
inline std::optional<int> whole_number(double v)
{
    if (!(v >= -1e9 && v <= 1e9))
        return std::nullopt;
    return static_cast<int>(v);
}

/// What drop_unrenderable removed or repaired, per kind.
struct DroppedGeometry {
    std::size_t line_segments = 0, curve_segments = 0, spheres = 0, discs = 0, triangles = 0;
    std::size_t instances = 0;
    std::size_t attributes = 0;  ///< normals, texture coordinates set to 0

    std::size_t total() const
    {
        return line_segments + curve_segments + spheres + discs + triangles + instances + attributes;
    }
};

/// Drops every primitive (of the scene and of its prototypes) with a position, radius,
/// tangent or normal that is not finite or beyond max_coordinate, and every instance
/// whose placement is not finite, scales beyond [min_instance_scale,
/// max_instance_scale] or puts its prototype beyond max_coordinate; non-finite normals
/// and texture coordinates become 0. One warning per kind names the count. Throws Error
/// when the view volume (Scene::bounds: turtle positions, surfaces) reaches beyond
/// max_coordinate, since no camera could frame it.
DroppedGeometry drop_unrenderable(Scene& scene);

/// Elements a buffer Embree reads in place keeps allocated (and initialised) past its
/// end: Embree loads the last vertex with a 16-byte load (rtcSetSharedGeometryBuffer).
inline constexpr std::size_t embree_padding_bytes = 16;

/// Whether `v` has room for Embree's loads past its last element, so that render may let
/// Embree read it in place instead of copying it (fit_mesh_buffers makes that room).
template <class T>
bool padded_for_embree(const std::vector<T>& v)
{
    return !v.empty() && (v.capacity() - v.size()) * sizeof(T) >= embree_padding_bytes;
}

/// Shrinks `v` to its size, leaving room for `pad_bytes` more (value-initialised), such as
/// embree_padding_bytes for a buffer Embree reads in place.
template <class T>
void fit_buffer(std::vector<T>& v, std::size_t pad_bytes = 0)
{
    std::size_t pad = (pad_bytes + sizeof(T) - 1) / sizeof(T);
    if (v.empty()) {
        std::vector<T>().swap(v);  // `v = {}` keeps the capacity
        return;
    }
    if (v.capacity() == v.size() + pad)
        return;
    std::vector<T> fitted;
    fitted.reserve(v.size() + pad);
    fitted.assign(v.begin(), v.end());
    fitted.resize(v.size() + pad);  // within the capacity: initialises the padding
    fitted.resize(v.size());
    v.swap(fitted);
}

/// Gives a mesh's buffers back their growth slack, leaving positions and triangles padded
/// for Embree to read in place (a leaf's vertex lives once, not both in the Scene and
/// in Embree), and drops what no hit reads: texture indices when none is set,
/// texture coordinates when all are zero (render reads a missing uv as 0) or when nothing
/// textures the mesh (`textured_by_instances`: a prototype whose instances bring a texture).
void fit_mesh_buffers(TriangleMesh& mesh, bool textured_by_instances);
/// fit_mesh_buffers for the scene's mesh and every prototype's; instances give back their
/// growth slack too.
void fit_scene_buffers(Scene& scene);

/// The bytes a geometry's primitive arrays have allocated (their capacities): what the
/// memory budget checks during interpretation.
std::size_t geometry_bytes(const Geometry& g);
/// The same for a whole Scene: its geometry, its prototypes' and its instances
/// (Cambium's own share of a render's memory, --stats).
std::size_t scene_buffer_bytes(const Scene& scene);

}  // namespace cambium::geom
