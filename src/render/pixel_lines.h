// SPDX-License-Identifier: Apache-2.0
// cpfg's pixel-width lines (`line style: pixel`, `initial line width: N pixels`) are
// aliased OpenGL lines: a line N pixels wide covers exactly N pixels in every column
// (or row) it crosses. A tube of radius N/2 would cover parts of N + 1 pixels and look
// half again as wide once anti-aliased, so the tube is made wider by a margin and each
// hit is kept only where the pixel it falls in is one OpenGL would draw.
#pragma once

#include "geom/vec.h"
#include "render/camera.h"

namespace cambium::render {

/// Pixels added to a pixel line's radius so that every sample of a pixel OpenGL draws
/// meets the tube (half a pixel's diagonal).
inline constexpr double pixel_line_margin = 0.75;

/// The world radius of a line `radius_px` pixels in radius at the depth of p.
double pixel_line_world_radius(double radius_px, const Camera& camera, const geom::Vec3& p);

/// Whether OpenGL's aliased line of `width_px` from a to b (image coordinates) draws the
/// pixel that holds `sample`: its centre lies within width/2 of the line measured along
/// the minor axis (columns of an x-major line, rows of a y-major one) and between the
/// ends along the major axis (half a pixel more, so polylines meet at their corners).
bool gl_line_draws(const PixelPoint& a, const PixelPoint& b, double width_px, const PixelPoint& sample);

/// The same for a hit at world point `hit` on the tube from `a` to `b` whose world radius
/// at a is `world_radius` (made by pixel_line_world_radius).
bool pixel_line_draws(const Camera& camera, const geom::Vec3& a, const geom::Vec3& b,
                      double world_radius, const geom::Vec3& hit);

}  // namespace cambium::render
