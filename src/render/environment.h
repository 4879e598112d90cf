// SPDX-License-Identifier: Apache-2.0
// What rays that leave the scene see: a uniform ambient, an analytic sky, an HDR map.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <utility>
#include <variant>
#include <vector>

#include "render/vecf.h"

namespace cambium::render {

/// A direction sampled from an environment, with its radiance and solid-angle pdf.
struct EnvironmentSample {
    Vec3f direction;  ///< unit, pointing away from the scene
    Vec3f radiance;   ///< linear
    float pdf = 0;    ///< per steradian
};

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

/// The kinds of environment, each a plain value with radiance, sample and pdf in its own
/// frame (Environment turns them). They are spelled out here so that Environment can hold
/// them in a std::variant; use them through Environment.
namespace environment_kind {

/// The same radiance from every direction (the stand-in for cpfg's ambient term),
/// sampled uniformly over the sphere.
struct Uniform {
    Vec3f value;
    Vec3f radiance(const Vec3f&) const { return value; }
    EnvironmentSample sample(float u1, float u2) const;
    float pdf(const Vec3f&) const;
    bool black() const { return !(value.x > 0 || value.y > 0 || value.z > 0); }
};

/// A piecewise-constant 1D distribution over [0, 1) with n equal bins.
struct Distribution1D {
    std::vector<float> func;
    std::vector<double> cdf;  ///< n + 1 entries, cdf[n] = 1 (or uniform when all zero)
    double integral = 0;      ///< mean of func

    explicit Distribution1D(std::vector<float> f);
    /// A continuous value in [0, 1), its bin and the density there.
    float sample(float u, std::size_t& bin, float& density) const;
    float density(std::size_t bin) const;
};

/// A piecewise-constant density over directions on a latitude-longitude grid of
/// `width` x `height` cells: cell (i, j) covers the polar band pi j / height .. pi (j + 1)
/// / height from +y and the azimuth 2 pi i / width .. 2 pi (i + 1) / width, the direction
/// of azimuth phi and polar angle t being (-sin t sin phi, cos t, sin t cos phi): phi 0
/// along +z, pi along -z, a quarter turn along -x (a lat-long image seen from inside,
/// unmirrored, as Blender and Mitsuba 3 read one: README, "Staging a still"). A cell is
/// drawn with probability in proportion to its weight times its solid angle (marginal
/// and conditional CDFs), and uniformly in solid angle within it, so the density is
/// constant over each cell. The one direction sampler of maps and of the sky's dome.
class LatLongTable {
public:
    LatLongTable() = default;
    /// `weight`: width x height values, rows top (+y) to bottom; negative or non-finite
    /// ones count as 0. All 0: the table is empty and its density 0 everywhere.
    LatLongTable(int width, int height, const std::vector<float>& weight);
    /// A direction, its density (per steradian) and its cell; pdf 0 when empty.
    Vec3f sample(float u1, float u2, float& pdf, int& i, int& j) const;
    float pdf(const Vec3f& d) const
    {
        auto [i, j] = cell_of(d);
        return density(i, j);
    }
    /// The cell that holds d.
    std::pair<int, int> cell_of(const Vec3f& d) const;
    /// The density over cell (i, j).
    float density(int i, int j) const;
    /// The weights' integral over the sphere (weight times solid angle, summed).
    double integral() const { return m_integral; }
    bool empty() const { return !(m_integral > 0); }
    /// The direction at azimuth fraction u (of a turn from +z, through -x) and
    /// cos(polar angle from +y) c.
    static Vec3f direction(float u, float c);

private:
    float row_band(int j) const;

