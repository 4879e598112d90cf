// SPDX-License-Identifier: Apache-2.0
// The BSDF: Lambertian reflection and transmission, the normalized Phong lobe, sampling
// against independent quadrature, energy bounds, and the cpfg material mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "render/color.h"
#include "render/material.h"
#include "render/sampler.h"

namespace cambium::render {
namespace {

constexpr float pi = std::numbers::pi_v<float>;
const Vec3f up(0, 0, 1);

Vec3f incidence(float theta) { return {std::sin(theta), 0, std::cos(theta)}; }

/// Every lobe in colour (each channel weighs diffuse, translucent and glossy
/// differently), with the Phong exponent `exponent`.
SurfaceMaterial coloured_lobes(float exponent)
{
    SurfaceMaterial m;
    m.diffuse = {0.6f, 0.3f, 0.1f};
    m.translucency = 0.3f;
    m.specular = {0.3f, 0.2f, 0.4f};
    m.exponent = exponent;
    return m;
}

/// Mean of bsdf_sample's weights: the BSDF's directional albedo by importance sampling.
Vec3f sampled_albedo(const Bsdf& b, const Vec3f& wo, int n = 200000)
{
    double r = 0, g = 0, bl = 0;
    for (int i = 0; i < n; ++i) {
        Sampler s(static_cast<std::uint32_t>(i), 0, 0, 11);
        BsdfSample bs = bsdf_sample(b, up, wo, s.next(), s.next());
        r += bs.weight.x;
        g += bs.weight.y;
        bl += bs.weight.z;
    }
    return Vec3f(float(r / n), float(g / n), float(bl / n));
}

/// The same albedo by uniform sampling of the sphere: independent of bsdf_sample and pdf.
/// Also returns the integral of the pdf over the sphere.
Vec3f quadrature_albedo(const Bsdf& b, const Vec3f& wo, double* pdf_integral, int n = 400000)
{
    double r = 0, g = 0, bl = 0, p = 0;
    for (int i = 0; i < n; ++i) {
        Sampler s(static_cast<std::uint32_t>(i), 1, 0, 13);
        float z = 1 - 2 * s.next(), phi = 2 * pi * s.next();
        float rad = std::sqrt(std::fmax(0.0f, 1 - z * z));
        Vec3f wi(rad * std::cos(phi), rad * std::sin(phi), z);
        Vec3f f = bsdf_eval(b, up, wo, wi) * (std::fabs(z) * 4 * pi);
        r += f.x;
        g += f.y;
        bl += f.z;
        p += bsdf_pdf(b, up, wo, wi) * 4 * pi;
    }
    *pdf_integral = p / n;
    return Vec3f(float(r / n), float(g / n), float(bl / n));
}

TEST(Material, LambertianSampleWeightIsTheAlbedo)
{
    Bsdf b = lambertian({0.2f, 0.5f, 0.9f});
    for (int i = 0; i < 100; ++i) {
        Sampler s(static_cast<std::uint32_t>(i), 0, 0, 1);
        BsdfSample bs = bsdf_sample(b, up, incidence(0.3f), s.next(), s.next());
        ASSERT_GT(bs.wi.z, 0);
        EXPECT_NEAR(bs.weight.y, 0.5f, 1e-5f);
        EXPECT_NEAR(bs.pdf, bs.wi.z / pi, 1e-5f);
    }
    EXPECT_NEAR(bsdf_eval(b, up, up, {0, 0, -1}).x, 0, 0);  // nothing through
}

// The inline cosine and sine of a fraction of a turn (BSDF sampling's azimuth) agree with
// the double-precision functions to float rounding over the whole turn, land exactly on
// the axes at quarter turns, and give unit directions.
TEST(Material, CosineAndSineOfTurnsAreWithinFloatRounding)
{
    double worst = 0;
    for (int i = 0; i <= 400000; ++i) {
        float turns = static_cast<float>(i) / 400000;
        auto [c, s] = bsdf_detail::cos_sin_turns(turns);
        double angle = 2 * std::numbers::pi * static_cast<double>(turns);
        worst = std::max({worst, std::fabs(c - std::cos(angle)), std::fabs(s - std::sin(angle))});
        ASSERT_NEAR(c * c + s * s, 1.0f, 4e-7f) << turns;
    }
    EXPECT_LT(worst, 1.5e-7);
    const std::array<float, 5> cosines{1, 0, -1, 0, 1}, sines{0, 1, 0, -1, 0};
    for (std::size_t quarter = 0; quarter <= 4; ++quarter) {
        auto [c, s] = bsdf_detail::cos_sin_turns(0.25f * static_cast<float>(quarter));
        EXPECT_EQ(c, cosines[quarter]) << quarter;
        EXPECT_EQ(s, sines[quarter]) << quarter;
    }
}

// The Phong lobe's inline power agrees with std::pow (in double, rounded to float) for
// every exponent a cpfg material can have (shininess 0..128 / 4: whole quarters), within
// one unit in the last place and exactly in nearly every case; other exponents are
// std::pow's own.
TEST(Material, PhongPowerIsStdPowToFloatRounding)
{
    long checked = 0, differ = 0;
    for (int q = 1; q <= 512; ++q) {
        const float e = static_cast<float>(q) / 4;
        for (int i = 1; i <= 4000; ++i) {
            // Cosines over (0, 1], denser near 1, where a narrow lobe lives.
            const float c = i % 2 ? static_cast<float>(i) / 4000
                                  : 1 - static_cast<float>(i) / 4000 * 1e-3f;
            const float got = bsdf_detail::power(c, e);
            const float want = static_cast<float>(std::pow(static_cast<double>(c), e));
            ++checked;
            if (got == want)
                continue;
            ++differ;
            ASSERT_EQ(std::nextafter(want, got), got) << c << "^" << e;  // one ulp at most
        }
    }
    EXPECT_LT(differ, checked / 100000) << differ << " of " << checked;
    for (float e : {0.3f, 12.7f, 200.0f})  // not whole quarters, or beyond cpfg's range
        EXPECT_EQ(bsdf_detail::power(0.9f, e), std::pow(0.9f, e)) << e;
    EXPECT_EQ(bsdf_detail::power(1.0f, 32), 1.0f);
    EXPECT_EQ(bsdf_detail::power(0.5f, 0.25f), static_cast<float>(std::pow(0.5, 0.25)));
}

// bsdf_sample()'s weight and pdf are bsdf_eval() |cos| / bsdf_pdf() and bsdf_pdf() of the
// direction it draws, for every lobe (it makes the Phong term once for both).
TEST(Material, SampleWeightAndPdfAreEvalAndPdf)
{
    const Bsdf b = make_bsdf(coloured_lobes(12.75f));
    const Vec3f wo = incidence(0.5f);
    int glossy = 0;
    for (int i = 0; i < 2000; ++i) {
        Sampler s(static_cast<std::uint32_t>(i), 0, 0, 1);
        const BsdfSample bs = bsdf_sample(b, up, wo, s.next(), s.next());
        if (!(bs.pdf > 0))
            continue;
        const float pdf = bsdf_pdf(b, up, wo, bs.wi);
        const Vec3f w = bsdf_eval(b, up, wo, bs.wi) * (std::fabs(bs.wi.z) / pdf);
        ASSERT_EQ(bs.pdf, pdf) << i;
        ASSERT_EQ(bs.weight.x, w.x) << i;
        ASSERT_EQ(bs.weight.z, w.z) << i;
        glossy += bsdf_detail::phong_term(b, up, wo, bs.wi) > 0.5f;
    }
    EXPECT_GT(glossy, 20);  // the glossy lobe was drawn and checked too
}

// One BsdfAt, made once for a vertex and then asked about many directions (as the path
// tracer does), gives f and pdf by the normalized Phong formulas written out here, about
// a tilted normal (so a wrong mirror direction shows), and its samples pick the lobe's
// side as u1 says: reflection below w.reflect, transmission up to w.reflect + w.transmit.
TEST(Material, BsdfAtIsTheFormulasForEveryDirection)
{
    const Bsdf b = make_bsdf(coloured_lobes(6.75f));
    const Vec3f n = normalize(Vec3f(0.3f, -0.2f, 0.9f));
    const Vec3f wo = normalize(Vec3f(-0.5f, 0.1f, 0.6f));
    const BsdfAt at = bsdf_at(b, n, wo);
    const double r = (b.reflect.x + b.reflect.y + b.reflect.z) / 3.0,
                 t = (b.transmit.x + b.transmit.y + b.transmit.z) / 3.0,
                 g = (b.glossy.x + b.glossy.y + b.glossy.z) / 3.0, sum = r + t + g;
    const double e = b.exponent;
    const Vec3f axis = n * (2 * dot(n, wo)) - wo;
    int below = 0, lobed = 0;
    for (int i = 0; i < 4000; ++i) {
        Sampler s(static_cast<std::uint32_t>(i), 3, 0, 17);
        const float z = 1 - 2 * s.next(), phi = 2 * pi * s.next();
        const float rad = std::sqrt(std::fmax(0.0f, 1 - z * z));
        const Vec3f wi(rad * std::cos(phi), rad * std::sin(phi), z);
        const double cos_i = dot(n, wi), c = std::fmax(0.0, double(dot(axis, wi)));
        const double phong = c > 0 ? std::pow(c, e) : 0;
        lobed += c > 0.5;
        below += cos_i < 0;
        const double want_f = cos_i < 0 ? b.transmit.y / pi
                                        : b.reflect.y / pi + b.glossy.y * (e + 2) / (2 * pi) * phong;
        const double want_pdf = cos_i < 0 ? t / sum * -cos_i / pi
                                          : r / sum * cos_i / pi + g / sum * (e + 1) / (2 * pi) * phong;
        ASSERT_NEAR(bsdf_eval(at, wi).y, want_f, 1e-5 * want_f + 1e-7) << i;
        ASSERT_NEAR(bsdf_pdf(at, wi), want_pdf, 1e-5 * want_pdf + 1e-7) << i;
        // The same to the bit as the calls that make their own BsdfAt.
        ASSERT_EQ(bsdf_eval(at, wi).x, bsdf_eval(b, n, wo, wi).x) << i;
        ASSERT_EQ(bsdf_pdf(at, wi), bsdf_pdf(b, n, wo, wi)) << i;
    }
    EXPECT_GT(below, 1000);
    EXPECT_GT(lobed, 100);
    for (int i = 0; i < 1000; ++i) {
        const float u1 = (static_cast<float>(i) + 0.5f) / 1000;
        const float u2 = static_cast<float>((i * 7919) % 1000) / 1000;
        const BsdfSample bs = bsdf_sample(at, u1, u2);
        if (u1 < r / sum - 1e-6) {
            ASSERT_GT(dot(n, bs.wi), 0) << u1;
        } else if (u1 > r / sum + 1e-6 && u1 < (r + t) / sum - 1e-6) {
            ASSERT_LT(dot(n, bs.wi), 0) << u1;
        }
        if (!(bs.pdf > 0))
            continue;
        ASSERT_NEAR(bs.pdf, bsdf_pdf(at, bs.wi), 1e-6f * bs.pdf) << u1;
    }
}

// Sampling agrees with quadrature of eval for every lobe mixture: pdf and eval match.
TEST(Material, SamplingMatchesQuadrature)
{
    Bsdf b = make_bsdf(coloured_lobes(8));
    for (float theta : {0.0f, 0.7f, 1.3f}) {
        double pdf_integral = 0;
        Vec3f q = quadrature_albedo(b, incidence(theta), &pdf_integral);
        Vec3f s = sampled_albedo(b, incidence(theta));
        EXPECT_NEAR(s.x, q.x, 0.01f) << theta;
        EXPECT_NEAR(s.y, q.y, 0.01f) << theta;
        EXPECT_NEAR(s.z, q.z, 0.01f) << theta;
        // The pdf integrates to 1 less the glossy samples that fall below the surface
        // (exactly that loss: Chi2.PdfIntegratesToOneLessTheGlossyLossBelowTheSurface).
        EXPECT_LE(pdf_integral, 1.01);
        EXPECT_GT(pdf_integral, 0.7);
    }
}

// Normalized Phong: albedo = specular at normal incidence for any exponent, less (never
// more) at oblique incidence.
TEST(Material, GlossyLobeConservesEnergy)
{
    for (float exponent : {0.0f, 4.0f, 16.0f}) {
        Bsdf b{Vec3f(), Vec3f(), Vec3f(1.0f), exponent};
        double unused = 0;
        Vec3f normal = quadrature_albedo(b, up, &unused);
        EXPECT_NEAR(normal.x, 1.0f, exponent > 8 ? 0.03f : 0.01f) << exponent;
        for (float theta : {0.5f, 1.0f, 1.4f}) {
            Vec3f a = sampled_albedo(b, incidence(theta), 50000);
            EXPECT_LE(a.x, 1.005f) << exponent << " " << theta;
            EXPECT_GT(a.x, 0.1f);  // lost below the horizon at grazing angles
        }
    }
}

// Translucency moves that fraction of the diffuse albedo to the other side.
TEST(Material, TranslucencySplitsDiffuseAlbedo)
{
    SurfaceMaterial m;
    m.diffuse = Vec3f(0.8f);
    m.translucency = 0.25f;
    Bsdf b = make_bsdf(m);
    double below = 0, above = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        Sampler s(static_cast<std::uint32_t>(i), 2, 0, 5);
        BsdfSample bs = bsdf_sample(b, up, incidence(0.4f), s.next(), s.next());
        (bs.wi.z < 0 ? below : above) += bs.weight.x;
    }
    EXPECT_NEAR(below / n, 0.8 * 0.25, 2e-3);
    EXPECT_NEAR(above / n, 0.8 * 0.75, 2e-3);
    EXPECT_NEAR(bsdf_eval(b, up, up, {0, 0, -1}).x, 0.2f / pi, 1e-6f);
}

// Diffuse plus specular never exceeds 1: the diffuse keeps 1 - max(specular).
TEST(Material, GlossyTakesItsShareFromDiffuse)
{
    SurfaceMaterial m;
    m.diffuse = Vec3f(1);
    m.specular = Vec3f(0.25f);
    m.exponent = 10;
    Bsdf b = make_bsdf(m);
    EXPECT_NEAR(b.reflect.x, 0.75f, 1e-6f);
    double unused = 0;
    EXPECT_NEAR(quadrature_albedo(b, up, &unused).x, 1.0f, 0.01f);
}

TEST(Material, MapsCpfgMaterials)
{
    geom::Material g;
    g.diffuse = {0.5f, 0.5f, 0.5f};
    g.specular = {1, 1, 1};
    g.shininess = 64;
    g.transparency = 0.25f;
    g.translucency = 0.4f;
    g.emission = {0.2f, 0, 0};
    SurfaceMaterial m = make_materials({g})[0];
    EXPECT_FLOAT_EQ(m.diffuse.x, srgb_to_linear(0.5f));
    EXPECT_FLOAT_EQ(m.exponent, 16);
    EXPECT_FLOAT_EQ(m.specular.x, 2.0f / 18);  // OpenGL's highlight peak (next test)
    EXPECT_FLOAT_EQ(m.opacity, 0.75f);
    EXPECT_FLOAT_EQ(m.translucency, 0.4f);
    EXPECT_FLOAT_EQ(m.emission.x, srgb_to_linear(0.2f));
}

// cpfg's window adds material ambient x (0.2 + each light's A:) to the lit colour
// (11-sympodial-asym: ambient (49, 39, 0) under two lights turns red fruit orange).
TEST(Material, AmbientGlowIsOpenGLsAmbientTerm)
{
    geom::Light two;
    two.ambient = {0.5f, 1, 1};
    geom::Rgb light = opengl_ambient_light({geom::Light{}, two});
    EXPECT_FLOAT_EQ(light.r, 1.7f);
    EXPECT_FLOAT_EQ(light.g, 2.2f);
    geom::Rgb none = opengl_ambient_light({});  // cpfg's default light: A 1 1 1
    EXPECT_FLOAT_EQ(none.b, 1.2f);

    geom::Material g;
    g.ambient = {49 / 255.0f, 39 / 255.0f, 0};
    g.diffuse = {1, 0, 0};
    SurfaceMaterial m = make_materials({g}, {2.2f, 2.2f, 2.2f})[0];
    EXPECT_FLOAT_EQ(m.ambient_glow.x, srgb_to_linear(49 / 255.0f * 2.2f));
    EXPECT_FLOAT_EQ(m.ambient_glow.y, srgb_to_linear(39 / 255.0f * 2.2f));
    EXPECT_FLOAT_EQ(m.ambient_glow.z, 0);
    g.ambient = {0.9f, 0.9f, 0.9f};  // clamped at 1, as OpenGL clamps the colour
    EXPECT_FLOAT_EQ(make_materials({g}, {2, 2, 2})[0].ambient_glow.x, 1);
    EXPECT_FLOAT_EQ(make_materials({g})[0].ambient_glow.x, 0);  // no ambient light
}

// OpenGL's specular term under a directional light of colour c facing the surface,
// seen from the mirror direction: specular * c * (n.h)^shininess = specular * c. The
// mapped lobe must give the same radiance there (irradiance pi c, radiance f pi c).
TEST(Material, HighlightPeakIsOpenGLs)
{
    geom::Material g;
    g.diffuse = {0, 0, 0};
    g.specular = {1, 1, 1};
    for (float shininess : {0.0f, 16.0f, 128.0f}) {
        g.shininess = shininess;
        Bsdf b = make_bsdf(make_materials({g})[0]);
        float radiance = bsdf_eval(b, up, up, up).x * pi;  // c = 1
        EXPECT_NEAR(radiance, 1.0f, 1e-5f) << "shininess " << shininess;
    }
}

TEST(Material, MixIsLinearInEveryParameter)
{
    SurfaceMaterial a, b;
    a.diffuse = {0.2f, 0.4f, 0.6f};
    b.diffuse = {0.6f, 0.0f, 1.0f};
    a.translucency = 0;
    b.translucency = 0.8f;
    a.specular = {0.1f, 0.1f, 0.1f};
    b.specular = {0.3f, 0.5f, 0.1f};
    a.exponent = 4;
    b.exponent = 36;
    b.emission = {2, 0, 0};
    a.opacity = 1;
    b.opacity = 0.5f;
    SurfaceMaterial m = mix(a, b, 0.25f);
    EXPECT_NEAR(m.diffuse.x, 0.3f, 1e-6f);
    EXPECT_NEAR(m.diffuse.y, 0.3f, 1e-6f);
    EXPECT_NEAR(m.diffuse.z, 0.7f, 1e-6f);
    EXPECT_NEAR(m.translucency, 0.2f, 1e-6f);
    EXPECT_NEAR(m.specular.y, 0.2f, 1e-6f);
    EXPECT_NEAR(m.exponent, 12, 1e-5f);
    EXPECT_NEAR(m.emission.x, 0.5f, 1e-6f);
    EXPECT_NEAR(m.opacity, 0.875f, 1e-6f);
    SurfaceMaterial end = mix(a, b, 1);
    EXPECT_NEAR(end.diffuse.x, 0.6f, 1e-6f);
    EXPECT_NEAR(end.opacity, 0.5f, 1e-6f);
}

}  // namespace
}  // namespace cambium::render
