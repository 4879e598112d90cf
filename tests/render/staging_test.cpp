// SPDX-License-Identifier: Apache-2.0
// Staged stills: a ground under the sky or a map. Light selection by what a light can
// deliver (nothing to a light the opaque ground hides), a furnace of the ground under an
// environment, and the ground's per-pixel noise under the sky.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "render/color.h"
#include "render/environment.h"
#include "render/ground.h"
#include "render/integrator.h"
#include "render/light.h"
#include "render/material.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

geom::Light directional_light(const geom::Vec3& toward)
{
    geom::Light l;
    l.kind = geom::Light::Kind::directional;
    l.direction = toward;
    return l;
}

geom::Light point_light(const geom::Vec3& at)
{
    geom::Light l;
    l.kind = geom::Light::Kind::point;
    l.position = at;
    return l;
}

SurfaceHit plant_hit(const Vec3f& at, const Vec3f& normal)
{
    SurfaceHit h;
    h.position = at;
    h.normal = h.geometric_normal = normal;
    h.geom_id = 0;
    h.prim_id = 0;
    h.shape = Shape::triangle;
    return h;
}

// FernLeaf's case: one light above, one shining from below the ground (and a point light
// under it), the sky around. A translucent vertical leaf above the ground would be lit by
// all three through its two sides, but the ground hides the two below: they get nothing,
// the light above and the sky keep their chance. Without the ground each gets some.
TEST(LightSelection, ALightBelowTheOpaqueGroundGetsNothing)
{
    const Environment sky = make_sky_environment();
    PathContext ctx;
    ctx.lights = make_lights({directional_light({0.3, 1, 0.5}), directional_light({0.2, -1, 0.4}),
                              point_light({0, -2, 1})});
    ctx.environment = &sky;
    GroundPlane ground;
    ground.height = 0;
    ctx.ground = ground;
    prepare_path_context(ctx);
    ASSERT_TRUE(ctx.prepared->lights.per_point());
    ASSERT_EQ(ctx.prepared->lights.size(), 4u);
    ASSERT_EQ(ctx.prepared->lights.kind(3), LightKind::environment);

    const Bsdf leaf{Vec3f(0.4f), Vec3f(0.3f), Vec3f(), 0};
    const SurfaceHit hit = plant_hit({0, 1, 0}, {0, 0, 1});
    const BsdfAt at = bsdf_at(leaf, hit.normal, {0, 0, 1});
    std::vector<float> p = light_choice_probabilities(ctx, hit, at);
    EXPECT_GT(p[0], 0.05f);
    EXPECT_EQ(p[1], 0.0f);
    EXPECT_EQ(p[2], 0.0f);
    EXPECT_GT(p[3], 0.05f);
    EXPECT_NEAR(p[0] + p[3], 1.0f, 1e-5f);
    // The environment is not sampled below the horizon there either.
    EXPECT_EQ(ctx.prepared->lights.environment_pdf({0, -1, 0}), 0.0f);
    EXPECT_GT(ctx.prepared->lights.environment_pdf(normalize(Vec3f(0.1f, 1, 0))), 0.0f);

    // A point on the ground itself: only what is above it.
    SurfaceHit on_ground = ground.hit({0.5f, 2, 0.5f}, {0, -1, 0}, 2);
    const Bsdf grey{Vec3f(0.2f), Vec3f(), Vec3f(), 0};
    std::vector<float> q =
        light_choice_probabilities(ctx, on_ground, bsdf_at(grey, on_ground.normal, {0, 1, 0}));
    EXPECT_GT(q[0], 0.0f);
    EXPECT_EQ(q[1], 0.0f);
    EXPECT_EQ(q[2], 0.0f);
    EXPECT_GT(q[3], 0.0f);

    ctx.ground.reset();
    prepare_path_context(ctx);
    std::vector<float> open = light_choice_probabilities(ctx, hit, at);
    for (std::size_t i = 0; i < open.size(); ++i)
        EXPECT_GT(open[i], 0.0f) << i;
    EXPECT_GT(ctx.prepared->lights.environment_pdf({0, -1, 0}), 0.0f);
}

/// A camera 2 above the ground at y = 0, looking down on it at 45 degrees; an empty scene
/// (nothing but the ground in view).
struct OpenGround {
    geom::Scene scene = testing::empty_scene({-0.1, 0, -0.1}, {0.1, 0.2, 0.1});
    Camera camera = Camera::perspective({0, 2, 2}, {0, 0, 0}, {0, 1, 0}, 30, 32, 32);
    RenderSettings settings = testing::small(32, 32, 64, 3);

