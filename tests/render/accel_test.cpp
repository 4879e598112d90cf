// SPDX-License-Identifier: Apache-2.0
// EmbreeScene: hits on round linear curves, pixel radii, empty scenes, spawn offsets.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "base/diagnostics.h"
#include "render/accel.h"
#include "render/line_geometry.h"
#include "render/material.h"
#include "render/sampler.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using testing::add_segment;
using testing::empty_scene;

constexpr float inf = std::numeric_limits<float>::infinity();

Camera unit_camera(const geom::Scene& s)
{
    return make_camera(s.view, s.bounds, 200, 100);
}

TEST(EmbreeScene, EmptySceneHitsNothing)
{
    geom::Scene s = empty_scene({0, 0, 0}, {0, 0, 0});
    EmbreeScene accel(s, unit_camera(s));
    EXPECT_EQ(accel.segment_count(), 0u);
    EXPECT_FALSE(accel.intersect({0, 0, 5}, {0, 0, -1}, 0, inf));
    EXPECT_FALSE(accel.occluded({0, 0, 5}, {0, 0, -1}, 0, inf));
}

TEST(EmbreeScene, HitsRoundSegmentWithMaterialAndRadius)
{
    geom::Scene s = empty_scene({-10, -1, 0}, {10, 1, 0});
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 1.0f, 7);
    EmbreeScene accel(s, unit_camera(s));
    auto hit = accel.intersect({2, 0, 10}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 9.0f, 1e-4f);
    EXPECT_NEAR(hit->normal.z, 1.0f, 1e-4f);
    EXPECT_EQ(hit->material, 7);
    EXPECT_EQ(hit->prim_id, 0u);
    EXPECT_NEAR(hit->radius, 1.0f, 1e-6f);
    // The normal faces the ray also when hit from below.
    auto below = accel.intersect({2, 0, -10}, {0, 0, 1}, 0, inf);
    ASSERT_TRUE(below);
    EXPECT_NEAR(below->normal.z, -1.0f, 1e-4f);
    EXPECT_TRUE(accel.occluded({2, 0, 10}, {0, 0, -1}, 0, 20));
    EXPECT_FALSE(accel.occluded({2, 0, 10}, {0, 0, -1}, 0, 8.5f));
    EXPECT_FALSE(accel.intersect({2, 1.5f, 10}, {0, 0, -1}, 0, inf));
}

// Radii in pixels become pixel_size * radius world units: here k = min(200/20, 100/10) = 10
// px per unit, so 5 px is 0.5 units; the tube is pixel_line_margin (0.75 px) wider, and only
// pixels OpenGL draws keep their hits (pixel_lines.h).
TEST(EmbreeScene, ConvertsPixelRadiiThroughCamera)
{
    geom::Scene s = empty_scene({-10, -5, 0}, {10, 5, 0});
    s.line_radius_in_pixels = true;
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 5.0f);
    Camera camera = unit_camera(s);
    ASSERT_NEAR(camera.pixel_size(), 0.1, 1e-12);
    EmbreeScene accel(s, camera);
    auto hit = accel.intersect({0, 0, 10}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 9.425f, 1e-4f);
    EXPECT_NEAR(hit->radius, 0.575f, 1e-6f);
    EXPECT_FALSE(accel.intersect({0, 0.6f, 10}, {0, 0, -1}, 0, inf));
}

