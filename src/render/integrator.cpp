// SPDX-License-Identifier: Apache-2.0
// The unidirectional path tracer: next-event estimation toward one light per vertex, chosen
// by what each can deliver there from the view file's lights, the environment and
// emissive primitives (MIS against BSDF sampling), transmission, opacity, Russian
// roulette, ray cones for texture filtering.
//
// Sampler dimensions: each path vertex spends the fixed block sample_dimension::vertex(depth)
// (light choice, light point, BSDF, opacity, roulette), whatever it meets (sampler.h).
#include "render/integrator.h"

#include <array>
#include <cmath>
#include <limits>
#include <new>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace cambium::render {

namespace {

constexpr float infinity = std::numeric_limits<float>::infinity();
/// Transparent surfaces a ray may pass through before it counts as blocked.
constexpr int max_pass_throughs = 64;
/// The throughput (largest channel) from which Russian roulette always keeps a path:
/// measured on the benchmark plants (docs/benchmarks.md, "TranslucentTree"), 1 cost
/// GeneralizedCylinder 12% in time to equal noise, 0.5 nothing, and either saves
/// TranslucentTree's bounces off its dark leaves.
constexpr float roulette_keep_above = 0.5f;

const SurfaceMaterial& material_at(const PathContext& ctx, std::uint16_t m)
{
    static const SurfaceMaterial fallback;
    return m < ctx.materials.size() ? ctx.materials[m] : fallback;
}

/// What a texture did to a surface's diffuse colour, per channel (1 untextured): in
/// cpfg's window GL_MODULATE multiplies the whole lit colour, ambient and specular too.
Vec3f texture_tint(const SurfaceMaterial& m, const Vec3f& diffuse_seen)
{
#if defined(__SSE2__)
    // The three divisions as one (a division lane by lane is the same IEEE division, so
    // the same values), where three in a row delayed every textured vertex: a lane whose
    // plain value is not above 0 takes 1, its quotient (inf or NaN) dropped.
    const __m128 seen = _mm_setr_ps(diffuse_seen.x, diffuse_seen.y, diffuse_seen.z, 1.0f);
    const __m128 plain = _mm_setr_ps(m.diffuse.x, m.diffuse.y, m.diffuse.z, 1.0f);
    const __m128 positive = _mm_cmpgt_ps(plain, _mm_setzero_ps());
    const __m128 ratio = _mm_or_ps(_mm_and_ps(positive, _mm_div_ps(seen, plain)),
                                   _mm_andnot_ps(positive, _mm_set1_ps(1.0f)));
    alignas(16) float out[4];
    _mm_store_ps(out, ratio);
    return {out[0], out[1], out[2]};
#else
    auto ratio = [](float seen, float plain) { return plain > 0 ? seen / plain : 1.0f; };
    return {ratio(diffuse_seen.x, m.diffuse.x), ratio(diffuse_seen.y, m.diffuse.y),
            ratio(diffuse_seen.z, m.diffuse.z)};
#endif
}

/// The power heuristic (beta = 2) for a sample drawn with pdf a against one of pdf b.
float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0 ? a2 / (a2 + b2) : 0;
}

/// The one MIS rule for light a BSDF-sampled ray (drawn with `bsdf_pdf`) finds on an
/// emissive surface or the environment, which light sampling would find with `light_pdf`
/// (choice included; 0 when that light is not sampled): the power heuristic, full weight
/// where light sampling cannot find it.
float bsdf_hit_weight(float bsdf_pdf, float light_pdf)
{
    return light_pdf > 0 ? power_heuristic(bsdf_pdf, light_pdf) : 1.0f;
}

/// Where a ray leaving the hit toward wi starts, and which primitive it must ignore:
/// the one it leaves (a flat one cannot be met again; a convex curve segment or sphere
/// cannot be met again from outside, where Embree would report spurious hits), unless it
/// goes into a closed primitive's volume, whose far wall is real.
struct Spawn {
    Vec3f origin;
    PrimId skip;
};

Spawn spawn(const SurfaceHit& hit, const Vec3f& wi)
{
    bool outward = dot(hit.geometric_normal, wi) >= 0;
    Vec3f offset = hit.geometric_normal * hit.spawn_offset;
    return {outward ? hit.position + offset : hit.position - offset,
            hit.enters(wi) ? PrimId{} : hit.prim()};
}

/// Whether wi is on the same side of the true surface as of the shading normal: where
/// interpolated normals disagree with the facet, light would leak through a sheet.
bool same_side(const SurfaceHit& hit, const Vec3f& wi)
{
    return (dot(hit.normal, wi) > 0) == (dot(hit.geometric_normal, wi) > 0);
}

/// Whether any material lets light through (then shadow rays must look at each hit).
bool any_transparent(const PathContext& ctx)
{
    for (const SurfaceMaterial& m : ctx.materials)
        if (m.opacity < 1)
            return true;
    return false;
}

/// Whether the ground takes part in rays other than camera rays: a shadow catcher is seen
/// by camera rays only, and a ray leaving the ground cannot meet it again.
bool ground_blocks(const PathContext& ctx, const PrimId& leaving)
{
    return ctx.ground && !ctx.ground->shadow_catcher && leaving.geom != ground_geom_id;
}

