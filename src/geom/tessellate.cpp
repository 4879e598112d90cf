// SPDX-License-Identifier: Apache-2.0
#include "geom/tessellate.h"

#include <cmath>
#include <numbers>

#include "geom/placed_geometry.h"

namespace cambium::geom {
namespace {

Vec3 point(const Float4& p) { return {p[0], p[1], p[2]}; }
Vec3 point(const Float3& p) { return {p[0], p[1], p[2]}; }
Float3 float3(const Vec3& v)
{
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

/// Writes triangles of one material into a mesh.
class MeshWriter {
public:
    MeshWriter(TriangleMesh& out, std::uint16_t material, std::uint16_t back, std::int16_t texture,
               std::uint32_t module)
        : m_out(out), m_material(material), m_back(back), m_texture(texture), m_module(module)
    {
    }
    std::uint32_t vertex(const Vec3& p, const Vec3& n, Float2 uv = {0, 0})
    {
        m_out.positions.push_back(float3(p));
        m_out.normals.push_back(float3(n));
        m_out.uvs.push_back(uv);
        return static_cast<std::uint32_t>(m_out.positions.size() - 1);
    }
    void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c)
    {
        m_out.triangles.push_back({a, b, c});
        m_out.material.push_back(m_material);
        m_out.back_material.push_back(m_back);
        m_out.texture.push_back(m_texture);
        m_out.module.push_back(m_module);
    }

private:
    TriangleMesh& m_out;
    std::uint16_t m_material, m_back;
    std::int16_t m_texture;
    std::uint32_t m_module;
};

/// Two unit vectors completing `axis` (unit) to a right-handed orthonormal frame.
void perpendiculars(const Vec3& axis, Vec3& u, Vec3& v)
{
    const Vec3 other = std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    u = normalize(cross(axis, other));
    v = cross(axis, u);
}

/// A ring of vertices around `centre` in the frame (u, v), normals pointing outward.
std::uint32_t ring(MeshWriter& w, const Vec3& centre, const Vec3& u, const Vec3& v, double radius,
                   int sides)
{
    std::uint32_t first = 0;
    for (int k = 0; k < sides; ++k) {
        const double a = 2 * std::numbers::pi * k / sides;
        const Vec3 out = std::cos(a) * u + std::sin(a) * v;
        const std::uint32_t i = w.vertex(centre + out * radius, out);
        if (k == 0)
            first = i;
    }
    return first;
}

/// The wall between two rings of `sides` vertices, wound counter-clockwise seen from
/// outside (the side the normals point to).
void wall(MeshWriter& w, std::uint32_t a, std::uint32_t b, int sides)
{
    for (int k = 0; k < sides; ++k) {
        const std::uint32_t n = static_cast<std::uint32_t>((k + 1) % sides);
        const std::uint32_t kk = static_cast<std::uint32_t>(k);
        w.triangle(a + kk, a + n, b + n);
        w.triangle(a + kk, b + n, b + kk);
    }
}

void frustum(MeshWriter& w, const Vec3& p0, double r0, const Vec3& p1, double r1, int sides)
{
    const Vec3 d = p1 - p0;
    if (!(length(d) > 0))
        return;
    Vec3 u, v;
    perpendiculars(normalize(d), u, v);
    const std::uint32_t a = ring(w, p0, u, v, r0, sides);
    const std::uint32_t b = ring(w, p1, u, v, r1, sides);
    wall(w, a, b, sides);
}

/// A cubic Hermite segment (Embree's layout: tangents are derivatives in t), its rings
/// all in the frame of the chord.
void hermite(MeshWriter& w, const Float4& p0, const Float4& t0, const Float4& p1, const Float4& t1,
             const Tessellation& how)
{
    auto at = [&](double t, int i) {
        const double t2 = t * t, t3 = t2 * t;
        return (2 * t3 - 3 * t2 + 1) * p0[i] + (t3 - 2 * t2 + t) * t0[i] +
               (-2 * t3 + 3 * t2) * p1[i] + (t3 - t2) * t1[i];
    };
    const Vec3 chord = point(p1) - point(p0);
    if (!(length(chord) > 0))
        return;
    Vec3 u, v;
    perpendiculars(normalize(chord), u, v);
    std::uint32_t previous = ring(w, point(p0), u, v, p0[3], how.sides);
    for (int k = 1; k <= how.curve_pieces; ++k) {
        const double t = double(k) / how.curve_pieces;
        const std::uint32_t next =
            ring(w, Vec3{at(t, 0), at(t, 1), at(t, 2)}, u, v, at(t, 3), how.sides);
        wall(w, previous, next, how.sides);
        previous = next;
    }
}

void sphere(MeshWriter& w, const Float4& c, int sides)
{
    const int bands = std::max(2, sides / 2);
    const Vec3 centre = point(c);
    std::vector<std::uint32_t> rows;
    for (int band = 0; band <= bands; ++band) {
        const double theta = std::numbers::pi * band / bands;
        for (int k = 0; k < sides; ++k) {
            const double phi = 2 * std::numbers::pi * k / sides;
            const Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta),
                         -std::sin(theta) * std::sin(phi)};
            const std::uint32_t i = w.vertex(centre + n * c[3], n);
            if (k == 0)
                rows.push_back(i);
        }
    }
    for (int band = 0; band < bands; ++band)
        for (int k = 0; k < sides; ++k) {
            const std::uint32_t n = static_cast<std::uint32_t>((k + 1) % sides);
            const std::uint32_t kk = static_cast<std::uint32_t>(k);
            const std::uint32_t a = rows[band], b = rows[band + 1];
            if (band > 0)
                w.triangle(a + kk, b + kk, a + n);
            if (band + 1 < bands)
                w.triangle(a + n, b + kk, b + n);
        }
}

