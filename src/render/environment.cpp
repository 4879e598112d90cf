// SPDX-License-Identifier: Apache-2.0
// Environments: uniform ambient, an analytic sun-and-sky, a lat-long HDR map.
//
// sky: Preetham, Shirley & Smits, "A Practical Analytic Model for Daylight" (SIGGRAPH 1999).
// With up = +y, theta the angle of a direction from the zenith and gamma its angle to the
// sun (theta_s for the sun), each of Y (luminance, kcd/m^2) and the chromaticities x, y is
//   value = zenith value * F(theta, gamma) / F(0, theta_s),
//   F = (1 + A exp(B / cos theta)) (1 + C exp(D gamma) + E cos^2 gamma),
// with A..E linear in the turbidity T (the paper's appendix), zenith Y from
// chi = (4/9 - T/120)(pi - 2 theta_s): Y_z = (4.0453 T - 4.9710) tan chi - 0.2155 T + 2.4192,
// zenith x, y cubic in theta_s and quadratic in T. xyY -> XYZ -> linear sRGB (D65).
// - Units: 1 unit of radiance is 128 000 / pi cd/m^2 (the sun's 128 klux outside the
//   atmosphere give irradiance pi, the view-file light convention); the dome is scaled
//   by sky_intensity, the sun by sun_intensity (both 1: their physical ratio).
// - sun: a disk of angular radius 0.2665 deg whose radiance outside the atmosphere gives
//   irradiance pi * sun_intensity, attenuated per channel by exp(-m (tau_R + tau_A)):
//   Rayleigh tau_R = 0.008735 lambda^-4.08 and Angstrom aerosol tau_A = beta lambda^-1.3,
//   beta = 0.04608 T - 0.04586 (the paper's appendix), lambda = 0.65 / 0.55 / 0.45 um for
//   R / G / B, m the relative air mass (Kasten & Young 1989).
// - Sun below the horizon: no disk; the dome is the theta_s = 90 deg one fading linearly
//   to black at 6 deg below (civil twilight), a documented approximation.
// - ground (y < 0): ground_albedo / pi times the irradiance of sun and dome on a
//   horizontal plane (the dome's integrated once, numerically).
// Sampling: the sun's cone with probability in proportion to its share of the luminous
// power (within [1/4, 3/4]; when the sun is up), else the dome tabulated by luminance
// (LatLongTable, the maps' sampler); pdf() is that mixture, so MIS weights are exact.
// Next-event estimation (LightSet) takes the two apart instead: the sun's disk as a light
// of its own, the dome through sample_without_sun() and pdf_without_sun().
#include "render/environment.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "base/diagnostics.h"
#include "render/image_codec.h"

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

Vec3f exp(const Vec3f& v) { return {std::exp(v.x), std::exp(v.y), std::exp(v.z)}; }

/// Linear sRGB (D65) of CIE xyY.
Vec3f xyY_to_rgb(float x, float y, float Y)
{
    if (!(y > 0))
        return {};
    float X = x * Y / y, Z = (1 - x - y) * Y / y;
    return {std::max(0.0f, 3.2406f * X - 1.5372f * Y - 0.4986f * Z),
            std::max(0.0f, -0.9689f * X + 1.8758f * Y + 0.0415f * Z),
            std::max(0.0f, 0.0557f * X - 0.2040f * Y + 1.0570f * Z)};
}

/// Rayleigh and Angstrom aerosol transmittance for R, G, B (0.65, 0.55, 0.45 um).
Vec3f sun_transmittance(float turbidity, float cos_zenith)
{
    float zenith_deg = std::acos(std::clamp(cos_zenith, 0.0f, 1.0f)) * 180 / pi;
    float airmass = 1 / (std::max(cos_zenith, 0.0f) +
                         0.50572f * std::pow(96.07995f - zenith_deg, -1.6364f));
    float beta = 0.04608f * turbidity - 0.04586f;
    auto tau = [&](float um) {
        return 0.008735f * std::pow(um, -4.08f) + beta * std::pow(um, -1.3f);
    };
    return exp(Vec3f(tau(0.65f), tau(0.55f), tau(0.45f)) * -airmass);
}

constexpr std::size_t max_map_texels = std::size_t{1} << 25;

}  // namespace

