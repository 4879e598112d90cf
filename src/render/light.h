// SPDX-License-Identifier: Apache-2.0
// The scene's lights as one closed set for next-event estimation: the view file's point,
// spot and directional lights (delta lights), the emissive primitives (one area-light
// group), the environment and a sky's sun disk, chosen by power or per point.
#pragma once

#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "geom/scene.h"
#include "render/area_light.h"
#include "render/environment.h"
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

/// The kinds of light next-event estimation knows: a closed set, dispatched by switch.
/// A sky's sun disk is a light of its own (`sun`), the rest of the sky the `environment`:
/// each is then chosen by what it gives a point, not as one mixture.
enum class LightKind : std::uint8_t { point, spot, directional, area, environment, sun };

/// Whether a light of this kind is a delta light: one direction toward it from any point.
constexpr bool is_delta(LightKind k)
{
    return k == LightKind::point || k == LightKind::spot || k == LightKind::directional;
}

/// Light arriving at a shading point from one light: the unit direction toward it, the
/// radiance along -wi (a delta light: the irradiance on a surface facing it), the
/// solid-angle density wi was drawn with (a delta light: 1; the light's choice not
/// included) and where a shadow ray toward it stops (just short of the light).
struct LightLiSample {
    Vec3f wi;
    Vec3f li;
    float pdf = 0;
    float tfar = std::numeric_limits<float>::infinity();
    bool delta = false;  ///< no BSDF ray can find this light (no MIS weight)
};

/// One light of a LightSet, chosen with `probability`.
struct ChosenLight {
    std::uint32_t index = 0;
    float probability = 0;
};

/// Every light next-event estimation samples, one at a time: chosen at each shading point
/// by what each can deliver there where the set holds the environment or emissive
/// primitives (per_point; the integrator weighs them), by what each gives the point among
/// delta lights only (delta_only), and otherwise (choose()) in proportion to its
/// power (pbrt's power light sampler): a delta light by the irradiance pi |colour| it gives
/// a surface facing it (attenuation at distance 0, the spot cone ignored), the
/// environment by the integral of its luminance over the sphere (a quarter of it reaches an
/// average surface, as a quarter of a delta light's does), the emissive primitives by
/// their power over pi r^2, r the scene's radius (the irradiance they give a surface that
/// far away), a sky's sun disk (when up) by the irradiance it gives a surface facing it,
/// as a directional light, and the rest of the sky as the environment. The weights only
/// steer variance: every light keeps a non-zero chance.
/// Emissive primitives so faint that a hemisphere full of the brightest of them would give
/// a surface less than 1% of the irradiance of the directional (and unattenuated point)
/// lights are not in the set (Lilac's petals glow at 0.002 under a sun of 1): BSDF
/// sampling finds their light alone, and pdf_li() says 0 for them, so those hits keep
/// full weight.
/// Holds pointers to the area lights and the environment, which must outlive it.
class LightSet {
public:
    LightSet() = default;
    /// `environment` is sampled only if `environment_nee` (a uniform one is left to BSDF
    /// sampling, which is perfect for it); a sky's sun, when up, is then a light of its own
    /// (LightKind::sun) and the environment entry is the rest (Environment::
    /// sample_without_sun).
    LightSet(const std::vector<RenderLight>& lights, const AreaLights* area_lights,
             const Environment* environment, bool environment_nee, float scene_radius);

    bool empty() const { return m_lights.empty(); }
    std::size_t size() const { return m_lights.size(); }
    LightKind kind(std::uint32_t index) const { return m_lights[index].kind; }
    /// Whether the set holds only delta lights (point, spot, directional), at most
    /// max_delta_choice of them: then next-event estimation can weigh each light by what
    /// it gives the shading point, at no more than a BSDF evaluation per light.
    bool delta_only() const { return m_delta_only; }
    static constexpr std::size_t max_delta_choice = 8;  ///< OpenGL's (cpfg's) eight lights