void disc(MeshWriter& w, const Float4& c, const Vec3& normal, int sides)
{
    Vec3 u, v;
    perpendiculars(normal, u, v);
    const std::uint32_t centre = w.vertex(point(c), normal);
    for (int k = 0; k < sides; ++k) {
        const double a = 2 * std::numbers::pi * k / sides;
        w.vertex(point(c) + (std::cos(a) * u + std::sin(a) * v) * c[3], normal);
    }
    for (int k = 0; k < sides; ++k)
        w.triangle(centre, centre + 1 + static_cast<std::uint32_t>(k),
                   centre + 1 + static_cast<std::uint32_t>((k + 1) % sides));
}

std::int16_t texture_of(const std::vector<std::int16_t>& textures, std::size_t i)
{
    return i < textures.size() ? textures[i] : no_texture;
}

/// The module of primitive `i`: `placed` (an instance's) when there is one, else the
/// primitive's own entry, else no_module.
std::uint32_t module_of(const std::vector<std::uint32_t>& modules, std::size_t i, std::uint32_t placed)
{
    if (placed != no_module)
        return placed;
    return i < modules.size() ? modules[i] : no_module;
}

void append_geometry(const Geometry& g, const GeometryMark& since, bool lines_in_pixels,
                     const Tessellation& how, std::uint32_t placed, TriangleMesh& out)
{
    if (!lines_in_pixels)
        for (std::size_t s = since.line_segments; s < g.lines.segments.size(); ++s) {
            MeshWriter w(out, g.lines.material[s], g.lines.material[s], texture_of(g.lines.texture, s),
                         module_of(g.lines.module, s, placed));
            const Float4& a = g.lines.keys[g.lines.segments[s]];
            const Float4& b = g.lines.keys[g.lines.segments[s] + 1];
            frustum(w, point(a), a[3], point(b), b[3], how.sides);
        }
    for (std::size_t s = since.curve_segments; s < g.curves.segments.size(); ++s) {
        MeshWriter w(out, g.curves.material[s], g.curves.material[s], texture_of(g.curves.texture, s),
                     module_of(g.curves.module, s, placed));
        const std::uint32_t i = g.curves.segments[s];
        hermite(w, g.curves.points[i], g.curves.tangents[i], g.curves.points[i + 1],
                g.curves.tangents[i + 1], how);
    }
    for (std::size_t s = since.spheres; s < g.spheres.centres.size(); ++s) {
        MeshWriter w(out, g.spheres.material[s], g.spheres.material[s], texture_of(g.spheres.texture, s),
                     module_of(g.spheres.module, s, placed));
        sphere(w, g.spheres.centres[s], how.sides);
    }
    for (std::size_t s = since.discs; s < g.discs.centres.size(); ++s) {
        MeshWriter w(out, g.discs.material[s], g.discs.back_material[s], no_texture,
                     module_of(g.discs.module, s, placed));
        disc(w, g.discs.centres[s], normalize(point(g.discs.normals[s])), how.sides);
    }
    const TriangleMesh& m = g.mesh;
    for (std::size_t t = since.triangles; t < m.triangles.size(); ++t) {
        MeshWriter w(out, m.material[t], m.back_material[t], texture_of(m.texture, t),
                     module_of(m.module, t, placed));
        std::uint32_t v[3];
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t i = m.triangles[t][k];
            v[k] = w.vertex(point(m.positions[i]), point(m.normals[i]),
                            i < m.uvs.size() ? m.uvs[i] : Float2{0, 0});
        }
        w.triangle(v[0], v[1], v[2]);
    }
}