// A prototype's line with a radius of 5 pixels, placed twice (once scaled by 4, once with an
// inherited material): every copy is 5 px = 0.5 units thick in world space, unlit, with its
// instance's material, and the prototype's own scene holds no unconverted copy.
TEST(EmbreeScene, PixelLinesInsidePrototypesKeepTheirPixelWidth)
{
    geom::Scene s = empty_scene({-10, -5, 0}, {10, 5, 0});
    s.line_radius_in_pixels = true;
    geom::Prototype proto;
    proto.geometry.lines.keys = {{-1, 0, 0, 5.0f}, {1, 0, 0, 5.0f}};
    proto.geometry.lines.segments = {0};
    proto.geometry.lines.material = {geom::inherit_material};
    s.prototypes.push_back(proto);
    geom::Instance big;
    big.transform = {4, 0, 0, 0, 4, 0, 0, 0, 4, 0, 2, 0};  // x4, at y = 2
    big.material = 9;
    geom::Instance small;
    small.transform = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -2, 0};  // at y = -2
    small.material = 4;
    s.instances = {big, small};
    Camera camera = unit_camera(s);
    ASSERT_NEAR(camera.pixel_size(), 0.1, 1e-12);
    EmbreeScene accel(s, camera);
    for (float y : {2.0f, -2.0f}) {
        auto hit = accel.intersect({0, y, 10}, {0, 0, -1}, 0, inf);
        ASSERT_TRUE(hit) << y;
        EXPECT_NEAR(hit->t, 9.425f, 1e-4f) << y;
        EXPECT_NEAR(hit->radius, 0.575f, 1e-6f) << y;
        EXPECT_TRUE(hit->unlit) << y;
        EXPECT_EQ(hit->material, y > 0 ? 9 : 4);
        EXPECT_FALSE(accel.intersect({0, y + 0.6f, 10}, {0, 0, -1}, 0, inf)) << y;
    }
    // The scaled copy spans x in [-4, 4], the other [-1, 1] (plus round caps of 0.5).
    EXPECT_TRUE(accel.intersect({3.5f, 2, 10}, {0, 0, -1}, 0, inf));
    EXPECT_FALSE(accel.intersect({1.8f, -2, 10}, {0, 0, -1}, 0, inf));  // past the round cap
    EXPECT_EQ(accel.segment_count(), 2u);
}

/// Diffuse rays spawned from camera hits on the scene's curves: how many hit a curve
/// again, of how many spawned. The scenes below are convex tubes, so every hit is spurious.
std::pair<int, int> count_rehits(const geom::Scene& s, float half_width)
{
    EmbreeScene accel(s, unit_camera(s));
    int rehits = 0, n = 0;
    for (std::uint32_t i = 0; i < 4000; ++i) {
        Sampler sm(i, 0, 0, 1);
        float ox = sm.next() * 10 - 5, oy = (sm.next() * 2 - 1) * half_width * 0.9f;
        auto hit = accel.intersect({ox, oy, 1}, {0, 0, -1}, 0, inf);
        if (!hit)
            continue;
        ++n;
        Vec3f org = hit->position + hit->normal * hit->spawn_offset;
        BsdfSample bs = bsdf_sample(lambertian(Vec3f(1)), hit->normal, Vec3f(0, 0, 1), sm.next(),
                                    sm.next());
        rehits += accel.intersect(org, bs.wi, 0, inf, hit->prim()) ? 1 : 0;
    }
    return {rehits, n};
}

// FACTS.md: without protection about half the diffuse rays leaving a curve hit it again.
TEST(EmbreeScene, SpawnedRaysDoNotHitTheirOwnSegment)
{
    geom::Scene s = empty_scene({-10, -1, -1}, {10, 1, 1});
    add_segment(s, {-10, 0, 0}, {10, 0, 0}, 0.01f);
    auto [rehits, n] = count_rehits(s, 0.01f);
    ASSERT_GT(n, 3000);
    EXPECT_LE(rehits, n / 1000) << rehits << " of " << n;
}

/// A scene of every kind of primitive but triangles, material 1: a cone segment of
/// `radius` along x from -1 to 1 (a curve with two caps), a unit sphere at y = 3 and a unit
/// disc at y = -3 facing +z.
geom::Scene round_and_flat_shapes(float radius)
{
    geom::Scene s = empty_scene({-10, -10, -10}, {10, 10, 10});
    add_segment(s, {-1, 0, 0}, {1, 0, 0}, radius);
    s.geometry.spheres.centres.push_back({0, 3, 0, 1});
    s.geometry.spheres.material.push_back(1);
    s.geometry.discs.centres.push_back({0, -3, 0, 1});
    s.geometry.discs.normals.push_back({0, 0, 1});
    s.geometry.discs.material.push_back(1);
    return s;
}

