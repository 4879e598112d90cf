// SPDX-License-Identifier: Apache-2.0
// Environments: uniform ambient, an analytic sun-and-sky, a lat-long HDR map.
//
// sky: not Preetham's model but a small documented one, cheap and smooth, meant for
// plants lit from outdoors. With up = +y, h = clamp((turbidity - 2) / 8, 0, 1):
// - dome (y >= 0): lerp(horizon, zenith, sqrt(y)) * (1 + glow), zenith = (0.10, 0.18,
//   0.32), horizon = lerp((0.35, 0.42, 0.50), (0.55, 0.55, 0.55), h), both times
//   sky_intensity; glow = (0.3 + 1.7 h) * max(0, cos(angle to the sun))^(16 - 12 h).
// - ground (y < 0): ground_albedo * (pi * sun_intensity * max(0, sun.y) * sun colour
//   + the horizon colour * pi) / pi, i.e. a Lambertian ground lit by sun and sky.
// - sun: a disk of angular radius 0.2665 deg whose radiance gives irradiance
//   pi * sun_intensity * colour, colour = exp(-tau * airmass), tau = (0.02, 0.04, 0.08)
//   * (turbidity / 3), airmass = 1 / max(sun.y, 0.05).
// Sampling: the sun cone with probability 1/2 (when the sun is up), else the uniform
// sphere; pdf() is that mixture, so MIS weights are exact.
#include "render/environment.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "base/diagnostics.h"

namespace cambium::render {
namespace {

constexpr float pi = std::numbers::pi_v<float>;
constexpr float inv_4pi = 1 / (4 * pi);

Vec3f uniform_sphere(float u1, float u2)
{
    float z = 1 - 2 * u1, r = std::sqrt(std::max(0.0f, 1 - z * z));
    float phi = 2 * pi * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

float luminance(const Vec3f& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

class UniformEnvironment final : public Environment {
public:
    explicit UniformEnvironment(const Vec3f& radiance) : m_radiance(radiance) {}
    Vec3f radiance(const Vec3f&) const override { return m_radiance; }
    EnvironmentSample sample(float u1, float u2) const override
    {
        return {uniform_sphere(u1, u2), m_radiance, inv_4pi};
    }
    float pdf(const Vec3f&) const override { return inv_4pi; }
    bool black() const override
    {
        return m_radiance.x <= 0 && m_radiance.y <= 0 && m_radiance.z <= 0;
    }

private:
    Vec3f m_radiance;
};

Vec3f lerp(const Vec3f& a, const Vec3f& b, float t) { return a + (b - a) * t; }

Vec3f exp(const Vec3f& v) { return {std::exp(v.x), std::exp(v.y), std::exp(v.z)}; }

class SkyEnvironment final : public Environment {
public:
    explicit SkyEnvironment(const SkyParameters& p)
    {
        m_sun = normalize(p.sun_direction);
        if (length(m_sun) == 0)
            m_sun = {0, 1, 0};
        float t = std::clamp(p.turbidity, 1.0f, 20.0f);
        float h = std::clamp((t - 2) / 8, 0.0f, 1.0f);
        m_zenith = Vec3f(0.10f, 0.18f, 0.32f) * p.sky_intensity;
        m_horizon = lerp({0.35f, 0.42f, 0.50f}, Vec3f(0.55f), h) * p.sky_intensity;
        m_glow_strength = 0.3f + 1.7f * h;
        m_glow_exponent = 16 - 12 * h;
        float airmass = 1 / std::max(m_sun.y, 0.05f);
        Vec3f colour = exp(Vec3f(0.02f, 0.04f, 0.08f) * (-(t / 3) * airmass));
        m_cos_sun = std::cos(0.2665f * pi / 180);
        m_sun_solid_angle = 2 * pi * (1 - m_cos_sun);
        m_sun_up = m_sun.y > 0 && p.sun_intensity > 0;
        m_sun_radiance = m_sun_up ? colour * (pi * p.sun_intensity / m_sun_solid_angle) : Vec3f();
        Vec3f sun_irradiance = m_sun_up ? colour * (pi * p.sun_intensity * m_sun.y) : Vec3f();
        m_ground = p.ground_albedo * (sun_irradiance + m_horizon * pi) * (1 / pi);
        m_black = is_black(m_zenith) && is_black(m_horizon) && !m_sun_up;
        m_sun_probability = m_sun_up ? 0.5f : 0.0f;
    }

    Vec3f radiance(const Vec3f& d) const override
    {
        float cos_sun = dot(d, m_sun);
        Vec3f sky;
        if (d.y < 0) {
            sky = m_ground;
        } else {
            float glow = m_glow_strength * std::pow(std::max(cos_sun, 0.0f), m_glow_exponent);
            sky = lerp(m_horizon, m_zenith, std::sqrt(d.y)) * (1 + glow);
        }
        if (m_sun_up && cos_sun >= m_cos_sun)
            sky += m_sun_radiance;
        return sky;
    }

    EnvironmentSample sample(float u1, float u2) const override
    {
        Vec3f d;
        if (u1 < m_sun_probability) {
            // Uniform in the sun's cone.
            float u = u1 / m_sun_probability;
            float cos_t = 1 - u * (1 - m_cos_sun);
            float sin_t = std::sqrt(std::max(0.0f, 1 - cos_t * cos_t));
            float phi = 2 * pi * u2;
            Vec3f t, b;
            make_basis(m_sun, t, b);
            d = normalize(t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi)) +
                          m_sun * cos_t);
        } else {
            float u = (u1 - m_sun_probability) / (1 - m_sun_probability);
            d = uniform_sphere(std::min(u, 0x1.fffffep-1f), u2);
        }
        return {d, radiance(d), pdf(d)};
    }

    float pdf(const Vec3f& d) const override
    {
        float p = (1 - m_sun_probability) * inv_4pi;
        if (m_sun_up && dot(d, m_sun) >= m_cos_sun)
            p += m_sun_probability / m_sun_solid_angle;
        return p;
    }

    bool black() const override { return m_black; }

private:
    Vec3f m_sun, m_zenith, m_horizon, m_ground, m_sun_radiance;
    float m_glow_strength = 0, m_glow_exponent = 1;
    float m_cos_sun = 1, m_sun_solid_angle = 0, m_sun_probability = 0;
    bool m_sun_up = false, m_black = false;
};

/// A piecewise-constant 1D distribution over [0, 1) with n equal bins.
struct Distribution1D {
    std::vector<float> func;
    std::vector<double> cdf;  // n + 1 entries, cdf[n] = 1 (or uniform when all zero)
    double integral = 0;      // mean of func

