// SPDX-License-Identifier: Apache-2.0
// `-o>` object instancing: keys, prototypes, placement, and cutting an expansion's geometry.
#include "geom/object_instancing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "base/diagnostics.h"
#include "geom/primitives.h"

namespace cambium::geom {
namespace {

/// A normal under the placement: by the inverse transpose of its 3x3 part (the
/// cofactor matrix over the determinant, of which only the sign matters), normalised.
Float3 place_normal(const std::array<float, 12>& m, const Float3& n)
{
    Vec3 x{m[0], m[1], m[2]}, y{m[3], m[4], m[5]}, z{m[6], m[7], m[8]};
    Vec3 r = cross(y, z) * n[0] + cross(z, x) * n[1] + cross(x, y) * n[2];
    if (dot(x, cross(y, z)) < 0)
        r = r * -1.0;
    double len = std::sqrt(dot(r, r));
    if (len == 0)
        return n;
    return {static_cast<float>(r.x / len), static_cast<float>(r.y / len), static_cast<float>(r.z / len)};
}

}  // namespace

std::array<float, 12> object_transform(const Turtle& t)
{
    auto f = [](double v) { return static_cast<float>(v); };
    return {f(-t.left.x), f(-t.left.y), f(-t.left.z), f(t.heading.x), f(t.heading.y), f(t.heading.z),
            f(-t.up.x),   f(-t.up.y),   f(-t.up.z),   f(t.position.x), f(t.position.y), f(t.position.z)};
}

void append_placed_mesh(TriangleMesh& into, const TriangleMesh& from, const Instance& instance)
{
    // provenance: the copies are the placing module's (kept only where `into` keeps it)
    if (into.module.size() == into.size() && (!into.module.empty() || into.size() == 0))
        into.module.insert(into.module.end(), from.size(), instance.module);
    auto base = static_cast<std::uint32_t>(into.positions.size());
    for (std::size_t i = 0; i < from.positions.size(); ++i) {
        into.positions.push_back(Affine3x4(instance.transform).apply(from.positions[i]));
        into.normals.push_back(i < from.normals.size() ? place_normal(instance.transform, from.normals[i])
                                                       : Float3{0, 0, 0});
        into.uvs.push_back(i < from.uvs.size() ? from.uvs[i] : Float2{0, 0});
    }
    auto pick = [](std::uint16_t own, std::uint16_t inherited) {
        return own == inherit_material ? inherited : own;
    };
    for (std::size_t t = 0; t < from.triangles.size(); ++t) {
        const auto& tri = from.triangles[t];
        into.triangles.push_back({base + tri[0], base + tri[1], base + tri[2]});
        std::uint16_t front = t < from.material.size() ? from.material[t] : inherit_material;
        std::uint16_t back = t < from.back_material.size() ? from.back_material[t] : front;
        into.material.push_back(pick(front, instance.material));
        into.back_material.push_back(pick(back, instance.back_material));
        std::int16_t texture = t < from.texture.size() ? from.texture[t] : no_texture;
        into.texture.push_back(texture == no_texture ? instance.texture : texture);
    }
    if (!from.hidden_edges.empty()) {  // keep each placed polygon's outline
        into.hidden_edges.resize(into.triangles.size() - from.triangles.size(), 0);
        for (std::size_t t = 0; t < from.triangles.size(); ++t)
            into.hidden_edges.push_back(t < from.hidden_edges.size() ? from.hidden_edges[t] : 0);
    }
}

GeometryCheckpoint::GeometryCheckpoint(const Geometry& g)
    : m_line_keys(g.lines.keys.size()), m_line_v(g.lines.v.size()), m_line_segments(g.lines.segments.size()),
      m_curve_points(g.curves.points.size()), m_curve_v(g.curves.v.size()),
      m_curve_segments(g.curves.segments.size()), m_spheres(g.spheres.centres.size()),
      m_sphere_textures(g.spheres.texture.size()), m_discs(g.discs.centres.size()),
      m_positions(g.mesh.positions.size()), m_uvs(g.mesh.uvs.size()), m_triangles(g.mesh.triangles.size()),
      m_mesh_textures(g.mesh.texture.size())
{
    if (!g.lines.flags.empty())
        m_line_flag = g.lines.flags.back();
    if (!g.curves.flags.empty())
        m_curve_flag = g.curves.flags.back();
}

bool GeometryCheckpoint::restore(Geometry& g) const
{
    bool drew_lines = g.lines.keys.size() != m_line_keys;
    auto cut = [](auto& v, std::size_t n) {
        if (v.size() > n)
            v.resize(n);
    };
    LinearCurves& l = g.lines;
    cut(l.keys, m_line_keys), cut(l.v, m_line_v), cut(l.segments, m_line_segments);
    cut(l.flags, m_line_segments), cut(l.material, m_line_segments), cut(l.texture, m_line_segments);
    HermiteCurves& c = g.curves;
    cut(c.points, m_curve_points), cut(c.tangents, m_curve_points), cut(c.v, m_curve_v);
    cut(c.segments, m_curve_segments), cut(c.flags, m_curve_segments), cut(c.material, m_curve_segments);
    cut(c.texture, m_curve_segments), cut(c.end_material, m_curve_segments);
    cut(g.spheres.centres, m_spheres), cut(g.spheres.material, m_spheres);
    cut(g.spheres.texture, m_sphere_textures);
    cut(g.discs.centres, m_discs), cut(g.discs.normals, m_discs), cut(g.discs.material, m_discs);
    cut(g.discs.back_material, m_discs);
    TriangleMesh& m = g.mesh;
    cut(m.positions, m_positions), cut(m.normals, m_positions), cut(m.uvs, m_uvs);
    cut(m.triangles, m_triangles), cut(m.material, m_triangles), cut(m.back_material, m_triangles);
    cut(m.texture, m_mesh_textures), cut(m.hidden_edges, m_triangles);
    // the segments before the object are no longer continued by the cut ones
    if (m_line_flag >= 0)
        l.flags.back() = static_cast<std::uint8_t>(m_line_flag);
    if (m_curve_flag >= 0)
        c.flags.back() = static_cast<std::uint8_t>(m_curve_flag);
    return drew_lines;
}

ObjectInstancer::ObjectInstancer(const ViewFile& view, Expand expand)
    : m_keying(view.rayshade_objects), m_expand(std::move(expand))
{
}

std::shared_ptr<const lsys::ModuleString> ObjectInstancer::expansion(lsys::ModuleRef m)
{
    std::string exact(reinterpret_cast<const char*>(&m.symbol), sizeof m.symbol);
    exact.append(reinterpret_cast<const char*>(m.params.data()), m.params.size_bytes());
    if (auto it = m_expansions.find(exact); it != m_expansions.end())
        return it->second;
    auto e = std::make_shared<const lsys::ModuleString>(m_expand(m));
    if (m_cached_modules + e->size() > max_cached_expansion_modules) {
        m_expansions.clear();
        m_cached_modules = 0;
    }
    m_cached_modules += e->size() + 1;
    m_expansions.emplace(std::move(exact), e);
    return e;
}

std::string ObjectInstancer::key(std::string_view name, lsys::ModuleRef m, const Turtle& t) const
{
    std::string key(name);
    char buffer[512];
    for (float p : m.params) {
        std::snprintf(buffer, sizeof buffer, m_keying.format.c_str(), static_cast<double>(p));
        key += '_';
        key += buffer;
    }
    if (m_keying.turtle_considered) {
        std::snprintf(buffer, sizeof buffer, "|%a|%a|%d|%d|%d", t.line_width, t.scale, t.color, t.back_color,
                      t.texture);
        key += buffer;
    }
    return key;
}

int ObjectInstancer::prototype(std::string key, Scene& scene, const std::function<Geometry()>& build)
{
    if (auto it = m_prototypes.find(key); it != m_prototypes.end())
        return it->second;
    Geometry built = build();
    int index = -1;
    if (!built.empty()) {
        index = static_cast<int>(scene.prototypes.size());
        scene.prototypes.push_back(Prototype{key, std::move(built)});
    }
    m_prototypes.emplace(std::move(key), index);
    return index;
}

}  // namespace cambium::geom
