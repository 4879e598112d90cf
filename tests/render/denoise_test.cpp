// SPDX-License-Identifier: Apache-2.0
// The denoiser on synthetic frames (docs/denoise.md): noise removed from a flat image
// within a derived bound, edges between albedos and organs not crossed, the result
// independent of the thread count; and end to end, rendered and written as EXR.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <vector>

#include "base/diagnostics.h"
#include "render/denoise.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

/// A synthetic frame: its layers and the spans a DenoiseInput reads.
struct Frame {
    int w = 0, h = 0;
    std::vector<float> beauty, variance, albedo, normal, depth;
    std::vector<std::uint32_t> organ;

    Frame(int width, int height) : w(width), h(height)
    {
        const std::size_t n = std::size_t(w) * h;
        beauty.assign(n * 4, 1.0f);
        variance.assign(n * 3, 0.0f);
        albedo.assign(n * 3, 0.5f);
        normal.assign(n * 3, 0.0f);
        for (std::size_t i = 0; i < n; ++i)
            normal[i * 3 + 2] = 1;
        depth.assign(n, 10.0f);
        organ.assign(n, 7);
    }
    std::size_t at(int x, int y) const { return std::size_t(y) * w + x; }
    void set_colour(int x, int y, float v)
    {
        for (int c = 0; c < 3; ++c)
            beauty[at(x, y) * 4 + c] = v;
    }
    void set_albedo(int x, int y, float v)
    {
        for (int c = 0; c < 3; ++c)
            albedo[at(x, y) * 3 + c] = v;
    }
    DenoiseInput input(bool with_albedo = true, bool with_organ = true) const
    {
        DenoiseInput in;
        in.width = w;
        in.height = h;
        in.beauty = beauty;
        in.variance = variance;
        if (with_albedo)
            in.albedo = albedo;
        in.normal = normal;
        in.depth = depth;
        if (with_organ)
            in.organ = organ;
        return in;
    }
};

/// Gaussian white noise of standard deviation sigma (Box-Muller on a fixed generator, so
/// every platform draws the same numbers).
class Noise {
public:
    explicit Noise(std::uint32_t seed) : m_rng(seed) {}
    float operator()(float sigma)
    {
        const double u1 = (double(m_rng()) + 1.0) / 4294967297.0, u2 = double(m_rng()) / 4294967296.0;
        return static_cast<float>(sigma * std::sqrt(-2 * std::log(u1)) * std::cos(6.283185307179586 * u2));
    }

private:
    std::mt19937 m_rng;
};

/// A flat grey frame with white noise whose variance the input states exactly.
Frame noisy_flat(int w, int h, float level, float sigma, std::uint32_t seed)
{
    Frame f(w, h);
    Noise noise(seed);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                f.beauty[f.at(x, y) * 4 + c] = level + noise(sigma);
                f.variance[f.at(x, y) * 3 + c] = sigma * sigma;
            }
        }
    return f;
}

// A flat image with white noise comes back within a stated error. The bound, derived
// (docs/denoise.md): on pure noise the patch distance has mean 0 and a standard deviation
// of sqrt(2 / 75) / k^2 = 0.81 (75 terms of (chi^2_1 - 1) / k^2, k = 0.45), so a
// neighbour's weight exp(-max(0, d)) averages about 0.78 and its square about 0.71: the
// 15 x 15 window's 225 neighbours count as some 190 independent ones, a residual RMS of
// sigma / 13.8. We ask for sigma / 8 (64 effective neighbours, a third of the window)
// away from the edges, sigma / 6 over every pixel (a corner sees a quarter of the
// window), and a mean within sigma / 20 of the level. Unfiltered, the RMS is sigma.
TEST(Denoise, FlatImageWithWhiteNoiseComesBackWithinBound)
{
    const float level = 0.5f, sigma = 0.05f;
    Frame f = noisy_flat(64, 64, level, sigma, 12345);
    std::vector<float> out = NlMeansDenoiser().denoise(f.input());
    const int margin = NlMeansParameters().search_radius;
    double all = 0, inner = 0, mean = 0;
    int count_all = 0, count_inner = 0;
    for (int y = 0; y < f.h; ++y)
        for (int x = 0; x < f.w; ++x)
            for (int c = 0; c < 3; ++c) {
                const double e = out[f.at(x, y) * 4 + c] - level;
                all += e * e;
                mean += e;
                ++count_all;
                if (x >= margin && y >= margin && x < f.w - margin && y < f.h - margin) {
                    inner += e * e;
                    ++count_inner;
                }
            }
    EXPECT_LT(std::sqrt(inner / count_inner), sigma / 8);
    EXPECT_LT(std::sqrt(all / count_all), sigma / 6);
    EXPECT_LT(std::fabs(mean / count_all), sigma / 20);
    // Alpha is the beauty's.
    for (std::size_t i = 0; i < out.size() / 4; ++i)
        ASSERT_EQ(out[i * 4 + 3], f.beauty[i * 4 + 3]);
}

