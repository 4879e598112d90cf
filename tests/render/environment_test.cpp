// SPDX-License-Identifier: Apache-2.0
// Environments: densities integrate to one, sample() agrees with pdf(), maps read right.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <unistd.h>

#include "base/diagnostics.h"
#include "render/environment.h"
#include "render/sampler.h"

namespace cambium::render {
namespace {

constexpr float pi = std::numbers::pi_v<float>;

Vec3f uniform_direction(Sampler& s)
{
    float z = 1 - 2 * s.next(), r = std::sqrt(std::max(0.0f, 1 - z * z));
    float phi = 2 * pi * s.next();
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Monte Carlo estimate of the integral of pdf() over the sphere (should be 1).
double pdf_integral(const Environment& env, int n)
{
    Sampler s(1, 2, 3, 4);
    double sum = 0;
    for (int i = 0; i < n; ++i)
        sum += env.pdf(uniform_direction(s));
    return sum / n * 4 * std::numbers::pi;
}

bool in_patch(int i, int j) { return i >= 20 && i < 24 && j >= 4 && j < 7; }

float patchy_texel(int i, int j, int c)
{
    return 0.2f + 0.05f * i + (in_patch(i, j) ? 3.0f : 0.0f) + 0.1f * c;
}

/// A map with a smooth gradient and a brighter patch: not constant, not too peaky.
std::unique_ptr<Environment> patchy_map()
{
    int w = 32, h = 16;
    std::vector<float> rgb(std::size_t(w) * h * 3);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            for (int c = 0; c < 3; ++c)
                rgb[(std::size_t(j) * w + i) * 3 + c] = patchy_texel(i, j, c);
    return make_map_environment(w, h, std::move(rgb));
}

TEST(Environment, UniformIsConstantWithTheSpherePdf)
{
    auto env = make_uniform_environment({0.1f, 0.2f, 0.3f});
    EXPECT_NEAR(pdf_integral(*env, 1000), 1.0, 1e-6);
    EnvironmentSample s = env->sample(0.3f, 0.7f);
    EXPECT_NEAR(length(s.direction), 1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(s.pdf, 1 / (4 * pi));
    EXPECT_EQ(s.radiance, Vec3f(0.1f, 0.2f, 0.3f));
    EXPECT_FALSE(env->black());
    EXPECT_TRUE(make_uniform_environment(Vec3f())->black());
}

TEST(MapEnvironment, PdfIntegratesToOne)
{
    EXPECT_NEAR(pdf_integral(*patchy_map(), 400000), 1.0, 0.01);
}

TEST(MapEnvironment, SamplesCarryTheirOwnPdfAndRadiance)
{
    auto env = patchy_map();
    Sampler s(9, 9, 9, 9);
    int mismatched = 0, n = 20000, patch_hits = 0;
    for (int i = 0; i < n; ++i) {
        EnvironmentSample e = env->sample(s.next(), s.next());
        ASSERT_NEAR(length(e.direction), 1.0f, 1e-4f);
        ASSERT_GT(e.pdf, 0.0f);
        // A sample on a texel border may be looked up in the neighbour texel.
        if (std::abs(env->pdf(e.direction) - e.pdf) > 1e-3f * e.pdf ||
            !(env->radiance(e.direction) == e.radiance))
            ++mismatched;
        patch_hits += e.radiance.x > 3.0f ? 1 : 0;
    }
    EXPECT_LT(mismatched, n / 500);
    // Texels are drawn in proportion to luminance times their solid angle.
    double patch = 0, all = 0;
    for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 32; ++i) {
            double lum = 0.2126 * patchy_texel(i, j, 0) + 0.7152 * patchy_texel(i, j, 1) +
                         0.0722 * patchy_texel(i, j, 2);
            double weight = lum * (std::cos(std::numbers::pi * j / 16) -
                                   std::cos(std::numbers::pi * (j + 1) / 16));
            all += weight;
            patch += in_patch(i, j) ? weight : 0;
        }
    EXPECT_NEAR(double(patch_hits) / n, patch / all, 0.01);
    EXPECT_GT(patch / all, 0.08);  // far above the patch's 2.3% share of the texels
}

// Importance sampling makes radiance / pdf nearly constant; its mean is the integral of
// the radiance, 4 pi L for a constant map whatever the pdf.
TEST(MapEnvironment, ConstantMapEqualsTheUniformEnvironment)
{
    int w = 64, h = 32;
    Vec3f L{0.5f, 0.25f, 1.0f};
    std::vector<float> rgb;
    for (int i = 0; i < w * h; ++i)
        rgb.insert(rgb.end(), {L.x, L.y, L.z});
    auto map = make_map_environment(w, h, std::move(rgb));
    auto uniform = make_uniform_environment(L);
    Sampler s(5, 6, 7, 8);
    double integral = 0;
    int n = 50000;
    for (int i = 0; i < n; ++i) {
        Vec3f d = uniform_direction(s);
        ASSERT_EQ(map->radiance(d), uniform->radiance(d));
        // Uniform in solid angle within each texel: exactly the sphere's density.
        ASSERT_NEAR(map->pdf(d), uniform->pdf(d), 1e-3f * uniform->pdf(d)) << d.y;
        EnvironmentSample e = map->sample(s.next(), s.next());
        integral += e.radiance.y / e.pdf;
    }
    EXPECT_NEAR(integral / n, 4 * std::numbers::pi * L.y, 0.01 * 4 * std::numbers::pi * L.y);
    EXPECT_FALSE(map->black());
}

TEST(MapEnvironment, ReadsLatLongFilesWithUpAtTheTopAndMinusZInTheCentre)
{
    auto dir = std::filesystem::temp_directory_path() /
               ("cambium_env_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto file = dir / "map.exr";
    int w = 8, h = 4;
    std::vector<float> rgb(std::size_t(w) * h * 3, 1.0f);
    auto set = [&](int i, int j, float r, float g, float b) {
        float* p = &rgb[(std::size_t(j) * w + i) * 3];
        p[0] = r;
        p[1] = g;
        p[2] = b;
    };
    for (int i = 0; i < w; ++i)
        set(i, 0, 5, 0, 0);  // the top row: straight up
    set(4, 1, 0, 7, 0);      // centre column, just above the horizon: toward -z
    {
        auto out = OIIO::ImageOutput::create(file.string());
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(out->open(file.string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
        out->close();
    }
    auto env = make_map_environment(file, 2.0f);
    EXPECT_EQ(env->radiance({0, 1, 0}), Vec3f(10, 0, 0));
    // Row 1 covers polar angles 45..90 deg; (0, 0.5, -1) is at 63 deg, column 4 of 8.
    EXPECT_EQ(env->radiance(normalize({0, 0.5f, -1})), Vec3f(0, 14, 0));
    EXPECT_EQ(env->radiance(normalize({0, 0.5f, 1})), Vec3f(2, 2, 2));
    EXPECT_EQ(env->radiance({0, -1, 0}), Vec3f(2, 2, 2));
    std::filesystem::remove_all(dir);
    EXPECT_THROW(make_map_environment(dir / "missing.exr"), Error);
    EXPECT_THROW(make_map_environment(0, 4, {}), Error);
    EXPECT_THROW(make_map_environment(2, 2, std::vector<float>(5)), Error);
}

TEST(SkyEnvironment, PdfIsTheSunAndSphereMixtureAndSamplesAgree)
{
    SkyParameters p;
    p.sun_direction = normalize({0.3f, 0.8f, 0.2f});
    auto sky = make_sky_environment(p);
    // Uniform Monte Carlo misses the tiny sun cone: it sees (1 - 1/2) of the mass.
    EXPECT_NEAR(pdf_integral(*sky, 100000), 0.5, 1e-3);
    Sampler s(1, 1, 1, 1);
    int in_sun = 0, n = 20000;
    float cos_sun = std::cos(0.2665f * pi / 180);
    for (int i = 0; i < n; ++i) {
        EnvironmentSample e = sky->sample(s.next(), s.next());
        ASSERT_NEAR(e.pdf, sky->pdf(e.direction), 1e-3f * e.pdf);
        in_sun += dot(e.direction, p.sun_direction) >= cos_sun ? 1 : 0;
    }
    EXPECT_NEAR(double(in_sun) / n, 0.5, 0.02);
    // The sun's share of the density integrates to 1/2 over its cone.
    float solid_angle = 2 * pi * (1 - cos_sun);
    float sun_share = (sky->pdf(p.sun_direction) - sky->pdf(-p.sun_direction)) * solid_angle;
    EXPECT_NEAR(sun_share, 0.5f, 1e-3f);
}

// Sun at the zenith, turbidity 3: colour exp(-(0.02, 0.04, 0.08)); its disk gives
// irradiance pi * sun_intensity * colour.
TEST(SkyEnvironment, SunDiskDeliversTheStatedIrradiance)
{
    SkyParameters p;
    p.sun_direction = {0, 1, 0};
    p.turbidity = 3;
    p.sun_intensity = 2;
    auto sky = make_sky_environment(p);
    float cos_sun = std::cos(0.2665f * pi / 180);
    float solid_angle = 2 * pi * (1 - cos_sun);
    Vec3f inside = sky->radiance({0, 1, 0});
    Vec3f outside = sky->radiance(normalize({0.01f, 1, 0}));  // 0.57 deg off: sky only
    Vec3f sun = (inside - outside) * solid_angle;
    EXPECT_NEAR(sun.x, pi * 2 * std::exp(-0.02f), 2e-3f * sun.x);
    EXPECT_NEAR(sun.z, pi * 2 * std::exp(-0.08f), 2e-3f * sun.z);
    // Zenith bluer than red; the ground below is dimmer than the zenith sky's blue.
    EXPECT_GT(outside.z, outside.x);
    EXPECT_FALSE(sky->black());
    // A sun below the horizon has no disk and is never sampled.
    p.sun_direction = {0, -1, 0};
    auto night = make_sky_environment(p);
    EXPECT_FLOAT_EQ(night->pdf({0, -1, 0}), 1 / (4 * pi));
}

}  // namespace
}  // namespace cambium::render