// Filter functions run only on geometries that need one: round shapes (to skip the
// primitive a ray leaves), pixel-width lines and alpha cut-outs; flat shapes run none.
TEST(EmbreeScene, FiltersOnlyRoundShapesOfAnUntexturedScene)
{
    geom::Scene s = round_and_flat_shapes(0.1f);
    geom::TriangleMesh& m = s.geometry.mesh;
    m.positions = {{5, 0, 0}, {6, 0, 0}, {5, 1, 0}};
    m.normals.assign(3, {0, 0, 1});
    m.triangles = {{0, 1, 2}};
    m.material = {1};
    EmbreeScene accel(s, unit_camera(s));
    EXPECT_EQ(accel.filtered_shapes(), (std::vector<Shape>{Shape::line, Shape::sphere}));
    // Skipping a flat primitive does nothing: rays leave it by its offset.
    auto cap = accel.intersect({-3, 0, 0}, {1, 0, 0}, 0, inf);
    ASSERT_TRUE(cap);
    EXPECT_EQ(cap->shape, Shape::cap);
    auto again = accel.intersect({-3, 0, 0}, {1, 0, 0}, 0, inf, cap->prim());
    ASSERT_TRUE(again);
    EXPECT_EQ(again->shape, Shape::cap);
}

// Only triangles carry vertex normals: a hit on any other shape shades by its true normal,
// and a triangle's shading normal is its vertex normals interpolated at the hit, unit, on
// the side hit (surface_hit makes the shading normal for triangles alone).
TEST(EmbreeScene, OnlyTrianglesShadeByAnInterpolatedNormal)
{
    geom::Scene s = round_and_flat_shapes(0.5f);
    s.geometry.discs.back_material.push_back(1);
    geom::TriangleMesh& m = s.geometry.mesh;
    m.positions = {{4, -1, 0}, {8, -1, 0}, {4, 3, 0}};
    // tilted toward -x, +x and +y: at barycentric (u, v) the sum leans by (2u - 1 + v, v)
    m.normals = {{-0.6f, 0, 0.8f}, {0.6f, 0, 0.8f}, {0, 0.6f, 0.8f}};
    m.triangles = {{0, 1, 2}};
    m.material = {1};
    m.back_material = {1};
    EmbreeScene accel(s, unit_camera(s));
    const Vec3f slant = normalize(Vec3f(0.3f, 0.2f, -1));
    auto expect_true_normal = [&](Vec3f org, Shape shape) {
        for (float side : {1.0f, -1.0f}) {
            Vec3f o(org.x, org.y, org.z * side), d(slant.x, slant.y, slant.z * side);
            auto hit = accel.intersect(o - d * 10, d, 0, inf);
            ASSERT_TRUE(hit) << int(shape);
            EXPECT_EQ(hit->shape, shape);
            EXPECT_EQ(hit->normal.x, hit->geometric_normal.x) << int(shape);
            EXPECT_EQ(hit->normal.y, hit->geometric_normal.y) << int(shape);
            EXPECT_EQ(hit->normal.z, hit->geometric_normal.z) << int(shape);
            EXPECT_LT(dot(hit->normal, d), 0) << int(shape);
        }
    };
    expect_true_normal({0, 0, 0.4f}, Shape::line);
    expect_true_normal({0, 3, 0.9f}, Shape::sphere);
    expect_true_normal({0, -3, 0}, Shape::disc);
    auto cap = accel.intersect({-5, 0.1f, 0.1f}, {1, 0, 0}, 0, inf);
    ASSERT_TRUE(cap);
    EXPECT_EQ(cap->shape, Shape::cap);
    EXPECT_EQ(cap->normal.x, cap->geometric_normal.x);
    EXPECT_EQ(cap->normal.x, -1.0f);

    // The triangle at (5, 0): barycentric u = 1/4, v = 1/4 (positions above).
    for (float side : {1.0f, -1.0f}) {
        Vec3f d(0, 0, -side);
        auto hit = accel.intersect(Vec3f(5, 0, 5 * side), d, 0, inf);
        ASSERT_TRUE(hit);
        EXPECT_EQ(hit->shape, Shape::triangle);
        EXPECT_EQ(hit->back, side < 0);
        Vec3f lean = Vec3f(-0.6f, 0, 0.8f) * 0.5f + Vec3f(0.6f, 0, 0.8f) * 0.25f +
                     Vec3f(0, 0.6f, 0.8f) * 0.25f;
        Vec3f expected = normalize(lean) * side;
        EXPECT_NEAR(hit->normal.x, expected.x, 1e-5f);
        EXPECT_NEAR(hit->normal.y, expected.y, 1e-5f);
        EXPECT_NEAR(hit->normal.z, expected.z, 1e-5f);
        EXPECT_NEAR(hit->geometric_normal.z, side, 1e-6f);
        EXPECT_GT(std::fabs(hit->normal.x - hit->geometric_normal.x), 0.05f);
    }
}