namespace environment_kind {

// ---- Uniform --------------------------------------------------------------------------

EnvironmentSample Uniform::sample(float u1, float u2) const
{
    return {uniform_sphere(u1, u2), value, inv_4pi};
}

float Uniform::pdf(const Vec3f&) const { return inv_4pi; }

// ---- Sky ------------------------------------------------------------------------------

float Sky::Perez::operator()(float cos_theta, float gamma, float cos_gamma) const
{
    return (1 + a * std::exp(b / std::max(cos_theta, 1e-3f))) *
           (1 + c * std::exp(d * gamma) + e * cos_gamma * cos_gamma);
}

Sky::Sky(const SkyParameters& p)
{
    m_sun = normalize(p.sun_direction);
    if (length(m_sun) == 0)
        m_sun = {0, 1, 0};
    const float t = std::clamp(p.turbidity, sky_min_turbidity, sky_max_turbidity);
    // Below the horizon the dome is the sunset one, fading out by -6 degrees.
    float elevation = std::asin(std::clamp(m_sun.y, -1.0f, 1.0f));
    float fade = std::clamp(1 + elevation / (6 * pi / 180), 0.0f, 1.0f);
    m_theta_s = std::min(pi / 2 - elevation, pi / 2);
    m_sun_dome = m_sun.y >= 0 ? m_sun : normalize(Vec3f(m_sun.x, 0, m_sun.z));
    if (length(m_sun_dome) == 0)
        m_sun_dome = {0, 1, 0};

    m_Y = {0.1787f * t - 1.4630f, -0.3554f * t + 0.4275f, -0.0227f * t + 5.3251f,
           0.1206f * t - 2.5771f, -0.0670f * t + 0.3703f};
    m_x = {-0.0193f * t - 0.2592f, -0.0665f * t + 0.0008f, -0.0004f * t + 0.2125f,
           -0.0641f * t - 0.8989f, -0.0033f * t + 0.0452f};
    m_y = {-0.0167f * t - 0.2608f, -0.0950f * t + 0.0092f, -0.0079f * t + 0.2102f,
           -0.0441f * t - 1.6537f, -0.0109f * t + 0.0529f};
    float chi = (4.0f / 9 - t / 120) * (pi - 2 * m_theta_s);
    float zenith_Y = std::max(0.0f, (4.0453f * t - 4.9710f) * std::tan(chi) - 0.2155f * t +
                                        2.4192f);  // kcd/m^2
    float th = m_theta_s, th2 = th * th, th3 = th2 * th, t2 = t * t;
    m_zenith_x = (0.00166f * th3 - 0.00375f * th2 + 0.00209f * th) * t2 +
                 (-0.02903f * th3 + 0.06377f * th2 - 0.03202f * th + 0.00394f) * t +
                 (0.11693f * th3 - 0.21196f * th2 + 0.06052f * th + 0.25886f);
    m_zenith_y = (0.00275f * th3 - 0.00610f * th2 + 0.00317f * th) * t2 +
                 (-0.04214f * th3 + 0.08970f * th2 - 0.04153f * th + 0.00516f) * t +
                 (0.15346f * th3 - 0.26756f * th2 + 0.06670f * th + 0.26688f);
    m_zenith_Y = zenith_Y * 1000 / sky_luminance_unit * std::max(p.sky_intensity, 0.0f) * fade;
    m_norm_Y = m_Y(1, m_theta_s, std::cos(m_theta_s));
    m_norm_x = m_x(1, m_theta_s, std::cos(m_theta_s));
    m_norm_y = m_y(1, m_theta_s, std::cos(m_theta_s));

    // The sun outside the atmosphere gives pi * sun_intensity; the air dims it.
    m_cos_sun = std::cos(0.2665f * pi / 180);
    m_sun_solid_angle = 2 * pi * (1 - m_cos_sun);
    m_sun_up = m_sun.y > 0 && p.sun_intensity > 0;
    Vec3f colour = sun_transmittance(t, m_sun.y);
    m_sun_radiance = m_sun_up ? colour * (pi * p.sun_intensity / m_sun_solid_angle) : Vec3f();
    Vec3f sun_irradiance = m_sun_up ? colour * (pi * p.sun_intensity * m_sun.y) : Vec3f();
    m_ground = p.ground_albedo * (sun_irradiance + dome_irradiance()) * (1 / pi);
    m_black = !(m_zenith_Y > 0) && !m_sun_up;
    tabulate(false);
}

void Sky::tabulate(bool hidden)
{
    // The dome's mean luminance over each cell (a 3 x 3 grid of directions uniform in
    // solid angle), the ground's below the horizon: the table's density follows the
    // dome to within its variation over a cell (2.8 x 2.8 degrees).
    constexpr int width = 128, height = 64, sub = 3;
    std::vector<float> weight(std::size_t(width) * height), up(weight.size());
    const float ground = luminance(m_ground);
    for (int j = 0; j < height; ++j) {
        const float c0 = std::cos(pi * float(j) / height), c1 = std::cos(pi * float(j + 1) / height);
        for (int i = 0; i < width; ++i) {
            float sum = 0, up_sum = 0;
            for (int a = 0; a < sub; ++a)
                for (int b = 0; b < sub; ++b) {
                    float c = c0 + (c1 - c0) * (a + 0.5f) / sub;
                    Vec3f d = LatLongTable::direction((i + (b + 0.5f) / sub) / width, c);
                    const float l = d.y < 0 ? ground : luminance(dome(d));
                    sum += l;
                    up_sum += l * std::max(d.y, 0.0f);
                }
            bool below = j >= height / 2;
            const std::size_t at = std::size_t(j) * width + std::size_t(i);
            weight[at] = hidden && below ? 0.0f : sum / (sub * sub);
            up[at] = below ? 0.0f : up_sum / (sub * sub);
        }
    }
    m_table = LatLongTable(width, height, weight);
    m_up_table = LatLongTable(width, height, up);
    // The sun's strategy by its share of the luminous power, within [1/4, 3/4]: each
    // strategy keeps enough samples for the points the other serves badly (the plant's
    // shadow on the ground, where the sun's samples are all blocked).
    const double sun_power = m_sun_up ? double(luminance(m_sun_radiance)) * m_sun_solid_angle : 0;
    const double total = sun_power + m_table.integral();
    if (!m_sun_up)
        m_sun_probability = 0;
    else if (m_table.empty())
        m_sun_probability = 1;
    else
        m_sun_probability = float(std::clamp(sun_power / total, 0.25, 0.75));
}

Vec3f Sky::radiance(const Vec3f& d) const
{
    float cos_sun = dot(d, m_sun);
    Vec3f sky = d.y < 0 ? m_ground : dome(d);
    if (m_sun_up && cos_sun >= m_cos_sun)
        sky += m_sun_radiance;
    return sky;
}

EnvironmentSample Sky::sample(float u1, float u2) const
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
        d = normalize(t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi)) + m_sun * cos_t);
    } else {
        if (m_table.empty())
            return {};
        float u = (u1 - m_sun_probability) / (1 - m_sun_probability);
        float density = 0;
        int i = 0, j = 0;
        d = m_table.sample(std::min(u, 0x1.fffffep-1f), u2, density, i, j);
    }
    return {d, radiance(d), pdf(d)};
}