    explicit Distribution1D(std::vector<float> f) : func(std::move(f)), cdf(func.size() + 1)
    {
        std::size_t n = func.size();
        for (std::size_t i = 0; i < n; ++i)
            cdf[i + 1] = cdf[i] + func[i] / double(n);
        integral = cdf[n];
        for (std::size_t i = 1; i <= n; ++i)
            cdf[i] = integral > 0 ? cdf[i] / integral : double(i) / double(n);
    }

    /// A continuous value in [0, 1), its bin and the density there.
    float sample(float u, std::size_t& bin, float& density) const
    {
        std::size_t n = func.size();
        auto it = std::upper_bound(cdf.begin(), cdf.end(), double(u));
        std::ptrdiff_t below = std::max<std::ptrdiff_t>(it - cdf.begin() - 1, 0);
        bin = std::min<std::size_t>(static_cast<std::size_t>(below), n - 1);
        double width = cdf[bin + 1] - cdf[bin];
        double t = width > 0 ? (u - cdf[bin]) / width : 0.5;
        density = integral > 0 ? float(func[bin] / integral) : 1.0f;
        double x = (double(bin) + std::clamp(t, 0.0, 1.0)) / double(n);
        return static_cast<float>(std::min(x, 1.0 - 1e-7));
    }

    float density(std::size_t bin) const
    {
        return integral > 0 ? float(func[bin] / integral) : 1.0f;
    }
};

/// Texels are drawn in proportion to luminance times solid angle, and uniformly in solid
/// angle within a texel (uniform in cos(theta) and phi), so the density is constant over
/// each texel and a constant map has exactly the uniform density.
class MapEnvironment final : public Environment {
public:
    MapEnvironment(int width, int height, std::vector<float> rgb)
        : m_width(width), m_height(height), m_rgb(std::move(rgb)),
          m_marginal(std::vector<float>(1))
    {
        m_cos.resize(std::size_t(height) + 1);
        for (int j = 0; j <= height; ++j)
            m_cos[std::size_t(j)] = std::cos(pi * float(j) / float(height));
        m_cos.back() = -1;
        std::vector<float> row_sums(static_cast<std::size_t>(height));
        m_conditional.reserve(std::size_t(height));
        for (int j = 0; j < height; ++j) {
            std::vector<float> f(static_cast<std::size_t>(width));
            for (int i = 0; i < width; ++i)
                f[std::size_t(i)] = std::max(0.0f, luminance(texel(i, j)));
            m_conditional.emplace_back(std::move(f));
            row_sums[std::size_t(j)] =
                static_cast<float>(m_conditional.back().integral) * row_band(j);
        }
        m_marginal = Distribution1D(std::move(row_sums));
        m_black = !(m_marginal.integral > 0);
    }

    Vec3f radiance(const Vec3f& d) const override
    {
        auto [i, j] = texel_of(d);
        return texel(i, j);
    }