// Without noise (variance 0) nothing is smoothed: a noise-free render stays as it is.
TEST(Denoise, NoiseFreeImageIsUnchanged)
{
    Frame f(32, 24);
    for (int y = 0; y < f.h; ++y)
        for (int x = 0; x < f.w; ++x)
            f.set_colour(x, y, 0.1f + 0.02f * float((x * 7 + y * 3) % 11));
    std::vector<float> out = NlMeansDenoiser().denoise(f.input());
    for (std::size_t i = 0; i < out.size(); ++i)
        ASSERT_NEAR(out[i], f.beauty[i], 1e-6f) << i;
}

/// The mean over rows of the denoised colour in column x.
double column_mean(const Frame& f, const std::vector<float>& out, int x)
{
    double sum = 0;
    for (int y = 0; y < f.h; ++y)
        sum += out[f.at(x, y) * 4];
    return sum / f.h;
}

/// Two halves of different albedo whose colours differ by less than the noise: left
/// 0.45 (albedo 0.3), right 0.55 (albedo 0.6), noise sigma 0.2.
Frame albedo_edge()
{
    Frame f = noisy_flat(48, 256, 0, 0.2f, 777);
    for (int y = 0; y < f.h; ++y)
        for (int x = 0; x < f.w; ++x) {
            const bool left = x < f.w / 2;
            for (int c = 0; c < 3; ++c)
                f.beauty[f.at(x, y) * 4 + c] += left ? 0.45f : 0.55f;
            f.set_albedo(x, y, left ? 0.3f : 0.6f);
        }
    return f;
}

// An edge between two albedos is not crossed: the columns next to it keep their side's
// level (averaged over 64 rows, whose residual noise is about 0.2 / 14 / 8 < 0.003) within
// 0.01, a tenth of the step. The colours alone (no albedo given) do not hold the edge:
// the same measure then drifts further, which shows the test can fail.
TEST(Denoise, EdgeBetweenAlbedosIsNotCrossed)
{
    const Frame f = albedo_edge();
    const std::vector<float> out = NlMeansDenoiser().denoise(f.input());
    const int edge = f.w / 2;
    for (int x = edge - 3; x < edge; ++x)
        EXPECT_NEAR(column_mean(f, out, x), 0.45, 0.01) << "column " << x;
    for (int x = edge; x < edge + 3; ++x)
        EXPECT_NEAR(column_mean(f, out, x), 0.55, 0.01) << "column " << x;

    const std::vector<float> blind = NlMeansDenoiser().denoise(f.input(false));
    const double drift = std::fabs(column_mean(f, blind, edge - 1) - 0.45) +
                         std::fabs(column_mean(f, blind, edge) - 0.55);
    EXPECT_GT(drift, 0.02) << "without the albedo the edge should blur";
}

// Pixels of different organs are never mixed, however alike: a noise-free left half
// claimed very noisy keeps its exact value beside a right half of another organ.
TEST(Denoise, OrgansAreNotMixed)
{
    Frame f(40, 20);
    for (int y = 0; y < f.h; ++y)
        for (int x = 0; x < f.w; ++x) {
            const bool left = x < f.w / 2;
            f.set_colour(x, y, left ? 0.3f : 0.9f);
            for (int c = 0; c < 3; ++c)
                f.variance[f.at(x, y) * 3 + c] = 1.0f;
            f.organ[f.at(x, y)] = left ? 1 : 2;
        }
    const std::vector<float> out = NlMeansDenoiser().denoise(f.input());
    for (int y = 0; y < f.h; ++y)
        for (int x = 0; x < f.w; ++x)
            ASSERT_NEAR(out[f.at(x, y) * 4], x < f.w / 2 ? 0.3f : 0.9f, 1e-5f) << x << "," << y;
    // The same frame without organ ids mixes the halves at the edge.
    const std::vector<float> mixed = NlMeansDenoiser().denoise(f.input(true, false));
    EXPECT_GT(mixed[f.at(f.w / 2 - 1, 10) * 4], 0.31f);
}

