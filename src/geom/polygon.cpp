// SPDX-License-Identifier: Apache-2.0
// Triangulation of turtle polygons (`{ . }`): concave outlines by ear clipping.
#include "geom/polygon.h"

#include <cmath>

namespace cambium::geom {
namespace {

struct Point2 {
    double x, y;
};

double cross2(const Point2& a, const Point2& b, const Point2& c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// p inside or on the triangle abc (counter-clockwise), with tolerance eps.
bool inside_triangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c, double eps)
{
    return cross2(a, b, p) >= -eps && cross2(b, c, p) >= -eps && cross2(c, a, p) >= -eps;
}

bool same_point(const Point2& a, const Point2& b) { return a.x == b.x && a.y == b.y; }

}  // namespace

Vec3 polygon_normal(std::span<const Vec3> outline)
{
    Vec3 n{0, 0, 0};
    for (std::size_t i = 0; i < outline.size(); ++i) {
        const Vec3& a = outline[i];
        const Vec3& b = outline[(i + 1) % outline.size()];
        n += Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
    }
    double len = length(n);
    return len > 0 ? n / len : Vec3{0, 0, 0};
}

std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const Vec3> outline)
{
    std::vector<std::array<std::uint32_t, 3>> triangles;
    Vec3 n = polygon_normal(outline);
    if (outline.size() < 3 || dot(n, n) == 0)
        return triangles;

    // A basis (u, v) of the plane with u x v = n, so the outline is counter-clockwise.
    Vec3 helper = std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    Vec3 u = normalize(cross(helper, n));
    Vec3 v = cross(n, u);
    std::vector<Point2> p(outline.size());
    double extent = 0;
    for (std::size_t i = 0; i < outline.size(); ++i) {
        p[i] = {dot(outline[i], u), dot(outline[i], v)};
        extent = std::max({extent, std::abs(p[i].x - p[0].x), std::abs(p[i].y - p[0].y)});
    }
    const double eps = 1e-12 * extent * extent;  // area tolerance, relative to the size

    std::vector<std::uint32_t> ring;  // remaining vertices, repeats dropped
    for (std::uint32_t i = 0; i < outline.size(); ++i)
        if (ring.empty() || !same_point(p[ring.back()], p[i]))
            ring.push_back(i);
    while (ring.size() > 1 && same_point(p[ring.front()], p[ring.back()]))
        ring.pop_back();

    auto at = [&](std::size_t k) -> const Point2& { return p[ring[k % ring.size()]]; };
    auto is_ear = [&](std::size_t k) {
        std::size_t a = (k + ring.size() - 1) % ring.size(), c = (k + 1) % ring.size();
        if (cross2(at(a), at(k), at(c)) <= eps)
            return false;
        const Point2* corner[3] = {&at(a), &at(k), &at(c)};
        for (std::size_t j = 0; j < ring.size(); ++j) {
            if (j == a || j == k || j == c)
                continue;
            const Point2& q = at(j);
            int shared = -1;
            for (int i = 0; i < 3; ++i)
                if (same_point(q, *corner[i]))
                    shared = i;
            if (shared < 0) {
                if (inside_triangle(q, at(a), at(k), at(c), eps))
                    return false;
                continue;
            }
            // q repeats a corner of the ear (an outline touching itself): the ear is
            // no ear when an edge leaving q runs into the triangle's corner.
            const Point2& x = *corner[shared];
            const Point2& next = *corner[(shared + 1) % 3];
            const Point2& prev = *corner[(shared + 2) % 3];
            for (const Point2* n : {&at(j + ring.size() - 1), &at(j + 1)})
                if (cross2(x, next, *n) > eps && cross2(x, *n, prev) > eps)
                    return false;
        }
        return true;
    };

    std::size_t k = 0, misses = 0;
    while (ring.size() >= 3) {
        std::size_t a = (k + ring.size() - 1) % ring.size(), c = (k + 1) % ring.size();
        double turn = cross2(at(a), at(k), at(c));
        bool collinear = std::abs(turn) <= eps;
        // Past a full round without an ear the outline crosses itself: clip anyway.
        if (collinear || is_ear(k) || misses > ring.size()) {
            if (!collinear && turn > 0)
                triangles.push_back({ring[a], ring[k], ring[c]});
            else if (!collinear && misses > ring.size())
                triangles.push_back({ring[a], ring[k], ring[c]});
            ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(k));
            if (k >= ring.size())
                k = 0;
            misses = 0;
            continue;
        }
        k = (k + 1) % ring.size();
        ++misses;
    }
    return triangles;
}

}  // namespace cambium::geom
