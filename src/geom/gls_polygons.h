// SPDX-License-Identifier: Apache-2.0
// Geometry as the polygons of cpfg's Graphics Library Statements (manual 5.4.10 and 6.4):
// what `interpreted modules:` sends an environmental program for a module.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "geom/scene.h"
#include "geom/vec.h"

namespace cambium::geom {

/// A GLS `polygon` statement: its vertices in order (at least three).
using GlsPolygon = std::vector<Vec3>;

/// How far a Scene's primitive arrays had grown at one moment of interpretation.
struct GeometryMark {
    std::size_t line_segments = 0, curve_segments = 0, spheres = 0, discs = 0, triangles = 0;
    std::size_t instances = 0;
};

GeometryMark geometry_mark(const Scene& scene);

/// Round primitives become this many sides (cylinders, discs) or this many meridians
/// (spheres, with half as many parallels): enough for an environment that computes
/// areas or shadows from the polygons, few enough to keep the messages short.
inline constexpr int gls_sides = 8;

/// Appends, as polygons in the scene's coordinates, every primitive `scene` gained since
/// `since`: triangles as they are, line and generalized-cylinder segments as the quads
/// of their side walls, spheres as quads and pole triangles, discs as one polygon, and
/// the primitives of placed instances (predefined surfaces, objects) moved into place.
/// Lines measured in pixels (`line style: pixel`) have no size in the scene and give
/// nothing.
void append_polygons_since(const Scene& scene, const GeometryMark& since,
                           std::vector<GlsPolygon>& out);

/// The statement's text: `polygon x1 y1 z1 ... xn yn zn`, numbers as "%g" writes them.
std::string gls_polygon_statement(const GlsPolygon& polygon);

}  // namespace cambium::geom
