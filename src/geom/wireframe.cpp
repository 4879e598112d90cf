// SPDX-License-Identifier: Apache-2.0
// `render mode: wireframe`: primitives replaced by their edges as pixel-width lines.
#include "geom/wireframe.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "base/diagnostics.h"
#include "geom/gencyl.h"

namespace cambium::geom {

namespace {

Vec3 vec(const Float3& f) { return {f[0], f[1], f[2]}; }
Vec3 vec(const Float4& f) { return {f[0], f[1], f[2]}; }

template <class T>
T at_or(const std::vector<T>& v, std::size_t i, T fallback)
{
    return i < v.size() ? v[i] : fallback;
}

/// A unit vector perpendicular to the unit vector d: `hint` made perpendicular when it
/// is usable (the frame carried from the previous segment), otherwise the world axis
/// least aligned with d.
Vec3 perpendicular(const Vec3& d, const Vec3& hint)
{
    Vec3 u = hint - d * dot(hint, d);
    if (length(u) > 1e-6)
        return normalize(u);
    Vec3 axis = std::fabs(d.x) < 0.6 ? Vec3{1, 0, 0} : std::fabs(d.y) < 0.6 ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
    return normalize(axis - d * dot(axis, d));
}

/// The edges being collected: two keys of the same pixel radius per edge.
class EdgeLines {
public:
    EdgeLines(LinearCurves& out, double width_px) : m_out(out), m_radius(static_cast<float>(width_px / 2)) {}

    void add(const Vec3& a, const Vec3& b, std::uint16_t material)
    {
        auto first = static_cast<std::uint32_t>(m_out.keys.size());
        for (const Vec3& p : {a, b}) {
            m_out.keys.push_back({static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), m_radius});
            m_out.v.push_back(0);
        }
        m_out.segments.push_back(first);
        m_out.flags.push_back(0);
        m_out.material.push_back(material);
        m_out.texture.push_back(no_texture);
    }

    /// A closed polygon through `points`.
    void add_loop(const std::vector<Vec3>& points, std::uint16_t material)
    {
        for (std::size_t i = 0; i < points.size(); ++i)
            add(points[i], points[(i + 1) % points.size()], material);
    }

private:
    LinearCurves& m_out;
    float m_radius;
};

/// `sides` points on the circle of `radius` about `centre` in the plane of u and v.
std::vector<Vec3> ring(const Vec3& centre, double radius, const Vec3& u, const Vec3& v, int sides)
{
    std::vector<Vec3> points;
    points.reserve(static_cast<std::size_t>(sides));
    for (int i = 0; i < sides; ++i) {
        double angle = 2 * std::numbers::pi * i / sides;
        points.push_back(centre + (u * std::cos(angle) + v * std::sin(angle)) * radius);
    }
    return points;
}

/// A chain of frustums as cpfg's cylinders are drawn: a triangle strip between the rings
/// of each piece (lengthwise edges, diagonals, both rings). `up` carries the rings'
/// frame from piece to piece and is updated.
class TubeEdges {
public:
    TubeEdges(EdgeLines& edges, int sides) : m_edges(edges), m_sides(sides) {}

