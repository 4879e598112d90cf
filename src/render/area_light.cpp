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
//
// Memory: the lights are kept per distinct geometry, not per placed copy. A field of 100
// Lilacs whose organs glow listed every primitive of every instance (2.4 GiB); now each
// prototype's lights are listed once per combination of the materials its instances pass
// down (inherit_material) and of whether round shapes may be listed (similarity), and an
// instance costs one Placement. Choosing the placement by its power (the group's power
// times the transform's area scale) and then the light by its own power is, under
// similarity transforms, the same density as choosing among all placed lights.
#include "render/area_light.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <map>
#include <string>
#include <tuple>

#include "base/diagnostics.h"
#include "render/shapes.h"

namespace cambium::render {

namespace {

constexpr float pi = std::numbers::pi_v<float>;

std::uint16_t resolve(std::uint16_t m, std::uint16_t inherited)
{
    return m == geom::inherit_material ? inherited : m;
}

/// Where u falls in a cumulative distribution (entries 0 .. n, last 1): the entry and
/// u rescaled to [0, 1) within it, for a second choice from the same number.
std::pair<std::size_t, float> choose(const std::vector<double>& cdf, float u)
{
    std::size_t n = cdf.size() - 1;
    auto it = std::upper_bound(cdf.begin(), cdf.end(), double(u));
    std::size_t i =
        std::min<std::size_t>(std::size_t(std::max<std::ptrdiff_t>(it - cdf.begin() - 1, 0)), n - 1);
    double width = cdf[i + 1] - cdf[i];
    double rest = width > 0 ? (double(u) - cdf[i]) / width : 0.0;
    return {i, float(std::clamp(rest, 0.0, double(std::nextafter(1.0f, 0.0f))))};
}

/// Cumulative distribution of `weights`, normalised; returns their sum.
double make_cdf(std::vector<double>& cdf, const std::vector<double>& weights)
{
    cdf.assign(weights.size() + 1, 0.0);
    for (std::size_t i = 0; i < weights.size(); ++i)
        cdf[i + 1] = cdf[i] + std::max(weights[i], 0.0);
    double total = cdf.back();
    for (std::size_t i = 1; i <= weights.size(); ++i)
        cdf[i] = total > 0 ? cdf[i] / total : double(i) / double(weights.size());
    return total;
}

float probability(const std::vector<double>& cdf, std::size_t i)
{
    return static_cast<float>(cdf[i + 1] - cdf[i]);
}

}  // namespace

AreaLights::Affine::Affine(const geom::Instance* inst)
{
    if (!inst)
        return;
    const auto& m = inst->transform;
    c0 = {m[0], m[1], m[2]};
    c1 = {m[3], m[4], m[5]};
    c2 = {m[6], m[7], m[8]};
    t = {m[9], m[10], m[11]};
    det = dot(c0, cross(c1, c2));
    float l0 = length(c0), l1 = length(c1), l2 = length(c2);
    scale = (l0 + l1 + l2) / 3;
    float tol = 1e-4f * scale;
    similarity = scale > 0 && std::fabs(l0 - scale) < tol && std::fabs(l1 - scale) < tol &&
                 std::fabs(l2 - scale) < tol && std::fabs(dot(c0, c1)) < tol * scale &&
                 std::fabs(dot(c1, c2)) < tol * scale && std::fabs(dot(c0, c2)) < tol * scale;
}

Vec3f AreaLights::Affine::normal(const Vec3f& n) const
{
    // The inverse transpose, up to a positive factor when det > 0.
    Vec3f r = cross(c1, c2) * n.x + cross(c2, c0) * n.y + cross(c0, c1) * n.z;
    return normalize(det < 0 ? -r : r);
}

std::uint64_t AreaLights::key(Shape shape, std::uint32_t prim)
{
    return (std::uint64_t(shape) << 29) | (prim & 0x1fffffffu);
}

void AreaLights::add(Group& group, const Light& light, std::uint64_t k)
{
    if (m_stored >= m_max) {
        m_full = true;
        return;
    }
    m_max_luminance =
        std::max({m_max_luminance, luminance(light.front), luminance(light.back)});
    group.index.emplace(k, static_cast<std::uint32_t>(group.lights.size()));
    group.lights.push_back(light);
    ++m_stored;
}

void AreaLights::add_emitters(Group& group, Shape shape, const GeometrySource& part,
                              std::uint16_t front_inherited, std::uint16_t back_inherited,
                              const std::vector<SurfaceMaterial>& materials)
{
    auto emission = [&](std::uint16_t m, std::uint16_t inherited) {
        m = resolve(m, inherited);
        return m < materials.size() ? materials[m].emission : Vec3f();
    };
    static_assert(int(Kind::triangle) == int(Emitter::Form::triangle) &&
                  int(Kind::disc) == int(Emitter::Form::disc) &&
                  int(Kind::sphere) == int(Emitter::Form::sphere) &&
                  int(Kind::cylinder) == int(Emitter::Form::cylinder));
    constexpr std::uint32_t max_prim = 0x1fffffffu;
    const std::size_t n = primitive_count(part);
    for (std::uint32_t i = 0; i < n && i <= max_prim; ++i) {
        // One-sided shapes (spheres, lines) emit from their front only.
        std::uint16_t fm = at_or(*part.material, i, std::uint16_t{0});
        Vec3f front = emission(fm, front_inherited);
        Vec3f back = part.back_material
                         ? emission(at_or(*part.back_material, i, fm), back_inherited)
                         : Vec3f();
        Emitter e;
        if ((is_black(front) && is_black(back)) || !kind(shape).emitter(part, i, e))
            continue;
        Light l;
        l.kind = static_cast<Kind>(e.form);
        l.a = e.a;
        l.b = e.b;
        l.c = e.c;
        l.normal = e.normal;
        l.radius = e.radius;
        l.area = e.area;
        l.side = e.side;
        l.front = front;
        l.back = back;
        add(group, l, key(shape, i));
    }
}

AreaLights::Group AreaLights::make_group(const geom::Geometry& g, std::uint16_t front_inherited,
                                         std::uint16_t back_inherited, bool round_shapes,
                                         const std::vector<SurfaceMaterial>& materials, bool lines)
{
    Group group;
    for (Shape shape : emitting_shapes) {
        const ShapeKind& row = kind(shape);
        // (lines: only shaded ones; pixel-width lines are drawn unlit)
        if ((row.similarity_only && !round_shapes) || (shape == Shape::line && !lines))
            continue;
        add_emitters(group, shape, row.emitting_part(g), front_inherited, back_inherited,
                     materials);
    }
    std::vector<double> power(group.lights.size());
    for (std::size_t i = 0; i < power.size(); ++i) {
        const Light& l = group.lights[i];
        power[i] = double(l.area) * (luminance(l.front) + luminance(l.back));
    }
    group.power = make_cdf(group.cdf, power);
    return group;
}

void AreaLights::place(std::uint32_t group, std::uint32_t instance, const Affine& transform)
{
    if (m_groups[group].lights.empty() || !(m_groups[group].power > 0))
        return;
    if (instance != PrimId::none)
        m_placement_of.emplace(instance, static_cast<std::uint32_t>(m_placements.size()));
    m_placements.push_back({group, instance, transform});
    m_placed += m_groups[group].lights.size();
}

AreaLights::Light AreaLights::placed(const Light& l, const Placement& where)
{
    if (where.instance == PrimId::none)
        return l;  // the scene's own geometry: in world space already
    const Affine& a = where.transform;
    Light w = l;
    w.a = a.point(l.a);
    switch (l.kind) {
    case Kind::triangle: {
        w.b = a.point(l.b);
        w.c = a.point(l.c);
        Vec3f face = cross(w.b - w.a, w.c - w.a);
        w.area = 0.5f * length(face);
        w.normal = normalize(face) * (a.det < 0 ? -l.side : l.side);
        break;
    }
    case Kind::disc:
        w.radius = l.radius * a.scale;
        w.normal = a.normal(l.normal);
        w.area = pi * w.radius * w.radius;
        break;
    case Kind::cylinder:
        w.b = a.point(l.b);
        w.radius = l.radius * a.scale;
        w.area = 2 * pi * w.radius * length(w.b - w.a);
        w.normal = normalize(w.b - w.a);
        break;
    case Kind::sphere:
        w.radius = l.radius * a.scale;
        w.area = 4 * pi * w.radius * w.radius;
        break;
    }
    return w;
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
    m_groups.push_back(make_group(scene.geometry, 0, 0, true, materials, lines));
    place(0, PrimId::none, Affine());
    // One group per prototype, inherited materials and listing of round shapes.
    std::map<std::tuple<std::uint32_t, std::uint16_t, std::uint16_t, bool>, std::uint32_t> groups;
    for (std::uint32_t i = 0; i < scene.instances.size(); ++i) {
        const geom::Instance& inst = scene.instances[i];
        if (inst.prototype >= scene.prototypes.size())
            continue;
        Affine transform(&inst);
        auto [it, made] = groups.try_emplace(
            {inst.prototype, inst.material, inst.back_material, transform.similarity},
            std::uint32_t(m_groups.size()));
        if (made)
            m_groups.push_back(make_group(scene.prototypes[inst.prototype].geometry,
                                          inst.material, inst.back_material,
                                          transform.similarity, materials, lines));
        place(it->second, i, transform);
    }
    if (m_full)
        warn("area lights: more than " + std::to_string(m_max) +
             " emissive primitives; the rest light the scene through BSDF sampling only");

    // A placement's power: its group's, times the transform's area scale (exact for
    // similarities; for other maps |det|^(2/3), which only steers the choice).
    std::vector<double> power(m_placements.size());
    for (std::size_t i = 0; i < power.size(); ++i) {
        const Affine& a = m_placements[i].transform;
        double area_scale = a.similarity ? double(a.scale) * a.scale
                                         : std::cbrt(double(a.det) * a.det);
        power[i] = m_groups[m_placements[i].group].power * area_scale;
    }
    m_power = m_placements.empty() ? 0 : make_cdf(m_cdf, power);
}

float AreaLights::pdf_of(const Light& l, const Vec3f& p, const Vec3f& x)
{
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
    if (m_placements.empty())
        return std::nullopt;
    auto [j, u_light] = choose(m_cdf, u_select);
    const Placement& where = m_placements[j];
    const Group& group = m_groups[where.group];
    std::size_t i = choose(group.cdf, u_light).first;
    float select = probability(m_cdf, j) * probability(group.cdf, i);
    if (!(select > 0))
        return std::nullopt;
    return sample_light(placed(group.lights[i], where), select, p, u1, u2);
}

std::optional<AreaLightSample> AreaLights::sample_light(const Light& l, float select,
                                                        const Vec3f& p, float u1, float u2) const
{

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
    pdf = pdf_of(l, p, x) * select;
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
    if (m_placements.empty())
        return 0;
    std::size_t j = 0;  // the scene's own geometry, when it glows
    if (hit.instance != PrimId::none) {
        auto found = m_placement_of.find(hit.instance);
        if (found == m_placement_of.end())
            return 0;
        j = found->second;
    } else if (m_placements[0].instance != PrimId::none) {
        return 0;
    }
    const Placement& where = m_placements[j];
    const Group& group = m_groups[where.group];
    auto it = group.index.find(key(hit.shape, hit.prim_id));
    if (it == group.index.end())
        return 0;
    const Light l = placed(group.lights[it->second], where);
    if (l.kind == Kind::cylinder) {
        // Only the lateral surface is sampled; the round ends are BSDF sampling's alone.
        float along = dot(hit.position - l.a, l.normal);
        if (along < 0 || along > length(l.b - l.a))
            return 0;
    }
    return pdf_of(l, p, hit.position) * probability(m_cdf, j) * probability(group.cdf, it->second);
}

}  // namespace cambium::render
