// SPDX-License-Identifier: Apache-2.0
// Every primitive of a Scene as triangles: what mesh formats (OBJ, PLY, GLS) and an
// environmental program (`interpreted modules:`) receive instead of round primitives.
#pragma once

#include <cstddef>

#include "geom/scene.h"

namespace cambium::geom {

/// How round primitives become triangles.
struct Tessellation {
    int sides = 12;          ///< around a cylinder, disc or sphere (meridians)
    int curve_pieces = 4;    ///< along one generalized-cylinder segment
    /// Cylinders (F, G) closed as the renderer closes them: a disc on each free end and,
    /// at each joint bent by more than about 0.8 degrees, the part of the joint's sphere
    /// between the two segments (geom/line_ends.h). Off: open walls.
    bool closed_lines = true;
};

/// How the vector drawing (-ps, .svg, .pdf; render/vector_drawing.h) tessellates:
/// cylinders stay open, as painting far to near by centres would paint a branch's base
/// disc, inside its parent, over the parent's wall.
inline constexpr Tessellation drawing_tessellation{12, 4, false};

/// How far a Scene's primitive arrays had grown at one moment of interpretation.
struct GeometryMark {
    std::size_t line_segments = 0, curve_segments = 0, spheres = 0, discs = 0, triangles = 0;
    std::size_t instances = 0;
};

GeometryMark geometry_mark(const Scene& scene);

/// Appends to `out` (smooth normals; uvs where the scene's mesh has them, else zero;
/// the front material, texture and module: an instance's module for its primitives)
/// every primitive `scene` gained since `since`:
/// triangles as they are; line segments as their side walls, with closed_lines a fan of
/// `sides` on each free end and, at each bent joint, the zone of the joint's sphere
/// the end ring sweeps turning to the next segment, one ring of `sides` per 360 /
/// `sides` degrees of bend (the renderer's discs and joint spheres); generalized-cylinder
/// segments as their side walls, open at the ends as the renderer's round Hermite curves
/// are; spheres as `sides` meridians and half as many parallels, discs as fans, and the
/// primitives of placed instances (predefined surfaces, objects) moved into place.
/// Lines measured in pixels (`line style: pixel`) have no size in the scene and give
/// nothing.
void tessellate_since(const Scene& scene, const GeometryMark& since, const Tessellation& how,
                      TriangleMesh& out);

/// The whole scene as triangles.
TriangleMesh tessellate(const Scene& scene, const Tessellation& how);

/// One Geometry's own primitives as triangles in its own frame (a prototype's before any
/// instance places it), each with its primitive's module where the geometry records one.
TriangleMesh tessellate_geometry(const Geometry& geometry, bool lines_in_pixels,
                                 const Tessellation& how);

/// The triangles tessellate_geometry() makes, counted without making them.
std::size_t tessellated_triangles(const Geometry& geometry, bool lines_in_pixels,
                                  const Tessellation& how);

/// The triangles tessellate() makes of `scene`, counted without making them (to check an
/// export against the memory budget first).
std::size_t tessellated_triangles(const Scene& scene, const Tessellation& how);

}  // namespace cambium::geom
