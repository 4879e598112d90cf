// SPDX-License-Identifier: Apache-2.0
// Environments: densities integrate to one, sample() agrees with pdf(), maps read right.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sys/stat.h>
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
    Sampler s(1, 2, 3, 4, SampleSequence::white);
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
Environment patchy_map()
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
    EXPECT_NEAR(pdf_integral(env, 1000), 1.0, 1e-6);
    EnvironmentSample s = env.sample(0.3f, 0.7f);
    EXPECT_NEAR(length(s.direction), 1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(s.pdf, 1 / (4 * pi));
    EXPECT_EQ(s.radiance, Vec3f(0.1f, 0.2f, 0.3f));
    EXPECT_FALSE(env.black());
    EXPECT_TRUE(make_uniform_environment(Vec3f()).black());
    EXPECT_TRUE(env.uniform());
    EXPECT_EQ(env.kind(), Environment::Kind::uniform);
}

TEST(MapEnvironment, PdfIntegratesToOne)
{
    EXPECT_NEAR(pdf_integral(patchy_map(), 400000), 1.0, 0.01);
}

TEST(MapEnvironment, SamplesCarryTheirOwnPdfAndRadiance)
{
    auto env = patchy_map();
    Sampler s(9, 9, 9, 9);
    int mismatched = 0, n = 20000, patch_hits = 0;
    for (int i = 0; i < n; ++i) {
        EnvironmentSample e = env.sample(s.next(), s.next());
        ASSERT_NEAR(length(e.direction), 1.0f, 1e-4f);
        ASSERT_GT(e.pdf, 0.0f);
        // A sample on a texel border may be looked up in the neighbour texel.
        if (std::abs(env.pdf(e.direction) - e.pdf) > 1e-3f * e.pdf ||
            !(env.radiance(e.direction) == e.radiance))
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
        ASSERT_EQ(map.radiance(d), uniform.radiance(d));
        // Uniform in solid angle within each texel: exactly the sphere's density.
        ASSERT_NEAR(map.pdf(d), uniform.pdf(d), 1e-3f * uniform.pdf(d)) << d.y;
        EnvironmentSample e = map.sample(s.next(), s.next());
        integral += e.radiance.y / e.pdf;
    }
    EXPECT_NEAR(integral / n, 4 * std::numbers::pi * L.y, 0.01 * 4 * std::numbers::pi * L.y);
    EXPECT_FALSE(map.black());
    EXPECT_TRUE(map.uniform());  // so the integrator leaves it to BSDF sampling
    EXPECT_EQ(map.kind(), Environment::Kind::map);
    EXPECT_FALSE(patchy_map().uniform());
    EXPECT_FALSE(make_sky_environment().uniform());
}

