// SPDX-License-Identifier: Apache-2.0
// Geometry as the polygons of cpfg's Graphics Library Statements (manual 5.4.10 and 6.4):
// what `interpreted modules:` sends an environmental program for a module.
#pragma once

#include <string>
#include <vector>

#include "geom/scene.h"
#include "geom/tessellate.h"
#include "geom/vec.h"

namespace cambium::geom {

/// A GLS `polygon` statement: its vertices in order (at least three).
using GlsPolygon = std::vector<Vec3>;

/// Round primitives become this many sides: enough for an environment that computes
/// areas or shadows from the polygons, few enough to keep the messages short. Cylinders
/// stay open: a module's joint depends on a segment a later module draws.
inline constexpr Tessellation gls_tessellation{8, 4, false};

/// Appends, as triangles in the scene's coordinates, every primitive `scene` gained
/// since `since` (tessellate_since with gls_tessellation).
void append_polygons_since(const Scene& scene, const GeometryMark& since,
                           std::vector<GlsPolygon>& out);

/// The statement's text: `polygon x1 y1 z1 ... xn yn zn`, numbers as "%g" writes them.
std::string gls_polygon_statement(const GlsPolygon& polygon);

}  // namespace cambium::geom