EnvironmentSample Sky::sample_without_sun(float u1, float u2) const
{
    if (m_table.empty())
        return {};
    float density = 0;
    int i = 0, j = 0;
    Vec3f d = m_table.sample(u1, u2, density, i, j);
    if (!(density > 0))
        return {};
    return {d, without_sun(d), density};
}

float Sky::pdf(const Vec3f& d) const
{
    float p = m_sun_probability < 1 ? (1 - m_sun_probability) * m_table.pdf(d) : 0.0f;
    if (m_sun_up && dot(d, m_sun) >= m_cos_sun)
        p += m_sun_probability / m_sun_solid_angle;
    return p;
}

/// Preetham's dome along d (d.y >= 0), without the sun disk.
Vec3f Sky::dome(const Vec3f& d) const
{
    if (!(m_zenith_Y > 0))
        return {};
    float cos_gamma = std::clamp(dot(d, m_sun_dome), -1.0f, 1.0f);
    float gamma = std::acos(cos_gamma);
    float Y = m_zenith_Y * m_Y(d.y, gamma, cos_gamma) / m_norm_Y;
    float x = m_zenith_x * m_x(d.y, gamma, cos_gamma) / m_norm_x;
    float y = m_zenith_y * m_y(d.y, gamma, cos_gamma) / m_norm_y;
    return xyY_to_rgb(x, y, std::max(Y, 0.0f));
}

/// The dome's irradiance on a horizontal plane: a midpoint rule in (cos theta, phi).
Vec3f Sky::dome_irradiance() const
{
    constexpr int n_cos = 32, n_phi = 64;
    Vec3f sum;
    for (int i = 0; i < n_cos; ++i) {
        float c = (i + 0.5f) / n_cos, s = std::sqrt(1 - c * c);
        for (int j = 0; j < n_phi; ++j) {
            float phi = 2 * pi * (j + 0.5f) / n_phi;
            sum += dome({s * std::cos(phi), c, s * std::sin(phi)}) * c;
        }
    }
    return sum * (2 * pi / (n_cos * n_phi));
}

