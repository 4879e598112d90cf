// SPDX-License-Identifier: Apache-2.0
// The unidirectional path tracer with next-event estimation toward the view file's lights.
#include "render/integrator.h"

#include <cmath>
#include <limits>

namespace cambium::render {

namespace {

constexpr float infinity = std::numeric_limits<float>::infinity();

const SurfaceMaterial& material_of(const PathContext& ctx, const SurfaceHit& hit)
{
    static const SurfaceMaterial fallback;
    return hit.material < ctx.materials.size() ? ctx.materials[hit.material] : fallback;
}

/// Direct light from every delta light, each with one shadow ray.
Vec3f direct_light(const PathContext& ctx, const SurfaceHit& hit, const Bsdf& bsdf,
                   const Vec3f& origin)
{
    Vec3f sum;
    for (const RenderLight& light : ctx.lights) {
        LightSample ls = sample_light(light, hit.position);
        float cos = dot(hit.normal, ls.wi);
        if (cos <= 0 || is_black(ls.irradiance))
            continue;
        // The offset origin is a little closer to the light; stop just short of it.
        float tfar = std::isinf(ls.distance) ? infinity : ls.distance * (1 - 1e-4f);
        if (ctx.accel->occluded(origin, ls.wi, 0, tfar, hit.prim()))
            continue;
        sum += bsdf_eval(bsdf, hit.normal, ls.wi) * ls.irradiance * cos;
    }
    return sum;
}

}  // namespace

PathResult trace_path(const PathContext& ctx, const Vec3f& camera_org, const Vec3f& camera_dir,
                      Sampler& sampler)
{
    PathResult result;
    Vec3f beta(1.0f);
    Vec3f org = camera_org, dir = camera_dir;
    PrimId leaving;  // the primitive the current ray leaves (none for the camera ray)
    for (int depth = 0; depth < ctx.max_depth; ++depth) {
        std::optional<SurfaceHit> hit =
            ctx.accel->intersect(org, dir, 0, infinity, leaving, depth == 0);
        if (!hit) {
            result.radiance += beta * (depth == 0 ? ctx.background : ctx.environment);
            break;
        }
        if (depth == 0)
            result.hit = true;
        const SurfaceMaterial& material = material_of(ctx, *hit);
        if (hit->unlit) {
            result.radiance += beta * flat_colour(material);
            break;
        }
        result.radiance += beta * material.emission;
        // Spawned rays leave from just outside the curve (FACTS.md: no self-hit guard).
        Vec3f origin = hit->position + hit->normal * hit->spawn_offset;
        result.radiance += beta * direct_light(ctx, *hit, material.bsdf, origin);
        if (depth + 1 == ctx.max_depth)
            break;

        // Continue the path: sample the BSDF, then Russian roulette on the throughput.
        float u1 = sampler.next(), u2 = sampler.next(), u_rr = sampler.next();
        BsdfSample bs = bsdf_sample(material.bsdf, hit->normal, u1, u2);
        beta *= bs.weight;
        if (is_black(beta))
            break;
        if (depth + 1 >= ctx.roulette_depth) {
            float survive = std::fmin(max_component(beta), 0.95f);
            if (u_rr >= survive)
                break;
            beta *= 1.0f / survive;
        }
        org = origin;
        dir = bs.wi;
        leaving = hit->prim();
    }
    return result;
}

}  // namespace cambium::render
