// SPDX-License-Identifier: Apache-2.0
// The scene's lights as one closed set for next-event estimation: the view file's point,
// spot and directional lights (delta lights), the emissive primitives (one area-light
// group), the environment and a sky's sun disk, chosen by power or per point.
#include "render/light.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/color.h"

namespace cambium::render {

namespace {

constexpr float pi = std::numbers::pi_v<float>;

float attenuation(const RenderLight& l, float d)
{
    float a = l.att_constant + l.att_linear * d + l.att_quadratic * d * d;
    return a > 0 ? 1.0f / a : 0.0f;
}

/// OpenGL's spot factor: (cos angle)^exponent inside the cone, 0 outside.
float spot_factor(const RenderLight& l, const Vec3f& from_light)
{
    float c = dot(from_light, l.spot_axis);
    if (c < l.spot_cos_cutoff)
        return 0;
    return l.spot_exponent > 0 ? std::pow(std::fmax(c, 0.0f), l.spot_exponent) : 1.0f;
}

}  // namespace

LightSample sample_light(const RenderLight& light, const Vec3f& p)
{
    if (light.kind == RenderLight::Kind::directional)
        return {light.toward_light, std::numeric_limits<float>::infinity(), light.colour * pi};
    Vec3f to = light.position - p;
    float d = length(to);
    if (d <= 0)
        return {Vec3f(0, 0, 1), 0, Vec3f()};
    Vec3f wi = to / d;
    float scale = pi * attenuation(light, d);
    if (light.kind == RenderLight::Kind::spot)
        scale *= spot_factor(light, -wi);
    return {wi, d, light.colour * scale};
}

std::vector<RenderLight> make_lights(const std::vector<geom::Light>& lights)
{
    constexpr double deg_to_rad = std::numbers::pi / 180.0;
    std::vector<RenderLight> out;
    out.reserve(lights.size());
    for (const geom::Light& l : lights) {
        RenderLight r;
        switch (l.kind) {
        case geom::Light::Kind::point: r.kind = RenderLight::Kind::point; break;
        case geom::Light::Kind::directional: r.kind = RenderLight::Kind::directional; break;
        case geom::Light::Kind::spot: r.kind = RenderLight::Kind::spot; break;
        }
        r.position = Vec3f(l.position);
        r.toward_light = normalize(Vec3f(l.direction));
        r.spot_axis = normalize(Vec3f(l.spot_direction));
        r.spot_exponent = l.spot_exponent;
        r.spot_cos_cutoff = l.spot_cutoff_deg >= 180
                                ? -1.0f
                                : static_cast<float>(std::cos(l.spot_cutoff_deg * deg_to_rad));
        r.att_constant = l.attenuation_constant;
        r.att_linear = l.attenuation_linear;
        r.att_quadratic = l.attenuation_quadratic;
        r.colour = decode_display(l.diffuse);
        if (r.kind == RenderLight::Kind::directional && is_black(r.toward_light))
            continue;  // a zero V: vector has no direction; cpfg draws nothing lit by it
        out.push_back(r);
    }
    return out;
}

}  // namespace cambium::render

namespace cambium::render {

namespace {

/// The integral of the environment's luminance over the sphere (a sky's sun disk left
/// out), estimated from its own importance sampling on a fixed 16 x 16 grid of uniforms
/// (the same for every render, so images stay a function of the seed).
double environment_luminance(const Environment& env)
{
    constexpr int n = 16;
    double sum = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            EnvironmentSample s = env.sample_without_sun((i + 0.5f) / n, (j + 0.5f) / n);
            if (s.pdf > 0)
                sum += luminance(s.radiance) / s.pdf;
        }
    return sum / (n * n);
}

/// Emissive primitives fainter than this share of the lights' irradiance are not sampled.
constexpr float faint_emission = 0.01f;

/// The luminance of the irradiance the view file's lights give every surface facing them:
/// directional lights and point lights without fall-off light each point alike (a spot
/// light's cone or an attenuated light's distance may leave a point unlit).
float sure_irradiance(const std::vector<RenderLight>& lights)
{
    float sum = 0;
    for (const RenderLight& l : lights) {
        bool everywhere = l.kind == RenderLight::Kind::directional ||
                          (l.kind == RenderLight::Kind::point && l.att_linear == 0 &&
                           l.att_quadratic == 0);
        if (everywhere)
            sum += pi * luminance(l.colour) * attenuation(l, 0);
    }
    return sum;
}

/// Whether the emissive primitives are too faint to be worth next-event samples: a
/// hemisphere full of the brightest of them (irradiance pi L) would give a surface less
/// than 1% of what the lights give it. BSDF sampling then finds their light alone,
/// without fireflies: a BSDF-sampled hit adds at most the surface's albedo times L.
bool faint(const AreaLights& area, const std::vector<RenderLight>& lights)
{
    return pi * area.max_luminance() < faint_emission * sure_irradiance(lights);
}

LightKind kind_of(const RenderLight& l)
{
    switch (l.kind) {
    case RenderLight::Kind::point: return LightKind::point;
    case RenderLight::Kind::spot: return LightKind::spot;
    case RenderLight::Kind::directional: return LightKind::directional;
    }
    return LightKind::point;
}

/// A direction uniform in the cone of unit axis `axis` and cosine `cos_max`.
Vec3f uniform_cone(const Vec3f& axis, float cos_max, float u1, float u2)
{
    float cos_t = 1 - u1 * (1 - cos_max);
    float sin_t = std::sqrt(std::max(0.0f, 1 - cos_t * cos_t));
    float phi = 2 * pi * u2;
    Vec3f t, b;
    make_basis(axis, t, b);
    return normalize(t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi)) + axis * cos_t);
}

}  // namespace