// The light report's lean hit is the full hit's fields of the same names, whether traced
// alone or in a stream, on every shape and on both sides of flat ones.
TEST(EmbreeScene, LightHitsAreTheSurfaceHitsFields)
{
    geom::Scene s = round_and_flat_shapes(0.5f);
    s.geometry.discs.back_material.push_back(2);
    geom::TriangleMesh& m = s.geometry.mesh;
    m.positions = {{4, -1, 0}, {8, -1, 0}, {4, 3, 0}};
    m.normals = {{-0.6f, 0, 0.8f}, {0.6f, 0, 0.8f}, {0, 0.6f, 0.8f}};
    m.triangles = {{0, 1, 2}};
    m.material = {1};
    m.back_material = {2};
    EmbreeScene accel(s, unit_camera(s));
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uniform(0, 1);
    auto next = [&] { return uniform(rng); };
    std::array<int, 7> shapes{};
    int backs = 0;
    for (int round = 0; round < 200; ++round) {
        std::array<LightRay, EmbreeScene::max_coherent_rays> rays;
        for (LightRay& r : rays) {
            // from a sphere of radius 12 toward a point among the shapes
            const Vec3f target(next() * 10 - 2, next() * 8 - 4, next() - 0.5f);
            const Vec3f from = normalize(Vec3f(next() - 0.5f, next() - 0.5f, next() - 0.5f)) * 12;
            r = {target + from, normalize(-from), inf};
        }
        std::array<LightHit, EmbreeScene::max_coherent_rays> streamed;
        const std::uint32_t bits = accel.intersect_light(rays, streamed);
        for (std::size_t k = 0; k < rays.size(); ++k) {
            const auto full = accel.intersect(rays[k].org, rays[k].dir, 0, inf);
            LightHit alone;
            ASSERT_EQ(accel.intersect_light(alone, rays[k].org, rays[k].dir, 0, inf), bool(full));
            ASSERT_EQ(bool(bits >> k & 1), bool(full));
            if (!full)
                continue;
            ++shapes[static_cast<std::size_t>(full->shape)];
            backs += full->back;
            // Traced alone: the very numbers. In a stream, Embree's packet kernels may round
            // the distance differently in its last bit: the numbers made from it within it.
            for (const auto& [h, ulps] : {std::pair{alone, 0.0f}, std::pair{streamed[k], 4.0f}}) {
                auto expect_near = [&, ulps = ulps](float a, float b, float scale) {
                    EXPECT_NEAR(a, b, ulps * std::numeric_limits<float>::epsilon() * scale) << int(full->shape);
                };
                expect_near(h.t, full->t, full->t);
                const float scale = 1 + std::fabs(full->t);
                expect_near(h.position.x, full->position.x, scale);
                expect_near(h.position.y, full->position.y, scale);
                expect_near(h.position.z, full->position.z, scale);
                expect_near(h.geometric_normal.x, full->geometric_normal.x, scale);
                expect_near(h.geometric_normal.y, full->geometric_normal.y, scale);
                expect_near(h.geometric_normal.z, full->geometric_normal.z, scale);
                expect_near(h.spawn_offset, full->spawn_offset, full->spawn_offset);
                EXPECT_EQ(h.prim().geom, full->prim().geom);
                EXPECT_EQ(h.prim().prim, full->prim().prim);
                EXPECT_EQ(h.prim().inst, full->prim().inst);
                EXPECT_EQ(h.instance, full->instance);
                EXPECT_EQ(h.primitive, full->primitive);
                EXPECT_EQ(h.material, full->material);
                EXPECT_EQ(h.end_material, full->end_material);
                EXPECT_EQ(h.material_blend, full->material_blend);
                EXPECT_EQ(h.shape, full->shape);
                EXPECT_EQ(h.back, full->back);
                EXPECT_EQ(h.unlit, full->unlit);
                EXPECT_EQ(h.closed(), full->closed());
            }
        }
    }
    for (Shape shape : {Shape::line, Shape::sphere, Shape::disc, Shape::triangle, Shape::cap})
        EXPECT_GT(shapes[static_cast<std::size_t>(shape)], 10) << int(shape);
    EXPECT_GT(backs, 10);
}

