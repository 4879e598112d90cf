// SPDX-License-Identifier: Apache-2.0
// Environments: uniform ambient (more kinds are being written).
#include "render/environment.h"

#include <cmath>
#include <numbers>

namespace cambium::render {
namespace {

class UniformEnvironment final : public Environment {
public:
    explicit UniformEnvironment(const Vec3f& radiance) : m_radiance(radiance) {}
    Vec3f radiance(const Vec3f&) const override { return m_radiance; }
    EnvironmentSample sample(float u1, float u2) const override
    {
        float z = 1 - 2 * u1, r = std::sqrt(std::max(0.0f, 1 - z * z));
        float phi = 2 * std::numbers::pi_v<float> * u2;
        return {Vec3f(r * std::cos(phi), r * std::sin(phi), z), m_radiance, pdf(Vec3f())};
    }
    float pdf(const Vec3f&) const override { return 1 / (4 * std::numbers::pi_v<float>); }
    bool black() const override { return m_radiance.x <= 0 && m_radiance.y <= 0 && m_radiance.z <= 0; }

private:
    Vec3f m_radiance;
};

}  // namespace

std::unique_ptr<Environment> make_uniform_environment(const Vec3f& radiance)
{
    return std::make_unique<UniformEnvironment>(radiance);
}

}  // namespace cambium::render
