// SPDX-License-Identifier: Apache-2.0
// What rays that leave the scene see: a uniform ambient, an analytic sky, an HDR map.
#pragma once

#include <memory>

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

}  // namespace cambium::render
