// SPDX-License-Identifier: Apache-2.0
// QuasiMC's specification file (vlab's light environment) as Cambium's light environment
// reads it: the lights, the rays, the scattering depth, the leaves' optics and what a ?E
// is answered with (docs/environment.md). The tracing itself is the light report's.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "env/environment.h"

namespace cambium::env {

/// What a ?E is answered with (QuasiMC's `return type:` letters).
enum class LightAnswer {
    absorbed_flux,        ///< F: the flux the organ absorbs
    absorbed_irradiance,  ///< D: that flux over the organ's one-sided area
    front_irradiance,     ///< U: irradiance arriving on the organ's front (upper) side
    back_irradiance,      ///< L: irradiance arriving on its back (lower) side
};

/// A leaf side's optics: the shares of arriving light reflected and transmitted
/// (both diffusely); the rest is absorbed.
struct LeafOptics {
    double reflectance = 0;
    double transmittance = 0;
};

/// A parallel light: the way it travels (QuasiMC's `light source:` vector, from the light
/// into the scene) and the irradiance it delivers to a surface facing it.
struct ParallelLight {
    std::array<double, 3> travel{0, -1, 0};
    double irradiance = 1;
};

struct LightSpec {
    /// QuasiMC's default: one light straight down, of weight 1.
    std::vector<ParallelLight> lights{ParallelLight{}};
    /// Rays traced per environmental pass, shared among the lights by their power.
    std::uint64_t rays = 100'000;
    /// Surfaces a ray meets before it is cut short (QuasiMC's `maximum depth:`).
    int max_depth = 5;
    /// Every organ's optics, front then back (`leaf material (top)`, `(bottom)`); unset:
    /// each organ's own material's reflectance and translucency.
    std::optional<std::array<LeafOptics, 2>> optics;
    LightAnswer answer = LightAnswer::absorbed_flux;
};

/// The most rays one pass may trace (`number of rays:`, the `Q` module).
inline constexpr std::uint64_t max_light_rays = 1'000'000'000;

/// Reads the specification file `args` names (its first argument that is not an
/// option), relative to the model folder and confined to it as every model file is.
/// Keywords are QuasiMC's, without regard to case; those Cambium does not follow are
/// warned of and ignored; bad values are errors naming the file and line.
LightSpec read_light_spec(const std::vector<std::string>& args, const Context& context);

/// The name the `.e` file's `executable:` gives vlab's light environment (its file name
/// compared without regard to case).
bool names_light_environment(const std::string& program);

}  // namespace cambium::env