/// The first hit along org + t dir, t < tfar, made in `hit` (storage for one): the Embree
/// scene's or the ground's; whether there is one. The camera ray meets the ground beyond
/// the far clipping plane too (the plane is staging, not part of the plant, and reaches
/// the horizon).
bool first_hit(const PathContext& ctx, const Vec3f& org, const Vec3f& dir, float tfar,
               PrimId leaving, bool camera, SurfaceHit& hit)
{
    bool found = ctx.accel->intersect(hit, org, dir, 0, tfar, leaving, camera);
    bool sees_ground = camera ? ctx.ground && leaving.geom != ground_geom_id
                              : ground_blocks(ctx, leaving);
    if (sees_ground)
        if (std::optional<float> t = ctx.ground->distance(org, dir, found ? hit.t : infinity)) {
            ::new (&hit) SurfaceHit(ctx.ground->hit(org, dir, *t));
            found = true;
        }
    return found;
}

/// Room for a hit, not made until a ray's hit is made in it: an empty
/// std::optional<SurfaceHit> would be zeroed whole (GCC 12's library), 8 ns per path.
union HitRoom {
    HitRoom() {}
    SurfaceHit hit;
};

/// The fraction of light passing from s.origin along wi for t < tfar: 0 if an opaque
/// surface blocks it, the product of transparencies through transparent ones (one
/// opacity-only traversal: EmbreeScene::transmittance).
float transmittance(const PathContext& ctx, const PathContext::SceneFlags& facts, Spawn s,
                    const Vec3f& wi, float tfar)
{
    if (ground_blocks(ctx, s.skip) && ctx.ground->distance(s.origin, wi, tfar))
        return 0;
    if (!facts.transparent)
        return ctx.accel->occluded(s.origin, wi, 0, tfar, s.skip) ? 0.0f : 1.0f;
    return ctx.accel->transmittance(s.origin, wi, 0, tfar, s.skip, facts.opacity);
}

/// The draws that decide, surface after surface, whether a ray stops (with probability
/// opacity) or passes through. The vertex's opacity dimension decides at the first
/// surface; after a pass the same value, rescaled to what is left of [opacity, 1), is
/// again uniform and decides at the next, so the decisions stay stratified; once its
/// bits run low, fresh white noise decides.
class PassThroughDraws {
public:
    PassThroughDraws(const Sampler& sampler, std::uint32_t dimension)
        : m_sampler(&sampler), m_dimension(dimension)
    {
    }

    bool stops(float opacity)
    {
        constexpr std::uint32_t rescaled_passes = 8;
        float u = m_passed == 0                ? m_sampler->get1d(m_dimension)
                  : m_passed < rescaled_passes ? m_u
                                               : m_sampler->extra(m_dimension, m_passed);
        if (u < opacity)
            return true;
        m_u = std::fmin((u - opacity) / (1 - opacity), 0x1.fffffep-1f);
        ++m_passed;
        return false;
    }

private:
    const Sampler* m_sampler;
    std::uint32_t m_dimension;
    std::uint32_t m_passed = 0;
    float m_u = 0;
};

/// A shading vertex: its hit and its BSDF seen along the path (made once per vertex).
struct Vertex {
    const SurfaceHit& hit;
    const BsdfAt& bsdf;
};

/// The four uniforms a vertex spends on next-event estimation.
struct LightUniforms {
    float choose, u0, u1, u2;
};

/// The fraction of light from a light sample (toward wi, its ray ending at `ends_at`) that
/// reaches the shading point: the spawned origin is off the surface, so the shadow ray
/// aims from it at the point where the light sample's ray ends (just short of the light),
/// as a ray parallel to wi could meet a curved light sooner; 0 where blocked.
float light_visibility(const PathContext& ctx, const PathContext::SceneFlags& facts,
                       const SurfaceHit& hit, const Vec3f& wi, float ends_at)
{
    Spawn s = spawn(hit, wi);
    Vec3f toward = wi;
    float tfar = ends_at;
    if (!std::isinf(tfar)) {
        Vec3f to = hit.position + wi * ends_at - s.origin;
        tfar = length(to);
        if (!(tfar > 0))
            return 0;
        toward = to / tfar;
    }
    return transmittance(ctx, facts, s, toward, tfar);
}

/// f |cos| of the light sample at the vertex, unshadowed; black where it cannot light the
/// surface's side the path sees.
Vec3f unshadowed(const Vertex& v, const LightLiSample& ls)
{
    if (!(ls.pdf > 0) || is_black(ls.li))
        return {};
    // The geometric tests first: a light on the far side of the true surface (or grazing
    // it) is refused before the BSDF (the Phong lobe's power) is evaluated for nothing.
    float cos = std::fabs(dot(v.hit.normal, ls.wi));
    if (cos <= 0 || !same_side(v.hit, ls.wi))
        return {};
    Vec3f f = bsdf_eval(v.bsdf, ls.wi);
    if (is_black(f))
        return {};
    return f * ls.li * cos;
}

/// Whether the opaque ground lies between the vertex and the light sample (FernLeaf's
/// second light shines from below it): such a light gives the point nothing.
bool ground_hides(const PathContext& ctx, const Vertex& v, const LightLiSample& ls)
{
    return ground_blocks(ctx, v.hit.prim()) && ls.pdf > 0 &&
           ctx.ground->distance(v.hit.position, ls.wi, ls.tfar);
}

/// Room for a vector per delta light, each made in place as its light is met: a
/// std::array<Vec3f> would be zeroed whole (Vec3f's members are initialised), a
/// `rep stos` at every vertex.
union DeltaRoom {
    DeltaRoom() {}
    std::array<Vec3f, LightSet::max_delta_choice> at;
};