    void frustum(const Vec3& a, double ra, const Vec3& b, double rb, std::uint16_t material, Vec3& up)
    {
        Vec3 d = b - a;
        if (!(length(d) > 0))
            return;
        d = normalize(d);
        up = perpendicular(d, up);
        Vec3 side = cross(d, up);
        std::vector<Vec3> base = ring(a, ra, up, side, m_sides), top = ring(b, rb, up, side, m_sides);
        for (std::size_t i = 0; i < base.size(); ++i) {
            std::size_t next = (i + 1) % base.size();
            m_edges.add(base[i], top[i], material);
            m_edges.add(base[i], base[next], material);
            m_edges.add(top[i], top[next], material);
            m_edges.add(top[i], base[next], material);
        }
    }

private:
    EdgeLines& m_edges;
    int m_sides;
};

void cylinder_edges(const LinearCurves& lines, TubeEdges& tubes)
{
    Vec3 up{0, 0, 1};
    for (std::size_t i = 0; i < lines.segments.size(); ++i) {
        std::uint32_t k = lines.segments[i];
        if (k + 1 >= lines.keys.size())
            continue;
        if (!(at_or(lines.flags, i, std::uint8_t{0}) & CurveFlags::neighbour_left))
            up = {0, 0, 1};
        const Float4 &a = lines.keys[k], &b = lines.keys[k + 1];
        tubes.frustum(vec(a), a[3], vec(b), b[3], at_or(lines.material, i, std::uint16_t{0}), up);
    }
}

void curve_edges(const HermiteCurves& curves, TubeEdges& tubes)
{
    constexpr int pieces = default_cylinder_strips;
    Vec3 up{0, 0, 1};
    for (std::size_t i = 0; i < curves.segments.size(); ++i) {
        std::uint32_t k = curves.segments[i];
        if (k + 1 >= curves.points.size() || k + 1 >= curves.tangents.size())
            continue;
        if (!(at_or(curves.flags, i, std::uint8_t{0}) & CurveFlags::neighbour_left))
            up = {0, 0, 1};
        const Float4 &p0 = curves.points[k], &p1 = curves.points[k + 1];
        const Float4 &t0 = curves.tangents[k], &t1 = curves.tangents[k + 1];
        // The radius is the fourth coordinate of the same cubic.
        auto at = [&](double s, double& radius) {
            Vec3 r = hermite({p0[3], 0, 0}, {p1[3], 0, 0}, {t0[3], 0, 0}, {t1[3], 0, 0}, s);
            radius = r.x;
            return hermite(vec(p0), vec(p1), vec(t0), vec(t1), s);
        };
        std::uint16_t material = at_or(curves.material, i, std::uint16_t{0});
        double r0 = 0, r1 = 0;
        Vec3 a = at(0, r0);
        for (int j = 1; j <= pieces; ++j) {
            Vec3 b = at(static_cast<double>(j) / pieces, r1);
            tubes.frustum(a, r0, b, r1, material, up);
            a = b;
            r0 = r1;
        }
    }
}

void disc_edges(const Discs& discs, EdgeLines& edges, int sides)
{
    for (std::size_t i = 0; i < discs.size(); ++i) {
        const Float4& c = discs.centres[i];
        Vec3 n = normalize(vec(at_or(discs.normals, i, Float3{0, 0, 1})));
        Vec3 u = perpendicular(n, {0, 0, 0});
        edges.add_loop(ring(vec(c), c[3], u, cross(n, u), sides), at_or(discs.material, i, std::uint16_t{0}));
    }
}

/// gluSphere(slices = sides, stacks = sides / 2 + 1) in GLU_SILHOUETTE style: the
/// edges between its non-coplanar quads, i.e. every meridian and inner parallel.
void quadric_sphere_edges(const Vec3& c, double r, std::uint16_t material, EdgeLines& edges, int sides)
{
    const int slices = sides, stacks = sides / 2 + 1;
    auto point = [&](int slice, int stack) {
        double theta = 2 * std::numbers::pi * slice / slices, phi = std::numbers::pi * stack / stacks;
        return c + Vec3{std::sin(phi) * std::cos(theta), std::sin(phi) * std::sin(theta), std::cos(phi)} * r;
    };
    for (int i = 0; i < slices; ++i)
        for (int j = 0; j < stacks; ++j) {
            edges.add(point(i, j), point(i, j + 1), material);
            if (j > 0)
                edges.add(point(i, j), point((i + 1) % slices, j), material);
        }
}

/// The octahedron subdivided (level - 1) times, each new vertex pushed onto the sphere:
/// 8 * 4^(level - 1) triangles, every edge drawn.
void octahedron_sphere_edges(const Vec3& c, double r, std::uint16_t material, EdgeLines& edges, int sides)
{
    int level = std::max(1, static_cast<int>(std::floor(std::log2(static_cast<double>(sides)) - 1)));
    level = std::min(level, 6);
    using Face = std::array<Vec3, 3>;
    const Vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
    std::vector<Face> faces;
    for (double sx : {1.0, -1.0})
        for (double sy : {1.0, -1.0})
            for (double sz : {1.0, -1.0})
                faces.push_back({x * sx, y * sy, z * sz});
    for (int l = 1; l < level; ++l) {
        std::vector<Face> finer;
        for (const Face& f : faces) {
            Vec3 ab = normalize(f[0] + f[1]), bc = normalize(f[1] + f[2]), ca = normalize(f[2] + f[0]);
            finer.push_back({f[0], ab, ca});
            finer.push_back({ab, f[1], bc});
            finer.push_back({ca, bc, f[2]});
            finer.push_back({ab, bc, ca});
        }
        faces = std::move(finer);
    }
    for (const Face& f : faces)
        edges.add_loop({c + f[0] * r, c + f[1] * r, c + f[2] * r}, material);
}

void sphere_edges(const Spheres& spheres, EdgeLines& edges, const WireframeStyle& style)
{
    for (std::size_t i = 0; i < spheres.size(); ++i) {
        const Float4& s = spheres.centres[i];
        std::uint16_t material = at_or(spheres.material, i, std::uint16_t{0});
        if (style.quadric_spheres)
            quadric_sphere_edges(vec(s), s[3], material, edges, style.sides);
        else
            octahedron_sphere_edges(vec(s), s[3], material, edges, style.sides);
    }
}

/// Every triangle edge once (shared edges of a mesh are one line), less polygons' inner edges.
void mesh_edges(const TriangleMesh& mesh, EdgeLines& edges)
{
    std::unordered_set<std::uint64_t> drawn;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto& tri = mesh.triangles[t];
        std::uint8_t hidden = at_or(mesh.hidden_edges, t, std::uint8_t{0});
        for (std::size_t k = 0; k < 3; ++k) {
            std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
            if ((hidden >> k) & 1u || a >= mesh.positions.size() || b >= mesh.positions.size())
                continue;
            std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
            if (drawn.insert(key).second)
                edges.add(vec(mesh.positions[a]), vec(mesh.positions[b]), at_or(mesh.material, t, std::uint16_t{0}));
        }
    }
}