/// A frame with every layer varying: noise, albedo patches, depth steps, organs.
Frame busy_frame()
{
    Frame f = noisy_flat(97, 71, 0.3f, 0.1f, 4242);
    Noise noise(99);
    for (int y = 0; y < f.h; ++y)
        for (int x = 0; x < f.w; ++x) {
            f.set_albedo(x, y, ((x / 9 + y / 7) % 3) * 0.3f);
            f.depth[f.at(x, y)] = (x + y) % 23 < 11 ? 5.0f + 0.01f * float(x) : 9.0f;
            if ((x * x + y * y) % 31 == 0)
                f.depth[f.at(x, y)] = std::numeric_limits<float>::infinity();
            f.organ[f.at(x, y)] = std::uint32_t((x / 13) * 5 + y / 17);
            for (int c = 0; c < 3; ++c)
                f.normal[f.at(x, y) * 3 + c] += noise(0.2f);
            f.beauty[f.at(x, y) * 4 + 3] = float((x + 2 * y) % 5) / 4;
        }
    return f;
}

// The result does not depend on the thread count: byte-identical at 1, 2 and 4 threads.
TEST(Denoise, ThreadCountIndependent)
{
    const Frame f = busy_frame();
    std::vector<std::vector<float>> results;
    for (int threads : {1, 2, 4}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        results.push_back(NlMeansDenoiser().denoise(f.input()));
    }
    ASSERT_EQ(results[0].size(), results[1].size());
    for (std::size_t k = 1; k < results.size(); ++k)
        EXPECT_EQ(std::memcmp(results[0].data(), results[k].data(), results[0].size() * sizeof(float)), 0)
            << "threads differ";
    // And it did filter: the output is not the input.
    EXPECT_NE(std::memcmp(results[0].data(), f.beauty.data(), f.beauty.size() * sizeof(float)), 0);
}

TEST(Denoise, MalformedInputIsAnError)
{
    Frame f(8, 8);
    DenoiseInput in = f.input();
    in.albedo = std::span<const float>(f.albedo.data(), 5);
    EXPECT_THROW(NlMeansDenoiser().denoise(in), Error);
    in = f.input();
    in.width = 9;
    EXPECT_THROW(NlMeansDenoiser().denoise(in), Error);
    NlMeansParameters bad;
    bad.search_radius = -1;
    EXPECT_THROW(NlMeansDenoiser{bad}, Error);
}

}  // namespace
}  // namespace cambium::render

