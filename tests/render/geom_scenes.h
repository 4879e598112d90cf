// SPDX-License-Identifier: Apache-2.0
// Hand-made Geometry parts (spheres, discs, meshes, Hermite curves, instances) and a small
// path-tracing loop for the render_geom_test physics tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "geom/scene.h"
#include "render/camera.h"
#include "render/integrator.h"
#include "render/sampler.h"

namespace cambium::render::testing {

inline void add_sphere(geom::Geometry& g, const geom::Vec3& c, float r, std::uint16_t m = 1)
{
    g.spheres.centres.push_back({float(c.x), float(c.y), float(c.z), r});
    g.spheres.material.push_back(m);
    g.spheres.texture.push_back(geom::no_texture);
}

inline void add_disc(geom::Geometry& g, const geom::Vec3& c, float r, const geom::Vec3& n,
                     std::uint16_t front, std::uint16_t back)
{
    g.discs.centres.push_back({float(c.x), float(c.y), float(c.z), r});
    g.discs.normals.push_back({float(n.x), float(n.y), float(n.z)});
    g.discs.material.push_back(front);
    g.discs.back_material.push_back(back);
}

/// A triangle with per-vertex normals and uvs; returns its index.
inline std::uint32_t add_triangle(geom::Geometry& g, const std::array<geom::Float3, 3>& p,
                                  const std::array<geom::Float3, 3>& n,
                                  const std::array<geom::Float2, 3>& uv, std::uint16_t front,
                                  std::uint16_t back, std::int16_t texture = geom::no_texture)
{
    geom::TriangleMesh& m = g.mesh;
    auto base = static_cast<std::uint32_t>(m.positions.size());
    for (int i = 0; i < 3; ++i) {
        m.positions.push_back(p[i]);
        m.normals.push_back(n[i]);
        m.uvs.push_back(uv[i]);
    }
    m.triangles.push_back({base, base + 1, base + 2});
    m.material.push_back(front);
    m.back_material.push_back(back);
    m.texture.push_back(texture);
    return static_cast<std::uint32_t>(m.triangles.size() - 1);
}

/// The square [x0, x1] x [y0, y1] at height z, front (normal) toward +z, uv = (0,0)..(1,1).
inline void add_quad(geom::Geometry& g, float x0, float y0, float x1, float y1, float z,
                     std::uint16_t front, std::uint16_t back,
                     std::int16_t texture = geom::no_texture)
{
    geom::Float3 n{0, 0, 1};
    add_triangle(g, {{{x0, y0, z}, {x1, y0, z}, {x1, y1, z}}}, {n, n, n},
                 {{{0, 0}, {1, 0}, {1, 1}}}, front, back, texture);
    add_triangle(g, {{{x0, y0, z}, {x1, y1, z}, {x0, y1, z}}}, {n, n, n},
                 {{{0, 0}, {1, 1}, {0, 1}}}, front, back, texture);
}

/// The closed cube [-h, h]^3 of 12 flat triangles, fronts outward.
inline void add_cube(geom::Geometry& g, float h, std::uint16_t front, std::uint16_t back)
{
    for (int axis = 0; axis < 3; ++axis)
        for (float side : {-1.0f, 1.0f}) {
            int a = (axis + 1) % 3, b = (axis + 2) % 3;
            auto corner = [&](float s, float t) {
                geom::Float3 p{};
                p[axis] = side * h;
                p[a] = s * h;
                p[b] = t * h;
                return p;
            };
            geom::Float3 n{};
            n[axis] = side;
            // Counter-clockwise seen from outside: flip the winding on the negative side.
            geom::Float3 p0 = corner(-1, -1), p1 = corner(1, -1), p2 = corner(1, 1),
                         p3 = corner(-1, 1);
            if (side < 0)
                std::swap(p1, p3);
            add_triangle(g, {{p0, p1, p2}}, {n, n, n}, {{{0, 0}, {1, 0}, {1, 1}}}, front, back);
            add_triangle(g, {{p0, p2, p3}}, {n, n, n}, {{{0, 0}, {1, 1}, {0, 1}}}, front, back);
        }
}

/// One round Hermite segment a -> b with tangents ta, tb (4th: radius derivative).
inline void add_hermite(geom::Geometry& g, const geom::Float4& a, const geom::Float4& ta,
                        const geom::Float4& b, const geom::Float4& tb, std::uint16_t m = 1)
{
    geom::HermiteCurves& c = g.curves;
    auto first = static_cast<std::uint32_t>(c.points.size());
    c.points.push_back(a);
    c.points.push_back(b);
    c.tangents.push_back(ta);
    c.tangents.push_back(tb);
    c.segments.push_back(first);
    c.flags.push_back(0);
    c.material.push_back(m);
    c.texture.push_back(geom::no_texture);
}

/// The column-major 3x4 transform x' = A x + t, A given by rows.
inline std::array<float, 12> transform(const std::array<float, 9>& rows,
                                       const geom::Vec3& t = {0, 0, 0})
{
    return {rows[0], rows[3], rows[6], rows[1], rows[4], rows[7],
            rows[2], rows[5], rows[8], float(t.x), float(t.y), float(t.z)};
}

/// An orthographic camera looking down -z at (cx, cy), `size` units across w pixels.
inline Camera top_camera(double cx, double cy, double size, int w, int h)
{
    return Camera::parallel({cx, cy, 0}, {0, 0, -1}, {0, 1, 0}, size / w, 100, w, h);
}

/// Mean radiance (and coverage) of the pixels [x0, x1) x [y0, y1) traced with ctx.
struct BlockMean {
    Vec3f radiance;
    double coverage = 0;
    /// The standard error of radiance.y (from the paths' own variance): tolerances of
    /// Monte Carlo tests are a few of these, not a fixed percentage.
    double standard_error = 0;
};

inline BlockMean trace_block(const PathContext& ctx, const Camera& camera, int x0, int y0, int x1,
                             int y1, int spp)
{
    double r = 0, g = 0, b = 0, g2 = 0, hits = 0, n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            for (int i = 0; i < spp; ++i) {
                Sampler s(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                          static_cast<std::uint32_t>(i), 7);
                double jx = s.next(), jy = s.next();
                CameraRay ray = camera.generate_ray(x + jx, y + jy);
                PathResult p = trace_path(ctx, Vec3f(ray.org), Vec3f(ray.dir), s);
                r += p.radiance.x;
                g += p.radiance.y;
                g2 += double(p.radiance.y) * p.radiance.y;
                b += p.radiance.z;
                hits += p.hit ? 1 : 0;
                n += 1;
            }
    double variance = n > 1 ? std::max(0.0, (g2 - g * g / n) / (n - 1)) : 0.0;
    return {Vec3f(float(r / n), float(g / n), float(b / n)), hits / n,
            std::sqrt(variance / n)};
}

}  // namespace cambium::render::testing
