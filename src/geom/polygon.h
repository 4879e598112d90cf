// SPDX-License-Identifier: Apache-2.0
// Triangulation of turtle polygons (`{ . }`): concave outlines by ear clipping.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "geom/vec.h"

namespace cambium::geom {

/// The polygon's Newell normal, unit length: the outline runs counter-clockwise
/// around it. Zero when the outline has no area.
Vec3 polygon_normal(std::span<const Vec3> outline);

/// Triangles (indices into `outline`) covering a simple polygon, convex or concave,
/// planar or nearly so: ear clipping in the plane of the Newell normal. Repeated and
/// collinear vertices produce no triangle; every triangle keeps the outline's
/// winding. A self-intersecting outline still gets triangles (never a hang). Near-linear
/// for common outlines; an outline that would take quadratic work beyond a budget (about
/// a second) has its rest cut in order, and `cut_short` (when given) says so. The
/// budget counts every step of the walk around the ring and every point test, at most
/// `max_tests` of them.
constexpr std::size_t max_polygon_tests = 300'000'000;
std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const Vec3> outline,
                                                              bool* cut_short = nullptr,
                                                              std::size_t max_tests = max_polygon_tests);

}  // namespace cambium::geom
