// SPDX-License-Identifier: Apache-2.0
// The ground plane (--ground) and the shadow catcher (--shadow-catcher).
#include <gtest/gtest.h>

#include "render/ground.h"
#include "render/render.h"
#include "geom_scenes.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using geom::Vec3;

TEST(Ground, LowestPointCountsEveryPrimitive)
{
    geom::Scene scene = testing::empty_scene({-1, 0, -1}, {1, 4, 1});
    EXPECT_DOUBLE_EQ(lowest_point(scene), 0);  // cpfg's bounds alone
    testing::add_segment(scene, {0, 0, 0}, {0, -0.5, 0}, 0.1f);
    EXPECT_NEAR(lowest_point(scene), -0.5, 1e-6);  // a curve's key (its end is flat)
    testing::add_sphere(scene.geometry, {3, -1, 0}, 0.25f);
    EXPECT_NEAR(lowest_point(scene), -1.25, 1e-6);
    // an instance moved down by 2 of a prototype whose lowest vertex is at y = 0.5
    geom::Prototype leaf;
    leaf.geometry.mesh.positions = {{0, 0.5f, 0}, {1, 1, 0}, {0, 1, 1}};
    scene.prototypes.push_back(leaf);
    geom::Instance inst;
    inst.transform[10] = -2;
    scene.instances.push_back(inst);
    EXPECT_NEAR(lowest_point(scene), -1.5, 1e-6);
    EXPECT_DOUBLE_EQ(lowest_point(geom::Scene{}), 0);
}

/// A ball at height 1 over the ground at y = -1, lit from +x+y at 45 degrees: its shadow
/// falls around (-2, -1, 0), seen from straight above by a parallel camera.
struct BallOverGround {
    geom::Scene scene = testing::empty_scene({-0.3, 0.7, -0.3}, {0.3, 1.3, 0.3});
    RenderSettings settings = testing::small(48, 48, 128, 2);
    Camera camera = Camera::parallel({0, 0, 0}, {0, -1, 0}, {0, 0, -1}, 0.125, 10, 48, 48);

    explicit BallOverGround(bool ball = true, float ambient = 0)
    {
        if (ball)
            testing::add_sphere(scene.geometry, {0, 1, 0}, 0.3f);
        scene.materials[1].diffuse = {0, 0, 0};  // black: no light bounces off it
        scene.lights.push_back(testing::directional({1, 1, 0}));
        settings.ambient = {ambient, ambient, ambient};
        settings.ground.enabled = true;
        settings.ground.height = -1;
    }
    /// Mean of channel c over the 3x3 pixels around where (x, z) on the ground lands.
    float mean(const Image& image, double x, double z, int c) const
    {
        PixelPoint q = camera.project({x, -1, z});
        float sum = 0;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                sum += image.at(int(q.x) + dx, int(q.y) + dy, c);
        return sum / 9;
    }
};

TEST(Ground, ReceivesTheShadowAndCoversTheFrame)
{
    BallOverGround s(true, 0.2f);
    Image image = render(s.scene, s.camera, s.settings);
    // The ground fills a view that looks down on it: every pixel is covered.
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            ASSERT_EQ(image.at(x, y, 3), 1.0f) << x << "," << y;
    float lit = s.mean(image, 2, 2, 1), shadow = s.mean(image, -2, 0, 1);
    EXPECT_GT(lit, 0.05f);
    EXPECT_LT(shadow, 0.5f * lit);
    EXPECT_GT(shadow, 0);  // the sky still lights it
    // Grey: the default colour is neutral.
    EXPECT_NEAR(s.mean(image, 2, 2, 0), lit, 1e-4f);
    EXPECT_NEAR(s.mean(image, 2, 2, 2), lit, 1e-4f);
    // Without the ground, the same camera sees only the ball.
    s.settings.ground.enabled = false;
    EXPECT_EQ(render(s.scene, s.camera, s.settings).at(2, 2, 3), 0.0f);
}

