// SPDX-License-Identifier: Apache-2.0
// The numbers a Scene may hold: what Embree's float BVH and rays can take.
#include "geom/scene_limits.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "base/diagnostics.h"
#include "geom/primitives.h"

namespace cambium::geom {
namespace {

bool key_in_range(const Float4& k) { return in_range(k[0]) && in_range(k[1]) && in_range(k[2]) && in_range(k[3]); }
bool point_in_range(const Float3& p) { return in_range(p[0]) && in_range(p[1]) && in_range(p[2]); }
bool finite(const Float3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

/// A key of a line or a curve point: position in range and a radius in [0, max].
bool valid_key(const Float4& k) { return key_in_range(k) && k[3] >= 0; }

std::string number(double v)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", v);
    return buffer;
}

/// Keeps the entries i of v with keep[i], when v has one entry per primitive (optional
/// attributes may be empty or shorter: those are left alone).
template <class T>
void compact(std::vector<T>& v, const std::vector<char>& keep)
{
    if (v.size() != keep.size())
        return;
    std::size_t out = 0;
    for (std::size_t i = 0; i < v.size(); ++i)
        if (keep[i])
            v[out++] = v[i];
    v.resize(out);
}

template <class T, class... Rest>
void compact(const std::vector<char>& keep, std::vector<T>& first, Rest&... rest)
{
    compact(first, keep);
    (compact(rest, keep), ...);
}

/// Neighbour flags name the segment before or after in the buffer: once some are gone,
/// a flag stays only where the neighbour still shares the key.
void clear_lost_neighbours(const std::vector<std::uint32_t>& segments, std::vector<std::uint8_t>& flags)
{
    if (flags.size() != segments.size())
        return;
    for (std::size_t i = 0; i < segments.size(); ++i) {
        if (i == 0 || segments[i - 1] + 1 != segments[i])
            flags[i] &= static_cast<std::uint8_t>(~CurveFlags::neighbour_left);
        if (i + 1 == segments.size() || segments[i] + 1 != segments[i + 1])
            flags[i] &= static_cast<std::uint8_t>(~CurveFlags::neighbour_right);
    }
}

/// Per segment (first key s, keys s and s + 1): whether both keys are usable; keys
/// that are not are zeroed so that nothing downstream reads them as numbers.
template <class KeyValid>
std::vector<char> usable_segments(const std::vector<std::uint32_t>& segments, std::vector<Float4>& keys,
                                  KeyValid valid)
{
    std::vector<char> key_ok(keys.size());
    for (std::size_t k = 0; k < keys.size(); ++k)
        key_ok[k] = valid(k) ? 1 : 0;
    std::vector<char> keep(segments.size(), 1);
    for (std::size_t i = 0; i < segments.size(); ++i) {
        std::size_t s = segments[i];
        // an index beyond the keys is render's to report (accel's check_segments)
        keep[i] = s + 1 >= keys.size() || (key_ok[s] && key_ok[s + 1]) ? 1 : 0;
    }
    for (std::size_t k = 0; k < keys.size(); ++k)
        if (!key_ok[k])
            keys[k] = {0, 0, 0, 0};
    return keep;
}

std::size_t dropped(const std::vector<char>& keep)
{
    std::size_t n = 0;
    for (char k : keep)
        n += k ? 0 : 1;
    return n;
}

void zero_non_finite(std::vector<float>& values, std::size_t& repaired)
{
    for (float& v : values)
        if (!std::isfinite(v)) {
            v = 0;
            ++repaired;
        }
}

void drop_from(Geometry& g, DroppedGeometry& d)
{
    LinearCurves& l = g.lines;
    std::vector<char> keep = usable_segments(l.segments, l.keys, [&](std::size_t k) { return valid_key(l.keys[k]); });
    d.line_segments += dropped(keep);
    compact(keep, l.segments, l.flags, l.material, l.texture, l.module);
    clear_lost_neighbours(l.segments, l.flags);
    zero_non_finite(l.v, d.attributes);

    HermiteCurves& c = g.curves;
    std::vector<char> point_ok(c.points.size());
    for (std::size_t k = 0; k < c.points.size(); ++k)
        point_ok[k] = valid_key(c.points[k]) && (k >= c.tangents.size() || key_in_range(c.tangents[k]));
    keep = usable_segments(c.segments, c.points, [&](std::size_t k) { return point_ok[k] != 0; });
    for (std::size_t k = 0; k < c.tangents.size() && k < point_ok.size(); ++k)
        if (!point_ok[k])
            c.tangents[k] = {0, 0, 0, 0};
    d.curve_segments += dropped(keep);
    compact(keep, c.segments, c.flags, c.material, c.texture, c.end_material, c.module);
    clear_lost_neighbours(c.segments, c.flags);
    zero_non_finite(c.v, d.attributes);

    Spheres& s = g.spheres;
    keep.assign(s.centres.size(), 1);
    for (std::size_t i = 0; i < keep.size(); ++i)
        keep[i] = valid_key(s.centres[i]) ? 1 : 0;
    d.spheres += dropped(keep);
    compact(keep, s.centres, s.material, s.texture, s.module);

    Discs& disc = g.discs;
    keep.assign(disc.centres.size(), 1);
    for (std::size_t i = 0; i < keep.size(); ++i) {
        const Float3* n = i < disc.normals.size() ? &disc.normals[i] : nullptr;
        bool facing = n && finite(*n) && ((*n)[0] != 0 || (*n)[1] != 0 || (*n)[2] != 0);
        keep[i] = valid_key(disc.centres[i]) && facing ? 1 : 0;
    }
    d.discs += dropped(keep);
    compact(keep, disc.centres, disc.normals, disc.material, disc.back_material, disc.module);

    TriangleMesh& m = g.mesh;
    std::vector<char> position_ok(m.positions.size());
    for (std::size_t k = 0; k < m.positions.size(); ++k)
        position_ok[k] = point_in_range(m.positions[k]) ? 1 : 0;
    keep.assign(m.triangles.size(), 1);
    for (std::size_t t = 0; t < keep.size(); ++t)
        for (std::uint32_t v : m.triangles[t])
            if (v < position_ok.size() && !position_ok[v])
                keep[t] = 0;
    d.triangles += dropped(keep);
    compact(keep, m.triangles, m.material, m.back_material, m.texture, m.module);
    for (std::size_t k = 0; k < m.positions.size(); ++k)
        if (!position_ok[k])
            m.positions[k] = {0, 0, 0};
    for (Float3& n : m.normals)
        if (!finite(n)) {
            n = {0, 0, 0};  // the face's own normal shades it
            ++d.attributes;
        }
    for (Float2& uv : m.uvs)
        if (!std::isfinite(uv[0]) || !std::isfinite(uv[1])) {
            uv = {0, 0};
            ++d.attributes;
        }
}

/// The largest |coordinate| + radius of a geometry: it lies in [-r, r]^3.
double reach(const Geometry& g)
{
    double r = 0;
    auto key = [&](const Float4& k) {
        double radius = std::abs(double(k[3]));
        for (int a = 0; a < 3; ++a)
            r = std::max(r, std::abs(double(k[a])) + radius);
    };
    for (const Float4& k : g.lines.keys)
        key(k);
    for (std::size_t i = 0; i < g.curves.points.size(); ++i) {
        key(g.curves.points[i]);
        if (i < g.curves.tangents.size())  // a Hermite segment stays within its Bezier hull
            for (int a = 0; a < 3; ++a)
                r = std::max(r, std::abs(double(g.curves.points[i][a])) +
                                    std::abs(double(g.curves.tangents[i][a])) / 3 +
                                    std::abs(double(g.curves.points[i][3])) +
                                    std::abs(double(g.curves.tangents[i][3])) / 3);
    }
    for (const Float4& k : g.spheres.centres)
        key(k);
    for (const Float4& k : g.discs.centres)
        key(k);
    for (const Float3& p : g.mesh.positions)
        r = std::max({r, std::abs(double(p[0])), std::abs(double(p[1])), std::abs(double(p[2]))});
    return r;
}

/// Whether an instance's placement keeps its prototype (within [-reach, reach]^3) in
/// range, and its inverse keeps rays within Embree's limits.
bool placeable(const Instance& instance, double reach)
{
    const auto& m = instance.transform;
    for (float v : m)
        if (!std::isfinite(v))
            return false;
    // Row sums of |M| bound how far it moves a point of the box (max norm).
    double norm = 0;
    for (int row = 0; row < 3; ++row)
        norm = std::max(norm, std::abs(double(m[row])) + std::abs(double(m[3 + row])) + std::abs(double(m[6 + row])));
    double det = Affine3x4(m).determinant();
    if (!(std::abs(det) > 0) || norm > max_instance_scale)
        return false;
    // The inverse's rows are the cofactor columns over the determinant.
    Vec3 x{m[0], m[1], m[2]}, y{m[3], m[4], m[5]}, z{m[6], m[7], m[8]};
    double inverse_norm = 0;
    for (const Vec3& r : {cross(y, z), cross(z, x), cross(x, y)})
        inverse_norm = std::max(inverse_norm, (std::abs(r.x) + std::abs(r.y) + std::abs(r.z)) / std::abs(det));
    if (inverse_norm > 1 / min_instance_scale)
        return false;
    double t = std::max({std::abs(double(m[9])), std::abs(double(m[10])), std::abs(double(m[11]))});
    return t + norm * reach <= max_coordinate;
}

void report(std::size_t count, const char* kind, const char* what)
{
    if (count > 0)
        warn(std::to_string(count) + " " + kind + " " + what + " (docs/security.md)");
}

}  // namespace

DroppedGeometry drop_unrenderable(Scene& scene)
{
    DroppedGeometry d;
    drop_from(scene.geometry, d);
    std::vector<double> reaches;
    for (Prototype& p : scene.prototypes) {
        drop_from(p.geometry, d);
        reaches.push_back(reach(p.geometry));
    }
    std::vector<char> keep(scene.instances.size(), 1);
    for (std::size_t i = 0; i < keep.size(); ++i) {
        const Instance& inst = scene.instances[i];
        // an unknown prototype is render's to report
        keep[i] = inst.prototype >= reaches.size() || placeable(inst, reaches[inst.prototype]) ? 1 : 0;
    }
    d.instances = dropped(keep);
    compact(scene.instances, keep);

    const std::string beyond = "not finite or beyond " + number(max_coordinate) + " dropped";
    report(d.line_segments, "line segment(s) with coordinates or widths", beyond.c_str());
    report(d.curve_segments, "generalized-cylinder segment(s) with coordinates, radii or tangents",
           beyond.c_str());
    report(d.spheres, "sphere(s) with a centre or diameter", beyond.c_str());
    report(d.discs, "disc(s) with a centre, diameter or normal", beyond.c_str());
    report(d.triangles, "triangle(s) with vertices", beyond.c_str());
    report(d.instances, "surface or object instance(s)",
           ("with a placement not finite, scaling by less than " + number(min_instance_scale) +
            " or more than " + number(max_instance_scale) + ", or reaching beyond " +
            number(max_coordinate) + " dropped").c_str());
    report(d.attributes, "normal(s) or texture coordinate(s)", "not finite set to 0");

    const Bounds3& b = scene.bounds;
    if (!b.empty())
        for (double v : {b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z})
            if (!in_range(v))
                throw Error("the view volume reaches " + number(v) + ": the turtle or a surface went beyond " +
                            number(max_coordinate) +
                            " from the origin, and such a scene cannot be framed (docs/security.md)");
    return d;
}

namespace {
/// The bytes the vectors have allocated.
template <class... Vectors>
std::size_t vector_bytes(const Vectors&... v)
{
    return ((v.capacity() * sizeof(typename Vectors::value_type)) + ...);
}

}  // namespace

std::size_t geometry_bytes(const Geometry& g)
{
    const LinearCurves& l = g.lines;
    const HermiteCurves& c = g.curves;
    const TriangleMesh& m = g.mesh;
    return vector_bytes(l.keys, l.v, l.segments, l.flags, l.material, l.texture, l.module) +
           vector_bytes(c.points, c.tangents, c.v, c.segments, c.flags, c.material, c.texture,
                        c.end_material, c.module) +
           vector_bytes(g.spheres.centres, g.spheres.material, g.spheres.texture,
                        g.spheres.module) +
           vector_bytes(g.discs.centres, g.discs.normals, g.discs.material,
                        g.discs.back_material, g.discs.module) +
           vector_bytes(m.positions, m.normals, m.uvs, m.triangles, m.material,
                        m.back_material, m.texture, m.module) +
           g.modules.records.capacity() * sizeof(ModuleRecord) +
           g.modules.orders.capacity() * sizeof(std::uint16_t) +
           g.modules.births.capacity() * sizeof(std::uint32_t);
}

void fit_mesh_buffers(TriangleMesh& mesh, bool textured_by_instances)
{
    bool untextured = std::all_of(mesh.texture.begin(), mesh.texture.end(),
                                  [](std::int16_t t) { return t == no_texture; });
    if (untextured)
        mesh.texture = {};
    bool zeros = std::all_of(mesh.uvs.begin(), mesh.uvs.end(),
                             [](const Float2& uv) { return uv[0] == 0 && uv[1] == 0; });
    if (zeros || (untextured && !textured_by_instances))
        mesh.uvs = {};
    fit_buffer(mesh.positions, embree_padding_bytes);
    fit_buffer(mesh.triangles, embree_padding_bytes);
    fit_buffer(mesh.normals);
    fit_buffer(mesh.uvs);
    fit_buffer(mesh.material);
    fit_buffer(mesh.back_material);
    fit_buffer(mesh.texture);
    fit_buffer(mesh.hidden_edges);
    fit_buffer(mesh.module);
}

void fit_scene_buffers(Scene& scene)
{
    fit_mesh_buffers(scene.geometry.mesh, false);
    // An instance's texture falls on its prototype's untextured primitives.
    std::vector<bool> textured(scene.prototypes.size(), false);
    for (const Instance& i : scene.instances)
        if (i.texture != no_texture && i.prototype < textured.size())
            textured[i.prototype] = true;
    for (std::size_t p = 0; p < scene.prototypes.size(); ++p)
        fit_mesh_buffers(scene.prototypes[p].geometry.mesh, textured[p]);
    fit_buffer(scene.instances);
    fit_buffer(scene.geometry.modules.records);  // one record per organ: millions in a tree
    fit_buffer(scene.geometry.modules.orders);
    fit_buffer(scene.geometry.modules.births);
    fit_buffer(scene.geometry.curves.module);
    fit_buffer(scene.geometry.spheres.module);
    fit_buffer(scene.geometry.discs.module);
}

std::size_t scene_buffer_bytes(const Scene& scene)
{
    std::size_t bytes = geometry_bytes(scene.geometry) +
                        scene.instances.capacity() * sizeof(Instance) +
                        scene.prototypes.capacity() * sizeof(Prototype);
    for (const Prototype& p : scene.prototypes)
        bytes += geometry_bytes(p.geometry);
    return bytes;
}

}  // namespace cambium::geom
