// SPDX-License-Identifier: Apache-2.0
#include "render/screen_mask.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>

#include "render/pixel_lines.h"

namespace cambium::render {

namespace {

using geom::Vec3;

/// A world-space box, and how many pixels its projection grows by beyond it (pixel-width
/// lines: their radius is in pixels, whatever the depth).
struct WorldBox {
    Vec3 lo, hi;
    double grow_px = 0;
    bool finite = true;  ///< false once a point or radius that is not finite was added
};

Vec3 point(const geom::Float4& k) { return {k[0], k[1], k[2]}; }
Vec3 point(const geom::Float3& k) { return {k[0], k[1], k[2]}; }

void extend(WorldBox& b, const Vec3& p, double radius)
{
    b.finite = b.finite && std::isfinite(p.x + p.y + p.z + radius);
    b.lo = {std::min(b.lo.x, p.x - radius), std::min(b.lo.y, p.y - radius),
            std::min(b.lo.z, p.z - radius)};
    b.hi = {std::max(b.hi.x, p.x + radius), std::max(b.hi.y, p.y + radius),
            std::max(b.hi.z, p.z + radius)};
}

WorldBox empty_box()
{
    constexpr double inf = std::numeric_limits<double>::infinity();
    return {{inf, inf, inf}, {-inf, -inf, -inf}, 0, true};
}

bool is_empty(const WorldBox& b) { return b.finite && !(b.lo.x <= b.hi.x); }

/// The box holding a and b, with the larger growth; not finite if either is not.
WorldBox joined(const WorldBox& a, const WorldBox& b)
{
    if (is_empty(b))
        return a;
    if (is_empty(a))
        return b;
    return {{std::min(a.lo.x, b.lo.x), std::min(a.lo.y, b.lo.y), std::min(a.lo.z, b.lo.z)},
            {std::max(a.hi.x, b.hi.x), std::max(a.hi.y, b.hi.y), std::max(a.hi.z, b.hi.z)},
            std::max(a.grow_px, b.grow_px), a.finite && b.finite};
}

/// A rectangle in continuous pixel coordinates (PixelPoint's).
struct PixelRect {
    double x0, y0, x1, y1;
};

/// What a box's projection is: nothing a camera ray can reach, a rectangle, or unbounded
/// (it reaches behind the eye, or some coordinate is not finite): then every pixel counts.
struct Projection {
    enum class Kind { unseen, rect, everywhere } kind;
    PixelRect rect{};
};

/// World boxes to the pixel rectangles that hold their projections. A perspective view
/// divides by depth, which over a box is extreme at its corners: the rectangle is made
/// from the box's extent along the camera's axes (a box around it), exact for rays that
/// start at the eye. A parallel view's rays start behind the focus plane; boxes behind
/// their start are kept (conservative).
class Projector {
public:
    explicit Projector(const Camera& camera)
        : m_perspective(camera.projection() == Camera::Projection::perspective),
          m_origin(camera.origin()), m_right(camera.right()), m_up(camera.up()),
          m_forward(camera.forward())
    {
        // The scale from the camera's own projection: pixels per unit of x / depth
        // (perspective) or per world unit (parallel), and the image centre.
        PixelPoint centre = camera.project(m_origin + m_forward);
        m_cx = centre.x;
        m_cy = centre.y;
        m_scale = camera.project(m_origin + m_forward + m_right).x - centre.x;
    }