    int m_width = 0, m_height = 0;
    std::vector<float> m_cos;  ///< cos(theta) at the row borders, top to bottom
    std::vector<Distribution1D> m_conditional;
    std::vector<Distribution1D> m_marginal;  ///< one, or none while empty
    double m_integral = 0;
};

/// Preetham's sky with the sun disk, sampled by two strategies, one chosen per sample: the
/// sun's cone (when the sun is up) with probability in proportion to the sun's share of
/// the sky's luminous power, kept within [1/4, 3/4], else the dome (and the ground's
/// radiance below the horizon) tabulated as a LatLongTable of 128 x 64 cells by their
/// mean luminance. pdf() is that mixture, so MIS against BSDF sampling stays exact. (The
/// light set samples the two as separate lights: sun_disk() and sample_without_sun().)
class Sky {
public:
    explicit Sky(const SkyParameters& parameters);
    Vec3f radiance(const Vec3f& d) const;
    EnvironmentSample sample(float u1, float u2) const;
    float pdf(const Vec3f& d) const;
    bool black() const { return m_black; }
    /// From now on sample nothing below the horizon (an opaque ground hides it).
    void hide_below_horizon() { tabulate(true); }
    /// The probability of the sun's strategy (0 when the sun is down).
    float sun_probability() const { return m_sun_probability; }
    /// The sky without its sun disk: the dome, and the ground's radiance below the
    /// horizon (what another renderer's map holds when it gets the sun as a lamp).
    Vec3f without_sun(const Vec3f& d) const { return d.y < 0 ? m_ground : dome(d); }
    /// The sun disk: unit direction toward it, its solid angle and its radiance, constant
    /// over the disk (0 when the sun is down), and the cosine of its angular radius.
    struct SunDisk {
        Vec3f direction;
        float solid_angle = 0;
        Vec3f radiance;
        float cos_radius = 1;
    };
    SunDisk sun_disk() const { return {m_sun, m_sun_solid_angle, m_sun_radiance, m_cos_sun}; }
    /// Whether the sun disk is up (it has radiance).
    bool sun_up() const { return m_sun_up; }
    /// The dome's strategy alone (the table, no sun): sampling and density of
    /// without_sun(), for a light set that samples the sun apart.
    EnvironmentSample sample_without_sun(float u1, float u2) const;
    float pdf_without_sun(const Vec3f& d) const { return m_table.pdf(d); }
    /// The same for a surface facing straight up (the ground): the dome drawn by its
    /// luminance times the cosine to +y, so that open ground's light from the dome hardly
    /// varies from sample to sample; nothing below the horizon.
    EnvironmentSample sample_without_sun_facing_up(float u1, float u2) const;
    float pdf_without_sun_facing_up(const Vec3f& d) const { return m_up_table.pdf(d); }

private:
    /// The Perez luminance distribution's five coefficients.
    struct Perez {
        float a, b, c, d, e;
        float operator()(float cos_theta, float gamma, float cos_gamma) const;
    };
    Vec3f dome(const Vec3f& d) const;
    Vec3f dome_irradiance() const;
    /// Fills m_table and m_sun_probability (hidden: rows below the horizon weigh 0).
    void tabulate(bool hidden);

    LatLongTable m_table;
    LatLongTable m_up_table;  ///< the dome by luminance times the cosine to +y

    Vec3f m_sun, m_sun_dome, m_ground, m_sun_radiance;
    Perez m_Y{}, m_x{}, m_y{};
    float m_theta_s = 0, m_zenith_Y = 0, m_zenith_x = 0, m_zenith_y = 0;
    float m_norm_Y = 1, m_norm_x = 1, m_norm_y = 1;
    float m_cos_sun = 1, m_sun_solid_angle = 0, m_sun_probability = 0;
    bool m_sun_up = false, m_black = false;
};

/// A latitude-longitude map (make_map_environment): a texel per LatLongTable cell, drawn
/// in proportion to luminance times solid angle and uniformly in solid angle within one.
/// Copies share the texels (a copy that hides the lower hemisphere has its own table).
class Map {
public:
    Map(int width, int height, std::vector<float> rgb);
    Vec3f radiance(const Vec3f& d) const;
    EnvironmentSample sample(float u1, float u2) const;
    float pdf(const Vec3f& d) const { return m_table.pdf(d); }
    bool black() const { return m_black; }
    /// Whether every texel has the same colour.
    bool constant() const { return m_constant; }
    /// From now on sample nothing below the horizon (an opaque ground hides it): rows
    /// wholly below it weigh 0. A second table then draws texels for a surface facing
    /// straight up (the ground), by luminance times the cosine to +y.
    void hide_below_horizon() { tabulate(true); }
    /// Whether the table for a surface facing up is made (hide_below_horizon); the two
    /// below then sample and give the density of the map drawn by it.
    bool samples_facing_up() const { return !m_up_table.empty(); }
    EnvironmentSample sample_facing_up(float u1, float u2) const;
    float pdf_facing_up(const Vec3f& d) const { return m_up_table.pdf(d); }

private:
    Vec3f texel(int i, int j) const;
    /// A texel drawn by `table`, with its direction and density.
    EnvironmentSample sample_by(const LatLongTable& table, float u1, float u2) const;
    void tabulate(bool hidden);

    int m_width, m_height;
    std::shared_ptr<const std::vector<float>> m_rgb;
    LatLongTable m_table;
    LatLongTable m_up_table;  ///< by luminance times the cosine to +y; empty until hidden
    bool m_black = true, m_constant = false;
};

}  // namespace environment_kind

/// Radiance arriving from infinitely far away, by direction: one of a closed set of kinds
/// (uniform, sky, map) dispatched by switch, as the lights are (LightSet), turned about the
/// world up axis +y by a stored angle. A value, safe to read from many threads. The
/// integrator samples it for next-event estimation through LightSet (sample, pdf) and
/// weights that against BSDF sampling (multiple importance sampling).
class Environment {
public:
    enum class Kind : std::uint8_t { uniform, sky, map };  ///< in the variant's order

