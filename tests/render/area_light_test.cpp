// SPDX-License-Identifier: Apache-2.0
// Emissive primitives as area lights: next-event estimation against closed-form
// irradiance (disc, square, sphere, instanced square) and against BSDF-only sampling.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>
#include <numbers>
#include <vector>

#include "render/accel.h"
#include "render/area_light.h"
#include "render/color.h"
#include "render/light.h"
#include "render/render.h"
#include "geom_scenes.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using namespace testing;

constexpr double pi = std::numbers::pi;

geom::Rgb grey(float display) { return {display, display, display}; }

/// Materials: 1 the receiving plane (albedo display 0.8), 2 an emitter of radiance 1
/// with black albedo, 3 black.
geom::Scene plane_scene()
{
    geom::Scene s;
    s.materials[1].diffuse = grey(0.8f);
    s.materials[2].diffuse = grey(0);
    s.materials[2].emission = grey(1);
    s.materials[3].diffuse = grey(0);
    add_quad(s.geometry, -50, -50, 50, 50, 0, 1, 1);
    return s;
}

double albedo() { return srgb_to_linear(0.8f); }

/// Looks down -z at a 0.008-unit patch around the origin, rays starting at height
/// `start` (below the emitter, which would hide the patch from above).
Camera patch_camera(double start)
{
    return Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.001, start, 8, 8);
}

/// Per-pixel values (green) of 8x8 pixels at `spp` samples each.
std::vector<double> pixels(const geom::Scene& s, const Camera& c, int depth, int spp,
                           bool nee)
{
    EmbreeScene accel(s, c);
    PathContext ctx;
    ctx.accel = &accel;
    ctx.materials = make_materials(s.materials);
    AreaLights lights(s, ctx.materials);
    ctx.area_lights = nee ? &lights : nullptr;
    ctx.max_depth = depth;
    prepare_path_context(ctx);
    std::vector<double> out;
    for (int y = 0; y < c.height(); ++y)
        for (int x = 0; x < c.width(); ++x) {
            double sum = 0;
            for (int i = 0; i < spp; ++i) {
                Sampler sm(std::uint32_t(x), std::uint32_t(y), std::uint32_t(i), 11);
                double jx = sm.next(), jy = sm.next();
                CameraRay ray = c.generate_ray(x + jx, y + jy);
                sum += trace_path(ctx, Vec3f(ray.org), Vec3f(ray.dir), sm).radiance.y;
            }
            out.push_back(sum / spp);
        }
    return out;
}

struct Stats {
    double mean = 0, variance = 0;
};

Stats stats(const std::vector<double>& v)
{
    Stats s;
    for (double x : v)
        s.mean += x;
    s.mean /= double(v.size());
    for (double x : v)
        s.variance += (x - s.mean) * (x - s.mean);
    s.variance /= double(v.size() - 1);
    return s;
}

// A disc of radius R at height h facing the plane: E = pi L R^2 / (h^2 + R^2) on its axis,
// so the plane's radiance is albedo R^2 / (h^2 + R^2).
TEST(AreaLight, DiscMatchesFormFactor)
{
    geom::Scene s = plane_scene();
    const double h = 2, r = 0.5;
    add_disc(s.geometry, {0, 0, h}, float(r), {0, 0, -1}, 2, 3);
    double expect = albedo() * r * r / (h * h + r * r);
    for (int depth : {1, 2}) {
        Stats got = stats(pixels(s, patch_camera(1), depth, 64, true));
        EXPECT_NEAR(got.mean, expect, 0.01 * expect) << "depth " << depth;
        std::printf("[area] disc depth %d: %.5f expected %.5f\n", depth, got.mean, expect);
    }
}

// A square of side a centred over the point at height h, emitting from its back (the
// side facing the plane): the form factor of four corner rectangles X = Y = a / 2h,
// F = 4 / (2 pi) * 2 X / sqrt(1 + X^2) atan(X / sqrt(1 + X^2)), E = pi L F.
double square_expectation(double a, double h)
{
    double x = a / (2 * h), q = std::sqrt(1 + x * x);
    double f = 4 / (2 * pi) * 2 * x / q * std::atan(x / q);
    return albedo() * f;
}

TEST(AreaLight, SquareBackFaceMatchesFormFactor)
{
    geom::Scene s = plane_scene();
    const float a = 1, h = 1.5f;
    add_quad(s.geometry, -a / 2, -a / 2, a / 2, a / 2, h, 3, 2);  // front up: black
    double expect = square_expectation(a, h);
    Stats got = stats(pixels(s, patch_camera(0.5), 2, 64, true));
    EXPECT_NEAR(got.mean, expect, 0.01 * expect);
    std::printf("[area] square: %.5f expected %.5f\n", got.mean, expect);
}

