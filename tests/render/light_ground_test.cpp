// SPDX-License-Identifier: Apache-2.0
// The light report's ground (--ground): light it reflects onto the organs against the
// view factor of a leaf's shadow, the environment's lower half hidden, the flux
// bookkeeping, thread independence, and the infinite canopy over it.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "render/environment.h"
#include "render/light.h"
#include "render/light_report.h"

using namespace cambium;
using namespace cambium::render;

namespace {

using geom::Float3;
constexpr std::uint16_t black = 1, grey = 2;

geom::Scene dark_scene()
{
    geom::Scene scene;
    scene.materials[black].diffuse = {0, 0, 0};
    scene.materials.resize(3);
    scene.materials[grey].diffuse = {0.6f, 0.6f, 0.6f};
    scene.materials[grey].translucency = 0.3f;
    scene.geometry.modules.names = {"L"};
    return scene;
}

void add_triangle(geom::Scene& scene, std::uint32_t module, Float3 a, Float3 b, Float3 c,
                  std::uint16_t material = black)
{
    geom::TriangleMesh& m = scene.geometry.mesh;
    auto base = static_cast<std::uint32_t>(m.positions.size());
    for (const Float3& p : {a, b, c}) {
        m.positions.push_back(p);
        m.normals.push_back({0, 0, 0});
    }
    m.triangles.push_back({base, base + 1, base + 2});
    m.material.push_back(material);
    m.back_material.push_back(material);
    m.module.push_back(module);
}

/// A horizontal black w x d rectangle at height y from the origin, its front up, module 0.
void add_leaf(geom::Scene& scene, double w, double d, float y)
{
    const float x = float(w), z = float(d);
    add_triangle(scene, 0, {0, y, 0}, {0, y, z}, {x, y, z});
    add_triangle(scene, 0, {0, y, 0}, {x, y, z}, {x, y, 0});
    scene.geometry.modules.records.push_back({0, 0, 0});
}

RenderLight sun_overhead()
{
    RenderLight l;
    l.kind = RenderLight::Kind::directional;
    l.toward_light = {0, 1, 0};
    l.colour = {1, 1, 1};
    return l;
}

LightReportSettings overhead(std::uint64_t rays, geom::Rgb ground, double height = 0)
{
    LightReportSettings s;
    s.rays = rays;
    s.view_lights = false;
    s.lights = {sun_overhead()};
    s.ground = LightReportSettings::Ground{ground, height};
    return s;
}

/// The view factor from a point at height h over a corner of a parallel a x b rectangle.
double corner_view_factor(double a, double b, double h)
{
    const double x = a / h, y = b / h, sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * std::numbers::pi);
}

/// The view factor from the lower face of an s x s square at height h to the square
/// under it, averaged over the face (the point formula over its four corner rectangles,
/// a 400 x 400 midpoint rule).
double shadow_view_factor(double s, double h)
{
    constexpr int n = 400;
    double sum = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double x = (i + 0.5) / n * s, z = (j + 0.5) / n * s;
            sum += corner_view_factor(x, z, h) + corner_view_factor(s - x, z, h) +
                   corner_view_factor(x, s - z, h) + corner_view_factor(s - x, s - z, h);
        }
    return sum / (n * n);
}

double closure(const LightReport& r)
{
    const double in = r.emitted + r.ground_emitted;
    return std::abs(in - (r.absorbed + r.ground_reached + r.escaped + r.truncated)) / in;
}

}  // namespace

// A black 1 x 1 leaf 0.5 above a ground of albedo rho, under a vertical light of
// irradiance 1: its upper side gets 1, its lower side rho (1 - F), F the view factor of
// its own shadow (the square under it), here 0.415.
TEST(LightReportGround, LowerSideSeesTheLitGroundAroundItsShadow)
{
    geom::Scene scene = dark_scene();
    add_leaf(scene, 1, 1, 0.5f);
    const LightReport r = trace_light(scene, overhead(1'000'000, {0.8f, 0.8f, 0.8f}));
    ASSERT_EQ(r.organs.size(), 1u);
    const OrganLight& o = r.organs[0];
    const double rho = r.ground_albedo, F = shadow_view_factor(1, 0.5);
    EXPECT_GT(rho, 0.5);
    EXPECT_NEAR(F, 0.415, 0.001);
    EXPECT_NEAR(o.incident_front, 1.0, 1e-3);
    const double lower = rho * (1 - F);
    EXPECT_NEAR(o.incident_back, lower, std::max(o.absorbed_ci95, 0.01 * lower));
    EXPECT_NEAR(o.absorbed, 1 + lower, o.absorbed_ci95);
    EXPECT_LT(o.absorbed_ci95, 0.02 * o.absorbed);
    // the ground within the beam: all of it less the shadow
    EXPECT_NEAR(r.ground_reached, r.emitted - 1, 1e-3);
    EXPECT_NEAR(r.ground_absorbed, (1 - rho) * r.ground_reached, 1e-12);
    EXPECT_LT(closure(r), 1e-9);
}