TEST(Ground, ReachesTheHorizonInPerspective)
{
    geom::Scene scene = testing::empty_scene({-0.1, 0, -0.1}, {0.1, 1, 0.1});
    RenderSettings settings = testing::small(40, 30, 4, 1);
    settings.ground.enabled = true;  // at y = 0, the bounds' lowest point
    // The eye 1 above the ground, looking along it.
    Camera camera = Camera::perspective({0, 1, 5}, {0, 1, 0}, {0, 1, 0}, 40, 40, 30);
    Image image = render(scene, camera, settings);
    for (int x = 0; x < 40; ++x) {
        EXPECT_EQ(image.at(x, 16, 3), 1.0f) << x;  // just below the horizon: ground
        EXPECT_EQ(image.at(x, 13, 3), 0.0f) << x;  // just above: the background
    }
}

TEST(ShadowCatcher, AlphaIsTheLightThePlantTakesAway)
{
    // Light only: an unshadowed ground pixel is exactly transparent and black, the
    // umbra exactly opaque and black.
    BallOverGround dark(true, 0);
    dark.settings.ground.shadow_catcher = true;
    Image only_light = render(dark.scene, dark.camera, dark.settings);
    EXPECT_TRUE(only_light.transparent);
    PixelPoint far = dark.camera.project({2.5, -1, 2.5});
    PixelPoint umbra = dark.camera.project({-2, -1, 0});
    for (int c = 0; c < 4; ++c) {
        EXPECT_EQ(only_light.at(int(far.x), int(far.y), c), 0.0f) << c;
        EXPECT_EQ(only_light.at(int(umbra.x), int(umbra.y), c), c == 3 ? 1.0f : 0.0f) << c;
    }
    // The ball itself stays opaque.
    PixelPoint ball = dark.camera.project({0, 1, 0});
    EXPECT_EQ(only_light.at(int(ball.x), int(ball.y), 3), 1.0f);

    // With a sky too, the umbra keeps the sky's light: its alpha is 1 - (ground lit with
    // the ball / ground lit without it), both measured by rendering a plain ground.
    BallOverGround with(true, 0.2f), without(false, 0.2f), catcher(true, 0.2f);
    catcher.settings.ground.shadow_catcher = true;
    with.settings.samples_per_pixel = without.settings.samples_per_pixel = 512;
    Image a = render(with.scene, with.camera, with.settings);
    Image b = render(without.scene, without.camera, without.settings);
    Image c = render(catcher.scene, catcher.camera, catcher.settings);
    float expected = 1 - with.mean(a, -2, 0, 1) / without.mean(b, -2, 0, 1);
    EXPECT_GT(expected, 0.3f);
    EXPECT_LT(expected, 0.95f);
    EXPECT_NEAR(catcher.mean(c, -2, 0, 3), expected, 0.04f);
    EXPECT_EQ(catcher.mean(c, -2, 0, 1), 0.0f);  // the catcher adds no colour
    // Far from the ball, only rare sky rays meet it.
    EXPECT_LT(catcher.mean(c, 2.5, 2.5, 3), 0.02f);
}

TEST(ShadowCatcher, AdaptiveSamplingFollowsTheShadowsNoise)
{
    // The catcher's colour is 0 everywhere; its light estimate is what is noisy in the
    // shadow (the sky's occlusion), and adaptive sampling must keep sampling there.
    BallOverGround s(true, 0.2f);
    s.settings.ground.shadow_catcher = true;
    s.settings.samples_per_pixel = 256;
    s.settings.noise_target = 0.002f;
    RenderReport report;
    render(s.scene, s.camera, s.settings, &report);
    const std::uint64_t pixels = std::uint64_t(s.settings.width) * s.settings.height;
    // without: every pixel stops at 16 samples (16 x pixels in all)
    EXPECT_GT(report.samples, 16 * pixels + 20 * 256);  // shadowed pixels went on
    EXPECT_LT(report.samples, 200 * pixels);  // the unshadowed ground stopped early
}

}  // namespace
}  // namespace cambium::render