// The same square as a prototype with inherited materials, placed rotated by 90 degrees
// about z, scaled by 2 and lifted to h: the light list must follow the instance.
TEST(AreaLight, InstancedSquareMatchesFormFactor)
{
    geom::Scene s = plane_scene();
    geom::Prototype proto;
    add_quad(proto.geometry, -0.25f, -0.25f, 0.25f, 0.25f, 0, geom::inherit_material,
             geom::inherit_material);
    s.prototypes.push_back(proto);
    geom::Instance inst;
    inst.transform = transform({0, -2, 0, 2, 0, 0, 0, 0, 2}, {0, 0, 1.5});
    inst.material = 3;
    inst.back_material = 2;
    s.instances.push_back(inst);
    double expect = square_expectation(1, 1.5);
    EXPECT_EQ(AreaLights(s, make_materials(s.materials)).size(), 2u);
    Stats got = stats(pixels(s, patch_camera(0.5), 2, 64, true));
    EXPECT_NEAR(got.mean, expect, 0.01 * expect);
    std::printf("[area] instanced square: %.5f expected %.5f\n", got.mean, expect);
}

/// x' = s R_x(tilt) R_z(turn) x + t, as the rows of its matrix.
std::array<float, 9> similarity(double s, double tilt, double turn)
{
    double cz = std::cos(turn), sz = std::sin(turn), cx = std::cos(tilt), sx = std::sin(tilt);
    // R_x R_z = [[cz, -sz, 0], [cx sz, cx cz, -sx], [sx sz, sx cz, cx]]
    return {float(s * cz),      float(-s * sz),     0.0f,
            float(s * cx * sz), float(s * cx * cz), float(-s * sx),
            float(s * sx * sz), float(s * sx * cz), float(s * cx)};
}

geom::Float3 apply(const std::array<float, 9>& m, const geom::Float3& p, const geom::Vec3& t)
{
    return {m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + float(t.x),
            m[3] * p[0] + m[4] * p[1] + m[5] * p[2] + float(t.y),
            m[6] * p[0] + m[7] * p[1] + m[8] * p[2] + float(t.z)};
}

// Forty placed copies of a glowing organ (a triangle, a disc and a sphere, facing the
// plane) light it as the same copies written out in world space do, within noise; the
// instanced scene keeps the organ's three lights once instead of 120.
TEST(AreaLight, InstancedEmittersLightAsTheirFlattenedCopiesWithLightsKeptOnce)
{
    const std::array<geom::Float3, 3> corners{{{-0.3f, -0.2f, 0}, {0.3f, -0.2f, 0}, {0, 0.3f, 0.1f}}};
    const geom::Float3 down{0, 0, -1}, sphere{0.5f, 0, 0.2f}, disc{-0.5f, 0, 0};
    geom::Scene instanced = plane_scene(), flattened = plane_scene();
    geom::Prototype organ;
    add_triangle(organ.geometry, corners, {down, down, down}, {{{0, 0}, {1, 0}, {0, 1}}}, 2, 3);
    add_sphere(organ.geometry, {sphere[0], sphere[1], sphere[2]}, 0.1f, 2);
    add_disc(organ.geometry, {disc[0], disc[1], disc[2]}, 0.15f, {0, 0, -1}, 2, 3);
    instanced.prototypes.push_back(organ);
    const int copies = 40;
    for (int k = 0; k < copies; ++k) {
        double s = 0.6 + 0.02 * k;
        std::array<float, 9> m = similarity(s, 0.3 * std::sin(k), 0.7 * k);
        geom::Vec3 t{1.2 * std::cos(k), 1.2 * std::sin(1.3 * k), 1.6 + 0.03 * k};
        geom::Instance inst;
        inst.transform = transform(m, t);
        instanced.instances.push_back(inst);
        geom::Float3 n = apply(m, down, {0, 0, 0});
        float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        n = {n[0] / len, n[1] / len, n[2] / len};
        add_triangle(flattened.geometry,
                     {apply(m, corners[0], t), apply(m, corners[1], t), apply(m, corners[2], t)},
                     {n, n, n}, {{{0, 0}, {1, 0}, {0, 1}}}, 2, 3);
        geom::Float3 c = apply(m, sphere, t);
        add_sphere(flattened.geometry, {c[0], c[1], c[2]}, float(0.1 * s), 2);
        c = apply(m, disc, t);
        add_disc(flattened.geometry, {c[0], c[1], c[2]}, float(0.15 * s), {n[0], n[1], n[2]}, 2, 3);
    }
    AreaLights kept(instanced, make_materials(instanced.materials));
    AreaLights listed(flattened, make_materials(flattened.materials));
    EXPECT_EQ(kept.size(), 3u);
    EXPECT_EQ(kept.placed_size(), 3u * copies);
    EXPECT_EQ(listed.size(), 3u * copies);
    EXPECT_NEAR(kept.power(), listed.power(), 1e-4 * listed.power());

    Stats a = stats(pixels(instanced, patch_camera(1), 1, 64, true));
    Stats b = stats(pixels(flattened, patch_camera(1), 1, 64, true));
    double noise = std::sqrt(a.variance / 64 + b.variance / 64);
    EXPECT_GT(b.mean, 0.01);
    EXPECT_NEAR(a.mean, b.mean, 4 * noise + 1e-6);
    std::printf("[area] instanced %.5f flattened %.5f (noise %.5f)\n", a.mean, b.mean, noise);
}

