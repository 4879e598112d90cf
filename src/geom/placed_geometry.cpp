// SPDX-License-Identifier: Apache-2.0
// Geometry moved into place by an instance's transform.
#include "geom/placed_geometry.h"

#include <cmath>

#include "geom/primitives.h"

namespace cambium::geom {
namespace {

using Transform = std::array<float, 12>;

/// Normals go by the inverse transpose: the cofactor matrix (the determinant's
/// factor does not matter after normalising; its sign does).
Float3 apply_normal(const Transform& m, const Float3& n, double det)
{
    // columns of the linear part: a = (m0 m1 m2), b = (m3 m4 m5), c = (m6 m7 m8)
    Vec3 a{m[0], m[1], m[2]}, b{m[3], m[4], m[5]}, c{m[6], m[7], m[8]};
    Vec3 r = cross(b, c) * double(n[0]) + cross(c, a) * double(n[1]) + cross(a, b) * double(n[2]);
    if (det < 0)
        r = r * -1.0;
    double l = length(r);
    if (l == 0)
        return {0, 0, 0};
    return {float(r.x / l), float(r.y / l), float(r.z / l)};
}

void place_key(Float4& k, const Transform& m, float radius_scale)
{
    Float3 p = Affine3x4(m).apply(Float3{k[0], k[1], k[2]});
    k = {p[0], p[1], p[2], k[3] * radius_scale};
}

void inherit(std::vector<std::uint16_t>& materials, std::uint16_t instance_material)
{
    for (auto& m : materials)
        if (m == inherit_material)
            m = instance_material;
}

/// Untextured primitives take the instance's texture (as render's texture_of does);
/// a texture array shorter than the primitives means untextured.
void inherit_texture(std::vector<std::int16_t>& textures, std::size_t count, std::int16_t texture)
{
    if (texture == no_texture)
        return;
    textures.resize(count, no_texture);
    for (auto& t : textures)
        if (t == no_texture)
            t = texture;
}

}  // namespace

void place_geometry(Geometry& g, const Instance& instance)
{
    const Transform& m = instance.transform;
    double det = Affine3x4(m).determinant();
    auto radius_scale = static_cast<float>(std::cbrt(std::abs(det)));

    for (Float4& k : g.lines.keys)
        place_key(k, m, radius_scale);
    inherit(g.lines.material, instance.material);
    inherit_texture(g.lines.texture, g.lines.segment_count(), instance.texture);

    for (Float4& p : g.curves.points)
        place_key(p, m, radius_scale);
    for (Float4& t : g.curves.tangents) {
        Float3 v = Affine3x4(m).linear(Float3{t[0], t[1], t[2]});
        t = {v[0], v[1], v[2], t[3] * radius_scale};
    }
    inherit(g.curves.material, instance.material);
    inherit(g.curves.end_material, instance.material);
    inherit_texture(g.curves.texture, g.curves.segment_count(), instance.texture);

    for (Float4& c : g.spheres.centres)
        place_key(c, m, radius_scale);
    inherit(g.spheres.material, instance.material);
    inherit_texture(g.spheres.texture, g.spheres.size(), instance.texture);

    for (std::size_t i = 0; i < g.discs.size(); ++i) {
        place_key(g.discs.centres[i], m, radius_scale);
        g.discs.normals[i] = apply_normal(m, g.discs.normals[i], det);
    }
    inherit(g.discs.material, instance.material);
    inherit(g.discs.back_material, instance.back_material);

    TriangleMesh& mesh = g.mesh;
    for (Float3& p : mesh.positions)
        p = Affine3x4(m).apply(p);
    for (Float3& n : mesh.normals)
        if (n[0] != 0 || n[1] != 0 || n[2] != 0)
            n = apply_normal(m, n, det);
    // A mirroring transform turns the winding: swap two corners so that a flat face's
    // front (counter-clockwise) stays on the side it was.
    if (det < 0)
        for (auto& t : mesh.triangles)
            std::swap(t[1], t[2]);
    for (std::size_t t = mesh.back_material.size(); t < mesh.material.size(); ++t)
        mesh.back_material.push_back(mesh.material[t]);  // a missing back is the front
    inherit(mesh.material, instance.material);
    inherit(mesh.back_material, instance.back_material);
    inherit_texture(mesh.texture, mesh.size(), instance.texture);
}

void offset_textures(Geometry& g, std::int16_t offset)
{
    auto shift = [offset](std::vector<std::int16_t>& textures) {
        for (auto& t : textures)
            if (t != no_texture)
                t = static_cast<std::int16_t>(t + offset);
    };
    shift(g.lines.texture);
    shift(g.curves.texture);
    shift(g.spheres.texture);
    shift(g.mesh.texture);
}

}  // namespace cambium::geom