    EnvironmentSample sample(float u1, float u2) const override
    {
        std::size_t row = 0, column = 0;
        float pv = 0, pu = 0;
        float v = m_marginal.sample(u1, row, pv);
        float u = m_conditional[row].sample(u2, column, pu);
        float t = std::clamp(v * float(m_height) - float(row), 0.0f, 1.0f);
        float cos_t = m_cos[row] + t * (m_cos[row + 1] - m_cos[row]);
        float sin_t = std::sqrt(std::max(0.0f, 1 - cos_t * cos_t));
        float phi = 2 * pi * u;
        Vec3f d{sin_t * std::sin(phi), cos_t, sin_t * std::cos(phi)};
        return {d, texel(int(column), int(row)), density(int(column), int(row))};
    }

    float pdf(const Vec3f& d) const override
    {
        auto [i, j] = texel_of(d);
        return density(i, j);
    }

    bool black() const override { return m_black; }

private:
    /// The band of cos(theta) that row j covers (its solid angle / 2 pi).
    float row_band(int j) const { return m_cos[std::size_t(j)] - m_cos[std::size_t(j) + 1]; }

    /// Solid-angle density over texel (i, j): P(texel) / its solid angle.
    float density(int i, int j) const
    {
        float band = row_band(j);
        if (band <= 0)
            return 0;
        return m_marginal.density(std::size_t(j)) *
               m_conditional[std::size_t(j)].density(std::size_t(i)) /
               (2 * pi * float(m_height) * band);
    }

    Vec3f texel(int i, int j) const
    {
        const float* p = &m_rgb[(std::size_t(j) * m_width + i) * 3];
        return {p[0], p[1], p[2]};
    }

    std::pair<int, int> texel_of(const Vec3f& d) const
    {
        float theta = std::acos(std::clamp(d.y, -1.0f, 1.0f));
        float phi = std::atan2(d.x, d.z);
        if (phi < 0)
            phi += 2 * pi;
        int i = std::clamp(int(phi / (2 * pi) * m_width), 0, m_width - 1);
        int j = std::clamp(int(theta / pi * m_height), 0, m_height - 1);
        return {i, j};
    }

    int m_width, m_height;
    std::vector<float> m_rgb;
    std::vector<float> m_cos;  // cos(theta) at the row borders, top to bottom
    std::vector<Distribution1D> m_conditional;
    Distribution1D m_marginal;
    bool m_black = true;
};

constexpr std::size_t max_map_texels = std::size_t{1} << 25;

}  // namespace

std::unique_ptr<Environment> make_uniform_environment(const Vec3f& radiance)
{
    return std::make_unique<UniformEnvironment>(radiance);
}

std::unique_ptr<Environment> make_sky_environment(const SkyParameters& parameters)
{
    return std::make_unique<SkyEnvironment>(parameters);
}

std::unique_ptr<Environment> make_map_environment(int width, int height, std::vector<float> rgb)
{
    if (width <= 0 || height <= 0 || std::size_t(width) * std::size_t(height) > max_map_texels)
        throw Error("environment map: size " + std::to_string(width) + "x" +
                    std::to_string(height) + " is empty or larger than 2^25 texels");
    if (rgb.size() != std::size_t(width) * std::size_t(height) * 3)
        throw Error("environment map: " + std::to_string(rgb.size()) + " values for " +
                    std::to_string(width) + "x" + std::to_string(height) + " RGB texels");
    for (float& v : rgb)
        if (!std::isfinite(v) || v < 0)
            v = 0;  // NaN, inf or negative texels would poison the sampling tables
    return std::make_unique<MapEnvironment>(width, height, std::move(rgb));
}

std::unique_ptr<Environment> make_map_environment(const std::filesystem::path& file, float scale)
{
    auto in = OIIO::ImageInput::open(file.string());
    if (!in)
        throw Error(file.string() + ": cannot read the environment map: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    int w = spec.width, h = spec.height, channels = spec.nchannels;
    if (w <= 0 || h <= 0 || std::size_t(w) * std::size_t(h) > max_map_texels || channels <= 0)
        throw Error(file.string() + ": environment map of " + std::to_string(w) + "x" +
                    std::to_string(h) + " texels is empty or larger than 2^25 texels");
    std::vector<float> pixels(std::size_t(w) * h * channels);
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
        throw Error(file.string() + ": cannot read the environment map: " + in->geterror());
    std::vector<float> rgb(std::size_t(w) * h * 3);
    for (std::size_t p = 0; p < std::size_t(w) * h; ++p)
        for (int c = 0; c < 3; ++c)
            rgb[p * 3 + c] = pixels[p * channels + (channels >= 3 ? c : 0)] * scale;
    return make_map_environment(w, h, std::move(rgb));
}

}  // namespace cambium::render
