// SPDX-License-Identifier: Apache-2.0
// The integrator against closed forms: white furnaces (diffuse, translucent, glossy; sphere,
// curves, instanced mesh), direct light from point and directional lights, two-sided and
// translucent leaves, transparency, emission, environment MIS.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "render/accel.h"
#include "render/color.h"
#include "geom_scenes.h"

namespace cambium::render {
namespace {

using namespace testing;

constexpr float pi = std::numbers::pi_v<float>;

geom::Rgb grey(float display) { return {display, display, display}; }

/// A context over accel with the scene's materials and lights.
PathContext context(const geom::Scene& s, const EmbreeScene& accel, float ambient, int depth)
{
    PathContext ctx;
    ctx.accel = &accel;
    ctx.materials = make_materials(s.materials);
    ctx.lights = make_lights(s.lights);
    ctx.background = decode_display(s.background);
    ctx.ambient = Vec3f(ambient);
    ctx.max_depth = depth;
    return ctx;
}

/// White furnace: environment and background of radiance 1, mean over a block of pixels
/// that all see the object (coverage must be 1); its standard error in `se`.
float furnace(const geom::Scene& s, const Camera& camera, int x0, int y0, int x1, int y1,
              int spp, int roulette_depth, const Environment* env = nullptr,
              double* se = nullptr)
{
    EmbreeScene accel(s, camera);
    PathContext ctx = context(s, accel, 1, 200);
    // The uniform environment as an object: the integrator must see it needs no NEE.
    const Environment uniform = make_uniform_environment(Vec3f(1));
    ctx.environment = env ? env : &uniform;
    ctx.background = Vec3f(1);
    ctx.roulette_depth = roulette_depth;
    prepare_path_context(ctx);
    BlockMean m = trace_block(ctx, camera, x0, y0, x1, y1, spp);
    EXPECT_EQ(m.coverage, 1.0);
    if (se)
        *se = m.standard_error;
    return m.radiance.y;
}

geom::Scene white(float translucency)
{
    geom::Scene s;
    s.materials[1].diffuse = grey(1);
    s.materials[1].translucency = translucency;
    return s;
}

// 16x16 pixels over 8x8 units; the block x, y in 5..11 sees a radius-3 sphere at the centre.
TEST(Physics, WhiteFurnaceSphere)
{
    for (float tr : {0.0f, 0.5f}) {
        geom::Scene s = white(tr);
        add_sphere(s.geometry, {0, 0, 0}, 3);
        Camera c = top_camera(0, 0, 8, 16, 16);
        float exact = furnace(s, c, 5, 5, 11, 11, 8, 1000);
        EXPECT_NEAR(exact, 1.0f, 1e-3f) << "translucency " << tr;
        float rr = furnace(s, c, 5, 5, 11, 11, 32, 2);
        EXPECT_NEAR(rr, 1.0f, 0.02f) << "translucency " << tr << " with Russian roulette";
        std::printf("[furnace] sphere translucency %.1f: %.5f (RR off) %.5f (RR on)\n", tr,
                    exact, rr);
    }
}

// Russian roulette from the first bounce: a convex grey sphere in a uniform sky of
// radiance 1 shows its albedo (every bounce ray escapes, with weight = albedo). A path of
// throughput at least 0.5 always goes on (no noise at all); a dimmer one goes on with
// probability throughput / 0.5 and is reweighted, so the mean stays the albedo (without
// the reweighting it would be 2 albedo^2) while the noise shows the roulette ran.
TEST(Physics, RouletteThinsOnlyDimPaths)
{
    for (float display : {0.5f, 0.9f}) {
        geom::Scene s;
        s.materials[1].diffuse = grey(display);
        add_sphere(s.geometry, {0, 0, 0}, 3);
        Camera c = top_camera(0, 0, 8, 16, 16);
        const float albedo = srgb_to_linear(display);
        double se = -1;
        float v = furnace(s, c, 5, 5, 11, 11, 32, 1, nullptr, &se);
        EXPECT_NEAR(v, albedo, std::fmax(4 * se, 1e-4)) << display;
        if (albedo >= 0.5f)
            EXPECT_LT(se, 1e-6) << "a path of throughput " << albedo << " was cut";
        else
            EXPECT_GT(se, 1e-3) << "no path of throughput " << albedo << " was cut";
        std::printf("[furnace] roulette, albedo %.3f: %.5f (standard error %.5f)\n", albedo, v,
                    se);
    }
}

TEST(Physics, WhiteFurnaceRoundCurves)
{
    for (float tr : {0.0f, 0.5f}) {
        geom::Scene s = white(tr);
        add_hermite(s.geometry, {-5, -1, 0, 2}, {10, 2, 0, 0}, {5, 1, 0, 2}, {10, 2, 0, 0});
        add_hermite(s.geometry, {-5, 1, -1, 1.5f}, {10, -2, 0, 0}, {5, -1, -1, 1.5f},
                    {10, -2, 0, 0});
        Camera c = top_camera(0, 0, 8, 16, 16);
        float v = furnace(s, c, 4, 6, 12, 10, 16, 1000);
        EXPECT_NEAR(v, 1.0f, 2e-3f) << "translucency " << tr;
        std::printf("[furnace] hermite curves translucency %.1f: %.5f\n", tr, v);
    }
}

// A closed cube as a prototype, rotated and scaled by its instance: rays inside meet the
// back faces (same white material) until they get out.
TEST(Physics, WhiteFurnaceInstancedMesh)
{
    for (float tr : {0.0f, 0.5f}) {
        geom::Scene s = white(tr);
        geom::Prototype p;
        add_cube(p.geometry, 1, geom::inherit_material, geom::inherit_material);
        s.prototypes.push_back(p);
        geom::Instance inst;
        float c = std::cos(0.5f), sn = std::sin(0.5f);
        inst.transform = transform({3 * c, -3 * sn, 0, 3 * sn, 3 * c, 0, 0, 0, 2});
        inst.material = inst.back_material = 1;
        s.instances.push_back(inst);
        Camera cam = top_camera(0, 0, 8, 16, 16);
        float v = furnace(s, cam, 6, 6, 10, 10, 16, 1000);
        EXPECT_NEAR(v, 1.0f, 2e-3f) << "translucency " << tr;
        std::printf("[furnace] instanced cube translucency %.1f: %.5f\n", tr, v);
    }
}

// Normalized Phong: at normal incidence its albedo is exactly the lobe's albedo, for any
// shininess; on a sphere (all incidences) it may lose energy, never gain it. A cpfg
// specular of 1 maps to albedo 2 / (n + 2), n = shininess / 4 (docs/materials.md).
TEST(Physics, GlossyFurnace)
{
    for (float shininess : {0.0f, 32.0f, 128.0f}) {
        const float albedo = 2 / (shininess / 4 + 2);
        geom::Scene s;
        s.materials[1].diffuse = grey(0);
        s.materials[1].specular = grey(1);
        s.materials[1].shininess = shininess;
        add_quad(s.geometry, -10, -10, 10, 10, 0, 1, 1);
        Camera c = top_camera(0, 0, 8, 16, 16);
        // Tolerances: 4 standard errors of the estimate itself (about 1 in 16 000 to fail
        // by chance), which must be small enough to mean something.
        double se_plane = 0, se_sphere = 0;
        float plane = furnace(s, c, 4, 4, 12, 12, 128, 1000, nullptr, &se_plane);
        EXPECT_LT(se_plane, 0.01 * albedo) << shininess;
        EXPECT_NEAR(plane, albedo, 4 * se_plane) << shininess;
        geom::Scene ball = s;
        ball.geometry = {};
        add_sphere(ball.geometry, {0, 0, 0}, 3.5f);
        float sphere = furnace(ball, c, 4, 4, 12, 12, 128, 1000, nullptr, &se_sphere);
        EXPECT_LT(se_sphere, 0.01 * albedo) << shininess;
        // Never more than the albedo; the loss at grazing angles is the lobe's part below
        // the surface, under a fifth of it seen from this camera.
        EXPECT_LE(sphere, albedo + 4 * se_sphere) << shininess;
        EXPECT_GT(sphere, 0.8f * albedo) << shininess;
        std::printf("[furnace] glossy shininess %.0f: plane %.4f sphere %.4f (albedo %.4f)\n",
                    shininess, plane, sphere, albedo);
    }
}

/// Mean radiance of the 2x2 pixels at the centre of a 0.2-unit camera looking down at (x, y).
float radiance_at(const geom::Scene& s, float x, float y, int depth = 1, int spp = 4,
                  bool from_below = false, double* se = nullptr)
{
    Camera c = from_below ? Camera::parallel({x, y, 0}, {0, 0, 1}, {0, 1, 0}, 0.01, 100, 20, 20)
                          : top_camera(x, y, 0.2, 20, 20);
    EmbreeScene accel(s, c);
    PathContext ctx = context(s, accel, 0, depth);
    prepare_path_context(ctx);
    BlockMean m = trace_block(ctx, c, 9, 9, 11, 11, spp);
    if (se)
        *se = m.standard_error;
    return m.radiance.y;
}

geom::Scene lit_plane(float albedo_display)
{
    geom::Scene s;
    s.materials[1].diffuse = grey(albedo_display);
    add_quad(s.geometry, -50, -50, 50, 50, 0, 1, 1);
    return s;
}

// A point light of colour 1 at height h with cpfg's T: c l q: L = albedo cos / (c + l d + q d^2).
TEST(Physics, PointLightWithAttenuationMatchesClosedForm)
{
    geom::Scene s = lit_plane(0.8f);
    geom::Light l;
    l.position = {0, 0, 5};
    l.attenuation_constant = 1;
    l.attenuation_linear = 0.1f;
    l.attenuation_quadratic = 0.02f;
    s.lights.push_back(l);
    float a = srgb_to_linear(0.8f);
    for (float x : {0.0f, 3.0f, 8.0f}) {
        float d = std::sqrt(x * x + 25);
        float expect = a * (5 / d) / (1 + 0.1f * d + 0.02f * d * d);
        float got = radiance_at(s, x, 0);
        EXPECT_NEAR(got, expect, 0.01f * expect) << x;
        std::printf("[direct] point light x=%.0f: %.5f expected %.5f (%.3f%%)\n", x, got, expect,
                    100 * (got - expect) / expect);
    }
}

TEST(Physics, DirectionalLightMatchesClosedForm)
{
    geom::Scene s = lit_plane(0.6f);
    geom::Light l;
    l.kind = geom::Light::Kind::directional;
    l.direction = {1, 0, 1};
    s.lights.push_back(l);
    float expect = srgb_to_linear(0.6f) / std::sqrt(2.0f);
    float got = radiance_at(s, 1, 2);
    EXPECT_NEAR(got, expect, 0.01f * expect);
    std::printf("[direct] directional 45 deg: %.5f expected %.5f\n", got, expect);
}

geom::Light directional(const geom::Vec3& toward)
{
    geom::Light l;
    l.kind = geom::Light::Kind::directional;
    l.direction = toward;
    return l;
}

// Seen from below and lit from below, a triangle shows its back material.
TEST(Physics, BackMaterialOnBackFaces)
{
    geom::Scene s;
    s.materials[1].diffuse = grey(0.2f);
    s.materials[2].diffuse = grey(0.9f);
    add_quad(s.geometry, -5, -5, 5, 5, 0, 1, 2);
    s.lights.push_back(directional({0, 0, -1}));
    EXPECT_NEAR(radiance_at(s, 0, 0, 1, 4, true), srgb_to_linear(0.9f), 1e-3f);
    s.lights[0] = directional({0, 0, 1});
    EXPECT_NEAR(radiance_at(s, 0, 0), srgb_to_linear(0.2f), 1e-3f);
}

// Interpolated normals tilted far from the facet must not let light through an opaque sheet:
// a light below the sheet (but above the tilted shading normal) leaves its top side dark.
TEST(Physics, ShadingNormalsDoNotLeakLightThroughSheets)
{
    geom::Scene s;
    s.materials[1].diffuse = grey(1);
    geom::Float3 n{0.866f, 0, 0.5f};
    add_triangle(s.geometry, {{{-5, -5, 0}, {5, -5, 0}, {0, 5, 0}}}, {n, n, n},
                 {{{0, 0}, {1, 0}, {0, 1}}}, 1, 1);
    s.lights.push_back(directional({1, 0, -0.2}));
    EXPECT_EQ(radiance_at(s, 0, 0), 0.0f);
    // Lit from above, the same sheet is lit (the shading normal's cosine).
    s.lights[0] = directional({0, 0, 1});
    EXPECT_NEAR(radiance_at(s, 0, 0), 0.5f, 1e-3f);
}

// A translucent leaf lit from behind shows translucency * albedo; an opaque one nothing.
TEST(Physics, TranslucentLeafLitFromBehind)
{
    geom::Scene s;
    s.materials[1].diffuse = grey(0.7f);
    s.materials[1].translucency = 0.4f;
    add_quad(s.geometry, -5, -5, 5, 5, 0, 1, 1);
    s.lights.push_back(directional({0, 0, -1}));
    EXPECT_NEAR(radiance_at(s, 0, 0), 0.4f * srgb_to_linear(0.7f), 1e-3f);
    s.materials[1].translucency = 0;
    EXPECT_EQ(radiance_at(s, 0, 0), 0.0f);
}

// Among a view file's lights, next-event estimation picks one by what it gives the point
// (docs/architecture.md): an opaque plane lit from above by one light and from below by
// another is never given the light below, so its direct light has no noise at all, and a
// translucent leaf between two lights of different colours shows, channel by channel,
// reflect x one light + transmit x the other.
TEST(Physics, DeltaLightsChosenByWhatTheyGive)
{
    geom::Scene s = lit_plane(0.6f);
    s.lights.push_back(directional({0, 0, 1}));
    s.lights.push_back(directional({0, 0, -1}));
    double se = -1;
    EXPECT_NEAR(radiance_at(s, 0, 0, 1, 16, false, &se), srgb_to_linear(0.6f), 1e-5f);
    EXPECT_EQ(se, 0.0) << "the light below the opaque plane was chosen";

    geom::Scene leaf;
    leaf.materials[1].diffuse = grey(0.7f);
    leaf.materials[1].translucency = 0.4f;
    add_quad(leaf.geometry, -5, -5, 5, 5, 0, 1, 1);
    geom::Light warm = directional({0.3, 0, 1});  // above, seen: reflected
    warm.diffuse = {1, 0.5f, 0.2f};
    geom::Light cool = directional({0, -0.4, -1});  // below: transmitted
    cool.diffuse = {0.1f, 0.3f, 0.9f};
    leaf.lights = {warm, cool};
    Camera c = top_camera(0, 0, 0.2, 20, 20);
    EmbreeScene accel(leaf, c);
    PathContext ctx = context(leaf, accel, 0, 1);
    prepare_path_context(ctx);
    BlockMean m = trace_block(ctx, c, 9, 9, 11, 11, 64);
    const float albedo = srgb_to_linear(0.7f);
    auto expect = [&](float w, float k) {
        float cos_warm = 1 / std::sqrt(1.09f), cos_cool = 1 / std::sqrt(1.16f);
        return 0.6f * albedo * srgb_to_linear(w) * cos_warm +
               0.4f * albedo * srgb_to_linear(k) * cos_cool;
    };
    // Each sample is exact but for the choice (the chosen light's colour, scaled to the
    // luminance of both): a pixel's 64 stratified choices take each light within one of
    // its share, which moves the mean by well under 1%; a wrong weight (the choice's
    // probability left out or taken by power) moves it by tens of percent.
    EXPECT_NEAR(m.radiance.x, expect(1, 0.1f), 1e-2f * expect(1, 0.1f));
    EXPECT_NEAR(m.radiance.y, expect(0.5f, 0.3f), 1e-2f * expect(0.5f, 0.3f));
    EXPECT_NEAR(m.radiance.z, expect(0.2f, 0.9f), 1e-2f * expect(0.2f, 0.9f));
    std::printf("[direct] leaf between two lights: %.5f %.5f %.5f expected %.5f %.5f %.5f\n",
                m.radiance.x, m.radiance.y, m.radiance.z, expect(1, 0.1f), expect(0.5f, 0.3f),
                expect(0.2f, 0.9f));
}

// Transparency 0.5: half the camera rays pass (black behind), and a shadow through it is half.
TEST(Physics, TransparencyPassesLightStochastically)
{
    geom::Scene s;
    s.materials[1].diffuse = grey(1);
    s.materials[1].transparency = 0.5f;
    add_quad(s.geometry, -5, -5, 5, 5, 0, 1, 1);
    s.lights.push_back(directional({0, 0, 1}));
    float seen = radiance_at(s, 0, 0, 1, 1024);
    EXPECT_NEAR(seen, 0.5f, 0.03f);
    // An opaque plane below, seen through the transparent one: lit at half strength, seen
    // half the time, plus the transparent plane itself the other half.
    s.materials[2].diffuse = grey(1);
    add_quad(s.geometry, -50, -50, 50, 50, -1, 2, 2);
    float through = radiance_at(s, 0, 0, 1, 1024);
    EXPECT_NEAR(through, 0.5f + 0.5f * 0.5f, 0.03f);
    std::printf("[transparency] %.4f (0.5), stacked %.4f (0.75)\n", seen, through);
}

// A transparent sphere between a plane point and a directional light: the shadow ray
// passes both of its walls, so the light arrives attenuated twice, (1 - opacity)^2.
TEST(Physics, TransparentSphereAttenuatesTwice)
{
    geom::Scene s = lit_plane(0.6f);
    s.materials[2].diffuse = grey(0.5f);
    s.materials[2].transparency = 0.6f;  // opacity 0.4: 0.6 of the light passes each wall
    // Its shadow centre is the plane's origin; the camera looks straight down past it.
    add_sphere(s.geometry, {2, 0, 2}, 0.5f, 2);
    s.lights.push_back(directional({1, 0, 1}));
    float expect = srgb_to_linear(0.6f) / std::sqrt(2.0f) * 0.6f * 0.6f;
    float got = radiance_at(s, 0, 0);
    EXPECT_NEAR(got, expect, 0.01f * expect);
    std::printf("[transparency] through a sphere: %.5f expected %.5f (t^2)\n", got, expect);
}

// Flat primitives skip nothing: their spawn offset alone must keep shadow rays leaving at
// grazing angles from meeting the surface they leave, also far from the origin on a
// tilted plane (hit points not exactly on it). Any self-hit darkens the closed form.
TEST(Physics, FlatSurfacesLitAtGrazingAnglesDoNotShadowThemselves)
{
    geom::Scene s;
    s.materials[1].diffuse = grey(0.8f);
    const float x0 = 1000, y0 = -2000;
    auto z = [&](float x) { return 0.3f * (x - x0); };
    Vec3f n = normalize(Vec3f(-0.3f, 0, 1)), along = normalize(Vec3f(1, 0, 0.3f));
    geom::Float3 nf{n.x, n.y, n.z};
    for (float dy : {-60.0f, 0.0f}) {
        add_triangle(s.geometry, {{{x0 - 50, y0 + dy, z(x0 - 50)}, {x0 + 50, y0 + dy, z(x0 + 50)},
                                   {x0 + 50, y0 + dy + 60, z(x0 + 50)}}},
                     {nf, nf, nf}, {{{0, 0}, {1, 0}, {1, 1}}}, 1, 1);
        add_triangle(s.geometry, {{{x0 - 50, y0 + dy, z(x0 - 50)}, {x0 + 50, y0 + dy + 60, z(x0 + 50)},
                                   {x0 - 50, y0 + dy + 60, z(x0 - 50)}}},
                     {nf, nf, nf}, {{{0, 0}, {1, 1}, {0, 1}}}, 1, 1);
    }
    s.lights.push_back(directional({0, 0, 1}));
    for (float degrees : {1.0f, 5.0f, 20.0f}) {
        float e = degrees * pi / 180;
        for (float side : {1.0f, -1.0f}) {
            Vec3f l = n * std::sin(e) + along * (side * std::cos(e));
            s.lights[0] = directional({l.x, l.y, l.z});
            float expect = srgb_to_linear(0.8f) * std::sin(e);
            float got = radiance_at(s, x0 + 3.7f, y0 + 1.3f);
            EXPECT_NEAR(got, expect, 0.01f * expect) << degrees << " degrees, side " << side;
        }
    }
}

// A sphere of emitted radiance Le, radius R, centre at distance D from a plane point, at
// angle theta from its normal: E = pi Le (R/D)^2 cos theta, so L = albedo Le (R/D)^2 cos
// theta, found by BSDF rays alone.
TEST(Physics, EmissiveSphereLightsByBsdfRays)
{
    geom::Scene s = lit_plane(1);
    s.materials[2].diffuse = grey(0);
    s.materials[2].emission = grey(1);
    add_sphere(s.geometry, {0, 0, 3}, 1, 2);
    double se = 0;
    float got = radiance_at(s, 2, 0, 2, 32768, false, &se);  // D^2 = 13, cos = 3 / sqrt 13
    float expect = 1.0f / 13 * 3 / std::sqrt(13.0f);
    // 4 standard errors of this very estimate, and that error small enough to see a 5% bias.
    EXPECT_LT(se, 0.0125 * expect);
    EXPECT_NEAR(got, expect, 4 * se);
    std::printf("[emission] %.5f expected %.5f (standard error %.5f)\n", got, expect, se);
}

/// A latitude-longitude map (up +y) of width columns: column i looks along azimuth
/// phi = 2 pi (i + 1/2) / width, i.e. toward (sin phi, ., cos phi).
Environment map_by_column(int width, int height, float (*r)(int, int), float (*g)(int, int))
{
    std::vector<float> rgb;
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i)
            rgb.insert(rgb.end(), {r(i, j), g(i, j), g(i, j)});
    return make_map_environment(width, height, std::move(rgb));
}

/// Radiance 2 over the half-space z > 0, none below: of 4 columns the first and last,
/// whose azimuths (cos phi > 0) look toward +z. The map samples that hemisphere
/// uniformly (its texels by luminance), the BSDF by cosine: MIS weighs the two.
Environment sky_over_plus_z()
{
    auto hemisphere = [](int i, int) { return i == 0 || i == 3 ? 2.0f : 0.0f; };
    return map_by_column(4, 1, hemisphere, hemisphere);
}

/// Green radiance 1 from everywhere, red 1 but 40 from a quarter of the directions:
/// a white furnace in the green channel whose map samples by luminance, so next-event
/// estimation draws lopsidedly and MIS against BSDF sampling must still add up to 1.
Environment lopsided_green_furnace()
{
    auto red = [](int i, int j) { return i == 1 && j < 2 ? 40.0f : 1.0f; };
    return map_by_column(2, 4, red, [](int, int) { return 1.0f; });
}

TEST(Physics, EnvironmentSamplingWithMis)
{
    geom::Scene s = lit_plane(0.5f);
    Camera c = top_camera(0, 0, 0.2, 20, 20);
    EmbreeScene accel(s, c);
    const Environment sky = sky_over_plus_z();
    ASSERT_FALSE(sky.uniform());
    PathContext ctx = context(s, accel, 0, 1);
    ctx.environment = &sky;
    ctx.max_depth = 2;
    prepare_path_context(ctx);
    float got = trace_block(ctx, c, 9, 9, 11, 11, 512).radiance.y;
    float expect = srgb_to_linear(0.5f) * 2;
    EXPECT_NEAR(got, expect, 0.01f * expect);
    std::printf("[environment] sky over plane %.5f expected %.5f\n", got, expect);
    // Direct light only: no BSDF ray follows the last vertex, so its environment sample
    // must take full weight (MIS weights there would lose the BSDF strategy's share).
    ctx.max_depth = 1;
    float direct = trace_block(ctx, c, 9, 9, 11, 11, 512).radiance.y;
    EXPECT_NEAR(direct, expect, 0.01f * expect);

    for (float tr : {0.0f, 0.3f}) {
        geom::Scene ball = white(tr);
        add_sphere(ball.geometry, {0, 0, 0}, 3);
        const Environment lop = lopsided_green_furnace();
        ASSERT_FALSE(lop.uniform());  // so it is sampled for next-event estimation
        float v = furnace(ball, top_camera(0, 0, 8, 16, 16), 5, 5, 11, 11, 512, 1000, &lop);
        EXPECT_NEAR(v, 1.0f, 0.02f);
        std::printf("[furnace] sphere (translucency %.1f) under a non-uniformly sampled white "
                    "environment: %.5f\n", tr, v);
        geom::Scene plane = white(tr);
        add_quad(plane.geometry, -10, -10, 10, 10, 0, 1, 1);
        v = furnace(plane, top_camera(0, 0, 8, 16, 16), 5, 5, 11, 11, 32, 1000, &lop);
        EXPECT_NEAR(v, 1.0f, 0.02f);
        std::printf("[furnace] plane (translucency %.1f): %.5f\n", tr, v);
    }
}

}  // namespace
}  // namespace cambium::render