// The same leaf 3 above the ground, where its shadow fills little of its view: the
// lower side tends to rho.
TEST(LightReportGround, HighLeafSeesNearlyTheWholeLitGround)
{
    geom::Scene scene = dark_scene();
    add_leaf(scene, 1, 1, 3);
    const LightReport r = trace_light(scene, overhead(1'000'000, {0.5f, 0.5f, 0.5f}));
    ASSERT_EQ(r.organs.size(), 1u);
    const OrganLight& o = r.organs[0];
    const double lower = r.ground_albedo * (1 - shadow_view_factor(1, 3));
    EXPECT_NEAR(o.incident_back, lower, std::max(o.absorbed_ci95, 0.01 * lower));
}

// A black ground takes nothing away from a beam from above (the same numbers as without
// it, bit for bit) but hides the environment's lower half: a uniform environment of
// radiance L lights only the upper side.
TEST(LightReportGround, BlackGroundHidesOnlyTheLowerHalf)
{
    geom::Scene scene = dark_scene();
    add_leaf(scene, 2, 3, 1);
    LightReportSettings with = overhead(100'000, {0, 0, 0});
    LightReportSettings without = with;
    without.ground.reset();
    const LightReport a = trace_light(scene, with), b = trace_light(scene, without);
    ASSERT_EQ(a.organs.size(), 1u);
    EXPECT_EQ(a.organs[0].absorbed, b.organs[0].absorbed);
    EXPECT_EQ(a.ground_albedo, 0);
    EXPECT_EQ(a.ground_emitted, 0);
    EXPECT_NEAR(a.ground_reached, b.escaped_down, 1e-12);

    const float L = 0.7f;
    with.lights.clear();
    with.rays = 400'000;
    with.environment = std::make_shared<Environment>(make_uniform_environment({L, L, L}));
    without = with;
    without.ground.reset();
    const LightReport e = trace_light(scene, with), f = trace_light(scene, without);
    const OrganLight &o = e.organs[0], &p = f.organs[0];
    EXPECT_EQ(o.incident_back, 0);
    EXPECT_NEAR(o.incident_front, L * 6, o.absorbed_ci95);
    EXPECT_NEAR(p.incident_back, L * 6, p.absorbed_ci95);  // without it, from below too
    EXPECT_TRUE(e.skipped_lights.empty());
}

// A light under the ground's horizon, or under the ground, is hidden by it.
TEST(LightReportGround, LightsBelowTheGroundAreSkipped)
{
    geom::Scene scene = dark_scene();
    add_leaf(scene, 1, 1, 1);
    LightReportSettings s = overhead(10'000, {0.5f, 0.5f, 0.5f});
    s.lights[0].toward_light = {0, -1, 0};
    RenderLight point;
    point.position = {0.5f, -1, 0.5f};
    point.colour = {1, 1, 1};
    s.lights.push_back(point);
    const LightReport r = trace_light(scene, s);
    EXPECT_EQ(r.skipped_lights.size(), 2u);
    EXPECT_EQ(r.organs[0].absorbed, 0);
}

// Grey translucent leaves over a grey ground under a slanted light, the sky-like
// environment and a point light: what enters (the lights' rays, what the ground sends
// up) is what is absorbed, reaches the ground, escapes or is cut short, to rounding, and
// the organs' sum is the total.
TEST(LightReportGround, FluxBalances)
{
    geom::Scene scene = dark_scene();
    std::mt19937 gen(11);
    std::uniform_real_distribution<float> u(0, 1);
    for (std::uint32_t i = 0; i < 200; ++i) {
        const Float3 c{u(gen) * 2, 0.1f + u(gen), u(gen) * 2};
        add_triangle(scene, i, c, {c[0] + 0.2f * u(gen), c[1] + 0.2f * (u(gen) - 0.5f), c[2]},
                     {c[0], c[1] + 0.2f * (u(gen) - 0.5f), c[2] + 0.2f * u(gen)}, grey);
        scene.geometry.modules.records.push_back({0, 0, 0});
    }
    LightReportSettings s = overhead(200'000, {0.7f, 0.6f, 0.5f});
    s.ground->height.reset();  // the scene's lowest point
    s.lights[0].toward_light = {0.6f, 0.8f, 0};
    RenderLight point;
    point.position = {1, 3, 1};
    point.colour = {0.5f, 0.5f, 0.5f};
    point.att_quadratic = 0.1f;
    s.lights.push_back(point);
    s.environment = std::make_shared<Environment>(make_uniform_environment({0.3f, 0.4f, 0.5f}));
    const LightReport r = trace_light(scene, s);
    EXPECT_LT(closure(r), 1e-12);
    EXPECT_GT(r.ground_emitted, 0);
    EXPECT_GT(r.ground_reached, 0);
    EXPECT_LT(r.ground_absorbed, r.ground_reached);
    EXPECT_GT(r.ground_absorbed, 0.5 * r.ground_reached);  // 1 - albedo: 0.5 to 0.8
    EXPECT_EQ(r.escaped_down, 0);
    double organs = 0;
    for (const OrganLight& o : r.organs)
        organs += o.absorbed;
    EXPECT_NEAR(organs + r.unattributed, r.absorbed, 1e-9 * r.absorbed);

    s.infinite_canopy = true;
    const LightReport c = trace_light(scene, s);
    EXPECT_LT(closure(c), 1e-12);
    EXPECT_EQ(c.escaped_down, 0);
}

TEST(LightReportGround, SameNumbersOnAnyThreads)
{
    geom::Scene scene = dark_scene();
    std::mt19937 gen(5);
    std::uniform_real_distribution<float> u(0, 1);
    for (std::uint32_t i = 0; i < 100; ++i) {
        const Float3 c{u(gen), 0.1f + u(gen), u(gen)};
        add_triangle(scene, i, c, {c[0] + 0.2f, c[1], c[2]}, {c[0], c[1] + 0.1f, c[2] + 0.2f}, grey);
        scene.geometry.modules.records.push_back({0, 0, 0});
    }
    LightReportSettings s = overhead(50'000, {0.8f, 0.8f, 0.8f});
    s.environment = std::make_shared<Environment>(make_uniform_environment({0.3f, 0.3f, 0.3f}));
    s.threads = 1;
    const LightReport one = trace_light(scene, s);
    s.threads = 2;
    const LightReport two = trace_light(scene, s);
    ASSERT_EQ(one.organs.size(), two.organs.size());
    for (std::size_t i = 0; i < one.organs.size(); ++i) {
        EXPECT_EQ(one.organs[i].absorbed, two.organs[i].absorbed);
        EXPECT_EQ(one.organs[i].absorbed_ci95, two.organs[i].absorbed_ci95);
    }
    EXPECT_EQ(one.ground_reached, two.ground_reached);
    EXPECT_EQ(one.ground_emitted, two.ground_emitted);
}

// An infinite canopy of black leaves covering half of each 1 x 1 tile, 2 above a ground
// of albedo rho, under a vertical light: half the light reaches the ground, which sends
// rho / 2 up, spread evenly over the leaves' layer so high above it (its offsets' spread
// hides the strips), and half of that meets the leaves: their lower side gets rho / 2.
TEST(LightReportGround, InfiniteCanopyOverTheGround)
{
    geom::Scene scene = dark_scene();
    add_leaf(scene, 0.5, 1, 2);
    LightReportSettings s = overhead(400'000, {0.8f, 0.8f, 0.8f});
    s.canopy_tile = std::array<double, 4>{0, 0, 1, 1};
    const LightReport r = trace_light(scene, s);
    ASSERT_EQ(r.organs.size(), 1u);
    const OrganLight& o = r.organs[0];
    const double rho = r.ground_albedo;
    EXPECT_NEAR(o.incident_front, 0.5, 1e-3);
    EXPECT_NEAR(o.incident_back / o.area, rho / 2, std::max(o.absorbed_ci95 / o.area, 0.01 * rho / 2));
    EXPECT_NEAR(r.ground_reached, 0.5, 1e-3);
    EXPECT_NEAR(r.ground_absorbed, (1 - rho) * 0.5, 1e-3);
    EXPECT_LT(closure(r), 1e-12);
    EXPECT_EQ(r.escaped_down, 0);
}
