// SPDX-License-Identifier: Apache-2.0
#include "geom/gls_polygons.h"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "geom/placed_geometry.h"

namespace cambium::geom {
namespace {

Vec3 point(const Float4& p) { return {p[0], p[1], p[2]}; }
Vec3 point(const Float3& p) { return {p[0], p[1], p[2]}; }

/// Two unit vectors completing `axis` (unit) to an orthonormal frame.
void perpendiculars(const Vec3& axis, Vec3& u, Vec3& v)
{
    const Vec3 other = std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    u = normalize(cross(axis, other));
    v = cross(axis, u);
}

/// The circle of `radius` around `centre` in the plane normal to `axis` (unit).
std::vector<Vec3> ring(const Vec3& centre, const Vec3& axis, double radius)
{
    Vec3 u, v;
    perpendiculars(axis, u, v);
    std::vector<Vec3> points(gls_sides);
    for (int k = 0; k < gls_sides; ++k) {
        const double a = 2 * std::numbers::pi * k / gls_sides;
        points[k] = centre + (std::cos(a) * u + std::sin(a) * v) * radius;
    }
    return points;
}

/// The side wall between two rings of the same frame, as quads.
void wall(const std::vector<Vec3>& a, const std::vector<Vec3>& b, std::vector<GlsPolygon>& out)
{
    for (int k = 0; k < gls_sides; ++k) {
        const int n = (k + 1) % gls_sides;
        out.push_back({a[k], a[n], b[n], b[k]});
    }
}

/// A frustum from (p0, r0) to (p1, r1); nothing for a segment of no length.
void frustum(const Vec3& p0, double r0, const Vec3& p1, double r1, std::vector<GlsPolygon>& out)
{
    const Vec3 d = p1 - p0;
    if (length(d) <= 0)
        return;
    const Vec3 axis = normalize(d);
    wall(ring(p0, axis, r0), ring(p1, axis, r1), out);
}

/// A cubic Hermite segment (Embree's layout: the tangents are derivatives in t) as
/// four frustums along the curve, all rings in the frame of the chord.
void hermite(const Float4& p0, const Float4& t0, const Float4& p1, const Float4& t1,
             std::vector<GlsPolygon>& out)
{
    constexpr int pieces = 4;
    auto at = [&](double t, int i) {
        const double t2 = t * t, t3 = t2 * t;
        return (2 * t3 - 3 * t2 + 1) * p0[i] + (t3 - 2 * t2 + t) * t0[i] + (-2 * t3 + 3 * t2) * p1[i] +
               (t3 - t2) * t1[i];
    };
    const Vec3 chord = point(p1) - point(p0);
    if (length(chord) <= 0)
        return;
    const Vec3 axis = normalize(chord);
    std::vector<Vec3> previous = ring(point(p0), axis, p0[3]);
    for (int k = 1; k <= pieces; ++k) {
        const double t = double(k) / pieces;
        std::vector<Vec3> next = ring(Vec3{at(t, 0), at(t, 1), at(t, 2)}, axis, at(t, 3));
        wall(previous, next, out);
        previous = std::move(next);
    }
}

void sphere(const Float4& c, std::vector<GlsPolygon>& out)
{
    const int bands = gls_sides / 2;
    const Vec3 centre = point(c);
    auto at = [&](int band, int k) {
        const double theta = std::numbers::pi * band / bands;
        const double phi = 2 * std::numbers::pi * k / gls_sides;
        return centre + Vec3{std::sin(theta) * std::cos(phi), std::cos(theta),
                             std::sin(theta) * std::sin(phi)} * c[3];
    };
    for (int band = 0; band < bands; ++band)
        for (int k = 0; k < gls_sides; ++k) {
            const int n = (k + 1) % gls_sides;
            if (band == 0)
                out.push_back({at(0, 0), at(1, n), at(1, k)});
            else if (band == bands - 1)
                out.push_back({at(band, k), at(band, n), at(bands, 0)});
            else
                out.push_back({at(band, k), at(band, n), at(band + 1, n), at(band + 1, k)});
        }
}

void append_geometry(const Geometry& g, const GeometryMark& since, bool lines_in_pixels,
                     std::vector<GlsPolygon>& out)
{
    if (!lines_in_pixels)
        for (std::size_t s = since.line_segments; s < g.lines.segments.size(); ++s) {
            const Float4& a = g.lines.keys[g.lines.segments[s]];
            const Float4& b = g.lines.keys[g.lines.segments[s] + 1];
            frustum(point(a), a[3], point(b), b[3], out);
        }
    for (std::size_t s = since.curve_segments; s < g.curves.segments.size(); ++s) {
        const std::uint32_t i = g.curves.segments[s];
        hermite(g.curves.points[i], g.curves.tangents[i], g.curves.points[i + 1],
                g.curves.tangents[i + 1], out);
    }
    for (std::size_t s = since.spheres; s < g.spheres.centres.size(); ++s)
        sphere(g.spheres.centres[s], out);
    for (std::size_t s = since.discs; s < g.discs.centres.size(); ++s) {
        const Float4& c = g.discs.centres[s];
        out.push_back(ring(point(c), normalize(point(g.discs.normals[s])), c[3]));
    }
    for (std::size_t t = since.triangles; t < g.mesh.triangles.size(); ++t) {
        const auto& tri = g.mesh.triangles[t];
        out.push_back({point(g.mesh.positions[tri[0]]), point(g.mesh.positions[tri[1]]),
                       point(g.mesh.positions[tri[2]])});
    }
}

}  // namespace

GeometryMark geometry_mark(const Scene& scene)
{
    const Geometry& g = scene.geometry;
    return {g.lines.segments.size(), g.curves.segments.size(), g.spheres.size(), g.discs.size(),
            g.mesh.size(), scene.instances.size()};
}

void append_polygons_since(const Scene& scene, const GeometryMark& since,
                           std::vector<GlsPolygon>& out)
{
    append_geometry(scene.geometry, since, scene.line_radius_in_pixels, out);
    for (std::size_t i = since.instances; i < scene.instances.size(); ++i) {
        const Instance& instance = scene.instances[i];
        Geometry placed = scene.prototypes.at(instance.prototype).geometry;
        place_geometry(placed, instance);
        append_geometry(placed, GeometryMark{}, scene.line_radius_in_pixels, out);
    }
}

std::string gls_polygon_statement(const GlsPolygon& polygon)
{
    std::string text = "polygon";
    char number[32];
    for (const Vec3& v : polygon)
        for (double x : {v.x, v.y, v.z}) {
            std::snprintf(number, sizeof number, " %g", x);
            text += number;
        }
    return text;
}

}  // namespace cambium::geom
