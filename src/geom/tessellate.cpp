// SPDX-License-Identifier: Apache-2.0
#include "geom/tessellate.h"

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "geom/line_ends.h"
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

/// Two unit vectors completing `axis` (unit) to a right-handed orthonormal frame.
void perpendiculars(const Vec3& axis, Vec3& u, Vec3& v)
{
    const Vec3 other = std::abs(axis.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    u = normalize(cross(axis, other));
    v = cross(axis, u);
}

/// A ring of vertices around `centre` in the frame (u, v), normals pointing outward,
/// leaning by `lean` (along the axis) where the wall is a cone's.
std::uint32_t ring(MeshWriter& w, const Vec3& centre, const Vec3& u, const Vec3& v, double radius,
                   int sides, const Vec3& lean = {0, 0, 0})
{
    std::uint32_t first = 0;
    for (int k = 0; k < sides; ++k) {
        const double a = 2 * std::numbers::pi * k / sides;
        const Vec3 out = std::cos(a) * u + std::sin(a) * v;
        const std::uint32_t i = w.vertex(centre + out * radius, normalize(out + lean));
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

/// `w` turned by `angle` about the unit `axis` (Rodrigues).
Vec3 turned(const Vec3& w, const Vec3& axis, double angle)
{
    const double c = std::cos(angle), s = std::sin(angle);
    return w * c + cross(axis, w) * s + axis * (dot(axis, w) * (1 - c));
}

/// The bend from unit direction `a` to unit direction `b`: the axis it turns about (any
/// unit vector square to `a` where they are opposite) and its angle.
struct Bend {
    Vec3 axis;
    double angle = 0;
};

Bend bend(const Vec3& a, const Vec3& b)
{
    const Vec3 k = cross(a, b);
    const double angle = std::atan2(length(k), dot(a, b));
    if (length(k) > 1e-12)
        return {normalize(k), angle};
    Vec3 u, v;
    perpendiculars(a, u, v);
    return {u, angle};
}

/// The unit direction of line key k to key k + 1, or zero where the keys coincide.
Vec3 line_axis(const LinearCurves& l, std::uint32_t k)
{
    const Vec3 d = point(l.keys[k + 1]) - point(l.keys[k]);
    return length(d) > 0 ? normalize(d) : Vec3{0, 0, 0};
}

/// The rings a joint's zone takes after the end ring: one per 360 / `sides` degrees of
/// bend from `a` to `b`, or 0 where either has no direction (the whole sphere is made).
int joint_steps(const Vec3& a, const Vec3& b, int sides)
{
    if (!(length(a) > 0) || !(length(b) > 0))
        return 0;
    const double steps = std::ceil(bend(a, b).angle * sides / (2 * std::numbers::pi) - 1e-9);
    return std::max(1, static_cast<int>(steps));
}

/// A ring of `sides` vertices round `centre` in the frame (u, v) turned by `angle` about
/// `axis` round `pivot`, normals pointing away from `pivot`: one ring of a joint's zone.
std::uint32_t turned_ring(MeshWriter& w, const Vec3& pivot, const Vec3& u, const Vec3& v,
                          double radius, const Vec3& axis, double angle, int sides)
{
    std::uint32_t first = 0;
    for (int k = 0; k < sides; ++k) {
        const double a = 2 * std::numbers::pi * k / sides;
        const Vec3 out = turned(std::cos(a) * u + std::sin(a) * v, axis, angle);
        const std::uint32_t i = w.vertex(pivot + out * radius, out);
        if (k == 0)
            first = i;
    }
    return first;
}

/// A flat end of a cylinder: a fan over the ring (u, v) round `centre`, facing `normal`
/// (the axis for the far end, against it for the near one).
void cap(MeshWriter& w, const Float4& centre, const Vec3& u, const Vec3& v, const Vec3& normal,
         bool far_end, int sides)
{
    const std::uint32_t middle = w.vertex(point(centre), normal);
    for (int k = 0; k < sides; ++k) {
        const double a = 2 * std::numbers::pi * k / sides;
        w.vertex(point(centre) + (std::cos(a) * u + std::sin(a) * v) * centre[3], normal);
    }
    for (int k = 0; k < sides; ++k) {
        const std::uint32_t a = middle + 1 + static_cast<std::uint32_t>(k);
        const std::uint32_t b = middle + 1 + static_cast<std::uint32_t>((k + 1) % sides);
        // counter-clockwise seen from the side the normal points to
        if (far_end)
            w.triangle(middle, a, b);
        else
            w.triangle(middle, b, a);
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

/// A bent joint as the renderer rounds it with a sphere of the joint's radius: the zone
/// of that sphere the end ring (u, v) sweeps turning from direction `a` to `b` (the
/// sphere's visible part lies between the two segments' end planes), or the whole sphere
/// where a segment has no direction.
void joint(MeshWriter& w, const Float4& at, const Vec3& u, const Vec3& v, const Vec3& a,
           const Vec3& b, int sides)
{
    const int steps = joint_steps(a, b, sides);
    if (steps == 0)
        return sphere(w, at, sides);
    const Bend turn = bend(a, b);
    std::uint32_t previous = turned_ring(w, point(at), u, v, at[3], turn.axis, 0, sides);
    for (int j = 1; j <= steps; ++j) {
        const std::uint32_t next =
            turned_ring(w, point(at), u, v, at[3], turn.axis, turn.angle * j / steps, sides);
        wall(w, previous, next, sides);
        previous = next;
    }
}

/// Whether line segment s continues segment s - 1 at its key (a chain, which carries
/// its ring frame on).
bool continues_chain(const LinearCurves& l, std::size_t s)
{
    const bool joined = l.flags.size() == l.segments.size() &&
                        (l.flags[s] & LinearCurves::neighbour_left);
    return s > 0 && joined && l.segments[s - 1] + 1 == l.segments[s];
}

/// Shaded cylinders (F, G) as the renderer draws them (render/line_geometry.h): each
/// segment's wall, with closed ends (`how.closed_lines`) a disc on each free end and
/// the joint sphere's zone at each bent joint, by the renderer's rule
/// (geom/line_ends.h). The ring frame is carried along a chain (turned at each joint as
/// the segments turn), so walls, discs and zones meet edge to edge.
void append_lines(const LinearCurves& l, std::size_t since, const Tessellation& how,
                  std::uint32_t placed, TriangleMesh& out)
{
    Vec3 u, v, along;  // the ring frame and the direction it is square to
    bool framed = false;
    for (std::size_t s = since; s < l.segments.size(); ++s) {
        MeshWriter w(out, l.material[s], l.material[s], texture_of(l.texture, s),
                     module_of(l.module, s, placed));
        const std::uint32_t k = l.segments[s];
        const Vec3 dir = line_axis(l, k);
        const bool carried = framed && s > since && continues_chain(l, s);
        if (length(dir) > 0) {
            if (carried) {
                const Bend turn = bend(along, dir);
                u = normalize(turned(u, turn.axis, turn.angle));
                u = normalize(u - dir * dot(u, dir));
                v = cross(dir, u);
            } else {
                perpendiculars(dir, u, v);
            }
            along = dir;
            framed = true;
            const Float4 &a = l.keys[k], &b = l.keys[k + 1];
            // a tapered segment's normals lean toward its narrow end, as the cone's do
            const Vec3 lean = dir * ((a[3] - b[3]) / length(point(b) - point(a)));
            wall(w, ring(w, point(a), u, v, a[3], how.sides, lean),
                 ring(w, point(b), u, v, b[3], how.sides, lean), how.sides);
        } else if (!carried) {
            framed = false;
        }
        if (!how.closed_lines)
            continue;
        visit_line_ends(
            l, l.keys.data(), s,
            [&](const Float4& at, const Float3& normal, bool far_end) {
                cap(w, at, u, v, point(normal), far_end, how.sides);
            },
            [&](const Float4& at) {
                if (framed)
                    joint(w, at, u, v, dir, line_axis(l, k + 1), how.sides);
                else
                    sphere(w, at, how.sides);
            });
    }
}

/// The triangles append_lines() makes of `l`.
std::size_t count_lines(const LinearCurves& l, const Tessellation& how)
{
    const std::size_t sides = std::size_t(how.sides);
    const std::size_t sphere = 2 * sides * (std::size_t(std::max(2, how.sides / 2)) - 1);
    std::size_t n = 0;
    for (std::size_t s = 0; s < l.segments.size(); ++s) {
        const std::uint32_t k = l.segments[s];
        const Vec3 dir = line_axis(l, k);
        if (length(dir) > 0)
            n += 2 * sides;
        if (!how.closed_lines)
            continue;
        visit_line_ends(
            l, l.keys.data(), s, [&](const Float4&, const Float3&, bool) { n += sides; },
            [&](const Float4&) {
                const int steps = joint_steps(dir, line_axis(l, k + 1), how.sides);
                n += steps == 0 ? sphere : 2 * sides * std::size_t(steps);
            });
    }
    return n;
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
    auto rate = [&](double t, int i) {  // d/dt of at(t, i)
        const double t2 = t * t;
        return (6 * t2 - 6 * t) * p0[i] + (3 * t2 - 4 * t + 1) * t0[i] + (-6 * t2 + 6 * t) * p1[i] +
               (3 * t2 - 2 * t) * t1[i];
    };
    const Vec3 chord = point(p1) - point(p0);
    if (!(length(chord) > 0))
        return;
    const Vec3 axis = normalize(chord);
    Vec3 u, v;
    perpendiculars(axis, u, v);
    // where the radius changes along the axis (@Gr, tapers) the normals lean as the wall does
    auto lean = [&](double t) {
        const double speed = length(Vec3{rate(t, 0), rate(t, 1), rate(t, 2)});
        return speed > 0 ? axis * (-rate(t, 3) / speed) : Vec3{0, 0, 0};
    };
    std::uint32_t previous = ring(w, point(p0), u, v, p0[3], how.sides, lean(0));
    for (int k = 1; k <= how.curve_pieces; ++k) {
        const double t = double(k) / how.curve_pieces;
        const std::uint32_t next =
            ring(w, Vec3{at(t, 0), at(t, 1), at(t, 2)}, u, v, at(t, 3), how.sides, lean(t));
        wall(w, previous, next, how.sides);
        previous = next;
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

void append_geometry(const Geometry& g, const GeometryMark& since, bool lines_in_pixels,
                     const Tessellation& how, std::uint32_t placed, TriangleMesh& out)
{
    if (!lines_in_pixels)
        append_lines(g.lines, since.line_segments, how, placed, out);
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
    return (lines_in_pixels ? 0 : count_lines(g.lines, how)) +
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
    // counted once a prototype: closed lines take a pass over its segments
    std::vector<std::optional<std::size_t>> per_prototype(scene.prototypes.size());
    for (const Instance& instance : scene.instances) {
        std::optional<std::size_t>& count = per_prototype.at(instance.prototype);
        if (!count)
            count = count_geometry(scene.prototypes[instance.prototype].geometry,
                                   scene.line_radius_in_pixels, how);
        n += *count;
    }
    return n;
}

}  // namespace cambium::geom
