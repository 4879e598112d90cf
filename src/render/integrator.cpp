// SPDX-License-Identifier: Apache-2.0
// The unidirectional path tracer: next-event estimation toward the view file's lights and
// the environment (MIS against BSDF sampling), transmission, opacity, Russian roulette.
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
        : m_env(ctx.environment), m_ambient(ctx.ambient)
    {
        m_black = m_env ? m_env->black() : is_black(m_ambient);
        // A uniform environment is sampled perfectly by the BSDF alone (exactly, for a
        // Lambertian surface), so NEE toward it would only add noise. Sixteen probes tell;
        // a wrong "uniform" costs variance only, never bias. Non-uniform ones fail fast.
        m_nee = m_env && !m_black && !looks_uniform(*m_env);
    }
    bool black() const { return m_black; }
    /// Whether to sample it for next-event estimation (and weight BSDF hits by MIS).
    bool nee() const { return m_nee; }
    Vec3f radiance(const Vec3f& d) const { return m_env ? m_env->radiance(d) : m_ambient; }
    const Environment& environment() const { return *m_env; }

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

    const Environment* m_env;
    Vec3f m_ambient;
    bool m_black = true, m_nee = false;
};

}  // namespace

namespace {

constexpr float infinity = std::numeric_limits<float>::infinity();
/// Transparent surfaces a ray may pass through before it counts as blocked.
constexpr int max_pass_throughs = 64;

const SurfaceMaterial& material_of(const PathContext& ctx, const SurfaceHit& hit)
{
    static const SurfaceMaterial fallback;
    return hit.material < ctx.materials.size() ? ctx.materials[hit.material] : fallback;
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
        through *= 1 - material_of(ctx, *hit).opacity;
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

/// One environment sample, weighted against BSDF sampling of the same direction.
Vec3f light_environment(const PathContext& ctx, const Environment& env, bool transparent,
                        const Vertex& v, float u1, float u2)
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
    float w = power_heuristic(es.pdf, bsdf_pdf(v.bsdf, v.hit.normal, v.wo, es.direction));
    return f * es.radiance * (cos * through * w / es.pdf);
}

}  // namespace

PathResult trace_path(const PathContext& ctx, const Vec3f& camera_org, const Vec3f& camera_dir,
                      Sampler& sampler)
{
    // Scene-wide facts, cheap enough per path next to the rays it traces.
    const EnvironmentView env(ctx);
    const bool env_nee = env.nee();
    const bool transparent = any_transparent(ctx);

    PathResult result;
    Vec3f beta(1.0f);
    Vec3f org = camera_org, dir = camera_dir;
    PrimId leaving;        // the primitive the current ray leaves (none for the camera ray)
    float bsdf_pdf_prev = 0;  // pdf the current ray's direction was drawn with
    int passes = 0;
    for (int depth = 0; depth < ctx.max_depth;) {
        std::optional<SurfaceHit> hit =
            ctx.accel->intersect(org, dir, 0, infinity, leaving, depth == 0);
        if (!hit) {
            if (depth == 0 && ctx.environment_visible) {
                result.radiance += beta * env.radiance(dir);
            } else if (depth == 0) {
                result.radiance += beta * ctx.background;
            } else if (!env.black()) {
                float w =
                    env_nee ? power_heuristic(bsdf_pdf_prev, env.environment().pdf(dir)) : 1.0f;
                result.radiance += beta * env.radiance(dir) * w;
            }
            break;
        }
        const SurfaceMaterial& material = material_of(ctx, *hit);
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
            diffuse = ctx.textures->apply(hit->texture, diffuse, hit->u, hit->v);
        if (hit->unlit) {
            result.radiance += beta * (diffuse + material.emission);
            break;
        }
        result.radiance += beta * material.emission;
        Bsdf bsdf = make_bsdf(material, diffuse);
        Vertex vertex{*hit, bsdf, -dir};
        result.radiance += beta * light_delta(ctx, transparent, vertex);
        float e1 = sampler.next(), e2 = sampler.next();
        if (env_nee)
            result.radiance +=
                beta * light_environment(ctx, env.environment(), transparent, vertex, e1, e2);
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
    }
    return result;
}

}  // namespace cambium::render