    /// The probability with which choose() picks light `index`.
    float probability(std::uint32_t index) const
    {
        return static_cast<float>(m_cdf[index + 1] - m_cdf[index]);
    }
    /// The light for the uniform u; nullopt when the set is empty.
    std::optional<ChosenLight> choose(float u) const;
    /// Light from light `index` at p, from three uniforms; pdf 0 when it sends none.
    /// (A directional light, most scenes' sun, is answered inline: asked at every vertex,
    /// the call's result came back through memory and stalled its reader.)
    LightLiSample sample_li(std::uint32_t index, const Vec3f& p, float u0, float u1, float u2) const
    {
        const Entry& e = m_lights[index];
        if (e.kind == LightKind::directional)
            return directional_li(e.delta);
        return sample_li_other(index, p, u0, u1, u2);
    }
    /// Whether next-event estimation chooses among the lights by what each can deliver
    /// to the shading point (sets with the environment or emissive primitives, at most
    /// max_point_choice lights): a delta light by its exact unshadowed contribution (0
    /// where the opaque ground hides it), the environment by environment_irradiance() and
    /// the sun by sun_irradiance() on either side of the surface (the sun 0 where the
    /// ground hides it), the emissive primitives by area_irradiance(), each times the
    /// BSDF's albedo on that side. The choice probabilities then differ from
    /// vertex to vertex, and the integrator carries them to weigh the next BSDF ray.
    bool per_point() const { return m_per_point; }
    static constexpr std::size_t max_point_choice = 16;
    /// Whether next-event estimation can sample every light at a vertex instead of
    /// choosing one (the integrator says where): an environment (a sky's dome with its
    /// sun, or a map) and at most max_delta_choice delta lights, no emissive primitives.
    /// Each delta light costs a shadow ray where it gives the point something and no
    /// random number; the environment and the sun a sample each. Then no choice adds
    /// variance where lights are shadowed (the ground in the plant's shadow).
    bool every_light() const { return m_every_light; }
    /// The luminance of the irradiance the sampled environment (without a sun of its own)
    /// gives a surface facing n (unshadowed), estimated once from 256 of its own samples for
    /// 128 normals and looked up at the nearest, never below 1/20 of the largest (an
    /// estimate only steers variance). 0 without a sampled environment.
    float environment_irradiance(const Vec3f& n) const;
    /// The luminance of the irradiance the sun disk gives a surface facing n: at normal
    /// incidence times the cosine to its centre raised by the sine of its angular radius
    /// (at most 1), so it is above 0 wherever any of the disk is in front of the surface.
    /// 0 without a sun of its own.
    float sun_irradiance(const Vec3f& n) const
    {
        if (!m_has_sun)
            return 0;
        float c = dot(n, m_sun.direction) + m_sun_sin_radius;
        return c > 0 ? m_sun_normal_irradiance * (c < 1 ? c : 1.0f) : 0.0f;
    }
    /// Whether the sun is a light of its own, its unit direction and the sine of its
    /// angular radius.
    bool has_sun() const { return m_has_sun; }
    /// The indices of the sun and of the environment (meaningful where they are in the set).
    std::uint32_t sun_index() const { return m_sun_index; }
    std::uint32_t environment_index() const { return m_environment_index; }
    const Vec3f& sun_direction() const { return m_sun.direction; }
    float sun_sin_radius() const { return m_sun_sin_radius; }
    /// The density of the sun's own sampling along wi (uniform over its cone; no choice)
    /// and the disk's radiance along wi: 0 outside it or without a sun of its own.
    float sun_pdf(const Vec3f& wi) const
    {
        return m_has_sun && dot(wi, m_sun.direction) >= m_sun.cos_radius ? m_sun_pdf : 0.0f;
    }
    Vec3f sun_radiance(const Vec3f& wi) const
    {
        return m_has_sun && dot(wi, m_sun.direction) >= m_sun.cos_radius ? m_sun.radiance : Vec3f();
    }
    /// The emissive primitives' power over pi r^2 (the irradiance they give a surface r
    /// away, r the scene's radius); 0 when they are not sampled.
    float area_irradiance() const { return m_area_irradiance; }
    /// The density of the environment's own sampling along wi (no choice; without the
    /// sun, which is sampled apart); 0 when it is not sampled.
    float environment_pdf(const Vec3f& wi) const
    {
        return m_environment ? m_environment->pdf_without_sun(wi) : 0.0f;
    }
    /// The environment for a surface facing straight up (the ground), where it has a
    /// sampling of its own (Environment::samples_facing_up): a sample and its density.
    bool environment_facing_up() const
    {
        return m_environment && m_environment->samples_facing_up();
    }
    LightLiSample environment_li_facing_up(float u1, float u2) const;
    float environment_pdf_facing_up(const Vec3f& wi) const
    {
        return m_environment ? m_environment->pdf_without_sun_facing_up(wi) : 0.0f;
    }
    /// The density of the area lights' own sampling of `hit` from p (no choice).
    float area_pdf(const Vec3f& p, const SurfaceHit& hit) const;
    /// The choice probabilities by power (choose()) of the environment, of the area
    /// lights and of the sun (0 when not in the set).
    float environment_probability() const { return m_environment_probability; }
    float area_probability() const { return m_area_probability; }
    float sun_probability() const { return m_sun_probability; }