LightSet::LightSet(const std::vector<RenderLight>& lights, const AreaLights* area_lights,
                   const Environment* environment, bool environment_nee, float scene_radius)
{
    for (const RenderLight& l : lights) {
        float falloff = attenuation(l, 0);
        add({kind_of(l), l}, pi * luminance(l.colour) * (falloff > 0 ? falloff : 1.0f));
    }
    if (area_lights && !area_lights->empty() && !faint(*area_lights, lights)) {
        m_area = area_lights;
        float r = scene_radius > 0 ? scene_radius : 1.0f;
        add({LightKind::area, {}}, area_lights->power() / (double(r) * r));
        m_area_irradiance = static_cast<float>(area_lights->power() / (pi * double(r) * r));
    }
    if (environment && environment_nee) {
        m_environment = environment;
        add({LightKind::environment, {}}, environment_luminance(*environment) / 4);
        tabulate_irradiance();
        if (std::optional<environment_kind::Sky::SunDisk> sun = environment->sun();
            sun && sun->solid_angle > 0) {
            // The sun apart from the dome: each is chosen by what it gives a point, where
            // as one mixture the sun's share of the sky's samples was fixed and competed
            // with the view's lights as one whole.
            m_sun = *sun;
            m_has_sun = true;
            m_sun_pdf = 1 / sun->solid_angle;
            m_sun_sin_radius = std::sqrt(std::max(0.0f, 1 - sun->cos_radius * sun->cos_radius));
            m_sun_normal_irradiance = luminance(sun->radiance) * sun->solid_angle;
            add({LightKind::sun, {}}, m_sun_normal_irradiance);
        }
    }
    // Every light keeps a chance: a weight of 0 (black, or a failed estimate) would make
    // its light unreachable, which is bias, not just variance.
    double total = 0, floor = 0;
    for (double w : m_weights)
        total += std::isfinite(w) ? std::max(w, 0.0) : 0.0;
    floor = total > 0 ? total * 1e-3 / double(m_weights.size()) : 1;
    m_cdf.assign(m_lights.size() + 1, 0.0);
    for (std::size_t i = 0; i < m_lights.size(); ++i) {
        double w = std::isfinite(m_weights[i]) ? std::max(m_weights[i], floor) : floor;
        m_cdf[i + 1] = m_cdf[i] + w;
    }
    for (double& c : m_cdf)
        c /= m_cdf.back();
    m_weights.clear();
    m_delta_only = !m_lights.empty() && m_lights.size() <= max_delta_choice &&
                   std::none_of(m_lights.begin(), m_lights.end(), [](const Entry& e) {
                       return e.kind == LightKind::area || e.kind == LightKind::environment ||
                              e.kind == LightKind::sun;
                   });
    m_per_point = !m_delta_only && m_lights.size() <= max_point_choice &&
                  (m_area != nullptr || m_environment != nullptr);
    const auto delta_lights = std::count_if(m_lights.begin(), m_lights.end(),
                                            [](const Entry& e) { return is_delta(e.kind); });
    m_every_light = m_environment != nullptr && m_area == nullptr &&
                    static_cast<std::size_t>(delta_lights) <= max_delta_choice;
    for (std::size_t i = 0; i < m_lights.size(); ++i) {
        float p = static_cast<float>(m_cdf[i + 1] - m_cdf[i]);
        if (m_lights[i].kind == LightKind::area)
            m_area_probability = p;
        if (m_lights[i].kind == LightKind::environment) {
            m_environment_probability = p;
            m_environment_index = static_cast<std::uint32_t>(i);
        }
        if (m_lights[i].kind == LightKind::sun) {
            m_sun_probability = p;
            m_sun_index = static_cast<std::uint32_t>(i);
        }
    }
}

void LightSet::add(const Entry& entry, double weight)
{
    m_lights.push_back(entry);
    m_weights.push_back(weight);
}

std::optional<ChosenLight> LightSet::choose(float u) const
{
    if (m_lights.empty())
        return std::nullopt;
    auto it = std::upper_bound(m_cdf.begin(), m_cdf.end(), double(u));
    std::size_t i = std::min<std::size_t>(
        std::size_t(std::max<std::ptrdiff_t>(it - m_cdf.begin() - 1, 0)), m_lights.size() - 1);
    return ChosenLight{static_cast<std::uint32_t>(i),
                       static_cast<float>(m_cdf[i + 1] - m_cdf[i])};
}