/// Direct light from a set of delta lights only (a view file's lights): each light's
/// unshadowed contribution is known exactly for the price of a BSDF evaluation, so one
/// light is chosen in proportion to it (its luminance) and one shadow ray traced. The
/// estimate is then the unshadowed sum times the chosen light's visibility: a light
/// behind an opaque surface (FernLeaf's and GeneralizedCylinder's two opposite lights)
/// is never chosen, and noise is left only where lights are partly shadowed. Unbiased:
/// every light that gives the point anything keeps a non-zero chance. Nullopt where a
/// contribution is not finite (a broken light): the choice by power then shows it.
/// The choice's uniform (dimension `choice`) is drawn only where two lights or more give
/// the point something: with one, that one is chosen whatever it would be (FernLeaf's
/// lights, opposite each other, light most points from one side only).
std::optional<Vec3f> sample_delta_ld(const PathContext& ctx,
                                     const PathContext::SceneFlags& facts, const Vertex& v,
                                     const Sampler& sampler, std::uint32_t choice)
{
    const LightSet& lights = facts.lights;
    const std::uint32_t n = static_cast<std::uint32_t>(lights.size());
    std::array<float, LightSet::max_delta_choice> weight;  // luminance of each contribution
    float total = 0;
    std::uint32_t lit = 0;  // lights that give the point something
    // Each light's direction, end and contribution, kept: the chosen light's are not made
    // twice (its BSDF evaluation, with the Phong lobe's power, is most of the loop's
    // cost). (Kept as values, not as LightLiSamples: copying that struct in the loop
    // stalled on store forwarding.)
    DeltaRoom wi, contribution;
    std::array<float, LightSet::max_delta_choice> ends_at;
    for (std::uint32_t i = 0; i < n; ++i) {
        const LightLiSample ls = lights.sample_li(i, v.hit.position, 0, 0, 0);  // no point
        ::new (&contribution.at[i]) Vec3f(unshadowed(v, ls));
        ::new (&wi.at[i]) Vec3f(ls.wi);
        ends_at[i] = ls.tfar;
        float w = luminance(contribution.at[i]);
        if (!std::isfinite(w))
            return std::nullopt;
        weight[i] = std::max(w, 0.0f);  // w is finite: as std::fmax, without a libm call
        total += weight[i];
        lit += weight[i] > 0;
    }
    if (!(total > 0) || !std::isfinite(total))
        return Vec3f();
    // The light whose share of the total holds u_choose; the last lit one if rounding
    // leaves u past the sum.
    const float u_choose = lit > 1 ? sampler.get1d(choice) : 0.0f;
    float target = u_choose * total;
    std::uint32_t chosen = n;
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!(weight[i] > 0))
            continue;
        chosen = i;
        if (target < weight[i])
            break;
        target -= weight[i];
    }
    float through = light_visibility(ctx, facts, v.hit, wi.at[chosen], ends_at[chosen]);
    if (through <= 0)
        return Vec3f();
    return contribution.at[chosen] * (through * total / weight[chosen]);
}

/// The vertex's next-event uniforms, drawn from its block only where they matter: the
/// choice when there is a choice, the point on the light for lights with extent (a delta
/// light has one). The dimensions are fixed (sampler.h), so a value left undrawn changes
/// no other; the hashing it would cost is a few percent of a plant's render.
LightUniforms light_uniforms(const LightSet& lights, const Sampler& sampler,
                             std::uint32_t block, std::optional<ChosenLight>& chosen)
{
    LightUniforms u{};
    bool drawn_choice = lights.size() > 1;
    if (drawn_choice) {
        auto [choose, area] = sampler.get2d(block + sample_dimension::light_choice);
        u.choose = choose;
        u.u0 = area;
    }
    chosen = lights.choose(u.choose);
    if (!chosen)
        return u;
    switch (lights.kind(chosen->index)) {
    case LightKind::point:
    case LightKind::spot:
    case LightKind::directional: return u;
    case LightKind::area:
    case LightKind::environment:
    case LightKind::sun: break;
    }
    if (!drawn_choice)
        u.u0 = sampler.get2d(block + sample_dimension::light_choice)[1];
    auto [u1, u2] = sampler.get2d(block + sample_dimension::light_point);
    u.u1 = u1;
    u.u2 = u2;
    return u;
}

/// The probabilities with which a vertex's next-event estimation chose the environment,
/// the emissive primitives and the sun: what a BSDF ray leaving that vertex is weighed
/// against when it finds them (0: not sampled there, full weight).
struct ChoiceAt {
    float environment = 0, area = 0, sun = 0;
    bool facing_up = false;  ///< the environment drawn for a surface facing up (the ground)
};

/// A light chosen for the vertex by what each light can deliver there (LightSet::
/// per_point): a delta light by its unshadowed f |cos| Li, exactly, and nothing when the
/// opaque ground lies between (FernLeaf's second light shines from below it); the
/// environment and the sun by their irradiance estimates on the surface's two sides
/// times the BSDF's albedo on each (the sun nothing where the ground hides all of its
/// disk; on the ground the dome never less than the sun, which the plant may shadow); the
/// emissive primitives by their irradiance estimate times the albedo. Every
/// light that can give the point something keeps a chance, except one the ground hides
/// (its contribution is 0), so the estimate stays unbiased; the environment, emissive
/// primitives' and sun's probabilities go to `choice` for MIS.
using PointWeights = std::array<float, LightSet::max_point_choice>;

