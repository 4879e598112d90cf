// SPDX-License-Identifier: Apache-2.0
// Whole renders of tiny scenes: silhouettes, lighting, symmetry, furnace, determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "base/diagnostics.h"
#include "render/color.h"
#include "render/pixel_lines.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using testing::add_segment;
using testing::empty_scene;
using testing::small;
using testing::directional;

// Bounds x -20..20, y -5..5 at 200x100: k = min(200/40, 100/10) = 5 px per unit, centre
// (100, 50). A segment x -10..10 of radius 2 covers rows 40..60 and (with its round caps)
// columns 40..160.
TEST(Render, SegmentSilhouetteWhereCameraPutsIt)
{
    geom::Scene s = empty_scene({-20, -5, 0}, {20, 5, 0});
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 2.0f);
    Image img = render(s, small(200, 100, 4));
    for (int y = 41; y <= 58; ++y)
        EXPECT_EQ(img.at(100, y, 3), 1.0f) << "row " << y;
    for (int y : {0, 20, 38, 61, 80, 99})
        EXPECT_EQ(img.at(100, y, 3), 0.0f) << "row " << y;
    // 5 pixels per unit: the cylinder's flat ends at x = -10 and 10 are columns 50, 150
    // (cpfg's cylinders end square; no half sphere beyond them)
    EXPECT_EQ(img.at(51, 50, 3), 1.0f);
    EXPECT_EQ(img.at(148, 50, 3), 1.0f);
    EXPECT_EQ(img.at(48, 50, 3), 0.0f);
    EXPECT_EQ(img.at(151, 50, 3), 0.0f);
    // Edge rows are partly covered.
    EXPECT_GT(img.at(100, 40, 3) + img.at(100, 59, 3), 0.0f);
}

/// How many of the first n pixels of column `at` (or row, when `rows`) the image covers,
/// and whether each is covered fully (coverage 0 or 1 only).
std::pair<int, bool> covered_pixels(const Image& img, int at, bool rows, int n)
{
    int count = 0;
    bool crisp = true;
    for (int i = 0; i < n; ++i) {
        float a = rows ? img.at(i, at, 3) : img.at(at, i, 3);
        count += a > 0;
        crisp = crisp && (a == 0 || a == 1);
    }
    return {count, crisp};
}

// cpfg's pixel lines are aliased GL lines: a line N pixels wide covers exactly N pixels of
// every column it crosses (x-major) or row (y-major), fully. A tube N pixels across would
// cover parts of N + 1 (and look wider once anti-aliased). 5 px per unit, centre (100, 50).
TEST(Render, PixelLineOfWidthNCoversNPixelsPerColumn)
{
    for (float width : {1.0f, 3.0f}) {
        geom::Scene s = empty_scene({-20, -5, 0}, {20, 5, 0});
        s.line_radius_in_pixels = true;
        add_segment(s, {-15, -3.1, 0}, {15, 2.3, 0}, width / 2);  // x-major: columns 25..175
        add_segment(s, {-18.3, -4, 0}, {-17.1, 4.5, 0}, width / 2);  // y-major: rows 28..70
        Image img = render(s, small(200, 100, 16));
        for (int x = 30; x <= 170; ++x) {
            auto [count, crisp] = covered_pixels(img, x, false, img.height);
            EXPECT_EQ(count, int(width)) << "column " << x << ", width " << width;
            EXPECT_TRUE(crisp) << "column " << x << ", width " << width;
        }
        for (int y = 32; y <= 66; ++y)  // left of column 24, where the x-major line starts
            EXPECT_EQ(covered_pixels(img, y, true, 24).first, int(width)) << "row " << y << ", width " << width;
    }
}

// A horizontal line exactly on a pixel boundary (y = 0 and y = 1 are rows 50.0 and 45.0)
// still covers N pixels of each column: the width computed back from the world radius
// may come out a hair under N (HilbertPanels' 1-pixel grid lines vanished).
TEST(Render, PixelLineOnAPixelBoundaryCoversNPixels)
{
    for (float width : {1.0f, 2.0f}) {
        for (double y : {0.0, 1.0}) {
            geom::Scene s = empty_scene({-20, -5, 0}, {20, 5, 0});
            s.line_radius_in_pixels = true;
            add_segment(s, {-15, y, 0}, {15, y, 0}, width / 2);
            Image img = render(s, small(200, 100, 4));
            for (int x = 30; x <= 170; x += 7)
                EXPECT_EQ(covered_pixels(img, x, false, img.height).first, int(width))
                    << "column " << x << ", y " << y << ", width " << width;
        }
    }
}