    Projection operator()(const WorldBox& b) const
    {
        if (!b.finite)
            return {Projection::Kind::everywhere};
        const Vec3 c = (b.lo + b.hi) * 0.5 - m_origin, h = (b.hi - b.lo) * 0.5;
        auto along = [&](const Vec3& axis, double& mid, double& half) {
            mid = geom::dot(c, axis);
            half = std::fabs(axis.x) * h.x + std::fabs(axis.y) * h.y + std::fabs(axis.z) * h.z;
        };
        double x, ex, y, ey, z, ez;
        along(m_right, x, ex);
        along(m_up, y, ey);
        along(m_forward, z, ez);
        if (!std::isfinite(x + ex + y + ey + z + ez + b.grow_px))
            return {Projection::Kind::everywhere};
        double x0 = x - ex, x1 = x + ex, y0 = y - ey, y1 = y + ey;
        if (m_perspective) {
            // Camera rays leave the eye forward: nothing at or behind its plane is met.
            if (z + ez <= 0)
                return {Projection::Kind::unseen};
            // Within a hair of the eye's plane, x / z has no useful bound.
            if (z - ez <= 1e-9 * (std::fabs(z) + ez))
                return {Projection::Kind::everywhere};
            const double near = z - ez, far = z + ez;
            x0 = std::min(x0 / near, x0 / far);
            x1 = std::max(x1 / near, x1 / far);
            y0 = std::min(y0 / near, y0 / far);
            y1 = std::max(y1 / near, y1 / far);
        }
        // Image y grows downward.
        return {Projection::Kind::rect,
                {m_cx + x0 * m_scale - b.grow_px, m_cy - y1 * m_scale - b.grow_px,
                 m_cx + x1 * m_scale + b.grow_px, m_cy - y0 * m_scale + b.grow_px}};
    }

private:
    bool m_perspective;
    Vec3 m_origin, m_right, m_up, m_forward;
    double m_cx = 0, m_cy = 0, m_scale = 1;
};

/// The box holding `b` moved by an instance's 3x4 column-major transform.
WorldBox placed_box(const WorldBox& b, const std::array<float, 12>& m)
{
    const Vec3 c = (b.lo + b.hi) * 0.5, h = (b.hi - b.lo) * 0.5;
    auto row = [&](int r, double& mid, double& half) {
        mid = m[9 + r] + m[r] * c.x + m[3 + r] * c.y + m[6 + r] * c.z;
        half = std::fabs(m[r]) * h.x + std::fabs(m[3 + r]) * h.y + std::fabs(m[6 + r]) * h.z;
    };
    double x, ex, y, ey, z, ez;
    row(0, x, ex);
    row(1, y, ey);
    row(2, z, ez);
    return {{x - ex, y - ey, z - ez}, {x + ex, y + ey, z + ez}, b.grow_px, b.finite};
}

/// The image's blocks, counting how many projections touch each: rectangles are added
/// as +1/-1 at their corners (from any thread) and summed once at the end.
class BlockCounts {
public:
    BlockCounts(int width, int height, double reach)
        : m_width(width), m_height(height), m_reach(reach + ScreenMask::safety_px)
    {
        constexpr std::size_t max_blocks = std::size_t{1} << 20;
        while (std::size_t((width >> m_shift) + 1) * std::size_t((height >> m_shift) + 1) >
               max_blocks)
            ++m_shift;
        m_columns = std::size_t(((width - 1) >> m_shift) + 1);
        m_rows = std::size_t(((height - 1) >> m_shift) + 1);
        m_diff = std::vector<std::int64_t>((m_columns + 1) * (m_rows + 1), 0);
    }

    int shift() const { return m_shift; }
    std::size_t columns() const { return m_columns; }

    void add(const Projection& p)
    {
        if (p.kind == Projection::Kind::unseen)
            return;
        if (p.kind == Projection::Kind::everywhere) {
            m_everywhere.store(true, std::memory_order_relaxed);
            return;
        }
        // Pixel i's samples lie within reach of its centre i + 0.5.
        const PixelRect& r = p.rect;
        double lo_x = std::floor(r.x0 - 0.5 - m_reach), hi_x = std::ceil(r.x1 - 0.5 + m_reach);
        double lo_y = std::floor(r.y0 - 0.5 - m_reach), hi_y = std::ceil(r.y1 - 0.5 + m_reach);
        if (hi_x < 0 || hi_y < 0 || lo_x > m_width - 1 || lo_y > m_height - 1)
            return;
        auto block = [&](double v, int size) {
            return std::size_t(int(std::clamp(v, 0.0, double(size - 1))) >> m_shift);
        };
        std::size_t bx0 = block(lo_x, m_width), bx1 = block(hi_x, m_width) + 1;
        std::size_t by0 = block(lo_y, m_height), by1 = block(hi_y, m_height) + 1;
        bump(by0, bx0, 1);
        bump(by0, bx1, -1);
        bump(by1, bx0, -1);
        bump(by1, bx1, 1);
    }

    /// Per block, 1 where some projection touches it; sets `empty` to the share of
    /// blocks none touches.
    std::vector<std::uint8_t> touched(double& empty) const
    {
        std::vector<std::uint8_t> cells(m_columns * m_rows, 1);
        if (m_everywhere.load()) {
            empty = 0;
            return cells;
        }
        const std::size_t stride = m_columns + 1;
        std::vector<std::int64_t> row_sum(m_columns + 1, 0);
        std::size_t none = 0;
        for (std::size_t y = 0; y < m_rows; ++y) {
            std::int64_t run = 0;
            for (std::size_t x = 0; x < m_columns; ++x) {
                run += m_diff[y * stride + x];
                row_sum[x] += run;
                cells[y * m_columns + x] = row_sum[x] > 0 ? 1 : 0;
                none += row_sum[x] > 0 ? 0 : 1;
            }
        }
        empty = double(none) / double(cells.size());
        return cells;
    }

private:
    void bump(std::size_t row, std::size_t column, std::int64_t v)
    {
        std::atomic_ref<std::int64_t>(m_diff[row * (m_columns + 1) + column])
            .fetch_add(v, std::memory_order_relaxed);
    }