// A straight polyline of short joined segments (neighbour flags) is one convex tube: rays
// leaving one segment must not hit its neighbours at the joints either.
TEST(EmbreeScene, SpawnedRaysDoNotHitJoinedNeighbours)
{
    geom::Scene s = empty_scene({-10, -1, -1}, {10, 1, 1});
    const int count = 40;
    for (int i = 0; i <= count; ++i)
        s.geometry.lines.keys.push_back({-10.0f + 20.0f * i / count, 0, 0, 0.05f});
    for (int i = 0; i < count; ++i) {
        s.geometry.lines.segments.push_back(static_cast<std::uint32_t>(i));
        std::uint8_t f = 0;
        if (i > 0)
            f |= geom::LinearCurves::neighbour_left;
        if (i + 1 < count)
            f |= geom::LinearCurves::neighbour_right;
        s.geometry.lines.flags.push_back(f);
        s.geometry.lines.material.push_back(1);
    }
    auto [rehits, n] = count_rehits(s, 0.05f);
    ASSERT_GT(n, 3000);
    EXPECT_LE(rehits, n / 500) << rehits << " of " << n;
}

// Embree's leaves hold primitives of one geometry: caps and joint spheres built beside
// every segment of a large tree in one BVH left most leaves with a single primitive (187 B
// per segment on tree10m). Past EmbreeScene::line_ends_beside_up_to segments they are in
// scenes of their own and pack like the segments do.
TEST(EmbreeScene, CapsAndJointsDoNotCrowdTheLinesLeaves)
{
    geom::Scene s = empty_scene({-60, -60, -60}, {60, 60, 60});
    geom::LinearCurves& l = s.geometry.lines;
    std::uint32_t state = 12345;
    auto next = [&state] {  // a small LCG: deterministic, in [-1, 1)
        state = state * 1664525u + 1013904223u;
        return static_cast<float>(state >> 8) / float(1 << 23) - 1;
    };
    const int per_chain = 6;
    const int chains = int(EmbreeScene::line_ends_beside_up_to / per_chain) + 1000;
    for (int c = 0; c < chains; ++c) {
        float x = 50 * next(), y = 50 * next(), z = 50 * next();
        auto first = static_cast<std::uint32_t>(l.keys.size());
        for (int k = 0; k <= per_chain; ++k) {
            l.keys.push_back({x, y, z, 0.05f});
            x += 0.3f * next();
            y += 0.4f;
            z += 0.3f * next();
        }
        for (int i = 0; i < per_chain; ++i) {
            l.segments.push_back(first + static_cast<std::uint32_t>(i));
            l.flags.push_back(static_cast<std::uint8_t>((i > 0 ? 1 : 0) | (i + 1 < per_chain ? 2 : 0)));
            l.material.push_back(1);
        }
    }
    EmbreeScene accel(s, unit_camera(s));
    // 36 000 segments, 12 000 caps and about 30 000 joints: with caps and joints beside
    // the segments in one BVH this measured 211 B per segment (268 k segments now, so
    // that they are in scenes of their own)
    double per_segment = double(accel.embree_bytes()) / double(l.segments.size());
    EXPECT_LT(per_segment, 120.0) << per_segment;
    EXPECT_GT(per_segment, 20.0);  // the caps and joints are there
    auto hit = accel.intersect({l.keys[0][0], l.keys[0][1] - 5, l.keys[0][2]}, {0, 1, 0}, 0, inf);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->shape, Shape::cap);  // the first chain's free start, from below
}