// The width the renderer computes back from a world radius can come out a hair under
// N; on a pixel boundary the line must still draw N rows, not N - 1.
TEST(Render, GlLineRuleKeepsWidthRoundedDownOnABoundary)
{
    for (double width : {0.9999999, 1.0, 1.0000001, 1.9999999, 2.0}) {
        int rows = 0;
        for (int row = 20; row < 28; ++row)
            rows += gl_line_draws({0, 24.0}, {100, 24.0}, width, {50.3, row + 0.5}) ? 1 : 0;
        EXPECT_EQ(rows, static_cast<int>(std::lround(width))) << "width " << width;
    }
}

// Camera rays that miss see the background: the PNG must hold cpfg's exact bytes.
TEST(Render, MissedPixelsAreTheDecodedBackground)
{
    geom::Scene s = empty_scene({-1, -1, 0}, {1, 1, 0});
    s.background = {161 / 255.0f, 229 / 255.0f, 7 / 255.0f};
    Image img = render(s, small(8, 8, 2));
    Vec3f bg = decode_display(s.background);
    EXPECT_FLOAT_EQ(img.at(3, 3, 0), bg.x);
    EXPECT_FLOAT_EQ(img.at(3, 3, 1), bg.y);
    EXPECT_FLOAT_EQ(img.at(3, 3, 2), bg.z);
    EXPECT_EQ(img.at(3, 3, 3), 0.0f);
}

// Light from +y, camera from +z: the upper half of the cylinder is lit, the lower half
// (normals toward -y) receives nothing.
TEST(Render, LitSideIsBrighterThanUnlitSide)
{
    geom::Scene s = empty_scene({-20, -5, 0}, {20, 5, 0});
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 2.0f);
    s.materials[1].diffuse = {0.8f, 0.8f, 0.8f};
    s.lights.push_back(directional({0, 1, 0}));
    Image img = render(s, small(200, 100, 4));
    float lit = img.at(100, 45, 1), unlit = img.at(100, 55, 1);
    EXPECT_GT(lit, 0.05f);
    EXPECT_LT(unlit, 0.5f * lit);
    // Normal incidence on the top of the cylinder: irradiance pi * 1, radiance = albedo.
    // Near row 41 the normal is ~ (0, 0.9, 0.44): expect albedo * cos within tolerance.
    float albedo = srgb_to_linear(0.8f);
    EXPECT_LE(img.at(100, 41, 1), albedo * 1.001f);
}

// Without the scene's lights (--no-view-lights) the same lit cylinder is lit by the
// environment alone: under a black one it is black, the OpenGL ambient term included (an
// empty light list is not mistaken for cpfg's default light, whose ambient is 1).
TEST(Render, SceneLightsCanBeLeftOut)
{
    geom::Scene s = empty_scene({-20, -5, 0}, {20, 5, 0});
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 2.0f);
    s.materials[1].diffuse = {0.8f, 0.8f, 0.8f};
    s.materials[1].ambient = {0.5f, 0.5f, 0.5f};
    s.lights.push_back(directional({0, 1, 0}));
    RenderSettings set = small(200, 100, 4);
    set.opengl_ambient = true;
    Image lit = render(s, set);
    EXPECT_GT(lit.at(100, 45, 1), 0.05f);
    EXPECT_GT(lit.at(100, 55, 1), 0.0f);  // the ambient term on the unlit side
    set.view_lights = false;
    Image dark = render(s, set);
    for (int y : {41, 45, 50, 55})
        EXPECT_EQ(dark.at(100, y, 1), 0.0f) << y;
    s.lights.clear();
    EXPECT_EQ(render(s, set).at(100, 55, 1), 0.0f);
}