    /// Radiance along `direction` (unit, pointing away from the scene).
    Vec3f radiance(const Vec3f& direction) const;
    /// A direction drawn in proportion to (roughly) radiance, from two uniform numbers.
    EnvironmentSample sample(float u1, float u2) const;
    /// The solid-angle density sample() draws `direction` with.
    float pdf(const Vec3f& direction) const;
    /// Whether the environment is black everywhere (the integrator skips it).
    bool black() const;
    /// Whether radiance is the same from every direction (a uniform environment or a
    /// constant map): BSDF sampling alone is then perfect (exactly, for a Lambertian
    /// surface), so the integrator does not sample it for next-event estimation.
    bool uniform() const;
    Kind kind() const { return static_cast<Kind>(m_kind.index()); }

    /// This environment turned by `degrees` more about +y (right-handed: +90 takes what
    /// was seen along +z to +x). Radiance, sampling and pdf all follow the turn exactly.
    /// Throws cambium::Error for a non-finite angle.
    Environment rotated(float degrees) const&;
    Environment rotated(float degrees) &&;
    /// The whole turn about +y, in degrees.
    double rotation_degrees() const { return m_degrees; }
    /// A copy whose sampling spends nothing below the horizon (y < 0), for scenes where an
    /// opaque ground plane hides it from every shading point: radiance is the same, and
    /// sample() and pdf() leave the lower hemisphere to BSDF sampling (pdf 0 there, so
    /// a BSDF ray that finds it takes full weight). A uniform environment is unchanged
    /// (it is never sampled for next-event estimation). Shares a map's texels.
    Environment hidden_below_horizon() const;
    /// The sky this environment is, unturned (nullptr for other kinds); with
    /// rotation_degrees() about +y it is what radiance() returns.
    const environment_kind::Sky* sky() const { return std::get_if<environment_kind::Sky>(&m_kind); }

    /// The sky's sun disk as the world sees it (turned), when this is a sky whose sun is
    /// up; nullopt otherwise. radiance() is radiance_without_sun() plus the disk's
    /// radiance within it.
    std::optional<environment_kind::Sky::SunDisk> sun() const;
    /// Everything but the sun disk: a sky's dome and ground (radiance, its table's
    /// sampling and density, with nothing of the sun's strategy); for any other kind the
    /// same as radiance(), sample() and pdf(). For a light set that samples the sun as a
    /// light of its own.
    Vec3f radiance_without_sun(const Vec3f& direction) const;
    EnvironmentSample sample_without_sun(float u1, float u2) const;
    float pdf_without_sun(const Vec3f& direction) const;
    /// Whether a surface facing straight up has a sampling of its own (a sky's dome:
    /// Sky::sample_without_sun_facing_up; a map under an opaque ground:
    /// Map::sample_facing_up); the two below then use it.
    bool samples_facing_up() const;
    EnvironmentSample sample_without_sun_facing_up(float u1, float u2) const;
    float pdf_without_sun_facing_up(const Vec3f& direction) const;

private:
    using Kinds = std::variant<environment_kind::Uniform, environment_kind::Sky,
                               environment_kind::Map>;
    friend Environment make_uniform_environment(const Vec3f& radiance);
    friend Environment make_sky_environment(const SkyParameters& parameters);
    friend Environment make_map_environment(int width, int height, std::vector<float> rgb);
    explicit Environment(Kinds kind) : m_kind(std::move(kind)) {}
    void turn_by(float degrees);
    Vec3f turn(const Vec3f& d) const;
    Vec3f unturn(const Vec3f& d) const;

    Kinds m_kind;
    double m_degrees = 0;
    bool m_turned = false;  ///< directions go through turn / unturn (m_degrees != 0)
    float m_cos = 1, m_sin = 0;
};

/// The same radiance from every direction (the stand-in for cpfg's ambient term).
Environment make_uniform_environment(const Vec3f& radiance);

/// Preetham's daylight sky and sun.
Environment make_sky_environment(const SkyParameters& parameters = {});

/// A latitude-longitude HDR map (EXR, HDR or anything OpenImageIO reads), linear RGB,
/// times `scale`. Texel coordinates (u, v) in [0, 1)^2, v down from the top row, look
/// along (-sin t sin p, cos t, sin t cos p) with t = pi v, p = 2 pi u: row 0 is straight
/// up (+y), the centre column is seen looking along -z (behind the plant in cpfg's
/// default view), the column a quarter in from the left looking along -x, the one a
/// quarter in from the right along +x: the image as seen from inside the sphere,
/// unmirrored, the convention of Blender's and Mitsuba 3's lat-long maps
/// (README, "Staging a still"). Radiance is constant over a texel (nearest lookup). Texels are
/// sampled through a LatLongTable of their luminance. Throws cambium::Error naming the file when it
/// cannot be read or is larger than 2^25 texels.
Environment make_map_environment(const std::filesystem::path& file, float scale = 1);

/// The same from texels in memory (rows top to bottom, 3 floats each): tests, generated
/// maps. Non-finite and negative texels count as 0.
Environment make_map_environment(int width, int height, std::vector<float> rgb);

}  // namespace cambium::render