TEST(EmbreeScene, RejectsSegmentPastTheKeys)
{
    geom::Scene s = empty_scene({0, 0, 0}, {1, 1, 1});
    s.geometry.lines.keys.push_back({0, 0, 0, 1});
    s.geometry.lines.segments.push_back(0);
    EXPECT_THROW(EmbreeScene(s, unit_camera(s)), Error);
}

}  // namespace
}  // namespace cambium::render

namespace cambium::render {
namespace {

/// A chain of cylinder segments through `points` (one polyline, joints flagged as the
/// interpreter flags them), radius r, material m.
void add_chain(geom::Scene& s, const std::vector<geom::Vec3>& points, float r, std::uint16_t m)
{
    geom::LinearCurves& l = s.geometry.lines;
    auto first = static_cast<std::uint32_t>(l.keys.size());
    for (const geom::Vec3& p : points)
        l.keys.push_back({float(p.x), float(p.y), float(p.z), r});
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
        l.segments.push_back(first + static_cast<std::uint32_t>(i));
        std::uint8_t f = 0;
        if (i > 0)
            f |= geom::LinearCurves::neighbour_left;
        if (i + 2 < points.size())
            f |= geom::LinearCurves::neighbour_right;
        l.flags.push_back(f);
        l.material.push_back(m);
    }
}

// cpfg's cylinders are frustums with flat ends: a short wide segment is a disc, not the
// ball a swept sphere would make.
TEST(CylinderEnds, FreeEndsAreFlatCaps)
{
    geom::Scene s = empty_scene({-1, 0, -1}, {1, 1, 1});
    add_chain(s, {{0, 0, 0}, {0, 0.1, 0}}, 1.0f, 4);
    EmbreeScene accel(s, unit_camera(s));
    // down the axis: the top cap, at the segment's end plane, facing up
    auto top = accel.intersect({0.5, 5, 0}, {0, -1, 0}, 0, inf);
    ASSERT_TRUE(top);
    EXPECT_NEAR(top->t, 4.9f, 1e-4f);
    EXPECT_NEAR(top->geometric_normal.y, 1.0f, 1e-4f);
    EXPECT_EQ(top->material, 4);
    EXPECT_EQ(top->shape, Shape::cap);
    // from below: the bottom cap at y = 0
    auto bottom = accel.intersect({0.5, -5, 0}, {0, 1, 0}, 0, inf);
    ASSERT_TRUE(bottom);
    EXPECT_NEAR(bottom->t, 5.0f, 1e-4f);
    // from the side, just above the top plane, nothing (a sphere of radius 1 would be there)
    EXPECT_FALSE(accel.intersect({0, 0.3, 5}, {0, 0, -1}, 0, inf));
    auto side = accel.intersect({0, 0.05, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(side);
    EXPECT_NEAR(side->t, 4.0f, 1e-3f);
}

// Tapered: the frustum's side, not a sphere swept from the wide end.
TEST(CylinderEnds, TaperedSegmentIsAFrustum)
{
    geom::Scene s = empty_scene({-1, 0, -1}, {1, 1, 1});
    geom::LinearCurves& l = s.geometry.lines;
    l.keys = {{0, 0, 0, 1.0f}, {0, 1, 0, 0.5f}};
    l.segments = {0};
    l.flags = {0};
    l.material = {1};
    EmbreeScene accel(s, unit_camera(s));
    // at height y the radius is 1 - y/2: a ray along -z at x = 0 meets z = 1 - y/2
    for (float y : {0.2f, 0.5f, 0.8f}) {
        auto hit = accel.intersect({0, y, 5}, {0, 0, -1}, 0, inf);
        ASSERT_TRUE(hit) << y;
        EXPECT_NEAR(hit->t, 5 - (1 - y / 2), 2e-3f) << y;
    }
    EXPECT_FALSE(accel.intersect({0, 1.2f, 5}, {0, 0, -1}, 0, inf));  // no half sphere on top
}

// A bend is rounded by a sphere of the joint's radius: the outer corner, outside both
// frustums, is covered; a straight chain gets no joint spheres.
TEST(CylinderEnds, BentJointsAreRound)
{
    geom::Scene s = empty_scene({-1, 0, -1}, {2, 2, 1});
    add_chain(s, {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}}, 0.2f, 2);
    EmbreeScene accel(s, unit_camera(s));
    // 0.15 from the corner, diagonally outward: x < -0 beyond the second, y > 1 beyond the first
    auto corner = accel.intersect({-0.106f, 1.106f, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(corner);
    EXPECT_EQ(corner->shape, Shape::joint);
    EXPECT_EQ(corner->material, 2);
    EXPECT_NEAR(corner->t, 5 - std::sqrt(0.04f - 0.106f * 0.106f * 2), 2e-3f);

    geom::Scene straight = empty_scene({-1, 0, -1}, {1, 2, 1});
    add_chain(straight, {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, 0.2f, 2);
    EmbreeScene line(straight, unit_camera(straight));
    // (a ray exactly through the joint plane slips between Embree's cones: measured, a
    // set of measure zero, left to jittered sampling)
    auto mid = line.intersect({0.1f, 1.0001f, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(mid);
    EXPECT_EQ(mid->shape, Shape::line);
}

// line_ends works on blocks of segments in parallel: its caps and joints still come in
// segment order, each with its segment, over many blocks (150 000 segments).
TEST(CylinderEnds, ListedInSegmentOrderOverManyBlocks)
{
    constexpr std::uint32_t chains = 50'000;
    geom::LinearCurves l;
    // chain j: up 1, up 1 (straight: no joint), then right 1 (a bend: a joint); every
    // seventh chain tapers to nothing at its end (no cap there)
    for (std::uint32_t j = 0; j < chains; ++j) {
        float x = static_cast<float>(j), end_radius = j % 7 == 0 ? 0.0f : 0.1f;
        auto first = static_cast<std::uint32_t>(l.keys.size());
        l.keys.insert(l.keys.end(),
                      {{x, 0, 0, 0.1f}, {x, 1, 0, 0.1f}, {x, 2, 0, 0.1f}, {x + 1, 2, 0, end_radius}});
        l.segments.insert(l.segments.end(), {first, first + 1, first + 2});
        l.flags.insert(l.flags.end(),
                       {geom::LinearCurves::neighbour_right,
                        geom::LinearCurves::neighbour_left | geom::LinearCurves::neighbour_right,
                        geom::LinearCurves::neighbour_left});
    }
    LineEnds e = line_ends(l, l.keys.data());
    std::size_t tapered = (chains + 6) / 7;
    ASSERT_EQ(e.caps.size(), 2 * chains - tapered);
    ASSERT_EQ(e.cap_normals.size(), e.caps.size());
    ASSERT_EQ(e.cap_segment.size(), e.caps.size());
    ASSERT_EQ(e.cap_at_end.size(), e.caps.size());
    ASSERT_EQ(e.joints.size(), chains);
    ASSERT_EQ(e.joint_segment.size(), chains);
    std::size_t c = 0;
    for (std::uint32_t j = 0; j < chains; ++j) {
        auto x = static_cast<float>(j);
        ASSERT_EQ(e.cap_segment[c], 3 * j) << j;
        EXPECT_EQ(e.cap_at_end[c], 0) << j;
        EXPECT_EQ(e.caps[c][0], x) << j;
        EXPECT_EQ(e.caps[c][1], 0.0f) << j;
        EXPECT_EQ(e.cap_normals[c][1], -1.0f) << j;  // out of the bottom
        ++c;
        if (j % 7 != 0) {
            ASSERT_EQ(e.cap_segment[c], 3 * j + 2) << j;
            EXPECT_EQ(e.cap_at_end[c], 1) << j;
            EXPECT_EQ(e.caps[c][0], x + 1) << j;
            EXPECT_EQ(e.cap_normals[c][0], 1.0f) << j;  // out along +x
            ++c;
        }
        EXPECT_EQ(e.joint_segment[j], 3 * j + 1) << j;
        EXPECT_EQ(e.joints[j][0], x) << j;
        EXPECT_EQ(e.joints[j][1], 2.0f) << j;
    }
}

}  // namespace
}  // namespace cambium::render