// `render mode: filled`: the same cylinder shows its flat colour on both sides, unlit;
// `flat`: lit by the facet normal (a round tube's is its smooth normal: still shaded).
TEST(Render, FilledRenderModeShowsFlatColours)
{
    geom::Scene s = empty_scene({-20, -5, 0}, {20, 5, 0});
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 2.0f);
    s.materials[1].diffuse = {0.8f, 0.4f, 0.2f};
    s.lights.push_back(directional({0, 1, 0}));
    s.shading = geom::Shading::filled;
    Image img = render(s, small(200, 100, 4));
    const geom::Rgb& d = s.materials[1].diffuse;
    for (int y : {43, 50, 57}) {
        EXPECT_NEAR(img.at(100, y, 0), srgb_to_linear(d.r), 1e-5f) << y;
        EXPECT_NEAR(img.at(100, y, 1), srgb_to_linear(d.g), 1e-5f) << y;
        EXPECT_NEAR(img.at(100, y, 2), srgb_to_linear(d.b), 1e-5f) << y;
    }
    s.shading = geom::Shading::flat;
    Image flat = render(s, small(200, 100, 4));
    EXPECT_LT(flat.at(100, 55, 0), 0.5f * flat.at(100, 45, 0));
}

// A white light straight onto a white-ish Lambertian surface gives exactly its albedo
// (cpfg/OpenGL convention, light.h) where the normal faces the light.
TEST(Render, LightIntensityConventionMatchesAlbedoAtNormalIncidence)
{
    geom::Scene s = empty_scene({-20, -5, 0}, {20, 5, 0});
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 2.0f);
    s.materials[1].diffuse = {0.6f, 0.6f, 0.6f};
    s.lights.push_back(directional({0, 0, 1}));  // toward the camera side
    RenderSettings set = small(200, 100, 1);
    Image img = render(s, set);
    // Pixel row 50 is the cylinder's axis: normal ~ +z, cos ~ 1.
    float albedo = srgb_to_linear(0.6f);
    EXPECT_NEAR(img.at(100, 50, 0), albedo, 0.01f * albedo);
}

// Seen from +y with the light straight above (+z): the lower cylinder's upper half is lit,
// unless a second, wider cylinder above it casts its shadow.
TEST(Render, ShadowRaysAreBlocked)
{
    geom::Scene s = empty_scene({-20, -2, -2}, {20, 2, 2});
    s.view.viewpoint = {0, 1, 0};  // looking straight down -y: screen up is -z
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 2.0f);
    s.lights.push_back(directional({0, 0, 1}));
    Camera c = make_camera(s.view, s.bounds, 100, 100);
    // The +z side of the cylinder is below the centre on screen.
    PixelPoint p = c.project({0, 2, 1});
    int px = static_cast<int>(p.x), py = static_cast<int>(p.y);
    ASSERT_GT(py, 50);

    Image open = render(s, small(100, 100, 1));
    EXPECT_EQ(open.at(px, py, 3), 1.0f);
    EXPECT_GT(open.at(px, py, 0), 0.1f);

    add_segment(s, {-10, 0, 10}, {10, 0, 10}, 4.0f);  // above it, off screen
    Image shadowed = render(s, small(100, 100, 1));
    EXPECT_EQ(shadowed.at(px, py, 3), 1.0f);
    EXPECT_EQ(shadowed.at(px, py, 0), 0.0f);
}

