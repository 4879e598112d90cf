// SPDX-License-Identifier: Apache-2.0
// cpfg's pixel-width lines drawn as OpenGL draws aliased wide lines.
#include "render/pixel_lines.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace cambium::render {

double pixel_line_world_radius(double radius_px, const Camera& camera, const geom::Vec3& p)
{
    return (radius_px + pixel_line_margin) * camera.pixel_size_at(p);
}

bool gl_line_draws(const PixelPoint& a, const PixelPoint& b, double width_px, const PixelPoint& sample)
{
    // The pixel's centre, in the frame where x is the line's major axis.
    double cx = std::floor(sample.x) + 0.5, cy = std::floor(sample.y) + 0.5;
    double ax = a.x, ay = a.y, bx = b.x, by = b.y;
    if (std::fabs(by - ay) > std::fabs(bx - ax)) {
        std::swap(ax, ay);
        std::swap(bx, by);
        std::swap(cx, cy);
    }
    if (cx < std::min(ax, bx) - 0.5 || cx > std::max(ax, bx) + 0.5)
        return false;
    double dx = bx - ax;
    double t = dx == 0 ? 0 : std::clamp((cx - ax) / dx, 0.0, 1.0);
    double offset = cy - (ay + t * (by - ay));
    // Half-open, so a line of width N on a pixel boundary draws N pixels, not N + 1. The
    // window moves by a hair so that a width rounded below N (0.9999999 px from the
    // world radius) on a boundary still draws its N pixels, not N - 1 (HilbertPanels'
    // grid lines lie on pixel boundaries).
    constexpr double hair = 1e-6;
    return offset >= -width_px / 2 - hair && offset < width_px / 2 - hair;
}

bool pixel_line_draws(const Camera& camera, const geom::Vec3& a, const geom::Vec3& b,
                      double world_radius, const geom::Vec3& hit)
{
    double width_px = 2 * (world_radius / camera.pixel_size_at(a) - pixel_line_margin);
    return gl_line_draws(camera.project(a), camera.project(b), width_px, camera.project(hit));
}

}  // namespace cambium::render