/// choose_at's weights of each light at the vertex, and their sum.
float point_weights(const PathContext& ctx, const LightSet& lights, const Vertex& v,
                    PointWeights& weight)
{
    const std::uint32_t n = static_cast<std::uint32_t>(lights.size());
    const Bsdf& b = v.bsdf.bsdf;
    const float front = luminance(b.reflect) + luminance(b.glossy);
    const float back = luminance(b.transmit);
    const bool ground = ground_blocks(ctx, v.hit.prim());
    float total = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
        float w = 0;
        switch (lights.kind(i)) {
        case LightKind::point:
        case LightKind::spot:
        case LightKind::directional: {
            const LightLiSample ls = lights.sample_li(i, v.hit.position, 0, 0, 0);
            if (!ground_hides(ctx, v, ls))
                w = luminance(unshadowed(v, ls));
            break;
        }
        case LightKind::environment:
            w = (front * lights.environment_irradiance(v.bsdf.n) +
                 back * lights.environment_irradiance(-v.bsdf.n)) *
                std::numbers::inv_pi_v<float>;
            break;
        case LightKind::area:
            w = (front + back) * lights.area_irradiance() * std::numbers::inv_pi_v<float>;
            break;
        case LightKind::sun:
            // A point below the ground sees none of a disk wholly above the horizon.
            if (ground && lights.sun_direction().y > lights.sun_sin_radius() &&
                ctx.ground->distance(v.hit.position, lights.sun_direction(), infinity))
                break;
            w = (front * lights.sun_irradiance(v.bsdf.n) +
                 back * lights.sun_irradiance(-v.bsdf.n)) *
                std::numbers::inv_pi_v<float>;
            break;
        }
        weight[i] = std::isfinite(w) && w > 0 ? w : 0.0f;
        total += weight[i];
    }
    if (lights.has_sun() && v.hit.geom_id == ground_geom_id) {
        // On the ground the dome gets at least what the sun gets: in the plant's shadow
        // the sun's samples are all blocked and the dome's light is what is left. (On the
        // plant the same floor cost more than it gained; docs/benchmarks.md.)
        float& dome = weight[lights.environment_index()];
        const float sun = weight[lights.sun_index()];
        if (dome > 0 && sun > dome) {
            total += sun - dome;
            dome = sun;
        }
    }
    return total;
}

std::optional<ChosenLight> choose_at(const PathContext& ctx, const LightSet& lights,
                                     const Vertex& v, float u, ChoiceAt& choice)
{
    const std::uint32_t n = static_cast<std::uint32_t>(lights.size());
    PointWeights weight;
    const float total = point_weights(ctx, lights, v, weight);
    if (!(total > 0) || !std::isfinite(total))
        return std::nullopt;
    float target = u * total;
    std::uint32_t chosen = n;
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!(weight[i] > 0))
            continue;
        chosen = i;
        if (target < weight[i])
            break;
        target -= weight[i];
    }
    for (std::uint32_t i = 0; i < n; ++i) {
        if (lights.kind(i) == LightKind::environment)
            choice.environment = weight[i] / total;
        else if (lights.kind(i) == LightKind::area)
            choice.area = weight[i] / total;
        else if (lights.kind(i) == LightKind::sun)
            choice.sun = weight[i] / total;
    }
    return ChosenLight{chosen, weight[chosen] / total};
}

/// Whether the vertex is the opaque ground seen from above, whose environment light is
/// drawn by radiance times the cosine to +y (Environment::samples_facing_up).
bool draws_facing_up(const Vertex& v, const LightSet& lights)
{
    return v.hit.geom_id == ground_geom_id && v.bsdf.n.y > 0.999f &&
           lights.environment_facing_up();
}

/// Whether next-event estimation at the vertex samples every light of the set
/// (LightSet::every_light): under the sky everywhere, under a map on the ground only. On
/// the plant under a map, one light chosen by what it delivers (choose_at) reaches the
/// same noise for two thirds of the time; on the ground, in the plant's shadow, the
/// choice's variance dominates (benchmarks/cycles/compare.py --staged env and sky).
bool samples_every_light(const Vertex& v, const LightSet& lights)
{
    return lights.every_light() && (lights.has_sun() || v.hit.geom_id == ground_geom_id);
}

/// Direct light from every light of the set at once (LightSet::every_light): each delta
/// light that gives the point something, exactly, with its shadow ray; the environment
/// and the sky's sun a sample each, weighed against BSDF sampling. No choice among them
/// adds variance: in the plant's shadow the dome's sample carries the light the blocked
/// sun and view lights do not (benchmarks/cycles/compare.py --staged sky, turntable
/// azimuths). The environment takes light_point's pair, as a chosen light does; with a
/// sun, the sun takes that pair and the dome the choice's, which no choice needs.
Vec3f sample_every_light_ld(const PathContext& ctx, const PathContext::SceneFlags& facts,
                            const Vertex& v, bool last, const Sampler& sampler,
                            std::uint32_t block, ChoiceAt& choice)
{
    const LightSet& lights = facts.lights;
    const bool up = draws_facing_up(v, lights);
    choice = {.environment = 1, .area = 0, .sun = lights.has_sun() ? 1.0f : 0.0f,
              .facing_up = up};
    auto reaching = [&](const LightLiSample& ls) {
        if (!(ls.pdf > 0))
            return Vec3f();
        const Vec3f c = unshadowed(v, ls);
        if (is_black(c))
            return Vec3f();
        const float through = light_visibility(ctx, facts, v.hit, ls.wi, ls.tfar);
        if (through <= 0)
            return Vec3f();
        const float w =
            ls.delta || last ? 1.0f : power_heuristic(ls.pdf, bsdf_pdf(v.bsdf, ls.wi));
        return c * (through * w / ls.pdf);
    };
    auto one = [&](std::uint32_t index, float u1, float u2) {
        return reaching(up && index == lights.environment_index()
                            ? lights.environment_li_facing_up(u1, u2)
                            : lights.sample_li(index, v.hit.position, 0, u1, u2));
    };
    Vec3f sum;
    for (std::uint32_t i = 0; i < lights.size(); ++i) {
        if (!is_delta(lights.kind(i)))
            continue;
        const LightLiSample ls = lights.sample_li(i, v.hit.position, 0, 0, 0);
        if (!ground_hides(ctx, v, ls))
            sum += reaching(ls);
    }
    auto [choice1, choice2] = sampler.get2d(block + sample_dimension::light_choice);
    auto [point1, point2] = sampler.get2d(block + sample_dimension::light_point);
    if (!lights.has_sun())
        return sum + one(lights.environment_index(), point1, point2);
    return sum + one(lights.environment_index(), choice1, choice2) +
           one(lights.sun_index(), point1, point2);
}

