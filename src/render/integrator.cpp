// SPDX-License-Identifier: Apache-2.0
// The unidirectional path tracer: next-event estimation toward the view file's lights, the
// environment and emissive primitives (MIS against BSDF sampling), transmission, opacity,
// Russian roulette, ray cones for texture filtering.
#include "render/integrator.h"

#include <array>
#include <cmath>
#include <limits>

namespace cambium::render {

namespace {

/// Probe directions spread over the sphere (a Fibonacci lattice).
struct Probes {
    std::array<Vec3f, 16> d;
    Probes()
    {
        for (int i = 0; i < 16; ++i) {
            float z = 1 - (i + 0.5f) / 8;
            float r = std::sqrt(std::fmax(0.0f, 1 - z * z)), phi = 2.39996323f * i;
            d[i] = Vec3f(r * std::cos(phi), r * std::sin(phi), z);
        }
    }
};

/// What escaping rays see: the Environment, or the uniform `ambient` colour.
class EnvironmentView {
public:
    explicit EnvironmentView(const PathContext& ctx)
    {
        const Environment* env = ctx.environment;
        m_black = env ? env->black() : is_black(ctx.ambient);
        // A uniform environment is sampled perfectly by the BSDF alone (exactly, for a
        // Lambertian surface), so NEE toward it would only add noise. Sixteen probes tell;
        // a wrong "uniform" costs variance only, never bias. Non-uniform ones fail fast.
        m_nee = env && !m_black && !looks_uniform(*env);
    }
    bool black() const { return m_black; }
    /// Whether to sample it for next-event estimation (and weight BSDF hits by MIS).
    bool nee() const { return m_nee; }

private:
    static bool looks_uniform(const Environment& env)
    {
        static const Probes probes;
        Vec3f first = env.radiance(probes.d[0]);
        float pdf = env.pdf(probes.d[0]);
        for (const Vec3f& d : probes.d)
            if (env.pdf(d) != pdf || !(env.radiance(d) == first))
                return false;
        return true;
    }