// ---- Map ------------------------------------------------------------------------------

Distribution1D::Distribution1D(std::vector<float> f) : func(std::move(f)), cdf(func.size() + 1)
{
    std::size_t n = func.size();
    for (std::size_t i = 0; i < n; ++i)
        cdf[i + 1] = cdf[i] + func[i] / double(n);
    integral = cdf[n];
    for (std::size_t i = 1; i <= n; ++i)
        cdf[i] = integral > 0 ? cdf[i] / integral : double(i) / double(n);
}

float Distribution1D::sample(float u, std::size_t& bin, float& density) const
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

float Distribution1D::density(std::size_t bin) const
{
    return integral > 0 ? float(func[bin] / integral) : 1.0f;
}

LatLongTable::LatLongTable(int width, int height, const std::vector<float>& weight)
    : m_width(width), m_height(height)
{
    m_cos.resize(std::size_t(height) + 1);
    for (int j = 0; j <= height; ++j)
        m_cos[std::size_t(j)] = std::cos(pi * float(j) / float(height));
    m_cos.back() = -1;
    std::vector<float> row_sums(static_cast<std::size_t>(height));
    m_conditional.reserve(std::size_t(height));
    for (int j = 0; j < height; ++j) {
        std::vector<float> f(static_cast<std::size_t>(width));
        for (int i = 0; i < width; ++i) {
            float w = weight[std::size_t(j) * std::size_t(width) + std::size_t(i)];
            f[std::size_t(i)] = std::isfinite(w) ? std::max(0.0f, w) : 0.0f;
        }
        m_conditional.emplace_back(std::move(f));
        row_sums[std::size_t(j)] = static_cast<float>(m_conditional.back().integral) * row_band(j);
    }
    Distribution1D marginal(std::move(row_sums));
    // The marginal's mean is that of each row's mean weight times its cos band:
    // times 2 pi for a row's solid angle, times the rows for the sum.
    m_integral = marginal.integral * 2 * double(pi) * double(height);
    if (m_integral > 0)
        m_marginal.push_back(std::move(marginal));
}

/// The direction at azimuth fraction u (of a full turn from +z, through -x) and
/// cos(polar angle from +y) c.
Vec3f LatLongTable::direction(float u, float c)
{
    float s = std::sqrt(std::max(0.0f, 1 - c * c));
    float phi = 2 * pi * u;
    return {-s * std::sin(phi), c, s * std::cos(phi)};
}

Vec3f LatLongTable::sample(float u1, float u2, float& pdf, int& i, int& j) const
{
    if (m_marginal.empty()) {
        pdf = 0;
        i = j = 0;
        return {0, 1, 0};
    }
    std::size_t row = 0, column = 0;
    float pv = 0, pu = 0;
    float v = m_marginal.front().sample(u1, row, pv);
    float u = m_conditional[row].sample(u2, column, pu);
    float t = std::clamp(v * float(m_height) - float(row), 0.0f, 1.0f);
    float cos_t = m_cos[row] + t * (m_cos[row + 1] - m_cos[row]);
    i = int(column);
    j = int(row);
    pdf = density(i, j);
    return direction(u, cos_t);
}

/// The band of cos(theta) that row j covers (its solid angle / 2 pi).
float LatLongTable::row_band(int j) const
{
    return m_cos[std::size_t(j)] - m_cos[std::size_t(j) + 1];
}

/// Solid-angle density over cell (i, j): P(cell) / its solid angle.
float LatLongTable::density(int i, int j) const
{
    float band = row_band(j);
    if (band <= 0 || m_marginal.empty())
        return 0;
    return m_marginal.front().density(std::size_t(j)) *
           m_conditional[std::size_t(j)].density(std::size_t(i)) /
           (2 * pi * float(m_height) * band);
}

std::pair<int, int> LatLongTable::cell_of(const Vec3f& d) const
{
    float theta = std::acos(std::clamp(d.y, -1.0f, 1.0f));
    float phi = std::atan2(-d.x, d.z);
    if (phi < 0)
        phi += 2 * pi;
    int i = std::clamp(int(phi / (2 * pi) * float(m_width)), 0, m_width - 1);
    int j = std::clamp(int(theta / pi * float(m_height)), 0, m_height - 1);
    return {i, j};
}