LightLiSample LightSet::sample_li_other(std::uint32_t index, const Vec3f& p, float u0, float u1,
                                        float u2) const
{
    const Entry& e = m_lights[index];
    switch (e.kind) {
    case LightKind::point:
    case LightKind::spot:
    case LightKind::directional: {
        LightSample ls = sample_light(e.delta, p);
        // The offset origin is a little closer to the light; stop just short of it.
        float tfar = std::isinf(ls.distance) ? ls.distance : ls.distance * (1 - 1e-4f);
        return {ls.wi, ls.irradiance, is_black(ls.irradiance) ? 0.0f : 1.0f, tfar, true};
    }
    case LightKind::area: {
        std::optional<AreaLightSample> ls = m_area->sample(p, u0, u1, u2);
        if (!ls)
            return {};
        // Stop just short of the light, whose own surface must not block the ray.
        return {ls->wi, ls->radiance, ls->pdf, ls->distance - ls->margin, false};
    }
    case LightKind::environment: {
        // (u1, u2): the pair the sampler stratifies jointly; u0 chooses among areas.
        EnvironmentSample es = m_environment->sample_without_sun(u1, u2);
        return {es.direction, es.radiance, es.pdf, std::numeric_limits<float>::infinity(),
                false};
    }
    case LightKind::sun: {
        // Uniform over the disk's cone, whose radiance is constant.
        Vec3f wi = uniform_cone(m_sun.direction, m_sun.cos_radius, u1, u2);
        if (!(dot(wi, m_sun.direction) >= m_sun.cos_radius))
            return {};  // rounding at the rim: sun_pdf() would say 0 there
        return {wi, m_sun.radiance, m_sun_pdf, std::numeric_limits<float>::infinity(), false};
    }
    }
    return {};
}

LightLiSample LightSet::environment_li_facing_up(float u1, float u2) const
{
    EnvironmentSample es = m_environment->sample_without_sun_facing_up(u1, u2);
    return {es.direction, es.radiance, es.pdf, std::numeric_limits<float>::infinity(), false};
}

namespace {
constexpr int irradiance_azimuths = 16, irradiance_bands = 8;
}  // namespace

void LightSet::tabulate_irradiance()
{
    // 256 directions of the environment's own sampling (a fixed stratified grid, so
    // images stay a function of the seed), each L / pdf, projected on every normal.
    constexpr int n = 16;
    struct Ray {
        Vec3f d;
        float weight;
    };
    std::vector<Ray> rays;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            EnvironmentSample s =
                m_environment->sample_without_sun((i + 0.5f) / n, (j + 0.5f) / n);
            float w = s.pdf > 0 ? luminance(s.radiance) / s.pdf : 0.0f;
            if (std::isfinite(w) && w > 0)
                rays.push_back({s.direction, w / (n * n)});
        }
    m_irradiance.assign(std::size_t(irradiance_azimuths) * irradiance_bands, 0.0f);
    float largest = 0;
    for (int b = 0; b < irradiance_bands; ++b)
        for (int a = 0; a < irradiance_azimuths; ++a) {
            float c = std::cos(pi * (b + 0.5f) / irradiance_bands);
            Vec3f normal = environment_kind::LatLongTable::direction((a + 0.5f) / irradiance_azimuths, c);
            float e = 0;
            for (const Ray& r : rays)
                e += r.weight * std::max(0.0f, dot(normal, r.d));
            m_irradiance[std::size_t(b) * irradiance_azimuths + std::size_t(a)] = e;
            largest = std::max(largest, e);
        }
    m_irradiance_floor = largest / 20;
}

float LightSet::environment_irradiance(const Vec3f& n) const
{
    if (m_irradiance.empty())
        return 0;
    float theta = std::acos(std::clamp(n.y, -1.0f, 1.0f));
    float phi = std::atan2(-n.x, n.z);
    if (phi < 0)
        phi += 2 * pi;
    int a = std::clamp(int(phi / (2 * pi) * irradiance_azimuths), 0, irradiance_azimuths - 1);
    int b = std::clamp(int(theta / pi * irradiance_bands), 0, irradiance_bands - 1);
    float e = m_irradiance[std::size_t(b) * irradiance_azimuths + std::size_t(a)];
    return std::isfinite(e) ? std::max(e, m_irradiance_floor) : m_irradiance_floor;
}

float LightSet::area_pdf(const Vec3f& p, const SurfaceHit& hit) const
{
    return m_area ? m_area->pdf(p, hit) : 0.0f;
}

float LightSet::pdf_li(const Vec3f& p, const SurfaceHit& hit) const
{
    return m_area ? m_area_probability * m_area->pdf(p, hit) : 0.0f;
}

}  // namespace cambium::render