/// Pixel lines as they are, with every optional attribute filled so that edges can be
/// appended after them.
LinearCurves pixel_lines_kept(LinearCurves lines)
{
    lines.v.resize(lines.keys.size(), 0);
    lines.flags.resize(lines.segments.size(), 0);
    lines.material.resize(lines.segments.size(), 0);
    lines.texture.resize(lines.segments.size(), no_texture);
    return lines;
}

/// Most edges a wireframe may have (each two keys, about 60 bytes).
constexpr double max_edges = double(std::size_t{1} << 26);

/// How many edges to_wireframe makes of `g`, at most.
double edge_count(const Geometry& g, bool lines_in_pixels, const WireframeStyle& style)
{
    const double sides = style.sides;
    const double per_sphere = style.quadric_spheres ? sides * (sides + 1) : 3 * 8 * std::pow(4.0, 5);
    return (lines_in_pixels ? 0.0 : 4 * sides * double(g.lines.segment_count())) +
           4 * sides * default_cylinder_strips * double(g.curves.segment_count()) + sides * double(g.discs.size()) +
           per_sphere * double(g.spheres.size()) + 3 * double(g.mesh.size());
}

void to_wireframe(Geometry& g, bool lines_in_pixels, const WireframeStyle& style)
{
    LinearCurves out = lines_in_pixels ? pixel_lines_kept(std::move(g.lines)) : LinearCurves{};
    EdgeLines edges(out, style.edge_width_px);
    TubeEdges tubes(edges, style.sides);
    if (!lines_in_pixels)
        cylinder_edges(g.lines, tubes);
    curve_edges(g.curves, tubes);
    disc_edges(g.discs, edges, style.sides);
    sphere_edges(g.spheres, edges, style);
    mesh_edges(g.mesh, edges);
    ModuleTable modules = std::move(g.modules);  // instances still name theirs
    g = Geometry{};
    g.modules = std::move(modules);
    g.lines = std::move(out);
    g.lines.module.clear();  // edges name no module (provenance)
}

}  // namespace

double wireframe_edge_width(const Bounds3& view_volume, int image_width)
{
    double width = view_volume.empty() || image_width <= 0 ? 0 : (view_volume.hi.x - view_volume.lo.x) / image_width / 10;
    return std::isfinite(width) ? std::max(1.0, width) : 1.0;
}

void draw_as_wireframe(Scene& scene, const WireframeStyle& style)
{
    WireframeStyle s = style;
    s.sides = std::clamp(s.sides, 3, 1000);
    double edges = edge_count(scene.geometry, scene.line_radius_in_pixels, s);
    for (const Prototype& p : scene.prototypes)
        edges += edge_count(p.geometry, scene.line_radius_in_pixels, s);
    if (edges > max_edges)
        throw Error("render mode: wireframe: the scene's edges would be about " + std::to_string(std::llround(edges)) +
                    " lines (at most " + std::to_string(std::llround(max_edges)) + ")");
    to_wireframe(scene.geometry, scene.line_radius_in_pixels, s);
    for (Prototype& p : scene.prototypes)
        to_wireframe(p.geometry, scene.line_radius_in_pixels, s);
    scene.line_radius_in_pixels = true;
}

}  // namespace cambium::geom
