// SPDX-License-Identifier: Apache-2.0
// Crop windows (RenderSettings::crop): a crop's pixels equal the same pixels of the whole
// image bit for bit, with and without adaptive sampling, in every layer.
#include <gtest/gtest.h>

#include <cstring>

#include "base/diagnostics.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using testing::add_segment;
using testing::directional;
using testing::empty_scene;
using testing::small;

/// Lit segments crossing the frame: noisy pixels beside converged background ones, so
/// adaptive sampling stops pixels at different passes.
geom::Scene crossing_scene()
{
    geom::Scene s = empty_scene({-10, -6, -1}, {10, 6, 1});
    add_segment(s, {-5, -4, 0}, {5, 4, 0}, 1.5f);
    add_segment(s, {-5, 4, 1}, {5, -4, 1}, 0.4f);
    s.lights.push_back(directional({1, 1, 1}));
    return s;
}

bool same_float_bits(const float* a, const float* b, std::size_t n)
{
    return std::memcmp(a, b, n * sizeof(float)) == 0;
}

/// Whether `crop` equals the pixels of `whole` at `rect` in RGBA and every layer.
void expect_same_pixels(const Image& whole, const Image& crop, const PixelRect& rect)
{
    ASSERT_EQ(crop.width, rect.width);
    ASSERT_EQ(crop.height, rect.height);
    ASSERT_EQ(crop.albedo.empty(), whole.albedo.empty());
    for (int y = 0; y < rect.height; ++y) {
        std::size_t w = std::size_t(whole.width) * std::size_t(rect.y + y) + std::size_t(rect.x);
        std::size_t c = std::size_t(rect.width) * std::size_t(y), n = std::size_t(rect.width);
        EXPECT_TRUE(same_float_bits(&whole.rgba[w * 4], &crop.rgba[c * 4], n * 4)) << "row " << y;
        if (whole.albedo.empty())
            continue;
        EXPECT_TRUE(same_float_bits(&whole.albedo[w * 3], &crop.albedo[c * 3], n * 3));
        EXPECT_TRUE(same_float_bits(&whole.normal[w * 3], &crop.normal[c * 3], n * 3));
        EXPECT_TRUE(same_float_bits(&whole.depth[w], &crop.depth[c], n));
    }
}

/// Crops at the corners, the edges, the inside, single pixels and whole rows.
const PixelRect crops[] = {{0, 0, 7, 5},   {41, 35, 7, 5}, {13, 9, 20, 17}, {0, 20, 48, 1},
                           {47, 0, 1, 40}, {24, 19, 1, 1}, {5, 0, 30, 40},  {0, 0, 48, 40}};

/// Renders the whole image with `set`, then each crop, and compares them.
void expect_crops_equal_whole(const geom::Scene& s, RenderSettings set)
{
    set.crop = {};
    Image whole = render(s, set);
    for (const PixelRect& rect : crops) {
        set.crop = rect;
        expect_same_pixels(whole, render(s, set), rect);
    }
}

TEST(Crop, EqualsTheWholeImageBitForBit)
{
    RenderSettings set = small(48, 40, 12, 3);
    set.ambient = {0.2f, 0.2f, 0.2f};
    set.aovs = true;
    set.filter = PixelFilter::gaussian;
    expect_crops_equal_whole(crossing_scene(), set);
}

TEST(Crop, AdaptiveSamplingEqualsTheWholeImageBitForBit)
{
    geom::Scene s = crossing_scene();
    RenderSettings set = small(48, 40, 256, 3);
    set.ambient = {0.2f, 0.2f, 0.2f};
    set.noise_target = 0.04f;
    RenderReport report;
    render(s, set, &report);
    // Adaptive sampling did decide: some pixels stopped early, others went on.
    ASSERT_LT(report.samples, 48u * 40u * 256u / 2);
    ASSERT_GT(report.samples, 48u * 40u * 32u);
    expect_crops_equal_whole(s, set);
    // Many equal passes: a margin of passes - 1 pixels, wider than some crops' distance
    // to the image's edge.
    set.passes = 12;
    expect_crops_equal_whole(s, set);
}

TEST(Crop, OutsideTheImageIsAnError)
{
    geom::Scene s = crossing_scene();
    RenderSettings set = small(48, 40, 1, 1);
    for (PixelRect rect : {PixelRect{-1, 0, 4, 4}, PixelRect{45, 0, 4, 4}, PixelRect{0, 37, 4, 4}}) {
        set.crop = rect;
        EXPECT_THROW(render(s, set), Error);
    }
}

}  // namespace
}  // namespace cambium::render