// A sphere of radius R with its centre at height d: E = pi L (R / d)^2 below it.
TEST(AreaLight, SphereMatchesClosedForm)
{
    geom::Scene s = plane_scene();
    const double d = 3, r = 1;
    add_sphere(s.geometry, {0, 0, d}, float(r), 2);
    double expect = albedo() * (r / d) * (r / d);
    Stats got = stats(pixels(s, patch_camera(1), 2, 64, true));
    EXPECT_NEAR(got.mean, expect, 0.01 * expect);
    std::printf("[area] sphere: %.5f expected %.5f\n", got.mean, expect);
}

// A line segment of radius R and length 2W along x at height h: the plane's radiance below
// its middle is albedo / pi times E = integral of L cos_p cos_l / d^2 over the visible half
// of the tube, here by a midpoint rule (for W >> h it tends to pi L R / h).
TEST(AreaLight, CylinderSegmentMatchesQuadrature)
{
    geom::Scene s = plane_scene();
    const double h = 1, r = 0.1, half = 4;
    testing::add_segment(s, {-half, 0, h}, {half, 0, h}, float(r), 2);
    double e = 0;
    const int nx = 4000, nphi = 720;
    for (int i = 0; i < nx; ++i) {
        double x = -half + (i + 0.5) * 2 * half / nx;
        for (int j = 0; j < nphi; ++j) {
            double phi = (j + 0.5) * 2 * pi / nphi;
            double ny = std::cos(phi), nz = std::sin(phi);  // outward normal
            double px = x, py = r * ny, pz = h + r * nz;   // the tube point
            double d2 = px * px + py * py + pz * pz, d = std::sqrt(d2);
            double cos_l = -(ny * py + nz * pz) / d;  // toward the origin
            double cos_p = pz / d;
            if (cos_l > 0 && cos_p > 0)
                e += cos_l * cos_p / d2 * r * (2 * pi / nphi) * (2 * half / nx);
        }
    }
    double expect = albedo() / pi * e;
    EXPECT_NEAR(expect, albedo() * r / h, 0.05 * albedo() * r / h);  // the long-tube limit
    EXPECT_EQ(AreaLights(s, make_materials(s.materials)).size(), 1u);
    // Uniform sampling along the tube is noisy (far points weigh little): 32k samples.
    Stats got = stats(pixels(s, patch_camera(0.5), 2, 512, true));
    EXPECT_NEAR(got.mean, expect, 0.02 * expect);
    std::printf("[area] cylinder: %.5f expected %.5f\n", got.mean, expect);
}

// BSDF sampling alone and NEE + MIS converge to the same mean; NEE with far less noise.
TEST(AreaLight, NeeLowersVarianceKeepingTheMean)
{
    geom::Scene s = plane_scene();
    add_disc(s.geometry, {0, 0, 2}, 0.3f, {0, 0, -1}, 2, 3);
    double expect = albedo() * 0.09 / (4 + 0.09);
    Stats nee = stats(pixels(s, patch_camera(1), 2, 8, true));
    Stats bsdf = stats(pixels(s, patch_camera(1), 2, 8, false));
    double se = std::sqrt((nee.variance + bsdf.variance) / 64);
    EXPECT_NEAR(nee.mean, bsdf.mean, 4 * se);
    EXPECT_NEAR(nee.mean, expect, 0.02 * expect);
    EXPECT_LT(nee.variance * 20, bsdf.variance);
    std::printf("[area] NEE %.5f (var %.3g)  BSDF only %.5f (var %.3g)  expected %.5f\n",
                nee.mean, nee.variance, bsdf.mean, bsdf.variance, expect);
}