/// Direct light from one light (pbrt's SampleLd): among delta lights only, chosen by what
/// each gives the point (sample_delta_ld); with the environment or emissive primitives,
/// chosen by what each can deliver (choose_at), else by power; a delta light at full
/// weight, the others weighted against BSDF sampling of the same direction by the power
/// heuristic (full weight at the path's last vertex, where no BSDF ray follows). The
/// choice's probabilities of the environment, the area lights and the sun go to `choice`.
Vec3f sample_ld(const PathContext& ctx, const PathContext::SceneFlags& facts, const Vertex& v,
                bool last, const Sampler& sampler, std::uint32_t block, ChoiceAt& choice)
{
    const LightSet& lights = facts.lights;
    choice = {};
    if (lights.delta_only()) {
        // A delta light needs no point on it: only the choice is drawn, and only when
        // there is a choice.
        if (std::optional<Vec3f> ld =
                sample_delta_ld(ctx, facts, v, sampler, block + sample_dimension::light_choice))
            return *ld;
    }
    if (samples_every_light(v, lights))
        return sample_every_light_ld(ctx, facts, v, last, sampler, block, choice);
    std::optional<ChosenLight> chosen;
    LightUniforms u{};
    if (lights.per_point()) {
        auto [choose, area] = sampler.get2d(block + sample_dimension::light_choice);
        u.choose = choose;
        u.u0 = area;
        chosen = choose_at(ctx, lights, v, u.choose, choice);
        choice.facing_up = draws_facing_up(v, lights);
        if (chosen) {
            LightKind k = lights.kind(chosen->index);
            if (k == LightKind::area || k == LightKind::environment || k == LightKind::sun) {
                auto [u1, u2] = sampler.get2d(block + sample_dimension::light_point);
                u.u1 = u1;
                u.u2 = u2;
            }
        }
    } else {
        u = light_uniforms(lights, sampler, block, chosen);
        choice = {lights.environment_probability(), lights.area_probability(),
                  lights.sun_probability()};
    }
    if (!chosen || !(chosen->probability > 0))
        return {};
    LightLiSample ls = choice.facing_up && chosen->index == lights.environment_index()
                           ? lights.environment_li_facing_up(u.u1, u.u2)
                           : lights.sample_li(chosen->index, v.hit.position, u.u0, u.u1, u.u2);
    Vec3f c = unshadowed(v, ls);
    if (is_black(c))
        return {};
    float through = light_visibility(ctx, facts, v.hit, ls.wi, ls.tfar);
    if (through <= 0)
        return {};
    float pdf = chosen->probability * ls.pdf;
    float w = ls.delta || last ? 1.0f
                               : power_heuristic(pdf, bsdf_pdf(v.bsdf, ls.wi));
    return c * (through * w / pdf);
}

/// A shadow catcher's point (Cycles' idea): the light a white Lambertian surface there
/// reflects with the plant in the way and without it, from the same samples: one light
/// chosen by power (lights, emissive primitives, a non-uniform environment; full weight,
/// no MIS) and, when the environment is uniform, one cosine-distributed direction toward
/// it. Light the plant reflects onto the ground is not counted. Uses 6 dimensions.
void catch_shadow(const PathContext& ctx, const PathContext::SceneFlags& facts,
                  const SurfaceHit& hit, const Sampler& sampler, PathResult& result)
{
    // The camera vertex's own block: the light pairs for the light, the BSDF pair for
    // the cosine-distributed direction toward the environment.
    result.catcher = true;
    const std::uint32_t block = sample_dimension::vertex(0);
    auto [u_choose, u_area] = sampler.get2d(block + sample_dimension::light_choice);
    auto [u_light0, u_light1] = sampler.get2d(block + sample_dimension::light_point);
    LightUniforms u{u_choose, u_area, u_light0, u_light1};
    auto [c1, c2] = sampler.get2d(block + sample_dimension::bsdf);
    auto add = [&](const Vec3f& wi, const Vec3f& reflected, float tfar) {
        float without = luminance(reflected);
        if (!(without > 0) || !std::isfinite(without))
            return;
        result.lit_without += without;
        result.lit_with +=
            without * transmittance(ctx, facts, spawn(hit, wi), wi, tfar);
    };
    std::optional<ChosenLight> chosen = facts.lights.choose(u.choose);
    if (chosen && chosen->probability > 0) {
        LightLiSample ls = facts.lights.sample_li(chosen->index, hit.position, u.u0, u.u1, u.u2);
        float cos = dot(hit.normal, ls.wi);
        if (ls.pdf > 0 && cos > 0)
            add(ls.wi,
                ls.li * (cos / (std::numbers::pi_v<float> * chosen->probability * ls.pdf)),
                ls.tfar);
    }
    if (!facts.environment_black && !facts.environment_nee) {
        // f cos / pdf = (1 / pi) cos / (cos / pi) = 1
        Vec3f wi = bsdf_detail::sample_cosine(hit.normal, c1, c2);  // as a Lambertian BSDF draws
        add(wi, escaped_radiance(ctx, wi), infinity);
    }
}

}  // namespace

