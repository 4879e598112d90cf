// SPDX-License-Identifier: Apache-2.0
// What rays that leave the scene see: a uniform ambient, an analytic sky, an HDR map.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "render/vecf.h"

namespace cambium::render {

/// A direction sampled from an environment, with its radiance and solid-angle pdf.
struct EnvironmentSample {
    Vec3f direction;  ///< unit, pointing away from the scene
    Vec3f radiance;   ///< linear
    float pdf = 0;    ///< per steradian
};

/// Radiance arriving from infinitely far away, by direction. Thread-safe after
/// construction. The integrator samples it for next-event estimation and weights that
/// against BSDF sampling (multiple importance sampling) with pdf().
class Environment {
public:
    virtual ~Environment() = default;
    /// Radiance along `direction` (unit, pointing away from the scene).
    virtual Vec3f radiance(const Vec3f& direction) const = 0;
    /// A direction drawn in proportion to (roughly) radiance, from two uniform numbers.
    virtual EnvironmentSample sample(float u1, float u2) const = 0;
    /// The solid-angle density sample() draws `direction` with.
    virtual float pdf(const Vec3f& direction) const = 0;
    /// Whether the environment is black everywhere (the integrator skips it).
    virtual bool black() const = 0;
};

/// The same radiance from every direction (the stand-in for cpfg's ambient term).
std::unique_ptr<Environment> make_uniform_environment(const Vec3f& radiance);

/// A simple analytic daylight sky with a sun disk (docs: render/environment.cpp, "sky").
/// World up is +y (cpfg's turtle grows along +y).
struct SkyParameters {
    /// Unit vector toward the sun; below the horizon there is no sun disk.
    Vec3f sun_direction{0.5f, 0.8f, 0.33f};
    /// Haze, 2 (clear) .. 10 (hazy): whiter horizon, wider glow, redder and dimmer sun.
    float turbidity = 3;
    /// A white Lambertian surface facing the unobstructed sun shows this radiance from
    /// the sun alone (the view-file light convention: irradiance pi * sun_intensity).
    float sun_intensity = 1;
    /// Scales the sky dome (zenith radiance is about 0.3 * sky_intensity in blue).
    float sky_intensity = 1;
    /// Linear reflectance of the ground seen below the horizon.
    Vec3f ground_albedo{0.2f, 0.18f, 0.15f};
};
std::unique_ptr<Environment> make_sky_environment(const SkyParameters& parameters = {});

/// A latitude-longitude HDR map (EXR, HDR or anything OpenImageIO reads), linear RGB,
/// times `scale`. Texel coordinates (u, v) in [0, 1)^2, v down from the top row, look
/// along (sin t sin p, cos t, sin t cos p) with t = pi v, p = 2 pi u: row 0 is straight
/// up (+y) and the centre column is seen looking along -z, behind the plant in cpfg's
/// default view. Radiance is constant over a texel (nearest lookup). Texels are sampled
/// in proportion to luminance times solid angle (marginal and conditional CDFs), and
/// uniformly in solid angle within one. Throws cambium::Error naming the file when it
/// cannot be read or is larger than 2^25 texels.
std::unique_ptr<Environment> make_map_environment(const std::filesystem::path& file,
                                                  float scale = 1);

/// The same from texels in memory (rows top to bottom, 3 floats each): tests, generated maps.
std::unique_ptr<Environment> make_map_environment(int width, int height,
                                                  std::vector<float> rgb);

}  // namespace cambium::render
