// SPDX-License-Identifier: Apache-2.0
// Surface materials: cpfg materials mapped to a small physically-based model.
#include "render/material.h"

#include <cmath>

#include "render/color.h"

namespace cambium::render {

namespace {

/// Cosine-weighted direction about n (Malley's method on a concentric-free disc).
Vec3f sample_cosine(const Vec3f& n, float u1, float u2)
{
    float r = std::sqrt(u1);
    float phi = 2 * std::numbers::pi_v<float> * u2;
    float x = r * std::cos(phi), y = r * std::sin(phi);
    float z = std::sqrt(std::fmax(0.0f, 1 - u1));
    Vec3f t, b;
    make_basis(n, t, b);
    return normalize(t * x + b * y + n * z);
}

}  // namespace

BsdfSample bsdf_sample(const Bsdf& bsdf, const Vec3f& n, float u1, float u2)
{
    return std::visit(
        [&](const auto& b) -> BsdfSample {
            using T = std::decay_t<decltype(b)>;
            if constexpr (std::is_same_v<T, Lambertian>)
                // f cos / pdf = (albedo / pi) cos / (cos / pi) = albedo
                return {sample_cosine(n, u1, u2), b.albedo};
        },
        bsdf);
}

std::vector<SurfaceMaterial> make_materials(const std::vector<geom::Material>& materials)
{
    std::vector<SurfaceMaterial> out;
    out.reserve(materials.size());
    for (const geom::Material& m : materials)
        out.push_back({Lambertian{decode_display(m.diffuse)}, decode_display(m.emission)});
    return out;
}

}  // namespace cambium::render