TextureFootprint texture_footprint(const SurfaceHit& hit, const Vec3f& dir, float width)
{
    const Vec3f &dpds = hit.dpds, &dpdt = hit.dpdt;
    if (!(width > 0) || (is_black(dpds) && is_black(dpdt)))
        return {};
    const Vec3f& n = hit.geometric_normal;  // unit
    // Grazing views stretch the footprint; beyond 50:1 it would only blur. (Compared by
    // hand: std::fmax is a library call here; a NaN cosine gives 0.02 as it did.)
    const float cos_abs = std::fabs(dot(dir, n));
    const float cos = cos_abs > 0.02f ? cos_abs : 0.02f;
    Vec3f minor = cross(dir, n), unused;
    float minor2 = dot(minor, minor);
    if (minor2 < 1e-12f) {
        make_basis(n, minor, unused);
        minor2 = dot(minor, minor);
    }
    // One root and one division each, where normalize() takes three: the footprint only
    // chooses MIP levels, and rounding there moves a blend weight by an ulp or so.
    minor = minor * (1 / std::sqrt(minor2));
    // n and minor are unit and perpendicular: their cross product is unit already.
    const Vec3f major = cross(n, minor) * (width / cos);
    minor = minor * width;
    const float a = dot(dpds, dpds), b = dot(dpds, dpdt), c = dot(dpdt, dpdt);
    const float det = a * c - b * b;
    const bool both = det > 1e-12f * a * c;
    const float inv_det = both ? 1 / det : 0.0f;
    auto to_st = [&](const Vec3f& w) -> std::array<float, 2> {
        const float x = dot(dpds, w), y = dot(dpdt, w);
        if (both)
            return {(c * x - b * y) * inv_det, (a * y - b * x) * inv_det};
        // One coordinate constant (or both parallel): each on its own.
        return {a > 0 ? x / a : 0.0f, c > 0 ? y / c : 0.0f};
    };
    auto [dsdx, dtdx] = to_st(major);
    auto [dsdy, dtdy] = to_st(minor);
    return {dsdx, dtdx, dsdy, dtdy};
}

bool footprint_within_texel(const SurfaceHit& hit, const Vec3f& dir, float width, float texels)
{
    if (!(texels > 0))
        return true;
    // texture_footprint's axes are the pixel's ellipse (`width` and width / cos across,
    // cos clamped as there) taken to (s, t) by the pseudo-inverse of J = (dpds dpdt). In
    // exact arithmetic an axis m gives |(ds, dt)|^2 <= |m|^2 / lambda_min(J^T J), and
    // lambda_min >= det / (a + c) (the larger eigenvalue is below the trace), so the
    // lookup's extent^2 in texels is at most texels^2 width^2 (a + c) / (cos^2 det). A
    // well-conditioned frame (det > 1/100 of a c, which a tube's orthogonal tangents
    // meet with det = a c) keeps texture_footprint's float error near 1e-5 of that bound
    // (its divisions by det); asking for a quarter of one texel^2 covers it many times.
    const Vec3f &dpds = hit.dpds, &dpdt = hit.dpdt;
    const float a = dot(dpds, dpds), b = dot(dpds, dpdt), c = dot(dpdt, dpdt);
    const float ac = a * c, det = ac - b * b;
    const float cos_abs = std::fabs(dot(dir, hit.geometric_normal));
    const float cos = cos_abs > 0.02f ? cos_abs : 0.02f;
    const float reach = texels * width;
    return ac > 1e-30f && det > 0.01f * ac &&
           4 * (reach * reach) * (a + c) <= (cos * cos) * det;
}

void prepare_path_context(PathContext& ctx)
{
    const Environment* env = ctx.environment;
    const bool black = env ? env->black() : is_black(ctx.ambient);
    // A uniform environment is sampled perfectly by the BSDF alone (exactly, for a
    // Lambertian surface), so next-event estimation toward it would only add noise.
    const bool nee = env && !black && !env->uniform();
    std::vector<float> opacity;
    for (const SurfaceMaterial& m : ctx.materials)
        opacity.push_back(m.opacity);
    // Under an opaque ground every shading point is at or above it, and a ray toward the
    // lower hemisphere from above meets it: light sampling spends nothing there (a BSDF
    // ray that escapes downward from a point on the plane still finds it, at full weight).
    std::shared_ptr<const Environment> sampled;
    if (nee && ctx.ground && !ctx.ground->shadow_catcher) {
        sampled = std::make_shared<const Environment>(env->hidden_below_horizon());
        env = sampled.get();
    }
    ctx.prepared = PathContext::SceneFlags{
        any_transparent(ctx), std::move(opacity), black, nee,
        LightSet(ctx.lights, ctx.area_lights, env, nee, ctx.scene_radius), sampled};
}

namespace {

/// Material `m` at `hit` with cpfg's colour-index lighting applied (a copy in `scratch`),
/// or the material itself where there is none.
const SurfaceMaterial& index_lit(const PathContext& ctx, const SurfaceHit& hit, std::uint16_t m,
                                 SurfaceMaterial& scratch)
{
    const SurfaceMaterial& material = material_at(ctx, m);
    if (m >= ctx.index_ramps.size() || ctx.index_ramps[m].rule == geom::IndexLighting::none ||
        hit.unlit || ctx.unlit)
        return material;
    // cpfg takes the cosine with the primitive's own front (a polygon's up vector, a
    // cylinder's outward normal), whichever side is seen.
    Vec3f front = hit.back || hit.inside ? -hit.normal : hit.normal;
    const geom::Vec3& l = ctx.index_light.to_light;
    float cos_light = dot(front, Vec3f(static_cast<float>(l.x), static_cast<float>(l.y),
                                       static_cast<float>(l.z)));
    scratch = material;
    scratch.diffuse = index_lit_albedo(ctx.index_ramps[m], ctx.index_light, cos_light);
    return scratch;
}

}  // namespace

