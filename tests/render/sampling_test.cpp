// SPDX-License-Identifier: Apache-2.0
// Chi-squared tests of the samplers against their own densities (pbrt's bsdfs_test.cpp
// style): bsdf_sample against bsdf_pdf for each lobe mix, the light set's sample_li
// against pdf_li for environments and emissive primitives (with the choice by power), and
// the pdf's integral against an independent quadrature of the lobes' mass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

#include "render/accel.h"
#include "render/area_light.h"
#include "render/environment.h"
#include "render/light.h"
#include "render/material.h"
#include "chi2.h"
#include "geom_scenes.h"

namespace cambium::render {
namespace {

using namespace testing;

constexpr float pi = std::numbers::pi_v<float>;
const Vec3f up(0, 0, 1);

Vec3f incidence(float theta) { return {std::sin(theta), 0, std::cos(theta)}; }

struct LobeMix {
    const char* name;
    Bsdf bsdf;
};

std::vector<LobeMix> lobe_mixes()
{
    return {
        {"reflect", {Vec3f(0.7f), Vec3f(), Vec3f(), 0}},
        {"transmit", {Vec3f(), Vec3f(0.6f), Vec3f(), 0}},
        {"glossy n=0", {Vec3f(), Vec3f(), Vec3f(0.8f), 0}},
        {"glossy n=8", {Vec3f(), Vec3f(), Vec3f(0.8f), 8}},
        {"glossy n=32", {Vec3f(), Vec3f(), Vec3f(0.5f), 32}},
        {"reflect+glossy", {Vec3f(0.4f), Vec3f(), Vec3f(0.3f), 4}},
        {"reflect+transmit", {Vec3f(0.4f), Vec3f(0.3f), Vec3f(), 0}},
        {"all three", {{0.3f, 0.2f, 0.1f}, {0.2f, 0.3f, 0.1f}, {0.2f, 0.1f, 0.3f}, 16}},
    };
}

const float incidences[] = {0.2f, 1.0f, 1.45f};

TEST(Chi2, BsdfSampleFollowsBsdfPdfForEveryLobeMix)
{
    const std::vector<LobeMix> mixes = lobe_mixes();
    const double alpha = sidak(int(mixes.size() * std::size(incidences)));
    for (const LobeMix& m : mixes)
        for (float theta : incidences) {
            Vec3f wo = incidence(theta);
            Chi2Result r = chi2_sphere(
                [&](Sampler& s) -> std::optional<Vec3f> {
                    float u1 = s.next(), u2 = s.next();
                    BsdfSample bs = bsdf_sample(m.bsdf, up, wo, u1, u2);
                    if (bs.pdf <= 0)
                        return std::nullopt;
                    return bs.wi;
                },
                [&](const Vec3f& wi) { return double(bsdf_pdf(m.bsdf, up, wo, wi)); }, 200000,
                17, 20, 40, 32);
            EXPECT_GT(r.p_value, alpha) << m.name << " theta " << theta << ": chi2 "
                                        << r.statistic << " dof " << r.dof;
        }
}

// A deliberately wrong density must fail: the test can tell.
TEST(Chi2, AWrongPdfIsRejected)
{
    Bsdf b{Vec3f(), Vec3f(), Vec3f(0.8f), 8};
    Vec3f wo = incidence(0.5f);
    Chi2Result r = chi2_sphere(
        [&](Sampler& s) -> std::optional<Vec3f> {
            BsdfSample bs = bsdf_sample(b, up, wo, s.next(), s.next());
            return bs.pdf > 0 ? std::optional<Vec3f>(bs.wi) : std::nullopt;
        },
        // exponent 7 instead of 8: a lobe 6% wider
        [&](const Vec3f& wi) {
            Bsdf wider = b;
            wider.exponent = 7;
            return double(bsdf_pdf(wider, up, wo, wi));
        },
        200000, 17);
    EXPECT_LT(r.p_value, 1e-6) << r.statistic;
}

/// The Phong lobe's mass below the surface: quadrature of (n+1)/(2 pi) cos^n about the
/// mirror direction over z < 0, in the lobe's own polar coordinates (independent of
/// bsdf_pdf).
double glossy_mass_below(float exponent, const Vec3f& wo)
{
    Vec3f r = up * (2 * dot(up, wo)) - wo;  // the mirror direction
    Vec3f t, b;
    make_basis(r, t, b);
    const int na = 2000, np = 720;
    double below = 0;
    for (int i = 0; i < na; ++i) {
        double ca = (i + 0.5) / na;  // cos alpha in (0, 1): the lobe's hemisphere
        double sa = std::sqrt(1 - ca * ca);
        for (int j = 0; j < np; ++j) {
            double phi = (j + 0.5) * 2 * std::numbers::pi / np;
            double z = ca * r.z + sa * (std::cos(phi) * t.z + std::sin(phi) * b.z);
            if (z < 0)
                below += (exponent + 1) / (2 * std::numbers::pi) * std::pow(ca, exponent);
        }
    }
    return below * (1.0 / na) * (2 * std::numbers::pi / np);
}

// The pdf integrates to 1 less exactly the glossy lobe's share below the surface.
TEST(Chi2, PdfIntegratesToOneLessTheGlossyLossBelowTheSurface)
{
    for (const LobeMix& m : lobe_mixes())
        for (float theta : incidences) {
            Vec3f wo = incidence(theta);
            Chi2Result r = chi2_sphere([](Sampler&) { return std::nullopt; },
                                       [&](const Vec3f& wi) {
                                           return double(bsdf_pdf(m.bsdf, up, wo, wi));
                                       },
                                       1, 1, 40, 80, 16);
            float total = m.bsdf.reflect.x + m.bsdf.reflect.y + m.bsdf.reflect.z +
                          m.bsdf.transmit.x + m.bsdf.transmit.y + m.bsdf.transmit.z +
                          m.bsdf.glossy.x + m.bsdf.glossy.y + m.bsdf.glossy.z;
            double glossy_share =
                (m.bsdf.glossy.x + m.bsdf.glossy.y + m.bsdf.glossy.z) / total;
            double expect = 1 - glossy_share * (glossy_share > 0
                                                    ? glossy_mass_below(m.bsdf.exponent, wo)
                                                    : 0.0);
            EXPECT_NEAR(r.pdf_integral, expect, 0.003) << m.name << " theta " << theta;
        }
}

// ---------------------------------------------------------------- lights

/// Directions sample_li draws at p for a set, nullopt where it refuses or picks a delta
/// light (no density).
std::optional<Vec3f> light_direction(const LightSet& set, const Vec3f& p, Sampler& s)
{
    float c = s.next(), u0 = s.next(), u1 = s.next(), u2 = s.next();
    std::optional<ChosenLight> chosen = set.choose(c);
    if (!chosen)
        return std::nullopt;
    LightLiSample ls = set.sample_li(chosen->index, p, u0, u1, u2);
    if (ls.delta || !(ls.pdf > 0))
        return std::nullopt;
    return ls.wi;
}

TEST(Chi2, EnvironmentSampleLiFollowsPdfLi)
{
    // A map with a bright patch and a dim rest, a sky, each also turned.
    std::vector<float> rgb(64 * 32 * 3, 0.1f);
    for (int y = 5; y < 9; ++y)
        for (int x = 40; x < 46; ++x)
            for (int c = 0; c < 3; ++c)
                rgb[(y * 64 + x) * 3 + c] = 20;
    Environment map = make_map_environment(64, 32, rgb);
    // No sun disc: half a degree across, no bin grid here could integrate its density.
    SkyParameters no_sun;
    no_sun.sun_intensity = 0;
    Environment sky = make_sky_environment(no_sun);
    std::vector<Environment> envs{map, map.rotated(30), sky, sky.rotated(-70)};
    std::vector<RenderLight> none;
    for (std::size_t i = 0; i < envs.size(); ++i) {
        LightSet set(none, nullptr, &envs[i], true, 1);
        Chi2Result r = chi2_sphere(
            [&](Sampler& s) { return light_direction(set, Vec3f(), s); },
            [&](const Vec3f& wi) { return double(set.pdf_li(wi)); }, 200000, 23, 20, 40, 32);
        EXPECT_GT(r.p_value, sidak(int(envs.size()))) << "environment " << i << ": chi2 "
                                                      << r.statistic << " dof " << r.dof;
        EXPECT_NEAR(r.pdf_integral, 1, 0.01) << i;
    }
}

/// A density in proportion to the environment's luminance (above the horizon only, when
/// `upper`), normalised by a midpoint rule of 1024 x 512 cells in (cos theta, phi).
std::function<double(const Vec3f&)> luminance_density(const Environment& env, bool upper)
{
    auto lum = [&env, upper](const Vec3f& d) {
        if (upper && d.y < 0)
            return 0.0;
        Vec3f L = env.radiance(d);
        return 0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z;
    };
    const int nc = 512, np = 1024;
    double sum = 0;
    for (int i = 0; i < nc; ++i) {
        double c = 1 - 2 * (i + 0.5) / nc, s = std::sqrt(std::max(0.0, 1 - c * c));
        for (int j = 0; j < np; ++j) {
            double phi = 2 * std::numbers::pi * (j + 0.5) / np;
            sum += lum(Vec3f(float(s * std::cos(phi)), float(c), float(s * std::sin(phi))));
        }
    }
    const double integral = sum * 4 * std::numbers::pi / (double(nc) * np);
    return [lum, integral](const Vec3f& d) { return lum(d) / integral; };
}

// The sky's dome is sampled in proportion to its radiance (as a map is): its sampling
// density against the luminance itself, normalised (not against its own pdf), for a
// high and a low sun, clear and hazy, turned, and with the lower hemisphere hidden by a
// ground (then nothing is drawn below the horizon). The sun is off: half a degree across,
// no bin grid here could integrate it. A sampler uniform over the sphere, as the dome's
// was, is rejected by the same test.
TEST(Chi2, SkySamplingDensityFollowsItsRadiance)
{
    struct Case {
        Vec3f sun;
        float turbidity;
        float turn;
        bool hidden;
    };
    const std::vector<Case> cases{{{0.5f, 0.8f, 0.33f}, 3, 0, false},
                                  {{0.9f, 0.15f, -0.3f}, 8, 0, false},
                                  {{-0.2f, 0.5f, 0.8f}, 2, 40, true},
                                  {{0.5f, 0.8f, 0.33f}, 3, 0, true}};
    const double alpha = sidak(int(cases.size()) + 1);
    for (std::size_t k = 0; k < cases.size(); ++k) {
        SkyParameters p;
        p.sun_direction = normalize(cases[k].sun);
        p.turbidity = cases[k].turbidity;
        p.sun_intensity = 0;
        Environment sky = make_sky_environment(p).rotated(cases[k].turn);
        if (cases[k].hidden)
            sky = sky.hidden_below_horizon();
        Chi2Result r = chi2_sphere(
            [&](Sampler& s) -> std::optional<Vec3f> {
                float u1 = s.next(), u2 = s.next();
                EnvironmentSample e = sky.sample(u1, u2);
                if (!(e.pdf > 0))
                    return std::nullopt;
                return e.direction;
            },
            luminance_density(sky, cases[k].hidden), 200000, 31 + std::uint32_t(k), 20, 40,
            24);
        EXPECT_GT(r.p_value, alpha) << "case " << k << ": chi2 " << r.statistic << " dof "
                                    << r.dof;
        EXPECT_NEAR(r.pdf_integral, 1, 0.01) << k;
        std::printf("[chi2] sky %zu against its radiance: chi2 %.1f dof %d p %.3f\n", k,
                    r.statistic, r.dof, r.p_value);
    }
    // The test can fail: the uniform sphere against the same sky's radiance.
    SkyParameters p;
    p.sun_intensity = 0;
    Environment sky = make_sky_environment(p);
    Chi2Result uniform = chi2_sphere(
        [](Sampler& s) -> std::optional<Vec3f> {
            float z = 1 - 2 * s.next(), r = std::sqrt(std::max(0.0f, 1 - z * z));
            float phi = 2 * pi * s.next();
            return Vec3f(r * std::cos(phi), r * std::sin(phi), z);
        },
        luminance_density(sky, false), 200000, 37, 20, 40, 24);
    EXPECT_LT(uniform.p_value, 1e-6) << "chi2 " << uniform.statistic;
}

TEST(Chi2, AreaLightSampleLiFollowsPdfLiWithTheChoiceByPower)
{
    // A disc, a sphere and a triangle, emissive, around p = origin (none hides another),
    // plus a directional light that takes its share of the choices.
    geom::Scene s;
    s.materials[2].diffuse = {0, 0, 0};
    s.materials[2].emission = {1, 1, 1};
    s.materials[3].diffuse = {0, 0, 0};
    s.materials[3].emission = {0.4f, 0.5f, 0.2f};
    add_disc(s.geometry, {0, 0, 2}, 0.8f, {0, 0, -1}, 2, 3);
    add_sphere(s.geometry, {2, 1, -1}, 0.7f, 3);
    add_triangle(s.geometry, {{{-2, -1, -1}, {-2, 1.5f, -0.5f}, {-1.5f, 0, 1}}},
                 {{{1, 0, 0}, {1, 0, 0}, {1, 0, 0}}}, {{{0, 0}, {1, 0}, {0, 1}}}, 2, 2);
    geom::Light sun;
    sun.kind = geom::Light::Kind::directional;
    sun.direction = {0, 1, 0};
    s.lights.push_back(sun);
    Camera camera = top_camera(0, 0, 1, 4, 4);
    EmbreeScene accel(s, camera);
    std::vector<SurfaceMaterial> materials = make_materials(s.materials);
    AreaLights area(s, materials);
    ASSERT_EQ(area.size(), 3u);
    LightSet set(make_lights(s.lights), &area, nullptr, false, 3);
    const Vec3f p(0, 0, 0);
    Chi2Result r = chi2_sphere(
        [&](Sampler& smp) { return light_direction(set, p, smp); },
        [&](const Vec3f& wi) {
            std::optional<SurfaceHit> hit = accel.intersect(p, wi, 0, 1e30f);
            return hit ? double(set.pdf_li(p, *hit)) : 0.0;
        },
        100000, 29, 20, 40, 24);
    EXPECT_GT(r.p_value, 0.01) << "chi2 " << r.statistic << " dof " << r.dof;
    // The directional light's share of the choices is the density's missing mass.
    double area_share = 1 - set.choose(0.0f)->probability;
    EXPECT_NEAR(r.pdf_integral, area_share, 0.01);
    std::printf("[chi2] area lights: chi2 %.1f dof %d p %.3f, area share %.3f\n", r.statistic,
                r.dof, r.p_value, area_share);
}

}  // namespace
}  // namespace cambium::render
