// SPDX-License-Identifier: Apache-2.0
// Surface materials: cpfg materials mapped to a small physically-based model.
#pragma once

#include <numbers>
#include <variant>
#include <vector>

#include "geom/scene.h"
#include "render/vecf.h"

namespace cambium::render {

/// An ideal diffuse reflector. Later lobes (glossy from specular/shininess, diffuse
/// transmission for leaves, opacity) become further alternatives of Bsdf.
struct Lambertian {
    Vec3f albedo;
};

using Bsdf = std::variant<Lambertian>;

/// A surface's scattering and its own emitted radiance (linear RGB).
struct SurfaceMaterial {
    Bsdf bsdf = Lambertian{Vec3f(0.5f)};
    Vec3f emission;
};

/// The colour a surface shows unlit (cpfg's flat colour): its diffuse albedo plus emission.
inline Vec3f flat_colour(const SurfaceMaterial& m)
{
    Vec3f albedo = std::visit([](const auto& b) { return b.albedo; }, m.bsdf);
    return albedo + m.emission;
}

/// A direction sampled from a BSDF: `weight` = f cos / pdf.
struct BsdfSample {
    Vec3f wi;
    Vec3f weight;
};

/// f(wo, wi) for a normal n facing wo.
inline Vec3f bsdf_eval(const Bsdf& bsdf, const Vec3f& n, const Vec3f& wi)
{
    return std::visit(
        [&](const auto& b) -> Vec3f {
            using T = std::decay_t<decltype(b)>;
            if constexpr (std::is_same_v<T, Lambertian>)
                return dot(n, wi) > 0 ? b.albedo * std::numbers::inv_pi_v<float> : Vec3f();
        },
        bsdf);
}

/// Samples wi given the shading normal n (facing the incoming ray) and two uniforms.
BsdfSample bsdf_sample(const Bsdf& bsdf, const Vec3f& n, float u1, float u2);

/// The cpfg materials decoded to linear RGB (display values decoded as sRGB).
std::vector<SurfaceMaterial> make_materials(const std::vector<geom::Material>& materials);

}  // namespace cambium::render