const SurfaceMaterial& hit_material(const PathContext& ctx, const SurfaceHit& hit,
                                    SurfaceMaterial& scratch)
{
    const SurfaceMaterial& start = index_lit(ctx, hit, hit.material, scratch);
    if (hit.material_blend <= 0)
        return start;  // the usual case: no copy
    SurfaceMaterial end_scratch;
    const SurfaceMaterial& end = index_lit(ctx, hit, hit.end_material, end_scratch);
    scratch = mix(start, end, hit.material_blend);
    return scratch;
}

namespace {

/// The camera ray's first hit as the image's layers show it.
VisibleSurface visible_surface(const SurfaceHit& hit, const SurfaceMaterial& material,
                               const Vec3f& diffuse)
{
    return {true,          hit.unlit ? flat_colour(material) : diffuse,
            hit.normal,    hit.t,
            hit.geom_id,   hit.primitive,
            hit.instance,  hit.shape};
}

}  // namespace

void unprepared_path_context(const char* caller)
{
    throw std::logic_error(std::string(caller) + ": prepare_path_context() was not called");
}

PathResult trace_path(const PathContext& ctx, const Vec3f& camera_org, const Vec3f& camera_dir,
                      const Sampler& sampler, float camera_tfar, VisibleSurface* first,
                      const std::optional<SurfaceHit>* camera_hit)
{
    if (!ctx.prepared)
        unprepared_path_context("trace_path");
    const PathContext::SceneFlags& facts = *ctx.prepared;
    const LightSet& lights = facts.lights;
    auto env_radiance = [&](const Vec3f& d) { return escaped_radiance(ctx, d); };

    PathResult result;
    Vec3f beta(1.0f);
    Vec3f org = camera_org, dir = camera_dir;
    float tfar = camera_tfar;  // the camera ray's range left (far clipping); later rays: none
    PrimId leaving;        // the primitive the current ray leaves (none for the camera ray)
    float bsdf_pdf_prev = 0;  // pdf the current ray's direction was drawn with
    Vec3f scatter_prev;       // where it was drawn (the last scattering vertex)
    ChoiceAt choice;          // how that vertex chose its light (MIS of the ray's finds)
    int passes = 0;
    float travelled = 0;  // along the path, for the ray cone
    PassThroughDraws pass_through(sampler, sample_dimension::vertex(0) + sample_dimension::opacity);
    HitRoom traced;  // the hit of each ray traced here, made in place
    for (int depth = 0; depth < ctx.max_depth;) {
        const std::uint32_t block = sample_dimension::vertex(depth);
        // The camera ray's hit, when given, is read where it lies (not copied); a ray
        // traced here has its hit made in `traced`.
        const SurfaceHit* hit = nullptr;
        if (depth == 0 && passes == 0 && camera_hit)
            hit = *camera_hit ? &**camera_hit : nullptr;
        else if (first_hit(ctx, org, dir, tfar, leaving, depth == 0, traced.hit))
            hit = &traced.hit;
        if (!hit) {
            if (depth == 0) {
                result.radiance += beta * seen_by_camera(ctx, dir);
            } else if (!facts.environment_black) {
                float w = bsdf_hit_weight(
                    bsdf_pdf_prev, choice.environment * (choice.facing_up
                                                             ? lights.environment_pdf_facing_up(dir)
                                                             : lights.environment_pdf(dir)));
                const float sun_pdf = lights.sun_pdf(dir);
                if (sun_pdf > 0) {
                    // Into the sun sampled apart: the disk weighed against the sun's
                    // sampling, the sky behind it against the environment's.
                    float w_sun = bsdf_hit_weight(bsdf_pdf_prev, choice.sun * sun_pdf);
                    result.radiance += beta * (ctx.environment->radiance_without_sun(dir) * w +
                                               lights.sun_radiance(dir) * w_sun);
                } else {
                    result.radiance += beta * env_radiance(dir) * w;
                }
            }
            break;
        }
        if (ctx.facet_normals) {  // `render mode: flat`: shaded by the true normal
            if (hit != &traced.hit)
                ::new (&traced.hit) SurfaceHit(*hit);
            traced.hit.normal = traced.hit.geometric_normal;
            hit = &traced.hit;
        }
        travelled += hit->t;
        SurfaceMaterial blended;
        const SurfaceMaterial& material = hit_material(ctx, *hit, blended);
        auto textured_diffuse = [&] {
            if (!ctx.textures || hit->texture == geom::no_texture)
                return material.diffuse;
            // Most hits see less than a texel (GeneralizedCylinder's almost all): then the
            // finest level is taken for sure, and the footprint is not made.
            const float width = ctx.camera_cone.width + ctx.camera_cone.spread * travelled;
            const bool finest = footprint_within_texel(
                *hit, dir, width, ctx.textures->footprint_texels(hit->texture));
            TextureSet::Rgbx seen;
            ctx.textures->apply(hit->texture, material.diffuse, hit->u, hit->v,
                                finest ? TextureFootprint{} : texture_footprint(*hit, dir, width),
                                seen);
            return seen.rgb();
        };
        std::optional<Vec3f> diffuse_seen;  // looked up once per vertex at most
        if (first && depth == 0 && passes == 0) {
            diffuse_seen = textured_diffuse();
            *first = visible_surface(*hit, material, *diffuse_seen);
        }
        // Opacity: the ray stops here with probability opacity, else passes on unchanged.
        if (material.opacity < 1 && !pass_through.stops(material.opacity)) {
            if (++passes > max_pass_throughs)
                break;
            // On through the surface: into a closed primitive the far wall is real.
            Spawn s = spawn(*hit, dir);
            org = s.origin;
            leaving = s.skip;
            if (depth == 0)
                tfar = std::isinf(tfar) ? tfar : tfar - hit->t;
            continue;
        }
        if (depth == 0 && hit->geom_id == ground_geom_id && ctx.ground->shadow_catcher) {
            catch_shadow(ctx, facts, *hit, sampler, result);
            break;
        }
        if (depth == 0)
            result.hit = true;
        Vec3f diffuse = diffuse_seen ? *diffuse_seen : textured_diffuse();
        if (hit->unlit || ctx.unlit) {
            result.radiance += beta * (diffuse + material.emission);
            break;
        }
        const bool textured = ctx.textures && hit->texture != geom::no_texture;
        const Vec3f tint = textured ? texture_tint(material, diffuse) : Vec3f(1.0f);
        if (depth == 0 && !is_black(material.ambient_glow))
            result.radiance += beta * material.ambient_glow * tint;
        if (!is_black(material.emission)) {
            // A BSDF-sampled hit on a listed light: weighted against sampling the light.
            float w = depth > 0 ? bsdf_hit_weight(bsdf_pdf_prev,
                                                  choice.area * lights.area_pdf(scatter_prev, *hit))
                                : 1.0f;
            result.radiance += beta * material.emission * w;
        }
        Bsdf bsdf = make_bsdf(material, diffuse);
        if (textured) {  // the highlight takes the texture's colour, as in cpfg's window
            // min(x, 1) by hand, as std::fmin gives it for every x (NaN: 1), where
            // std::fmin is a library call (three at every textured vertex).
            const Vec3f g = bsdf.glossy * tint;
            auto at_most_1 = [](float x) { return x < 1 ? x : 1.0f; };
            bsdf.glossy = {at_most_1(g.x), at_most_1(g.y), at_most_1(g.z)};
        }
        const BsdfAt at = bsdf_at(bsdf, hit->normal, -dir);
        Vertex vertex{*hit, at};
        const bool last = depth + 1 == ctx.max_depth;
        result.radiance += beta * sample_ld(ctx, facts, vertex, last, sampler, block, choice);
        if (++depth == ctx.max_depth)
            break;

        // Continue the path: sample the BSDF, then Russian roulette on the throughput.
        auto [u1, u2] = sampler.get2d(block + sample_dimension::bsdf);
        BsdfSample bs = bsdf_sample(at, u1, u2);
        if (bs.pdf <= 0 || !same_side(*hit, bs.wi))
            break;
        beta *= bs.weight;
        if (is_black(beta))
            break;
        if (depth >= ctx.roulette_depth) {
            // A path goes on for sure while its throughput's largest channel is at least
            // roulette_keep_above, else with probability in proportion to it: dim paths
            // (after a dark leaf) are thinned from the first bounce, bright ones are never
            // cut (a fixed cap below 1 killed a share of them for nothing but noise);
            // max_depth ends every path.
            float survive = max_component(beta) / roulette_keep_above;
            if (survive < 1) {
                if (sampler.get1d(block + sample_dimension::roulette) >= survive)
                    break;
                beta *= 1.0f / survive;
            }
        }
        Spawn s = spawn(*hit, bs.wi);
        org = s.origin;
        dir = bs.wi;
        tfar = infinity;
        leaving = s.skip;
        pass_through = PassThroughDraws(sampler, sample_dimension::vertex(depth) +
                                                     sample_dimension::opacity);
        bsdf_pdf_prev = bs.pdf;
        scatter_prev = hit->position;
    }
    return result;
}

