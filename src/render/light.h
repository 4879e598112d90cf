// SPDX-License-Identifier: Apache-2.0
// The view file's lights (point, directional, spot) as delta lights for next-event estimation.
#pragma once

#include <limits>
#include <vector>

#include "geom/scene.h"
#include "render/vecf.h"

namespace cambium::render {

/// A light, in world space with a linear RGB colour.
///
/// Conventions (docs/lights.md): a light of colour c gives irradiance pi * c at normal
/// incidence (times attenuation and the spot factor), so a white light shining straight
/// onto a Lambertian surface makes it as bright as its albedo, as in cpfg's OpenGL
/// window. Attenuation is OpenGL's 1 / (c + l d + q d^2). A directional light's
/// `toward_light` is the view file's `V:` vector normalised: it points from the scene
/// toward the light (OpenGL's w = 0 position), so light travels along -V.
struct RenderLight {
    enum class Kind { point, directional, spot };
    Kind kind = Kind::point;
    Vec3f position;       ///< point, spot
    Vec3f toward_light;   ///< directional: unit vector toward the light
    Vec3f spot_axis;      ///< spot: unit direction the cone points along
    float spot_exponent = 0;
    float spot_cos_cutoff = -1;  ///< cos of the cutoff angle; -1 = no cutoff (180 deg)
    float att_constant = 1, att_linear = 0, att_quadratic = 0;
    Vec3f colour;         ///< linear RGB (decoded diffuse colour)
};

/// What a light delivers at a point: unit direction to it, distance (infinite for a
/// directional light) and the irradiance on a surface facing it.
struct LightSample {
    Vec3f wi;
    float distance = std::numeric_limits<float>::infinity();
    Vec3f irradiance;
};

LightSample sample_light(const RenderLight& light, const Vec3f& p);

/// Converts the view file's lights; colours are decoded from display values.
std::vector<RenderLight> make_lights(const std::vector<geom::Light>& lights);

}  // namespace cambium::render