    OpenGround()
    {
        settings.ground.enabled = true;
        settings.ground.height = 0;
    }

    /// Mean and spread over the pixels of channel c (all of them see the ground).
    static std::pair<double, double> mean_and_spread(const Image& image, int c)
    {
        double sum = 0, sum2 = 0;
        int n = 0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                double v = image.at(x, y, c);
                sum += v;
                sum2 += v * v;
                ++n;
            }
        double mean = sum / n;
        return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean))};
    }
};

// A furnace of the ground: an environment of radiance 0.5 above the horizon and 2 below
// it (which the ground hides), a directional light from below the ground: every point of
// the ground reflects albedo x 0.5 exactly. Rendered with light sampling of the map
// (not constant, so it is sampled), its choice per point and MIS; the mean over 1024
// pixels at 64 spp is within 4 standard errors of the pixels' spread.
TEST(Staging, GroundUnderAnEnvironmentReflectsAlbedoTimesItsRadiance)
{
    OpenGround g;
    const int w = 64, h = 32;
    std::vector<float> rgb(std::size_t(w) * h * 3);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w * 3; ++i)
            rgb[std::size_t(j) * w * 3 + std::size_t(i)] = j < h / 2 ? 0.5f : 2.0f;
    g.settings.environment =
        std::make_shared<const Environment>(make_map_environment(w, h, rgb));
    g.scene.lights.push_back(directional_light({0.3, -1, 0.2}));
    g.settings.ground.colour = {0.6f, 0.6f, 0.6f};
    const double albedo = srgb_to_linear(0.6f);
    Image image = render(g.scene, g.camera, g.settings);
    for (int c = 0; c < 3; ++c) {
        auto [mean, spread] = OpenGround::mean_and_spread(image, c);
        double se = spread / std::sqrt(32.0 * 32.0);
        EXPECT_NEAR(mean, albedo * 0.5, 4 * se + 1e-5) << "channel " << c;
        std::printf("[furnace] channel %d: %.5f (expected %.5f), spread %.4f\n", c, mean,
                    albedo * 0.5, spread);
    }
}

// The ground's grain under the default --sky with FernLeaf's two view lights: the spread
// of an open patch's pixels at 64 spp relative to their mean (the true radiance is the
// same at every pixel: nothing shadows it). Measured 4.4% (R) and 3.9% (G); with the
// lights chosen by power and the dome sampled uniformly over the sphere (the sun's cone
// at 1/2) 13.1% and 11.6%, as on FernLeaf's staged still; with only the dome's sampling
// reverted, 5.7% and 5.1%. Bound: 6%. The sky alone with independent (white-noise)
// samples shows the dome's sampling itself: measured 8.1% and 7.7%, 10.2% and 9.6% with
// the uniform sphere; bound 9.5% (the renders are deterministic: the margin is for
// changes elsewhere, not for chance).
TEST(Staging, GroundUnderTheSkyHasLittleGrainAt64Spp)
{
    OpenGround g;
    g.settings.environment = std::make_shared<const Environment>(make_sky_environment());
    // FernLeaf's view lights: one from above at 26 degrees, one from below the ground.
    g.scene.lights.push_back(directional_light({0.5, 1, 2}));
    g.scene.lights.push_back(directional_light({-0.5, -1, -2}));
    g.scene.lights.back().diffuse = {0.6f, 0.6f, 0.6f};
    Image image = render(g.scene, g.camera, g.settings);
    for (int c = 0; c < 2; ++c) {
        auto [mean, spread] = OpenGround::mean_and_spread(image, c);
        ASSERT_GT(mean, 0.01) << c;
        std::printf("[sky ground] channel %d: mean %.4f, relative spread %.4f\n", c, mean,
                    spread / mean);
        EXPECT_LT(spread / mean, 0.06) << "channel " << c;
    }
    // The sky alone, each sample's own variance (independent samples): the dome sampled
    // as its radiance, nothing spent below the horizon.
    OpenGround open;
    open.settings.environment = g.settings.environment;
    open.settings.sampler = SampleSequence::white;
    Image alone = render(open.scene, open.camera, open.settings);
    for (int c = 0; c < 2; ++c) {
        auto [mean, spread] = OpenGround::mean_and_spread(alone, c);
        std::printf("[sky ground] sky alone, white noise, channel %d: relative spread %.4f\n",
                    c, spread / mean);
        EXPECT_LT(spread / mean, 0.095) << "channel " << c;
    }
}

}  // namespace
}  // namespace cambium::render