    bool m_black = true, m_nee = false;
};

}  // namespace

namespace {

constexpr float infinity = std::numeric_limits<float>::infinity();
/// Transparent surfaces a ray may pass through before it counts as blocked.
constexpr int max_pass_throughs = 64;

const SurfaceMaterial& material_at(const PathContext& ctx, std::uint16_t m)
{
    static const SurfaceMaterial fallback;
    return m < ctx.materials.size() ? ctx.materials[m] : fallback;
}

/// The power heuristic (beta = 2) for a sample drawn with pdf a against one of pdf b.
float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0 ? a2 / (a2 + b2) : 0;
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

/// The fraction of light passing from s.origin along wi for t < tfar: 0 if an opaque
/// surface blocks it, the product of transparencies through transparent ones.
float transmittance(const PathContext& ctx, bool transparent_scene, Spawn s, const Vec3f& wi,
                    float tfar)
{
    if (!transparent_scene)
        return ctx.accel->occluded(s.origin, wi, 0, tfar, s.skip) ? 0.0f : 1.0f;
    float through = 1;
    for (int i = 0; i < max_pass_throughs; ++i) {
        std::optional<SurfaceHit> hit = ctx.accel->intersect(s.origin, wi, 0, tfar, s.skip);
        if (!hit)
            return through;
        SurfaceMaterial scratch;
        through *= 1 - hit_material(ctx, *hit, scratch).opacity;
        if (through <= 0)
            return 0;
        tfar = std::isinf(tfar) ? tfar : tfar - hit->t;
        s = {hit->position, hit->prim()};
    }
    return 0;
}

struct Vertex {
    const SurfaceHit& hit;
    const Bsdf& bsdf;
    Vec3f wo;
};

/// Direct light from every delta light, each with one shadow ray.
Vec3f light_delta(const PathContext& ctx, bool transparent, const Vertex& v)
{
    Vec3f sum;
    for (const RenderLight& light : ctx.lights) {
        LightSample ls = sample_light(light, v.hit.position);
        if (is_black(ls.irradiance))
            continue;
        Vec3f f = bsdf_eval(v.bsdf, v.hit.normal, v.wo, ls.wi);
        float cos = std::fabs(dot(v.hit.normal, ls.wi));
        if (is_black(f) || cos <= 0 || !same_side(v.hit, ls.wi))
            continue;
        // The offset origin is a little closer to the light; stop just short of it.
        float tfar = std::isinf(ls.distance) ? infinity : ls.distance * (1 - 1e-4f);
        float through = transmittance(ctx, transparent, spawn(v.hit, ls.wi), ls.wi, tfar);
        if (through > 0)
            sum += f * ls.irradiance * (cos * through);
    }
    return sum;
}

/// One point on an emissive primitive, weighted against BSDF sampling of the same
/// direction (weight 1 at the path's last vertex, where no BSDF ray follows).
Vec3f light_area(const PathContext& ctx, bool transparent, const Vertex& v, bool last,
                 float u0, float u1, float u2)
{
    std::optional<AreaLightSample> ls = ctx.area_lights->sample(v.hit.position, u0, u1, u2);
    if (!ls)
        return {};
    Vec3f f = bsdf_eval(v.bsdf, v.hit.normal, v.wo, ls->wi);
    float cos = std::fabs(dot(v.hit.normal, ls->wi));
    if (is_black(f) || cos <= 0 || !same_side(v.hit, ls->wi))
        return {};
    // Stop just short of the light, whose own surface must not block the ray.
    float through = transmittance(ctx, transparent, spawn(v.hit, ls->wi), ls->wi,
                                  ls->distance - ls->margin);
    if (through <= 0)
        return {};
    float w = last ? 1.0f
                   : power_heuristic(ls->pdf, bsdf_pdf(v.bsdf, v.hit.normal, v.wo, ls->wi));
    return f * ls->radiance * (cos * through * w / ls->pdf);
}

/// One environment sample, weighted against BSDF sampling of the same direction
/// (weight 1 at the path's last vertex, where no BSDF ray follows).
Vec3f light_environment(const PathContext& ctx, const Environment& env, bool transparent,
                        const Vertex& v, bool last, float u1, float u2)
{
    EnvironmentSample es = env.sample(u1, u2);
    if (es.pdf <= 0 || is_black(es.radiance))
        return {};
    Vec3f f = bsdf_eval(v.bsdf, v.hit.normal, v.wo, es.direction);
    float cos = std::fabs(dot(v.hit.normal, es.direction));
    if (is_black(f) || cos <= 0 || !same_side(v.hit, es.direction))
        return {};
    float through = transmittance(ctx, transparent, spawn(v.hit, es.direction), es.direction,
                                  infinity);
    if (through <= 0)
        return {};
    float w = last ? 1.0f
                   : power_heuristic(es.pdf,
                                     bsdf_pdf(v.bsdf, v.hit.normal, v.wo, es.direction));
    return f * es.radiance * (cos * through * w / es.pdf);
}

}  // namespace

TextureFootprint texture_footprint(const SurfaceHit& hit, const Vec3f& dir, float width)
{
    const Vec3f &dpds = hit.dpds, &dpdt = hit.dpdt;
    if (!(width > 0) || (is_black(dpds) && is_black(dpdt)))
        return {};
    const Vec3f& n = hit.geometric_normal;
    // Grazing views stretch the footprint; beyond 50:1 it would only blur.
    float cos = std::fmax(std::fabs(dot(dir, n)), 0.02f);
    Vec3f minor = cross(dir, n), unused;
    if (dot(minor, minor) < 1e-12f)
        make_basis(n, minor, unused);
    minor = normalize(minor);
    Vec3f major = normalize(cross(n, minor)) * (width / cos);
    minor = minor * width;
    float a = dot(dpds, dpds), b = dot(dpds, dpdt), c = dot(dpdt, dpdt);
    float det = a * c - b * b;
    auto to_st = [&](const Vec3f& w) -> std::array<float, 2> {
        float x = dot(dpds, w), y = dot(dpdt, w);
        if (det > 1e-12f * a * c)
            return {(c * x - b * y) / det, (a * y - b * x) / det};
        // One coordinate constant (or both parallel): each on its own.
        return {a > 0 ? x / a : 0.0f, c > 0 ? y / c : 0.0f};
    };
    auto [dsdx, dtdx] = to_st(major);
    auto [dsdy, dtdy] = to_st(minor);
    return {dsdx, dtdx, dsdy, dtdy};
}

namespace {

PathContext::Prepared scene_facts(const PathContext& ctx)
{
    const EnvironmentView env(ctx);
    return {any_transparent(ctx), env.black(), env.nee()};
}

}  // namespace

void prepare_path_context(PathContext& ctx) { ctx.prepared = scene_facts(ctx); }

const SurfaceMaterial& hit_material(const PathContext& ctx, const SurfaceHit& hit,
                                    SurfaceMaterial& scratch)
{
    const SurfaceMaterial& start = material_at(ctx, hit.material);
    if (hit.material_blend <= 0)
        return start;  // the usual case: no copy
    scratch = mix(start, material_at(ctx, hit.end_material), hit.material_blend);
    return scratch;
}

PathResult trace_path(const PathContext& ctx, const Vec3f& camera_org, const Vec3f& camera_dir,
                      Sampler& sampler)
{
    const PathContext::Prepared facts = ctx.prepared ? *ctx.prepared : scene_facts(ctx);
    const bool env_nee = facts.environment_nee;
    const bool env_black = facts.environment_black;
    const bool transparent = facts.transparent;
    auto env_radiance = [&](const Vec3f& d) {
        return ctx.environment ? ctx.environment->radiance(d) : ctx.ambient;
    };
    const bool area_nee = ctx.area_lights && !ctx.area_lights->empty();

    PathResult result;
    Vec3f beta(1.0f);
    Vec3f org = camera_org, dir = camera_dir;
    PrimId leaving;        // the primitive the current ray leaves (none for the camera ray)
    float bsdf_pdf_prev = 0;  // pdf the current ray's direction was drawn with
    Vec3f scatter_prev;       // where it was drawn (the last scattering vertex)
    int passes = 0;
    float travelled = 0;  // along the path, for the ray cone
    for (int depth = 0; depth < ctx.max_depth;) {
        std::optional<SurfaceHit> hit =
            ctx.accel->intersect(org, dir, 0, infinity, leaving, depth == 0);
        if (!hit) {
            if (depth == 0 && ctx.environment_visible) {
                result.radiance += beta * env_radiance(dir);
            } else if (depth == 0) {
                result.radiance += beta * ctx.background;
            } else if (!env_black) {
                float w = env_nee
                              ? power_heuristic(bsdf_pdf_prev, ctx.environment->pdf(dir))
                              : 1.0f;
                result.radiance += beta * env_radiance(dir) * w;
            }
            break;
        }
        travelled += hit->t;
        if (ctx.facet_normals)
            hit->normal = hit->geometric_normal;
        SurfaceMaterial blended;
        const SurfaceMaterial& material = hit_material(ctx, *hit, blended);
        // Opacity: the ray stops here with probability opacity, else passes on unchanged.
        if (material.opacity < 1 && sampler.next() >= material.opacity) {
            if (++passes > max_pass_throughs)
                break;
            org = hit->position;
            leaving = hit->prim();
            continue;
        }
        if (depth == 0)
            result.hit = true;
        Vec3f diffuse = material.diffuse;
        if (ctx.textures && hit->texture != geom::no_texture)
            diffuse = ctx.textures->apply(
                hit->texture, diffuse, hit->u, hit->v,
                texture_footprint(*hit, dir,
                                  ctx.camera_cone.width + ctx.camera_cone.spread * travelled));
        if (hit->unlit || ctx.unlit) {
            result.radiance += beta * (diffuse + material.emission);
            break;
        }
        if (!is_black(material.emission)) {
            // A BSDF-sampled hit on a listed light: weighted against sampling the light.
            float w = 1;
            if (depth > 0 && area_nee) {
                float light_pdf = ctx.area_lights->pdf(scatter_prev, *hit);
                if (light_pdf > 0)
                    w = power_heuristic(bsdf_pdf_prev, light_pdf);
            }
            result.radiance += beta * material.emission * w;
        }
        Bsdf bsdf = make_bsdf(material, diffuse);
        Vertex vertex{*hit, bsdf, -dir};
        const bool last = depth + 1 == ctx.max_depth;
        result.radiance += beta * light_delta(ctx, transparent, vertex);
        float e1 = sampler.next(), e2 = sampler.next();
        if (env_nee)
            result.radiance += beta * light_environment(ctx, *ctx.environment, transparent,
                                                        vertex, last, e1, e2);
        if (area_nee) {
            float a0 = sampler.next(), a1 = sampler.next(), a2 = sampler.next();
            result.radiance += beta * light_area(ctx, transparent, vertex, last, a0, a1, a2);
        }
        if (++depth == ctx.max_depth)
            break;

        // Continue the path: sample the BSDF, then Russian roulette on the throughput.
        float u1 = sampler.next(), u2 = sampler.next(), u_rr = sampler.next();
        BsdfSample bs = bsdf_sample(bsdf, hit->normal, vertex.wo, u1, u2);
        if (bs.pdf <= 0 || !same_side(*hit, bs.wi))
            break;
        beta *= bs.weight;
        if (is_black(beta))
            break;
        if (depth >= ctx.roulette_depth) {
            float survive = std::fmin(max_component(beta), 0.95f);
            if (u_rr >= survive)
                break;
            beta *= 1.0f / survive;
        }
        Spawn s = spawn(*hit, bs.wi);
        org = s.origin;
        dir = bs.wi;
        leaving = s.skip;
        bsdf_pdf_prev = bs.pdf;
        scatter_prev = hit->position;
    }
    return result;
}

}  // namespace cambium::render
