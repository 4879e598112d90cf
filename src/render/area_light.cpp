// SPDX-License-Identifier: Apache-2.0
// Emissive primitives as area lights: the list next-event estimation samples from.
//
// Facts (docs/lights.md): a material's `emission` is the radiance a surface sends from
// each point in every direction of its side (Lambertian emitter), decoded from display
// values like every cpfg colour. Triangles and discs emit from each side with that
// side's material; spheres emit the same radiance from every point, seen from outside
// or inside; a line segment of constant radius emits from its lateral surface (its round
// ends and joints are left to BSDF sampling: pdf() is 0 there). Instanced spheres, discs
// and segments are listed only under similarity transforms
// (Embree draws them as ellipsoids and ellipses otherwise, which we do not sample);
// left out, they are found by BSDF sampling alone, which stays unbiased.
#include "render/area_light.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "base/diagnostics.h"

namespace cambium::render {

namespace {

constexpr float pi = std::numbers::pi_v<float>;

float luminance(const Vec3f& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

Vec3f vec(const geom::Float3& a) { return {a[0], a[1], a[2]}; }
Vec3f vec(const geom::Float4& a) { return {a[0], a[1], a[2]}; }

/// An instance's affine map x' = A x + t, the cofactor matrix for normals and whether it
/// is a similarity (uniform scale times a rotation or reflection).
struct Affine {
    Vec3f c0{1, 0, 0}, c1{0, 1, 0}, c2{0, 0, 1}, t;
    float det = 1, scale = 1;
    bool similarity = true;

    Vec3f point(const Vec3f& p) const { return c0 * p.x + c1 * p.y + c2 * p.z + t; }
    /// A normal's image, unit (the inverse transpose, up to a positive factor when det > 0).
    Vec3f normal(const Vec3f& n) const
    {
        Vec3f r = cross(c1, c2) * n.x + cross(c2, c0) * n.y + cross(c0, c1) * n.z;
        return normalize(det < 0 ? -r : r);
    }
};

Affine affine(const geom::Instance* inst)
{
    Affine a;
    if (!inst)
        return a;
    const auto& m = inst->transform;
    a.c0 = {m[0], m[1], m[2]};
    a.c1 = {m[3], m[4], m[5]};
    a.c2 = {m[6], m[7], m[8]};
    a.t = {m[9], m[10], m[11]};
    a.det = dot(a.c0, cross(a.c1, a.c2));
    float l0 = length(a.c0), l1 = length(a.c1), l2 = length(a.c2);
    a.scale = (l0 + l1 + l2) / 3;
    float tol = 1e-4f * a.scale;
    a.similarity = a.scale > 0 && std::fabs(l0 - a.scale) < tol &&
                   std::fabs(l1 - a.scale) < tol && std::fabs(l2 - a.scale) < tol &&
                   std::fabs(dot(a.c0, a.c1)) < tol * a.scale &&
                   std::fabs(dot(a.c1, a.c2)) < tol * a.scale &&
                   std::fabs(dot(a.c0, a.c2)) < tol * a.scale;
    return a;
}

std::uint16_t resolve(std::uint16_t m, std::uint16_t inherited)
{
    return m == geom::inherit_material ? inherited : m;
}

template <class T>
T at_or(const std::vector<T>& v, std::size_t i, T fallback)
{
    return i < v.size() ? v[i] : fallback;
}

}  // namespace

std::uint64_t AreaLights::key(Shape shape, std::uint32_t prim, std::uint32_t instance)
{
    return (std::uint64_t{instance} << 32) | (std::uint64_t(shape) << 29) |
           (prim & 0x1fffffffu);
}

void AreaLights::add(const Light& light, std::uint64_t k)
{
    if (m_lights.size() >= m_max) {
        m_full = true;
        return;
    }
    m_index.emplace_back(k, static_cast<std::uint32_t>(m_lights.size()));
    m_lights.push_back(light);
}

void AreaLights::add_geometry(const geom::Geometry& g, const geom::Instance* inst,
                              std::uint32_t index, const std::vector<SurfaceMaterial>& materials,
                              bool lines)
{
    const Affine a = affine(inst);
    const std::uint16_t front_inherited = inst ? inst->material : 0;
    const std::uint16_t back_inherited = inst ? inst->back_material : 0;
    auto emission = [&](std::uint16_t m, std::uint16_t inherited) {
        m = resolve(m, inherited);
        return m < materials.size() ? materials[m].emission : Vec3f();
    };
    constexpr std::uint32_t max_prim = 0x1fffffffu;

    const geom::TriangleMesh& mesh = g.mesh;
    for (std::uint32_t i = 0; i < mesh.size() && i <= max_prim; ++i) {
        std::uint16_t fm = at_or(mesh.material, i, std::uint16_t{0});
        Vec3f front = emission(fm, front_inherited);
        Vec3f back = emission(at_or(mesh.back_material, i, fm), back_inherited);
        if (is_black(front) && is_black(back))
            continue;
        const auto& tri = mesh.triangles[i];
        if (tri[0] >= mesh.positions.size() || tri[1] >= mesh.positions.size() ||
            tri[2] >= mesh.positions.size())
            continue;  // the Embree scene rejects such a mesh with a message
        Vec3f p0 = vec(mesh.positions[tri[0]]), p1 = vec(mesh.positions[tri[1]]),
              p2 = vec(mesh.positions[tri[2]]);
        // The front, as accel decides it: where the vertex normals point, else the winding.
        Vec3f nsum;
        if (mesh.normals.size() == mesh.positions.size())
            nsum = vec(mesh.normals[tri[0]]) + vec(mesh.normals[tri[1]]) +
                   vec(mesh.normals[tri[2]]);
        float side = dot(cross(p1 - p0, p2 - p0), nsum) < 0 ? -1.0f : 1.0f;
        Light l;
        l.kind = Kind::triangle;
        l.a = a.point(p0);
        l.b = a.point(p1);
        l.c = a.point(p2);
        Vec3f face = cross(l.b - l.a, l.c - l.a);
        l.area = 0.5f * length(face);
        if (!(l.area > 0))
            continue;
        l.normal = normalize(face) * (a.det < 0 ? -side : side);
        l.front = front;
        l.back = back;
        add(l, key(Shape::triangle, i, index));
    }

    const geom::Discs& discs = g.discs;
    for (std::uint32_t i = 0; i < discs.size() && i <= max_prim && a.similarity; ++i) {
        std::uint16_t fm = at_or(discs.material, i, std::uint16_t{0});
        Vec3f front = emission(fm, front_inherited);
        Vec3f back = emission(at_or(discs.back_material, i, fm), back_inherited);
        if ((is_black(front) && is_black(back)) || i >= discs.normals.size())
            continue;
        Light l;
        l.kind = Kind::disc;
        l.a = a.point(vec(discs.centres[i]));
        l.radius = discs.centres[i][3] * a.scale;
        l.normal = a.normal(normalize(vec(discs.normals[i])));
        l.area = pi * l.radius * l.radius;
        if (!(l.area > 0) || length(l.normal) == 0)
            continue;
        l.front = front;
        l.back = back;
        add(l, key(Shape::disc, i, index));
    }

    const geom::LinearCurves& segs = g.lines;
    for (std::uint32_t i = 0; lines && a.similarity && i < segs.segments.size() && i <= max_prim;
         ++i) {
        Vec3f e = emission(at_or(segs.material, i, std::uint16_t{0}), front_inherited);
        std::uint32_t k = segs.segments[i];
        if (is_black(e) || std::size_t(k) + 1 >= segs.keys.size())
            continue;
        float r0 = segs.keys[k][3], r1 = segs.keys[k + 1][3];
        // Cones (tapered lines) are not sampled; a cylinder is.
        if (!(r0 > 0) || std::fabs(r0 - r1) > 1e-3f * std::max(r0, r1))
            continue;
        Light l;
        l.kind = Kind::cylinder;
        l.a = a.point(vec(segs.keys[k]));
        l.b = a.point(vec(segs.keys[k + 1]));
        l.radius = 0.5f * (r0 + r1) * a.scale;
        l.area = 2 * pi * l.radius * length(l.b - l.a);
        if (!(l.area > 0))
            continue;
        l.normal = normalize(l.b - l.a);  // the axis
        l.front = e;
        add(l, key(Shape::line, i, index));
    }

    const geom::Spheres& spheres = g.spheres;
    for (std::uint32_t i = 0; i < spheres.size() && i <= max_prim && a.similarity; ++i) {
        Vec3f e = emission(at_or(spheres.material, i, std::uint16_t{0}), front_inherited);
        if (is_black(e))
            continue;
        Light l;
        l.kind = Kind::sphere;
        l.a = a.point(vec(spheres.centres[i]));
        l.radius = spheres.centres[i][3] * a.scale;
        l.area = 4 * pi * l.radius * l.radius;
        if (!(l.area > 0))
            continue;
        l.front = e;
        add(l, key(Shape::sphere, i, index));
    }
}

AreaLights::AreaLights(const geom::Scene& scene, const std::vector<SurfaceMaterial>& materials,
                       std::size_t max_lights)
    : m_max(max_lights)
{
    auto emissive = [&](std::uint16_t m) {
        return m < materials.size() && !is_black(materials[m].emission);
    };
    bool any = false;
    for (std::size_t m = 0; m < materials.size() && !any; ++m)
        any = emissive(static_cast<std::uint16_t>(m));
    if (!any)
        return;  // the common case: nothing glows, nothing to look at
    // Pixel-width lines are drawn unlit, never shaded: not lights.
    const bool lines = !scene.line_radius_in_pixels;
    // Each placement's lights form one run of m_index, sorted by key: the scene's own
    // geometry's first, then instance i's as run i + 1.
    m_runs.reserve(scene.instances.size() + 2);
    auto close_run = [&] {
        auto begin = m_index.begin() + (m_runs.empty() ? 0 : m_runs.back());
        std::sort(begin, m_index.end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
        m_runs.push_back(static_cast<std::uint32_t>(m_index.size()));
    };
    m_runs.push_back(0);
    add_geometry(scene.geometry, nullptr, PrimId::none, materials, lines);
    close_run();
    for (std::uint32_t i = 0; i < scene.instances.size(); ++i) {
        const geom::Instance& inst = scene.instances[i];
        if (inst.prototype < scene.prototypes.size())
            add_geometry(scene.prototypes[inst.prototype].geometry, &inst, i, materials, lines);
        close_run();
    }
    if (m_full)
        warn("area lights: more than " + std::to_string(m_max) +
             " emissive primitives; the rest light the scene through BSDF sampling only");

    m_cdf.assign(m_lights.size() + 1, 0.0);
    for (std::size_t i = 0; i < m_lights.size(); ++i) {
        const Light& l = m_lights[i];
        double power = double(l.area) * (luminance(l.front) + luminance(l.back));
        m_cdf[i + 1] = m_cdf[i] + std::max(power, 0.0);
    }
    double total = m_cdf.back();
    m_power = total;
    for (std::size_t i = 1; i <= m_lights.size(); ++i)
        m_cdf[i] = total > 0 ? m_cdf[i] / total : double(i) / double(m_lights.size());
}

float AreaLights::select_probability(std::size_t i) const
{
    return static_cast<float>(m_cdf[i + 1] - m_cdf[i]);
}

float AreaLights::pdf_of(std::size_t i, const Vec3f& p, const Vec3f& x) const
{
    const Light& l = m_lights[i];
    Vec3f to_p = p - x;
    float d2 = dot(to_p, to_p);
    if (!(d2 > 0))
        return 0;
    if (l.kind == Kind::sphere) {
        Vec3f oc = p - l.a;
        float s = l.radius * l.radius / dot(oc, oc);
        if (s < 1) {
            // Uniform in the cone: 1 - cos_max, written to keep tiny cones accurate.
            float one_minus_cos = s / (1 + std::sqrt(1 - s));
            return 1 / (2 * pi * one_minus_cos);
        }
        // From inside: uniform by area.
        float cos = std::fabs(dot(normalize(x - l.a), to_p)) / std::sqrt(d2);
        return cos > 0 ? d2 / (l.area * cos) : 0;
    }
    if (l.kind == Kind::cylinder) {
        Vec3f ax = x - l.a;
        Vec3f radial = normalize(ax - l.normal * dot(ax, l.normal));
        float cos = std::fabs(dot(radial, to_p)) / std::sqrt(d2);
        return cos > 0 ? d2 / (l.area * cos) : 0;
    }
    float cos = std::fabs(dot(l.normal, to_p)) / std::sqrt(d2);
    return cos > 0 ? d2 / (l.area * cos) : 0;
}

std::optional<AreaLightSample> AreaLights::sample(const Vec3f& p, float u_select, float u1,
                                                  float u2) const
{
    if (m_lights.empty())
        return std::nullopt;
    auto it = std::upper_bound(m_cdf.begin(), m_cdf.end(), double(u_select));
    std::size_t i = std::min<std::size_t>(
        std::size_t(std::max<std::ptrdiff_t>(it - m_cdf.begin() - 1, 0)), m_lights.size() - 1);
    float select = select_probability(i);
    if (!(select > 0))
        return std::nullopt;
    const Light& l = m_lights[i];

    Vec3f x, radiance = l.front;
    float pdf = 0;
    switch (l.kind) {
    case Kind::triangle: {
        float r = std::sqrt(u1);
        x = l.a * (1 - r) + l.b * (r * (1 - u2)) + l.c * (r * u2);
        break;
    }
    case Kind::disc: {
        float r = l.radius * std::sqrt(u1), phi = 2 * pi * u2;
        Vec3f t, b;
        make_basis(l.normal, t, b);
        x = l.a + t * (r * std::cos(phi)) + b * (r * std::sin(phi));
        break;
    }
    case Kind::cylinder: {
        Vec3f t, b;
        make_basis(l.normal, t, b);
        float phi = 2 * pi * u2;
        Vec3f radial = t * std::cos(phi) + b * std::sin(phi);
        x = l.a + (l.b - l.a) * u1 + radial * l.radius;
        // The far side faces away; its own tube would block the shadow ray anyway.
        if (dot(radial, p - x) <= 0)
            return std::nullopt;
        break;
    }
    case Kind::sphere: {
        Vec3f oc = l.a - p;
        float d2 = dot(oc, oc), s = l.radius * l.radius / d2;
        if (s < 1) {
            // A direction uniform in the subtended cone, then its nearer meeting point.
            float one_minus_cos_max = s / (1 + std::sqrt(1 - s));
            float one_minus_cos = u1 * one_minus_cos_max;
            float cos_t = 1 - one_minus_cos;
            float sin_t = std::sqrt(std::max(0.0f, one_minus_cos * (2 - one_minus_cos)));
            float phi = 2 * pi * u2;
            float d = std::sqrt(d2);
            Vec3f axis = oc / d, t, b;
            make_basis(axis, t, b);
            Vec3f wi = normalize(t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi)) +
                                 axis * cos_t);
            float tc = d * cos_t;
            float h2 = std::max(0.0f, l.radius * l.radius - (d2 - tc * tc));
            float dist = std::max(0.0f, tc - std::sqrt(h2));
            if (!(dist > 0))
                return std::nullopt;
            return AreaLightSample{wi, dist, l.front, select / (2 * pi * one_minus_cos_max),
                                   1e-4f * dist};
        }
        float z = 1 - 2 * u1, rr = std::sqrt(std::max(0.0f, 1 - z * z));
        x = l.a + Vec3f(rr * std::cos(2 * pi * u2), rr * std::sin(2 * pi * u2), z) * l.radius;
        break;
    }
    }
    if ((l.kind == Kind::triangle || l.kind == Kind::disc) && dot(l.normal, p - x) < 0)
        radiance = l.back;
    if (is_black(radiance))
        return std::nullopt;
    pdf = pdf_of(i, p, x) * select;
    if (!(pdf > 0) || !std::isfinite(pdf))
        return std::nullopt;
    Vec3f to_x = x - p;
    float dist = length(to_x);
    float margin = 1e-4f * dist;
    if (l.kind == Kind::cylinder)
        margin = std::max(margin, 0.05f * l.radius);
    return AreaLightSample{to_x / dist, dist, radiance, pdf, margin};
}

float AreaLights::pdf(const Vec3f& p, const SurfaceHit& hit) const
{
    if (m_lights.empty())
        return 0;
    const std::size_t run = hit.instance == PrimId::none ? 0 : std::size_t{hit.instance} + 1;
    if (run + 1 >= m_runs.size())
        return 0;
    const std::uint64_t k = key(hit.shape, hit.prim_id, hit.instance);
    auto end = m_index.begin() + m_runs[run + 1];
    auto it = std::lower_bound(m_index.begin() + m_runs[run], end, k,
                               [](const auto& entry, std::uint64_t v) { return entry.first < v; });
    if (it == end || it->first != k)
        return 0;
    const Light& l = m_lights[it->second];
    if (l.kind == Kind::cylinder) {
        // Only the lateral surface is sampled; the round ends are BSDF sampling's alone.
        float along = dot(hit.position - l.a, l.normal);
        if (along < 0 || along > length(l.b - l.a))
            return 0;
    }
    return pdf_of(it->second, p, hit.position) * select_probability(it->second);
}

}  // namespace cambium::render