    /// The density (choice included) with which sampling the set finds the emissive
    /// point `hit` seen from p; 0 when it is not a sampled area light.
    float pdf_li(const Vec3f& p, const SurfaceHit& hit) const;
    /// The density (choice by power included) with which sampling the set finds the
    /// environment along wi, the sun's sampling included; 0 when the environment is not
    /// sampled. Inline: most bounce rays off a leaf escape and ask, and most sets hold no
    /// environment.
    float pdf_li(const Vec3f& wi) const
    {
        return m_environment ? m_environment_probability * m_environment->pdf_without_sun(wi) +
                                   m_sun_probability * sun_pdf(wi)
                             : 0.0f;
    }

private:
    struct Entry {
        LightKind kind = LightKind::point;
        RenderLight delta;  ///< point, spot, directional
    };
    void add(const Entry& entry, double weight);
    /// Fills m_irradiance from the environment's own samples.
    void tabulate_irradiance();
    /// sample_li() of a directional light: its irradiance along its direction, no end.
    static LightLiSample directional_li(const RenderLight& l)
    {
        Vec3f li = l.colour * std::numbers::pi_v<float>;  // as sample_light() gives it
        return {l.toward_light, li, is_black(li) ? 0.0f : 1.0f,
                std::numeric_limits<float>::infinity(), true};
    }
    /// sample_li() of every other kind.
    LightLiSample sample_li_other(std::uint32_t index, const Vec3f& p, float u0, float u1,
                                  float u2) const;

    std::vector<Entry> m_lights;
    std::vector<double> m_cdf;      ///< m_lights.size() + 1 entries, last 1
    std::vector<double> m_weights;  ///< unnormalised, while adding
    const AreaLights* m_area = nullptr;
    const Environment* m_environment = nullptr;
    float m_area_probability = 0, m_environment_probability = 0, m_sun_probability = 0;
    /// The sky's sun disk (world space), when it is a light of its own.
    environment_kind::Sky::SunDisk m_sun;
    float m_sun_pdf = 0, m_sun_sin_radius = 0, m_sun_normal_irradiance = 0;
    bool m_has_sun = false;
    std::uint32_t m_sun_index = 0, m_environment_index = 0;
    float m_area_irradiance = 0;
    /// environment_irradiance() by normal: 16 azimuths x 8 polar bands (LatLongTable's
    /// directions), and its floor.
    std::vector<float> m_irradiance;
    float m_irradiance_floor = 0;
    bool m_delta_only = false, m_per_point = false, m_every_light = false;
};

}  // namespace cambium::render