namespace cambium::render {
namespace {

namespace fs = std::filesystem;

/// Relative MSE of RGB against a reference (Rousselle et al.'s: over (ref^2 + 0.01)).
double relative_mse(const std::vector<float>& image, const std::vector<float>& ref)
{
    double sum = 0;
    for (std::size_t i = 0; i < ref.size(); ++i)
        if (i % 4 != 3) {
            const double d = double(image[i]) - ref[i];
            sum += d * d / (double(ref[i]) * ref[i] + 0.01);
        }
    return sum / double(ref.size() / 4 * 3);
}

/// A cylinder over a ground under a uniform sky: its shadow and bounces are noisy at a
/// few samples.
geom::Scene cylinder_over_ground()
{
    geom::Scene s = testing::empty_scene({-5, -1, -5}, {5, 5, 5});
    testing::add_segment(s, {-3, 1.5, 0}, {3, 1.5, 0}, 0.8f);
    s.materials[1].diffuse = {0.6f, 0.4f, 0.2f};
    return s;
}

RenderSettings ground_settings(int spp, std::uint64_t seed)
{
    RenderSettings set = testing::small(48, 36, spp, 4);
    set.threads = 2;
    set.seed = seed;
    set.ambient = {0.8f, 0.8f, 0.8f};
    set.ground.enabled = true;
    set.ground.height = 0.0;
    set.aovs = false;
    return set;
}

// End to end: a render with the denoiser writes an EXR whose RGBA is the denoised frame,
// with the raw frame, the variance and the organ ids beside it; the denoised frame is
// closer to a 512-spp reference than the raw one it came from.
TEST(DenoiseRender, ExrKeepsTheRawFrameAndTheDenoisedOneIsCloser)
{
    const geom::Scene s = cylinder_over_ground();
    const Camera camera = Camera::perspective({0, 4, 12}, {0, 1, 0}, {0, 1, 0}, 40, 48, 36);
    RenderSettings set = ground_settings(8, 1);
    set.denoiser = make_default_denoiser();
    const Image img = render(s, camera, set);
    ASSERT_EQ(img.noisy.size(), img.rgba.size());
    ASSERT_EQ(img.organ.size(), img.rgba.size() / 4);
    const Image ref = render(s, camera, ground_settings(512, 99));
    const double raw_error = relative_mse(img.noisy, ref.rgba);
    const double denoised_error = relative_mse(img.rgba, ref.rgba);
    EXPECT_LT(denoised_error, 0.5 * raw_error) << "raw " << raw_error << ", denoised " << denoised_error;

    const fs::path dir = fs::temp_directory_path() / ("cambium_denoise_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "denoised.exr";
    write_image(img, file);
    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec spec = in->spec();
    for (const char* name : {"R", "G", "B", "A", "noisy.R", "noisy.G", "noisy.B", "noisy.A",
                             "albedo.R", "normal.Z", "Z", "variance.R", "variance.albedo",
                             "variance.normal", "organ.id"})
        EXPECT_GE(spec.channelindex(name), 0) << name;
    const int organ = spec.channelindex("organ.id");
    ASSERT_GE(organ, 0);
    EXPECT_EQ(spec.channelformat(organ), OIIO::TypeDesc::UINT);
    const std::size_t n = std::size_t(img.width) * img.height;
    std::vector<float> rgba(n * 4), noisy(n * 4);
    std::vector<std::uint32_t> ids(n);
    ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, rgba.data()));
    const int noisy_r = spec.channelindex("noisy.R");
    ASSERT_TRUE(in->read_image(0, 0, noisy_r, noisy_r + 4, OIIO::TypeDesc::FLOAT, noisy.data()));
    ASSERT_TRUE(in->read_image(0, 0, organ, organ + 1, OIIO::TypeDesc::UINT, ids.data()));
    in->close();
    fs::remove_all(dir);
    // As written (half floats): RGBA the denoised frame, noisy the raw one; they differ.
    double differ = 0;
    for (std::size_t i = 0; i < n * 4; ++i) {
        EXPECT_NEAR(rgba[i], img.rgba[i], 2e-3f * std::max(1.0f, std::fabs(img.rgba[i])));
        EXPECT_NEAR(noisy[i], img.noisy[i], 2e-3f * std::max(1.0f, std::fabs(img.noisy[i])));
        differ += std::fabs(rgba[i] - noisy[i]);
    }
    EXPECT_GT(differ / double(n * 4), 1e-3);
    // The organ ids exactly: the cylinder (no module known), the ground, the sky.
    EXPECT_EQ(ids, img.organ);
    EXPECT_NE(std::find(ids.begin(), ids.end(), organ_unknown), ids.end());
    EXPECT_NE(std::find(ids.begin(), ids.end(), organ_ground), ids.end());
    EXPECT_NE(std::find(ids.begin(), ids.end(), organ_background), ids.end());
}

// Whole renders with the denoiser are byte-identical at 1 and 2 threads.
TEST(DenoiseRender, ThreadCountIndependent)
{
    const geom::Scene s = cylinder_over_ground();
    const Camera camera = Camera::perspective({0, 4, 12}, {0, 1, 0}, {0, 1, 0}, 40, 48, 36);
    std::vector<Image> images;
    for (int threads : {1, 2}) {
        RenderSettings set = ground_settings(8, 1);
        set.threads = threads;
        set.denoiser = make_default_denoiser();
        images.push_back(render(s, camera, set));
    }
    EXPECT_EQ(images[0].rgba, images[1].rgba);
    EXPECT_EQ(images[0].noisy, images[1].noisy);
}

// A crop cannot be denoised (its neighbours are missing), and the memory budget counts
// the denoiser's buffers.
TEST(DenoiseRender, CropAndMemoryBudgetAreErrors)
{
    const geom::Scene s = cylinder_over_ground();
    RenderSettings set = ground_settings(1, 1);
    set.denoiser = make_default_denoiser();
    set.crop = {0, 0, 8, 8};
    EXPECT_THROW(render(s, set), Error);
    set.crop = {};
    set.max_memory_bytes = 1 << 16;
    try {
        render(s, set);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--max-memory"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace cambium::render