/// An 8x8 render of `spp` samples, two segments deep, lit by the scene's lights alone (no
/// ambient, no OpenGL ambient term), without layers.
RenderSettings lit_only_by_lights(int spp)
{
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.samples_per_pixel = spp;
    settings.max_depth = 2;
    settings.threads = 2;
    settings.ambient = {0, 0, 0};
    settings.opengl_ambient = false;
    settings.aovs = false;
    return settings;
}

// render() builds the list (RenderSettings::area_lights) and gets the same mean without it.
TEST(AreaLight, RenderSamplesEmittersUnlessTurnedOff)
{
    geom::Scene s = plane_scene();
    add_disc(s.geometry, {0, 0, 2}, 0.3f, {0, 0, -1}, 2, 3);
    double expect = albedo() * 0.09 / (4 + 0.09);
    RenderSettings settings = lit_only_by_lights(16);  // the emitter alone lights the patch
    auto block = [&](bool area) {
        settings.area_lights = area;
        Image img = render(s, patch_camera(1), settings);
        std::vector<double> g;
        for (std::size_t i = 0; i < img.rgba.size(); i += 4)
            g.push_back(img.rgba[i + 1]);
        return stats(g);
    };
    Stats on = block(true), off = block(false);
    EXPECT_NEAR(on.mean, expect, 0.01 * expect);
    EXPECT_NEAR(off.mean, expect, 4 * std::sqrt(off.variance / 64) + 0.01 * expect);
    EXPECT_LT(on.variance * 20, off.variance);
}

// Emitters far fainter than the view's lights are left to BSDF sampling (LightSet), and
// all their light still arrives: a sun from below lights nothing the camera sees, so the
// patch shows the faint disc's light alone, against the closed form. Were the disc left
// out of the set while pdf_li() still weighed its hits against light sampling, the mean
// would fall short.
TEST(AreaLight, FaintEmittersAreLeftToBsdfSamplingWithAllTheirLight)
{
    geom::Scene s = plane_scene();
    const float display = 0.05f;  // linear 0.0039: pi L is 1.2% of the sun's pi
    s.materials[2].emission = grey(display);
    const double h = 1, r = 1.5;
    add_disc(s.geometry, {0, 0, float(h)}, float(r), {0, 0, -1}, 2, 3);
    geom::Light sun;
    sun.kind = geom::Light::Kind::directional;
    sun.direction = {0, 0, -1};  // toward the light: below the plane
    s.lights.push_back(sun);
    const Camera camera = patch_camera(0.5);

    EmbreeScene accel(s, camera);
    const Vec3f p(0, 0, 0.5f);
    std::optional<SurfaceHit> on_disc = accel.intersect(p, {0, 0, 1}, 0, 1e30f);
    ASSERT_TRUE(on_disc);
    auto light_set = [&](float emission_display) {
        geom::Scene lit = s;
        lit.materials[2].emission = grey(emission_display);
        std::vector<SurfaceMaterial> materials = make_materials(lit.materials);
        auto area = std::make_unique<AreaLights>(lit, materials);
        LightSet set(make_lights(lit.lights), area.get(), nullptr, false, 3);
        return std::pair(std::move(area), std::move(set));
    };
    auto [faint_area, faint] = light_set(display);
    EXPECT_EQ(faint_area->size(), 1u);
    EXPECT_EQ(faint.size(), 1u);  // the sun alone
    EXPECT_EQ(faint.pdf_li(p, *on_disc), 0.0f);
    auto [bright_area, bright] = light_set(0.3f);  // linear 0.073: 7% of the sun's
    EXPECT_EQ(bright.size(), 2u);
    EXPECT_GT(bright.pdf_li(p, *on_disc), 0.0f);

    RenderSettings settings = lit_only_by_lights(64);
    Image img = render(s, camera, settings);
    std::vector<double> g;
    for (std::size_t i = 0; i < img.rgba.size(); i += 4)
        g.push_back(img.rgba[i + 1]);
    Stats got = stats(g);
    double expect = albedo() * srgb_to_linear(display) * r * r / (h * h + r * r);
    EXPECT_NEAR(got.mean, expect, 0.02 * expect);
    std::printf("[area] faint disc, BSDF sampling alone: %.6f expected %.6f\n", got.mean,
                expect);
}

// Nothing emits: the list is empty and sampling gives nothing.
TEST(AreaLight, NoEmittersNoLights)
{
    geom::Scene s = plane_scene();
    s.materials[2].emission = grey(0);
    add_sphere(s.geometry, {0, 0, 3}, 1, 2);
    AreaLights lights(s, make_materials(s.materials));
    EXPECT_TRUE(lights.empty());
    EXPECT_FALSE(lights.sample({0, 0, 0}, 0.5f, 0.5f, 0.5f).has_value());
}

}  // namespace
}  // namespace cambium::render