std::size_t count_geometry(const Geometry& g, bool lines_in_pixels, const Tessellation& how)
{
    const std::size_t wall = 2 * std::size_t(how.sides);
    const std::size_t bands = std::size_t(std::max(2, how.sides / 2));
    return (lines_in_pixels ? 0 : g.lines.segment_count() * wall) +
           g.curves.segment_count() * wall * std::size_t(how.curve_pieces) +
           g.spheres.size() * wall * (bands - 1) + g.discs.size() * std::size_t(how.sides) +
           g.mesh.size();
}

}  // namespace

GeometryMark geometry_mark(const Scene& scene)
{
    const Geometry& g = scene.geometry;
    return {g.lines.segments.size(), g.curves.segments.size(), g.spheres.size(), g.discs.size(),
            g.mesh.size(), scene.instances.size()};
}

void tessellate_since(const Scene& scene, const GeometryMark& since, const Tessellation& how,
                      TriangleMesh& out)
{
    append_geometry(scene.geometry, since, scene.line_radius_in_pixels, how, no_module, out);
    for (std::size_t i = since.instances; i < scene.instances.size(); ++i) {
        const Instance& instance = scene.instances[i];
        Geometry placed = scene.prototypes.at(instance.prototype).geometry;
        place_geometry(placed, instance);
        append_geometry(placed, GeometryMark{}, scene.line_radius_in_pixels, how, instance.module, out);
    }
}

TriangleMesh tessellate(const Scene& scene, const Tessellation& how)
{
    TriangleMesh out;
    tessellate_since(scene, GeometryMark{}, how, out);
    return out;
}

TriangleMesh tessellate_geometry(const Geometry& geometry, bool lines_in_pixels,
                                 const Tessellation& how)
{
    TriangleMesh out;
    append_geometry(geometry, GeometryMark{}, lines_in_pixels, how, no_module, out);
    return out;
}

std::size_t tessellated_triangles(const Geometry& geometry, bool lines_in_pixels,
                                  const Tessellation& how)
{
    return count_geometry(geometry, lines_in_pixels, how);
}

std::size_t tessellated_triangles(const Scene& scene, const Tessellation& how)
{
    std::size_t n = count_geometry(scene.geometry, scene.line_radius_in_pixels, how);
    for (const Instance& instance : scene.instances)
        n += count_geometry(scene.prototypes.at(instance.prototype).geometry,
                            scene.line_radius_in_pixels, how);
    return n;
}

}  // namespace cambium::geom