TEST(MapEnvironment, ReadsLatLongFilesWithUpAtTheTopMinusZInTheCentreAndMinusXLeft)
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
    set(2, 1, 0, 0, 3);      // a quarter in from the left: toward -x (seen from inside)
    set(6, 1, 4, 4, 0);      // a quarter in from the right: toward +x
    {
        auto out = OIIO::ImageOutput::create(file.string());
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(out->open(file.string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
        out->close();
    }
    auto env = make_map_environment(file, 2.0f);
    EXPECT_EQ(env.radiance({0, 1, 0}), Vec3f(10, 0, 0));
    // Row 1 covers polar angles 45..90 deg; (0, 0.5, -1) is at 63 deg, column 4 of 8.
    EXPECT_EQ(env.radiance(normalize({0, 0.5f, -1})), Vec3f(0, 14, 0));
    EXPECT_EQ(env.radiance(normalize({0, 0.5f, 1})), Vec3f(2, 2, 2));
    // Looking along -z with +y up, -x is on the left: the image is not mirrored.
    EXPECT_EQ(env.radiance(normalize({-1, 0.5f, -0.2f})), Vec3f(0, 0, 6));
    EXPECT_EQ(env.radiance(normalize({1, 0.5f, 0.2f})), Vec3f(8, 8, 0));
    EXPECT_EQ(env.radiance({0, -1, 0}), Vec3f(2, 2, 2));
    std::filesystem::remove_all(dir);
    EXPECT_THROW(make_map_environment(dir / "missing.exr"), Error);
    EXPECT_THROW(make_map_environment(0, 4, {}), Error);
    EXPECT_THROW(make_map_environment(2, 2, std::vector<float>(5)), Error);
}

// OpenEXR allocates an attribute's declared size before reading it: an attribute that
// declares more bytes than the file holds is refused before OpenImageIO opens the file
// (a 600-byte file once asked for 1.8 GB).
TEST(Environment, ExrAttributeLargerThanTheFileIsRefusedBeforeReading)
{
    auto dir = std::filesystem::temp_directory_path() /
               ("cambium_env_attribute_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto file = dir / "huge.exr";
    std::string bytes("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
    bytes += std::string("comments\0string\0", 16);
    bytes += std::string("\x00\x00\x00\x70", 4);  // 0x70000000 bytes
    bytes += "abc";
    std::ofstream(file, std::ios::binary) << bytes;
    std::string message;
    try {
        make_map_environment(file, 1.0f);
    } catch (const Error& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("huge.exr: error: is not a valid OpenEXR file: the header's attribute "
                           "'comments' declares 1879048192 bytes, more than the 3 the file has left"),
              std::string::npos)
        << message;
    std::filesystem::remove_all(dir);
}

// A map whose header declares many channels is decoded in its first three only (the
// texel limit does not multiply by channels); the others never reach the radiance.
TEST(Environment, MapWithManyChannelsUsesItsFirstThree)
{
    auto dir = std::filesystem::temp_directory_path() /
               ("cambium_env_channels_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto file = dir / "many.exr";
    const int w = 8, h = 4, channels = 64;
    std::vector<float> values(std::size_t(w) * h * channels, 100.0f);
    for (std::size_t p = 0; p < std::size_t(w) * h; ++p)
        for (int c = 0; c < 3; ++c)
            values[p * channels + std::size_t(c)] = float(c + 1);
    {
        auto out = OIIO::ImageOutput::create(file.string());
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(out->open(file.string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data()));
        out->close();
    }
    auto env = make_map_environment(file, 1.0f);
    EXPECT_EQ(env.radiance({0, 1, 0}), Vec3f(1, 2, 3));
    EXPECT_EQ(env.radiance({0, -1, 0}), Vec3f(1, 2, 3));
    std::filesystem::remove_all(dir);
}

// OpenImageIO decodes every channel of a chunk before it keeps three, so a map's values
// are bounded, not only its texels: a header declaring 8192x4096 texels (the texel limit)
// of five channels is refused before a value is read. The file is a small map whose
// windows are rewritten and zeros appended where the taller window's chunk offsets go.
TEST(Environment, MapWhoseChannelsExceedTheValueLimitIsRefusedBeforeReading)
{
    auto dir = std::filesystem::temp_directory_path() /
               ("cambium_env_values_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto file = dir / "wide.exr";
    {
        std::vector<float> values(8 * 4 * 5, 1.0f);
        auto out = OIIO::ImageOutput::create(file.string());
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(8, 4, 5, OIIO::TypeDesc::FLOAT);
        ASSERT_TRUE(out->open(file.string(), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data()));
        out->close();
    }
    std::string bytes;
    {
        std::ifstream in(file, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    for (const char* window : {"dataWindow", "displayWindow"}) {
        const std::string key = std::string(window) + std::string("\0box2i\0\x10\0\0\0", 11);
        const std::size_t at = bytes.find(key);
        ASSERT_NE(at, std::string::npos) << window;
        const std::int32_t box[4] = {0, 0, 8191, 4095};  // little-endian, as on x86
        std::memcpy(bytes.data() + at + key.size(), box, sizeof box);
    }
    bytes.append(std::size_t{1} << 16, '\0');  // room for the taller window's chunk offsets
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
    std::string message;
    try {
        make_map_environment(file, 1.0f);
    } catch (const Error& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("wide.exr: error: environment map of 8192x4096 texels with 5 channels "
                           "holds 167772160 values, more than the 134217728"),
              std::string::npos)
        << message;
    std::filesystem::remove_all(dir);
}

// A FIFO named as a map would block the reader for ever: it is refused before opening.
TEST(Environment, MapThatIsNotARegularFileIsRefused)
{
    auto dir = std::filesystem::temp_directory_path() /
               ("cambium_env_fifo_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto fifo = dir / "sky.exr";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    for (const auto& file : {fifo, dir}) {
        std::string message;
        try {
            make_map_environment(file, 1.0f);
        } catch (const Error& e) {
            message = e.what();
        }
        EXPECT_NE(message.find("cannot open the environment map: not a regular file"),
                  std::string::npos)
            << message;
    }
    std::filesystem::remove_all(dir);
}

/// A Monte Carlo estimate and its standard error.
struct Estimate {
    double mean = 0, se = 0;
};

/// The mean of f over n draws and its standard error.
template <typename F>
Estimate estimate(int n, F f)
{
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        double v = f();
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / n, var = std::max(0.0, sum2 / n - mean * mean);
    return {mean, std::sqrt(var / (n - 1))};
}

/// A direction drawn uniformly in the cone of half-angle acos(cos_max) about the unit axis.
Vec3f uniform_in_cone(const Vec3f& axis, float cos_max, Sampler& s)
{
    float cos_t = 1 - s.next() * (1 - cos_max), sin_t = std::sqrt(1 - cos_t * cos_t);
    float phi = 2 * pi * s.next();
    Vec3f t, b;
    make_basis(axis, t, b);
    return normalize(t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi)) + axis * cos_t);
}

// The sun's cone is 7e-5 sr: uniform sampling of the sphere finds it about once in
// 100 000 draws, so the density is integrated over the cone and over the rest of the
// sphere separately (each by uniform samples of its own domain), with a tolerance of
// 5 standard errors of those very estimates. The sampled directions' share in the cone
// is checked against that integral (binomial, 5 standard errors), for several seeds.
TEST(SkyEnvironment, PdfIsTheSunAndSphereMixtureAndSamplesAgree)
{
    SkyParameters p;
    p.sun_direction = normalize({0.3f, 0.8f, 0.2f});
    Environment sky = make_sky_environment(p);
    const Vec3f sun = p.sun_direction;
    const float cos_sun = std::cos(0.2665f * pi / 180);
    const double cone = 2 * std::numbers::pi * (1 - double(cos_sun));
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
        Sampler s(1, 2, 3, seed, SampleSequence::white);
        Estimate in_cone =
            estimate(20000, [&] { return sky.pdf(uniform_in_cone(sun, cos_sun, s)); });
        Estimate outside = estimate(100000, [&] {
            Vec3f d = uniform_direction(s);
            return dot(d, sun) >= cos_sun ? 0.0 : double(sky.pdf(d));
        });
        double sun_mass = in_cone.mean * cone;
        double integral = sun_mass + outside.mean * 4 * std::numbers::pi;
        double se = std::hypot(in_cone.se * cone, outside.se * 4 * std::numbers::pi);
        EXPECT_NEAR(integral, 1.0, 5 * se + 1e-5) << "seed " << seed;
        // The sun's strategy takes its share of the power, within [1/4, 3/4], and the
        // density says so.
        EXPECT_GE(sun_mass, 0.25 - 5 * in_cone.se * cone) << "seed " << seed;
        EXPECT_LE(sun_mass, 0.75 + 5 * in_cone.se * cone) << "seed " << seed;

        int in_sun = 0, n = 100000;
        for (int i = 0; i < n; ++i) {
            EnvironmentSample e = sky.sample(s.next(), s.next());
            ASSERT_NEAR(length(e.direction), 1.0f, 1e-5f);
            ASSERT_NEAR(e.pdf, sky.pdf(e.direction), 1e-3f * e.pdf);
            ASSERT_EQ(e.radiance, sky.radiance(e.direction));
            in_sun += dot(e.direction, sun) >= cos_sun ? 1 : 0;
        }
        double share = double(in_sun) / n;
        EXPECT_NEAR(share, sun_mass, 5 * std::sqrt(sun_mass * (1 - sun_mass) / n))
            << "seed " << seed;
    }
}

// The dome drawn for a surface facing up (the ground) follows luminance times the cosine
// to +y: its density integrates to 1, nothing lies below the horizon, samples agree with
// pdf_without_sun_facing_up(), and the irradiance estimate on a horizontal surface is the
// dome's irradiance (integrated by uniform samples of the hemisphere) with a relative
// spread per sample of a few percent (the cells' variation of radiance times cosine), where
// drawing by radiance alone spreads by the cosine's whole range and wastes the samples
// below the horizon (measured 4.4% and 110%).
TEST(SkyEnvironment, DomeFacingUpFollowsRadianceTimesCosine)
{
    SkyParameters p;
    p.sun_direction = normalize({0.3f, 0.8f, 0.2f});
    Environment sky = make_sky_environment(p);
    Sampler s(4, 5, 6, 7, SampleSequence::white);
    Estimate density = estimate(200000, [&] {
        return double(sky.pdf_without_sun_facing_up(uniform_direction(s))) * 4 * pi;
    });
    EXPECT_NEAR(density.mean, 1.0, 5 * density.se);
    EXPECT_EQ(sky.pdf_without_sun_facing_up(normalize(Vec3f{0.3f, -0.1f, 0.2f})), 0.0f);

    auto irradiance_y = [&](const EnvironmentSample& e) {
        return e.pdf > 0 ? double(e.radiance.y) * std::max(0.0f, e.direction.y) / e.pdf : 0.0;
    };
    Estimate truth = estimate(400000, [&] {
        Vec3f d = uniform_direction(s);
        d.y = std::abs(d.y);
        return double(sky.radiance_without_sun(d).y) * d.y * 2 * pi;
    });
    const int n = 100000;
    int other_cell = 0;  // a direction rounded onto a cell border reads the neighbour's density
    Estimate up = estimate(n, [&] {
        EnvironmentSample e = sky.sample_without_sun_facing_up(s.next(), s.next());
        EXPECT_GE(e.direction.y, 0.0f);
        other_cell += std::abs(e.pdf - sky.pdf_without_sun_facing_up(e.direction)) > 1e-3f * e.pdf;
        EXPECT_EQ(e.radiance, sky.radiance_without_sun(e.direction));
        return irradiance_y(e);
    });
    EXPECT_LT(other_cell, n / 1000);
    Estimate plain = estimate(n, [&] {
        return irradiance_y(sky.sample_without_sun(s.next(), s.next()));
    });
    EXPECT_NEAR(up.mean, truth.mean, 5 * std::hypot(up.se, truth.se));
    const double spread_up = up.se * std::sqrt(double(n)) / up.mean;
    const double spread_plain = plain.se * std::sqrt(double(n)) / plain.mean;
    std::printf("[dome facing up] irradiance %.4f (uniform: %.4f +- %.4f), relative spread "
                "per sample %.3f facing up, %.3f by radiance alone\n",
                up.mean, truth.mean, truth.se, spread_up, spread_plain);
    EXPECT_LT(spread_up, 0.05);
    EXPECT_GT(spread_plain, 0.3);
}

// Under an opaque ground the ground's points draw the map by luminance times the cosine
// to +y: the density integrates to 1 and is 0 below the horizon, samples carry their own
// density and radiance, the irradiance on a horizontal surface is the map's (by uniform
// integration), and it varies less from sample to sample than when drawn by luminance
// alone.
TEST(MapEnvironment, FacingUpFollowsRadianceTimesCosineUnderAnOpaqueGround)
{
    EXPECT_FALSE(patchy_map().samples_facing_up());
    const Environment map = patchy_map().hidden_below_horizon();
    ASSERT_TRUE(map.samples_facing_up());
    Sampler s(4, 5, 6, 7, SampleSequence::white);
    Estimate density = estimate(200000, [&] {
        return double(map.pdf_without_sun_facing_up(uniform_direction(s))) * 4 * pi;
    });
    EXPECT_NEAR(density.mean, 1.0, 5 * density.se);
    EXPECT_EQ(map.pdf_without_sun_facing_up(normalize(Vec3f{0.3f, -0.1f, 0.2f})), 0.0f);

    auto irradiance_y = [&](const EnvironmentSample& e) {
        return e.pdf > 0 ? double(e.radiance.y) * std::max(0.0f, e.direction.y) / e.pdf : 0.0;
    };
    Estimate truth = estimate(400000, [&] {
        Vec3f d = uniform_direction(s);
        d.y = std::abs(d.y);
        return double(map.radiance(d).y) * d.y * 2 * pi;
    });
    const int n = 100000;
    int other_cell = 0;  // a direction rounded onto a cell border reads the neighbour's
    Estimate up = estimate(n, [&] {
        EnvironmentSample e = map.sample_without_sun_facing_up(s.next(), s.next());
        EXPECT_GE(e.direction.y, 0.0f);
        other_cell += std::abs(e.pdf - map.pdf_without_sun_facing_up(e.direction)) > 1e-3f * e.pdf ||
                      !(e.radiance == map.radiance(e.direction));
        return irradiance_y(e);
    });
    EXPECT_LT(other_cell, n / 500);
    Estimate plain = estimate(n, [&] { return irradiance_y(map.sample(s.next(), s.next())); });
    EXPECT_NEAR(up.mean, truth.mean, 5 * std::hypot(up.se, truth.se));
    const double spread_up = up.se * std::sqrt(double(n)) / up.mean;
    const double spread_plain = plain.se * std::sqrt(double(n)) / plain.mean;
    std::printf("[map facing up] irradiance %.4f (uniform: %.4f +- %.4f), relative spread "
                "per sample %.3f facing up, %.3f by luminance alone\n",
                up.mean, truth.mean, truth.se, spread_up, spread_plain);
    EXPECT_LT(spread_up, 0.5 * spread_plain);
}

// Sun at the zenith, turbidity 3: outside the atmosphere it gives irradiance
// pi * sun_intensity; Rayleigh (0.008735 lambda^-4.08) and Angstrom aerosol (beta
// lambda^-1.3, beta = 0.04608 T - 0.04586) optical depths at 0.65 and 0.45 um over one
// air mass (Kasten & Young at zenith angle 0) dim it.
TEST(SkyEnvironment, SunDiskDeliversTheStatedIrradiance)
{
    SkyParameters p;
    p.sun_direction = {0, 1, 0};
    p.turbidity = 3;
    p.sun_intensity = 2;
    auto sky = make_sky_environment(p);
    float cos_sun = std::cos(0.2665f * pi / 180);
    float solid_angle = 2 * pi * (1 - cos_sun);
    Vec3f inside = sky.radiance({0, 1, 0});
    Vec3f outside = sky.radiance(normalize({0.01f, 1, 0}));  // 0.57 deg off: sky only
    Vec3f sun = (inside - outside) * solid_angle;
    double airmass = 1 / (1 + 0.50572 * std::pow(96.07995, -1.6364));
    double beta = 0.04608 * 3 - 0.04586;
    auto transmitted = [&](double um) {
        double tau = 0.008735 * std::pow(um, -4.08) + beta * std::pow(um, -1.3);
        return std::exp(-airmass * tau);
    };
    EXPECT_NEAR(sun.x, pi * 2 * transmitted(0.65), 2e-3 * sun.x);
    EXPECT_NEAR(sun.z, pi * 2 * transmitted(0.45), 2e-3 * sun.z);
    EXPECT_GT(sun.x, sun.z);  // the direct sun is yellowish
    // Zenith bluer than red.
    EXPECT_GT(outside.z, outside.x);
    EXPECT_FALSE(sky.black());
    // A sun below the horizon has no disk and is never sampled.
    p.sun_direction = {0, -1, 0};
    auto night = make_sky_environment(p);
    EXPECT_EQ(night.pdf({0, -1, 0}), 0.0f);  // nothing to sample: black everywhere
    EXPECT_TRUE(night.black());  // 90 degrees down: past civil twilight
}

/// CIE xy of linear sRGB (D65 matrix of IEC 61966-2-1).
std::pair<double, double> chromaticity(const Vec3f& c)
{
    double X = 0.4124 * c.x + 0.3576 * c.y + 0.1805 * c.z;
    double Y = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    double Z = 0.0193 * c.x + 0.1192 * c.y + 0.9505 * c.z;
    return {X / (X + Y + Z), Y / (X + Y + Z)};
}

// Preetham et al. 1999, appendix: zenith luminance Y_z (kcd/m^2) and chromaticity from
// the turbidity T and the sun's zenith angle; the environment's unit is 128000 / pi cd/m^2.
TEST(SkyEnvironment, ZenithMatchesPreethamFormulas)
{
    for (double turbidity : {2.0, 3.0, 6.0})
        for (double elevation_deg : {20.0, 45.0, 70.0}) {
            double theta_s = (90 - elevation_deg) * std::numbers::pi / 180;
            double chi = (4.0 / 9 - turbidity / 120) * (std::numbers::pi - 2 * theta_s);
            double yz = (4.0453 * turbidity - 4.9710) * std::tan(chi) - 0.2155 * turbidity +
                        2.4192;
            double t = turbidity, th = theta_s;
            double xz = t * t * (0.00166 * th * th * th - 0.00375 * th * th + 0.00209 * th) +
                        t * (-0.02903 * th * th * th + 0.06377 * th * th - 0.03202 * th +
                             0.00394) +
                        (0.11693 * th * th * th - 0.21196 * th * th + 0.06052 * th + 0.25886);
            SkyParameters p;
            double e = elevation_deg * std::numbers::pi / 180;
            p.sun_direction = {float(std::cos(e)), float(std::sin(e)), 0};
            p.turbidity = float(turbidity);
            auto sky = make_sky_environment(p);
            Vec3f zenith = sky.radiance({0, 1, 0});
            double expect = yz * 1000 / (128000 / std::numbers::pi);
            EXPECT_NEAR(luminance(zenith), expect, 2e-3 * expect)
                << "T " << turbidity << " elevation " << elevation_deg;
            EXPECT_NEAR(chromaticity(zenith).first, xz, 2e-3)
                << "T " << turbidity << " elevation " << elevation_deg;
        }
}

// The sky is brightest around the sun (Perez circumsolar term); hazier skies are whiter
// (less saturated blue) away from the sun.
TEST(SkyEnvironment, BrighterNearTheSunAndWhiterWhenHazy)
{
    SkyParameters p;
    float e = 30 * pi / 180;
    p.sun_direction = {std::cos(e), std::sin(e), 0};
    auto sky = make_sky_environment(p);
    auto at = [&](float azimuth_deg) {
        float a = azimuth_deg * pi / 180;
        return luminance(sky.radiance({std::cos(e) * std::cos(a), std::sin(e),
                                        std::cos(e) * std::sin(a)}));
    };
    EXPECT_GT(at(5), 2 * at(90));
    EXPECT_GT(at(90), 0.0f);
    EXPECT_GT(at(5), at(20));
    Vec3f away = sky.radiance(normalize({-1, 0.5f, 0}));
    p.turbidity = 8;
    Vec3f hazy = make_sky_environment(p).radiance(normalize({-1, 0.5f, 0}));
    EXPECT_GT(away.z / away.x, hazy.z / hazy.x);
}

// A map of one bright texel, turned by 90 degrees about +y: the light comes from the
// bright texel's direction d turned right-handedly, R_y(90) d = (d.z, d.y, -d.x).
TEST(RotatedEnvironment, LightComesFromTheTurnedDirection)
{
    const int w = 32, h = 16;
    std::vector<float> rgb(std::size_t(w) * h * 3, 0.01f);
    const int bi = 4, bj = 5;  // bright texel
    for (int c = 0; c < 3; ++c)
        rgb[(std::size_t(bj) * w + bi) * 3 + c] = 1000;
    // Its centre direction from the documented layout (t = pi v, p = 2 pi u).
    float theta = pi * (bj + 0.5f) / h, phi = 2 * pi * (bi + 0.5f) / w;
    Vec3f d0{-std::sin(theta) * std::sin(phi), std::cos(theta),
             std::sin(theta) * std::cos(phi)};
    Environment map = make_map_environment(w, h, rgb);
    EXPECT_GT(map.radiance(d0).x, 100.0f);
    Environment turned = map.rotated(90);
    EXPECT_EQ(turned.rotation_degrees(), 90);
    EXPECT_EQ(map.rotation_degrees(), 0);  // a turned copy: the map itself is as it was
    Vec3f d1{d0.z, d0.y, -d0.x};
    EXPECT_GT(turned.radiance(d1).x, 100.0f);
    EXPECT_LT(turned.radiance(d0).x, 1.0f);
    EXPECT_NEAR(turned.pdf(d1), map.pdf(d0), 1e-6f * map.pdf(d0));
    // The density is nearly all in one texel (1/512 of the sphere): a midpoint rule over
    // (cos theta, phi), not uniform random directions, integrates it.
    double integral = 0;
    const int nc = 1024, np = 2048;
    for (int i = 0; i < nc; ++i) {
        float c = 1 - 2 * (i + 0.5f) / nc, sn = std::sqrt(std::max(0.0f, 1 - c * c));
        for (int j = 0; j < np; ++j) {
            float ph = 2 * pi * (j + 0.5f) / np;
            integral += turned.pdf({sn * std::cos(ph), c, sn * std::sin(ph)});
        }
    }
    EXPECT_NEAR(integral * 4 * std::numbers::pi / (double(nc) * np), 1.0, 0.01);
    // Nearly all samples come from around d1, and agree with pdf().
    Sampler s(3, 3, 3, 3, SampleSequence::white);
    int near = 0, n = 2000;
    for (int i = 0; i < n; ++i) {
        EnvironmentSample e = turned.sample(s.next(), s.next());
        ASSERT_NEAR(e.pdf, turned.pdf(e.direction), 1e-3f * e.pdf);
        near += dot(e.direction, d1) > 0.95f ? 1 : 0;
    }
    EXPECT_GT(near, n * 9 / 10);
    // +90 then -90 is the identity: the angles add up to no turn at all.
    Environment back = std::move(turned).rotated(-90);
    EXPECT_EQ(back.rotation_degrees(), 0);
    EXPECT_EQ(back.radiance(d0), map.radiance(d0));
    EXPECT_EQ(back.pdf(d0), map.pdf(d0));
    EXPECT_THROW((void)map.rotated(std::nanf("")), Error);
    EXPECT_THROW((void)map.rotated(INFINITY), Error);
}

}  // namespace
}  // namespace cambium::render
