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

/// Preetham's (1999) analytic daylight sky with a sun disk (docs: render/environment.cpp,
/// "sky"). World up is +y (cpfg's turtle grows along +y).
struct SkyParameters {
    /// Unit vector toward the sun; below the horizon there is no sun disk and the dome
    /// fades out by 6 degrees below.
    Vec3f sun_direction{0.5f, 0.8f, 0.33f};
    /// Haze, 2 (clear) .. 10 (hazy), clamped to [sky_min_turbidity, sky_max_turbidity].
    float turbidity = 3;
    /// The sun outside the atmosphere gives irradiance pi * sun_intensity (the view-file
    /// light convention); the atmosphere dims it.
    float sun_intensity = 1;
    /// Scales the dome, whose radiance 1 is sky_luminance_unit cd/m^2.
    float sky_intensity = 1;
    /// Linear reflectance of the ground seen below the horizon.
    Vec3f ground_albedo{0.2f, 0.18f, 0.15f};
};
/// The range of turbidity the model's fit covers.
inline constexpr float sky_min_turbidity = 1.7f, sky_max_turbidity = 10;
/// Luminance (cd/m^2) of radiance 1: 128 000 lux of sunlight outside
/// the atmosphere (the solar illuminance constant) becomes irradiance pi.
inline constexpr float sky_luminance_unit = 128000 / 3.14159265f;
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

/// `inner` turned by `degrees` about the world up axis +y (right-handed: +90 takes what
/// was seen along +z to +x). Radiance, sampling and pdf all follow the turn exactly.
std::unique_ptr<Environment> make_rotated_environment(std::shared_ptr<const Environment> inner,
                                                      float degrees);

/// The same from texels in memory (rows top to bottom, 3 floats each): tests, generated maps.
std::unique_ptr<Environment> make_map_environment(int width, int height,
                                                  std::vector<float> rgb);

}  // namespace cambium::render