// Two segments mirrored about x = 0, a point light on the axis: the image is mirror
// symmetric up to sampling noise.
TEST(Render, MirrorSymmetricSceneRendersSymmetric)
{
    geom::Scene s = empty_scene({-10, -6, -1}, {10, 6, 1});
    add_segment(s, {2, -5, 0}, {8, 5, 0}, 0.8f);
    add_segment(s, {-2, -5, 0}, {-8, 5, 0}, 0.8f);
    s.materials[1].diffuse = {0.7f, 0.7f, 0.7f};
    geom::Light l;
    l.position = {0, 3, 4};
    l.attenuation_quadratic = 0.02f;
    s.lights.push_back(l);
    RenderSettings set = small(64, 48, 16, 4);
    set.ambient = {0.1f, 0.1f, 0.1f};
    Image img = render(s, set);
    double total = 0, diff = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 32; x += 4) {
            // Compare 4-pixel blocks to average the per-pixel noise.
            double a = 0, b = 0;
            for (int i = 0; i < 4; ++i) {
                a += img.at(x + i, y, 1);
                b += img.at(63 - x - i, y, 1);
            }
            total += a + b;
            diff += std::abs(a - b);
        }
    ASSERT_GT(total, 1.0);
    EXPECT_LT(diff / total, 0.05);
    // An asymmetric light breaks it: the check has teeth.
    s.lights[0].position = {6, 3, 4};
    Image shifted = render(s, set);
    double d2 = 0, t2 = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 32; ++x) {
            t2 += shifted.at(x, y, 1) + shifted.at(63 - x, y, 1);
            d2 += std::abs(shifted.at(x, y, 1) - shifted.at(63 - x, y, 1));
        }
    EXPECT_GT(d2 / t2, 0.2);
}

// White furnace: albedo 1, environment = background = E, no lights. Every path carries E
// exactly (cosine sampling: weight = albedo), so every pixel is E whatever it hits.
TEST(Render, WhiteFurnaceConservesEnergy)
{
    geom::Scene s = empty_scene({-10, -6, -1}, {10, 6, 1});
    add_segment(s, {-5, -4, 0}, {5, 4, 0}, 2.0f);
    add_segment(s, {-5, 4, 0.5}, {5, -4, 0.5}, 2.0f);
    s.materials[1].diffuse = {1, 1, 1};
    float e = 0.5f;
    s.background = {linear_to_srgb(e), linear_to_srgb(e), linear_to_srgb(e)};
    RenderSettings set = small(32, 24, 8, 64);
    set.roulette_depth = 1000;
    float bg = decode_display(s.background).x;
    set.ambient = {bg, bg, bg};
    Image img = render(s, set);
    int covered = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 32; ++x) {
            EXPECT_NEAR(img.at(x, y, 0), bg, 1e-5f) << x << "," << y;
            covered += img.at(x, y, 3) > 0 ? 1 : 0;
        }
    EXPECT_GT(covered, 100);

    // Albedo 0.5 on a lone convex cylinder: one bounce then escape -> exactly 0.5 E.
    geom::Scene one = empty_scene({-10, -6, -1}, {10, 6, 1});
    add_segment(one, {-8, 0, 0}, {8, 0, 0}, 3.0f);
    one.materials[1].diffuse = {linear_to_srgb(0.5f), linear_to_srgb(0.5f), linear_to_srgb(0.5f)};
    Image half = render(one, set);
    EXPECT_NEAR(half.at(16, 12, 0), 0.5f * bg, 2e-3f * bg);
}

TEST(Render, BitIdenticalForAnyThreadCount)
{
    geom::Scene s = empty_scene({-10, -6, -1}, {10, 6, 1});
    add_segment(s, {-5, -4, 0}, {5, 4, 0}, 1.0f);
    add_segment(s, {-5, 4, 1}, {5, -4, 1}, 1.0f);
    s.lights.push_back(directional({1, 1, 1}));
    RenderSettings set = small(48, 40, 4, 6);
    set.ambient = {0.2f, 0.2f, 0.2f};
    set.threads = 1;
    Image one = render(s, set);
    set.threads = 2;
    Image two = render(s, set);
    ASSERT_EQ(one.rgba.size(), two.rgba.size());
    EXPECT_EQ(std::memcmp(one.rgba.data(), two.rgba.data(), one.rgba.size() * sizeof(float)), 0);
    set.seed = 1;
    Image other = render(s, set);
    EXPECT_NE(std::memcmp(one.rgba.data(), other.rgba.data(), one.rgba.size() * sizeof(float)),
              0);
}

TEST(Render, RejectsInvalidSettings)
{
    geom::Scene s = empty_scene({0, 0, 0}, {1, 1, 1});
    RenderSettings set = small(0, 10, 1);
    EXPECT_THROW(render(s, set), Error);
    set = small(10, 10, 0);
    EXPECT_THROW(render(s, set), Error);
}

}  // namespace
}  // namespace cambium::render