    int m_width, m_height;
    double m_reach;
    int m_shift = 0;
    std::size_t m_columns = 0, m_rows = 0;
    std::vector<std::int64_t> m_diff;
    std::atomic<bool> m_everywhere{false};
};

/// Calls add(box) for every primitive of g (in parallel): each segment, curve segment,
/// sphere, disc and triangle has a box of its own.
template <typename Add>
void each_primitive_box(const geom::Geometry& g, bool radius_in_pixels, const Add& add)
{
    auto each = [](std::size_t n, const auto& f) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t i = r.begin(); i != r.end(); ++i)
                                  f(i);
                          });
    };
    const geom::LinearCurves& l = g.lines;
    each(l.segments.size(), [&](std::size_t i) {
        std::uint32_t k = l.segments[i];
        if (std::size_t(k) + 1 >= l.keys.size())
            return;  // the accel refuses such a scene
        const geom::Float4 &a = l.keys[k], &b = l.keys[k + 1];
        WorldBox box = empty_box();
        if (radius_in_pixels) {
            extend(box, point(a), 0);
            extend(box, point(b), 0);
            box.grow_px = 2 * (std::max(double(a[3]), double(b[3])) + pixel_line_margin);
        } else {
            double r = std::max(std::fabs(double(a[3])), std::fabs(double(b[3])));
            extend(box, point(a), r);
            extend(box, point(b), r);
        }
        add(box);
    });
    const geom::HermiteCurves& c = g.curves;
    each(c.segments.size(), [&](std::size_t i) {
        std::uint32_t k = c.segments[i];
        if (std::size_t(k) + 1 >= c.points.size() || std::size_t(k) + 1 >= c.tangents.size())
            return;
        // Within the Bézier control points p0, p0 + t0 / 3, p1 - t1 / 3, p1 (Embree's
        // Hermite form), grown by the largest control radius.
        const Vec3 p0 = point(c.points[k]), p1 = point(c.points[k + 1]);
        const Vec3 q0 = p0 + point(c.tangents[k]) * (1.0 / 3);
        const Vec3 q1 = p1 - point(c.tangents[k + 1]) * (1.0 / 3);
        const double r0 = c.points[k][3], r1 = c.points[k + 1][3];
        const double s0 = r0 + c.tangents[k][3] / 3.0, s1 = r1 - c.tangents[k + 1][3] / 3.0;
        const double r = std::max({std::fabs(r0), std::fabs(r1), std::fabs(s0), std::fabs(s1)});
        WorldBox box = empty_box();
        for (const Vec3& p : {p0, q0, q1, p1})
            extend(box, p, r);
        add(box);
    });
    each(g.spheres.centres.size(), [&](std::size_t i) {
        WorldBox box = empty_box();
        extend(box, point(g.spheres.centres[i]), std::fabs(double(g.spheres.centres[i][3])));
        add(box);
    });
    each(g.discs.centres.size(), [&](std::size_t i) {
        WorldBox box = empty_box();
        extend(box, point(g.discs.centres[i]), std::fabs(double(g.discs.centres[i][3])));
        add(box);
    });
    const geom::TriangleMesh& m = g.mesh;
    each(m.triangles.size(), [&](std::size_t i) {
        WorldBox box = empty_box();
        for (std::uint32_t v : m.triangles[i]) {
            if (v >= m.positions.size())
                return;
            extend(box, point(m.positions[v]), 0);
        }
        add(box);
    });
}

/// The bounds of a geometry in its own frame (a prototype's), with the pixels its
/// pixel-width lines add: the union of its primitives' boxes.
WorldBox geometry_box(const geom::Geometry& g, bool radius_in_pixels)
{
    tbb::combinable<WorldBox> boxes(empty_box);
    each_primitive_box(g, radius_in_pixels,
                       [&](const WorldBox& b) { boxes.local() = joined(boxes.local(), b); });
    return boxes.combine(joined);
}

}  // namespace

ScreenMask::ScreenMask(const geom::Scene& scene, const Camera& camera, double reach)
{
    const Projector project(camera);
    BlockCounts counts(camera.width(), camera.height(), reach);
    auto add = [&](const WorldBox& box) {
        if (!is_empty(box))
            counts.add(project(box));
    };
    each_primitive_box(scene.geometry, scene.line_radius_in_pixels, add);
    // Instances: the prototype's bounds, placed.
    std::vector<WorldBox> prototype_boxes;
    prototype_boxes.reserve(scene.prototypes.size());
    for (const geom::Prototype& p : scene.prototypes)
        prototype_boxes.push_back(geometry_box(p.geometry, scene.line_radius_in_pixels));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, scene.instances.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i) {
                              const geom::Instance& inst = scene.instances[i];
                              if (inst.prototype >= prototype_boxes.size())
                                  continue;
                              const WorldBox& b = prototype_boxes[inst.prototype];
                              if (!is_empty(b))
                                  add(placed_box(b, inst.transform));
                          }
                      });
    m_shift = counts.shift();
    m_columns = counts.columns();
    m_cells = counts.touched(m_empty_share);
}

}  // namespace cambium::render
