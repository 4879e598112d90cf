// SPDX-License-Identifier: Apache-2.0
// MipMap: the pyramid's levels, bilinear and nearest filtering with GL_REPEAT, the level
// a footprint chooses, and the sRGB decoding of integer textures, each against values
// worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "render/color.h"
#include "render/integrator.h"
#include "render/mip_map.h"

namespace cambium::render {
namespace {

/// A one-channel float texture (linear values) of w x h with value f(x, y), rows top down.
template <typename F>
TexturePixels grey(int w, int h, F f)
{
    TexturePixels p{w, h, 1, {}, {}, false};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            p.floats.push_back(f(x, y));
    return p;
}

/// (s, t) of the centre of texel (x, y) of a w x h level (t runs up, rows down).
float centre_s(int x, int w) { return (x + 0.5f) / w; }
float centre_t(int y, int h) { return 1 - (y + 0.5f) / h; }

TEST(MipMap, LevelsHalveDownToOneTexelAndAverageWhatTheyCover)
{
    // 5 x 3 with value x + 10 y: level 1 is 2 x 1, its texel 0 covering x 0..1 and y 0..2
    // (mean 0.5 + 10), texel 1 covering x 2..4 (mean 3 + 10); level 2 is 1 x 1.
    MipMap map(grey(5, 3, [](int x, int y) { return float(x + 10 * y); }), {true, true});
    ASSERT_EQ(map.levels(), 3u);
    EXPECT_EQ(map.bytes(), (15u + 2u + 1u) * sizeof(float));
    // A footprint of 2 texels of the finest level is level 1, exactly.
    TextureFootprint two{2.0f / 5, 0, 0, 2.0f / 3};
    EXPECT_FLOAT_EQ(map.lookup(centre_s(0, 2), 0.5f, two).colour.x, 10.5f);
    EXPECT_FLOAT_EQ(map.lookup(centre_s(1, 2), 0.5f, two).colour.x, 13.0f);
    // 4 texels and more: the last level, the mean of its two parents' texels.
    TextureFootprint wide{1, 0, 0, 1};
    EXPECT_FLOAT_EQ(map.lookup(0.3f, 0.7f, wide).colour.x, 11.75f);
}

TEST(MipMap, BilinearHitsTexelCentresAndWrapsAtTheEdges)
{
    MipMap map(grey(4, 2, [](int x, int y) { return float(x + 4 * y); }), {true, false});
    EXPECT_EQ(map.levels(), 1u);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            EXPECT_FLOAT_EQ(map.lookup(centre_s(x, 4), centre_t(y, 2), {}).colour.x,
                            float(x + 4 * y));
    // Halfway between columns 1 and 2 of the top row.
    EXPECT_FLOAT_EQ(map.lookup(0.5f, centre_t(0, 2), {}).colour.x, 1.5f);
    // s = 0 lies between the last column and the first (GL_REPEAT): (3 + 0) / 2.
    EXPECT_FLOAT_EQ(map.lookup(0.0f, centre_t(0, 2), {}).colour.x, 1.5f);
    // s and t far outside [0, 1] repeat.
    EXPECT_NEAR(map.lookup(centre_s(2, 4) + 7, centre_t(1, 2) - 3, {}).colour.x, 6.0f, 1e-4f);
    // t = 1 is the top edge: between the top row and the bottom row, wrapping.
    EXPECT_FLOAT_EQ(map.lookup(centre_s(0, 4), 1.0f, {}).colour.x, 2.0f);
}

TEST(MipMap, NearestTakesTheTexelUnderThePoint)
{
    MipMap map(grey(4, 2, [](int x, int y) { return float(x + 4 * y); }), {false, false});
    EXPECT_EQ(map.lookup(0.49f, 0.9f, {}).colour.x, 1.0f);
    EXPECT_EQ(map.lookup(0.51f, 0.9f, {}).colour.x, 2.0f);
    EXPECT_EQ(map.lookup(0.99f, 0.1f, {}).colour.x, 7.0f);
    EXPECT_EQ(map.lookup(-0.01f, 0.1f, {}).colour.x, 7.0f);  // wraps to the last column
    EXPECT_EQ(map.lookup(std::nanf(""), 0.9f, {}).colour.x, 0.0f);  // no crash, a texel
}

TEST(MipMap, FootprintBlendsBetweenLevels)
{
    // A one-texel checker: level 0 alternates 0 and 1, level 1 is 0.5 everywhere.
    MipMap map(grey(8, 8, [](int x, int y) { return float((x + y) % 2); }), {true, true});
    const float s = centre_s(2, 8), t = centre_t(2, 8);  // a texel of value 0
    EXPECT_FLOAT_EQ(map.lookup(s, t, {}).colour.x, 0.0f);
    EXPECT_FLOAT_EQ(map.lookup(s, t, {0.5f / 8, 0, 0, 0.5f / 8}).colour.x, 0.0f);  // magnified
    // sqrt(2) texels: log2 = 0.5, half level 0 (0) and half level 1 (0.5).
    const float w = std::sqrt(2.0f) / 8;
    EXPECT_NEAR(map.lookup(s, t, {w, 0, 0, w}).colour.x, 0.25f, 1e-5f);
    // The longer axis decides: 2 texels along t alone is level 1.
    EXPECT_NEAR(map.lookup(s, t, {0, 0, 0, 2.0f / 8}).colour.x, 0.5f, 1e-6f);
}

TEST(MipMap, IntegerTexturesAreDecodedFromSrgbAfterFiltering)
{
    // Two 8-bit RGBA texels, red channels 0 and 200, alpha 255 and 0.
    TexturePixels p{2, 1, 4, {0, 10, 20, 255, 200, 30, 40, 0}, {}, true};
    MipMap map(std::move(p), {true, false});
    EXPECT_TRUE(map.has_alpha());
    Texel left = map.lookup(centre_s(0, 2), 0.5f, {});
    EXPECT_NEAR(left.colour.y, srgb_to_linear(10 / 255.0f), 1e-6f);
    EXPECT_EQ(left.alpha, 1.0f);
    // Halfway: the display values are averaged (100), then decoded; alpha is linear.
    Texel half = map.lookup(0.5f, 0.5f, {});
    EXPECT_NEAR(half.colour.x, srgb_to_linear(100 / 255.0f), 1e-6f);
    EXPECT_FLOAT_EQ(half.alpha, 0.5f);
    // The decoding table stays within 1e-6 of the curve everywhere.
    for (int v = 0; v <= 255; ++v) {
        TexturePixels one{1, 1, 1, {static_cast<std::uint8_t>(v)}, {}, true};
        MipMap single(std::move(one), {true, true});
        EXPECT_NEAR(single.lookup(0.5f, 0.5f, {}).colour.z, srgb_to_linear(v / 255.0f), 1e-6f)
            << v;
    }
}

TEST(MipMap, GreyAndAlphaFillOutToRgba)
{
    TexturePixels p{1, 1, 2, {}, {0.25f, 0.5f}, false};
    Texel t = MipMap(std::move(p), {true, true}).lookup(0.5f, 0.5f, {});
    EXPECT_EQ(t.colour, Vec3f(0.25f));
    EXPECT_EQ(t.alpha, 0.5f);
    TexturePixels rgb{1, 1, 3, {}, {0.1f, 0.2f, 0.3f}, false};
    MipMap three(std::move(rgb), {true, true});
    EXPECT_FALSE(three.has_alpha());
    EXPECT_EQ(three.lookup(0.5f, 0.5f, {}).alpha, 1.0f);
}

TEST(MipMap, CanCutOutOnlyWhereSomeAlphaIsBelowHalf)
{
    auto rgba = [](std::uint8_t a0, std::uint8_t a1) {
        return MipMap(TexturePixels{2, 1, 4, {9, 9, 9, a0, 9, 9, 9, a1}, {}, true}, {true, true});
    };
    EXPECT_FALSE(rgba(255, 128).can_cut_out());
    EXPECT_TRUE(rgba(255, 127).can_cut_out());
    EXPECT_TRUE(rgba(0, 255).can_cut_out());
    auto grey_alpha = [](float a) {
        return MipMap(TexturePixels{1, 2, 2, {}, {0.3f, 1, 0.3f, a}, false}, {true, true});
    };
    EXPECT_FALSE(grey_alpha(0.6f).can_cut_out());
    EXPECT_TRUE(grey_alpha(0.5f).can_cut_out());  // a blend of 0.5s may round below it
    EXPECT_TRUE(grey_alpha(std::nanf("")).can_cut_out());
    EXPECT_FALSE(MipMap(TexturePixels{1, 1, 3, {0, 0, 0}, {}, true}, {}).can_cut_out());
    // The reason it may say no: every blend of alphas of 128/255 stays at 1/2 or above.
    TexturePixels half{5, 3, 4, std::vector<std::uint8_t>(5 * 3 * 4, 128), {}, true};
    MipMap all_128(std::move(half), {true, true});
    for (int i = 0; i <= 1000; ++i) {
        const float s = i * 0.001237f - 0.3f, t = i * 0.000711f + 0.2f;
        EXPECT_GE(all_128.lookup(s, t, {}).alpha, 0.5f);
    }
}

TEST(MipMap, RefusesPixelsThatDoNotMatchTheirSize)
{
    EXPECT_THROW(MipMap(TexturePixels{2, 2, 1, {}, {1, 2, 3}, false}, {}), std::invalid_argument);
    EXPECT_THROW(MipMap(TexturePixels{1, 1, 5, {}, {1, 2, 3, 4, 5}, false}, {}),
                 std::invalid_argument);
    EXPECT_THROW(MipMap(TexturePixels{0, 1, 1, {}, {}, false}, {}), std::invalid_argument);
}

TEST(MipMap, FootprintTexelsIsTheFinestLevelsLongerSideWhereLevelsAreChosen)
{
    EXPECT_EQ(MipMap(grey(5, 3, [](int, int) { return 0.0f; }), {true, true}).footprint_texels(),
              5.0f);
    EXPECT_EQ(MipMap(grey(3, 8, [](int, int) { return 0.0f; }), {true, true}).footprint_texels(),
              8.0f);
    // One level: no footprint changes a lookup.
    EXPECT_EQ(MipMap(grey(4, 4, [](int, int) { return 0.0f; }), {true, false}).footprint_texels(),
              0.0f);
    EXPECT_EQ(MipMap(grey(1, 1, [](int, int) { return 0.0f; }), {true, true}).footprint_texels(),
              0.0f);
}

// footprint_within_texel (integrator.h) is a bound: where it says a footprint is under one
// texel, the lookup through the whole footprint takes the finest level alone, bit for bit
// the lookup without one. A checkerboard of single texels makes every coarser level grey,
// so any blend toward level 1 shows. Tangent frames of every shape (down to slivers) and
// scale, views down to grazing, widths from far under a texel to several texels.
TEST(MipMap, FootprintWithinTexelNeverHidesACoarserLevel)
{
    MipMap map(grey(64, 32, [](int x, int y) { return float((x + y) & 1); }), {true, true});
    ASSERT_EQ(map.footprint_texels(), 64.0f);
    std::mt19937 rng(16);
    std::uniform_real_distribution<float> u(-1, 1), unit(0, 1);
    int within = 0, beyond = 0, coarser = 0;
    for (int i = 0; i < 200000; ++i) {
        SurfaceHit hit;
        hit.geometric_normal = normalize(Vec3f(u(rng), u(rng), u(rng)));
        Vec3f e0, e1;
        make_basis(hit.geometric_normal, e0, e1);
        const float phi = 3.2f * unit(rng), gap = 3.1f * unit(rng) + 0.001f;
        const float scale_s = std::pow(10.0f, 3 * u(rng)), scale_t = std::pow(10.0f, 3 * u(rng));
        hit.dpds = (e0 * std::cos(phi) + e1 * std::sin(phi)) * scale_s;
        hit.dpdt = (e0 * std::cos(phi + gap) + e1 * std::sin(phi + gap)) * scale_t;
        const Vec3f dir = normalize(Vec3f(u(rng), u(rng), u(rng)));
        const float width = std::pow(10.0f, 1.5f * u(rng) - 0.5f) *
                            std::min(scale_s, scale_t) / map.footprint_texels();
        const float s = unit(rng), t = unit(rng);
        const float zero = map.lookup(s, t, {}).colour.x;
        const float full = map.lookup(s, t, texture_footprint(hit, dir, width)).colour.x;
        coarser += full != zero;
        if (footprint_within_texel(hit, dir, width, map.footprint_texels())) {
            ++within;
            ASSERT_EQ(full, zero) << "frame " << i;
        } else {
            beyond += full == zero;
        }
    }
    // Both answers are common, and the bound lets most footprints under a texel through.
    EXPECT_GT(within, 40000);
    EXPECT_GT(coarser, 40000);
    EXPECT_LT(beyond, within);
}

TEST(MipMap, FootprintWithinTexelWithoutLevelsOrWithNaN)
{
    SurfaceHit hit;
    hit.geometric_normal = {0, 0, 1};
    hit.dpds = {1, 0, 0};
    hit.dpdt = {0, 1, 0};
    const Vec3f down{0, 0, -1};
    EXPECT_TRUE(footprint_within_texel(hit, down, 1e-3f, 100));
    EXPECT_FALSE(footprint_within_texel(hit, down, 1e-2f, 100));  // one texel exactly
    EXPECT_TRUE(footprint_within_texel(hit, down, 1e6f, 0));      // no levels to choose
    EXPECT_FALSE(footprint_within_texel(hit, down, std::nanf(""), 100));
    hit.dpdt = {1, 1e-3f, 0};  // a sliver: no bound from it
    EXPECT_FALSE(footprint_within_texel(hit, down, 1e-9f, 100));
    hit.dpdt = {};  // t constant
    EXPECT_FALSE(footprint_within_texel(hit, down, 1e-9f, 100));
}

}  // namespace
}  // namespace cambium::render