Map::Map(int width, int height, std::vector<float> rgb)
    : m_width(width), m_height(height),
      m_rgb(std::make_shared<const std::vector<float>>(std::move(rgb)))
{
    tabulate(false);
    m_black = m_table.empty();
    // Each texel equal to the one before it (values three floats apart).
    m_constant = std::equal(m_rgb->begin() + 3, m_rgb->end(), m_rgb->begin());
}

namespace {

/// The mean of max(0, cos theta) over a band of cos theta from c1 up to c0, uniform in
/// solid angle as cos theta is.
float mean_cos_above_horizon(float c0, float c1)
{
    if (c1 >= 0)
        return 0.5f * (c0 + c1);
    if (c0 <= 0)
        return 0;
    return 0.5f * c0 * c0 / (c0 - c1);
}

}  // namespace

void Map::tabulate(bool hidden)
{
    std::vector<float> weight(std::size_t(m_width) * std::size_t(m_height)), up;
    if (hidden)
        up.resize(weight.size());
    for (int j = 0; j < m_height; ++j) {
        const float c0 = std::cos(pi * float(j) / float(m_height));
        const float c1 = std::cos(pi * float(j + 1) / float(m_height));
        // A row whose top border is at or below the horizon lies wholly below it.
        const bool below = hidden && c0 <= 0;
        const float cos_up = mean_cos_above_horizon(c0, c1);
        for (int i = 0; i < m_width; ++i) {
            const std::size_t at = std::size_t(j) * std::size_t(m_width) + std::size_t(i);
            const float l = std::max(0.0f, luminance(texel(i, j)));
            weight[at] = below ? 0.0f : l;
            if (hidden)
                up[at] = l * cos_up;
        }
    }
    m_table = LatLongTable(m_width, m_height, weight);
    // Only under an opaque ground is a surface seen facing straight up (the table costs
    // as much memory as the map's own).
    if (hidden)
        m_up_table = LatLongTable(m_width, m_height, up);
}

Vec3f Map::radiance(const Vec3f& d) const
{
    auto [i, j] = m_table.cell_of(d);
    return texel(i, j);
}

EnvironmentSample Map::sample(float u1, float u2) const { return sample_by(m_table, u1, u2); }

EnvironmentSample Map::sample_facing_up(float u1, float u2) const
{
    return sample_by(m_up_table, u1, u2);
}

EnvironmentSample Map::sample_by(const LatLongTable& table, float u1, float u2) const
{
    float density = 0;
    int i = 0, j = 0;
    Vec3f d = table.sample(u1, u2, density, i, j);
    if (!(density > 0))
        return {};
    return {d, texel(i, j), density};
}

Vec3f Map::texel(int i, int j) const
{
    const float* p = &(*m_rgb)[(std::size_t(j) * std::size_t(m_width) + std::size_t(i)) * 3];
    return {p[0], p[1], p[2]};
}

}  // namespace environment_kind

// ---- Environment: the closed set, turned ----------------------------------------------

Vec3f Environment::radiance(const Vec3f& direction) const
{
    const Vec3f d = m_turned ? unturn(direction) : direction;
    return std::visit([&](const auto& kind) { return kind.radiance(d); }, m_kind);
}

EnvironmentSample Environment::sample(float u1, float u2) const
{
    EnvironmentSample s = std::visit([&](const auto& kind) { return kind.sample(u1, u2); }, m_kind);
    if (m_turned)
        s.direction = turn(s.direction);
    return s;
}

float Environment::pdf(const Vec3f& direction) const
{
    const Vec3f d = m_turned ? unturn(direction) : direction;
    return std::visit([&](const auto& kind) { return kind.pdf(d); }, m_kind);
}

bool Environment::black() const
{
    return std::visit([](const auto& kind) { return kind.black(); }, m_kind);
}

bool Environment::uniform() const
{
    switch (kind()) {
    case Kind::uniform: return true;
    case Kind::sky: return false;
    case Kind::map: return std::get<environment_kind::Map>(m_kind).constant();
    }
    return false;
}

std::optional<environment_kind::Sky::SunDisk> Environment::sun() const
{
    const environment_kind::Sky* s = sky();
    if (!s || !s->sun_up())
        return std::nullopt;
    environment_kind::Sky::SunDisk disk = s->sun_disk();
    if (m_turned)
        disk.direction = turn(disk.direction);
    return disk;
}