std::vector<float> light_choice_probabilities(const PathContext& ctx, const SurfaceHit& hit,
                                              const BsdfAt& bsdf)
{
    if (!ctx.prepared)
        unprepared_path_context("light_choice_probabilities");
    const LightSet& lights = ctx.prepared->lights;
    std::vector<float> p(lights.size(), 0.0f);
    const Vertex v{hit, bsdf};
    PointWeights weight{};
    float total = 0;
    if (samples_every_light(v, lights)) {
        for (std::uint32_t i = 0; i < lights.size(); ++i)
            if (!is_delta(lights.kind(i))) {
                p[i] = 1;
            } else {
                const LightLiSample ls = lights.sample_li(i, hit.position, 0, 0, 0);
                p[i] = !ground_hides(ctx, v, ls) && !is_black(unshadowed(v, ls)) ? 1.0f : 0.0f;
            }
        return p;
    }
    if (lights.per_point()) {
        total = point_weights(ctx, lights, v, weight);
    } else if (lights.delta_only()) {
        for (std::uint32_t i = 0; i < lights.size(); ++i) {
            weight[i] = luminance(unshadowed(v, lights.sample_li(i, hit.position, 0, 0, 0)));
            total += weight[i];
        }
    } else {
        for (std::uint32_t i = 0; i < lights.size(); ++i)
            p[i] = lights.probability(i);
        return p;
    }
    if (total > 0)
        for (std::size_t i = 0; i < p.size(); ++i)
            p[i] = weight[i] / total;
    return p;
}

}  // namespace cambium::render