Vec3f Environment::radiance_without_sun(const Vec3f& direction) const
{
    const environment_kind::Sky* s = sky();
    if (!s)
        return radiance(direction);
    return s->without_sun(m_turned ? unturn(direction) : direction);
}

EnvironmentSample Environment::sample_without_sun(float u1, float u2) const
{
    const environment_kind::Sky* s = sky();
    if (!s)
        return sample(u1, u2);
    EnvironmentSample e = s->sample_without_sun(u1, u2);
    if (m_turned)
        e.direction = turn(e.direction);
    return e;
}

EnvironmentSample environment_kind::Sky::sample_without_sun_facing_up(float u1, float u2) const
{
    if (m_up_table.empty())
        return {};
    float density = 0;
    int i = 0, j = 0;
    Vec3f d = m_up_table.sample(u1, u2, density, i, j);
    if (!(density > 0))
        return {};
    return {d, without_sun(d), density};
}

bool Environment::samples_facing_up() const
{
    const auto* map = std::get_if<environment_kind::Map>(&m_kind);
    return sky() != nullptr || (map && map->samples_facing_up());
}

EnvironmentSample Environment::sample_without_sun_facing_up(float u1, float u2) const
{
    EnvironmentSample e;
    if (const environment_kind::Sky* s = sky())
        e = s->sample_without_sun_facing_up(u1, u2);
    else if (const auto* map = std::get_if<environment_kind::Map>(&m_kind);
             map && map->samples_facing_up())
        e = map->sample_facing_up(u1, u2);
    else
        return sample_without_sun(u1, u2);
    if (m_turned)  // a turn about +y keeps the cosine to +y
        e.direction = turn(e.direction);
    return e;
}

float Environment::pdf_without_sun_facing_up(const Vec3f& direction) const
{
    const Vec3f d = m_turned ? unturn(direction) : direction;
    if (const environment_kind::Sky* s = sky())
        return s->pdf_without_sun_facing_up(d);
    if (const auto* map = std::get_if<environment_kind::Map>(&m_kind);
        map && map->samples_facing_up())
        return map->pdf_facing_up(d);
    return pdf_without_sun(direction);
}

float Environment::pdf_without_sun(const Vec3f& direction) const
{
    const environment_kind::Sky* s = sky();
    if (!s)
        return pdf(direction);
    return s->pdf_without_sun(m_turned ? unturn(direction) : direction);
}

Environment Environment::hidden_below_horizon() const
{
    Environment e = *this;
    if (auto* sky = std::get_if<environment_kind::Sky>(&e.m_kind))
        sky->hide_below_horizon();
    else if (auto* map = std::get_if<environment_kind::Map>(&e.m_kind))
        map->hide_below_horizon();
    return e;
}

Environment Environment::rotated(float degrees) const&
{
    Environment e = *this;
    e.turn_by(degrees);
    return e;
}

Environment Environment::rotated(float degrees) &&
{
    turn_by(degrees);
    return std::move(*this);
}

void Environment::turn_by(float degrees)
{
    if (!std::isfinite(degrees))
        throw Error("environment: the rotation must be a finite angle");
    m_degrees += double(degrees);
    double radians = m_degrees * std::numbers::pi / 180;
    m_cos = static_cast<float>(std::cos(radians));
    m_sin = static_cast<float>(std::sin(radians));
    m_turned = m_degrees != 0;
}

Vec3f Environment::turn(const Vec3f& d) const
{
    return {m_cos * d.x + m_sin * d.z, d.y, -m_sin * d.x + m_cos * d.z};
}

Vec3f Environment::unturn(const Vec3f& d) const
{
    return {m_cos * d.x - m_sin * d.z, d.y, m_sin * d.x + m_cos * d.z};
}

Environment make_uniform_environment(const Vec3f& radiance)
{
    return Environment(environment_kind::Uniform{radiance});
}

Environment make_sky_environment(const SkyParameters& parameters)
{
    return Environment(environment_kind::Sky(parameters));
}

Environment make_map_environment(int width, int height, std::vector<float> rgb)
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
    return Environment(environment_kind::Map(width, height, std::move(rgb)));
}

Environment make_map_environment(const std::filesystem::path& file, float scale)
{
    MapTexels map = image_codec().read_map(file, scale, max_map_texels);
    return make_map_environment(map.width, map.height, std::move(map.rgb));
}

}  // namespace cambium::render
