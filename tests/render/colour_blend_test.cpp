// SPDX-License-Identifier: Apache-2.0
// Generalized cylinders' colours blended along the axis (HermiteCurves::end_material):
// the hit's blend weight from Embree's u, instances' inherited materials, and the
// radiance of a two-coloured tube under a uniform environment.
#include <gtest/gtest.h>

#include <limits>
#include <memory>

#include "render/accel.h"
#include "render/environment.h"
#include "geom_scenes.h"

namespace cambium::render {
namespace {

using namespace testing;

constexpr float inf = std::numeric_limits<float>::infinity();

/// A straight tube along x from -4 to 4 (tangents = the chord, so u = (x + 4) / 8),
/// radius 0.5, material `start` at u = 0 and `end` at u = 1.
void add_tube(geom::Geometry& g, std::uint16_t start, std::uint16_t end)
{
    add_hermite(g, {-4, 0, 0, 0.5f}, {8, 0, 0, 0}, {4, 0, 0, 0.5f}, {8, 0, 0, 0}, start);
    g.curves.end_material.push_back(end);
}

std::optional<SurfaceHit> hit_above(const EmbreeScene& accel, float x)
{
    return accel.intersect({x, 0, 10}, {0, 0, -1}, 0, inf);
}

TEST(ColourBlend, HitCarriesTheBlendWeightAlongTheSegment)
{
    geom::Scene s;
    add_tube(s.geometry, 2, 7);
    EmbreeScene accel(s, top_camera(0, 0, 10, 10, 10));
    for (float x : {-3.0f, 0.0f, 1.0f, 3.5f}) {
        auto hit = hit_above(accel, x);
        ASSERT_TRUE(hit);
        EXPECT_EQ(hit->material, 2);
        EXPECT_EQ(hit->end_material, 7);
        EXPECT_NEAR(hit->material_blend, (x + 4) / 8, 0.01f) << "x = " << x;
    }
}

TEST(ColourBlend, EqualOrMissingEndMaterialIsNoBlend)
{
    geom::Scene s;
    add_tube(s.geometry, 3, 3);
    add_hermite(s.geometry, {-4, 5, 0, 0.5f}, {8, 0, 0, 0}, {4, 5, 0, 0.5f}, {8, 0, 0, 0}, 4);
    EmbreeScene accel(s, top_camera(0, 0, 10, 10, 10));
    auto same = hit_above(accel, 1);
    ASSERT_TRUE(same);
    EXPECT_EQ(same->material, 3);
    EXPECT_EQ(same->material_blend, 0.0f);
    auto missing = accel.intersect({1, 5, 10}, {0, 0, -1}, 0, inf);  // end_material too short
    ASSERT_TRUE(missing);
    EXPECT_EQ(missing->material, 4);
    EXPECT_EQ(missing->material_blend, 0.0f);
}

TEST(ColourBlend, InstancesResolveInheritedStartAndEnd)
{
    geom::Scene s;
    geom::Prototype p;
    add_tube(p.geometry, geom::inherit_material, 6);
    s.prototypes.push_back(std::move(p));
    geom::Instance i;
    i.material = 5;
    s.instances.push_back(i);
    geom::Prototype q;
    add_tube(q.geometry, 6, geom::inherit_material);
    s.prototypes.push_back(std::move(q));
    geom::Instance j;
    j.prototype = 1;
    j.transform = transform({1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 5, 0});
    j.material = 6;  // the inherited end equals the start: no blend
    s.instances.push_back(j);
    EmbreeScene accel(s, top_camera(0, 0, 10, 10, 10));
    auto hit = hit_above(accel, 0);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->material, 5);
    EXPECT_EQ(hit->end_material, 6);
    EXPECT_NEAR(hit->material_blend, 0.5f, 0.01f);
    auto plain = accel.intersect({0, 5, 10}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(plain);
    EXPECT_EQ(plain->material, 6);
    EXPECT_EQ(plain->material_blend, 0.0f);
}

// A convex Lambertian surface under a uniform environment of radiance 1 reflects its
// albedo (its hemisphere sees only the environment), so the tube's pixels show the
// albedo blended along x: the mean of a block is the albedo at its mean u.
TEST(ColourBlend, TubeRadianceFollowsTheBlendedAlbedo)
{
    geom::Scene s;
    s.materials[1].diffuse = {0.5f, 0.5f, 0.5f};
    s.materials[2].diffuse = {0.9f, 0.9f, 0.9f};
    add_tube(s.geometry, 1, 2);
    // 40 x 8 pixels over 10 x 2 units: pixel px spans x in -5 + [px, px + 1] / 4.
    Camera camera = top_camera(0, 0, 10, 40, 8);
    EmbreeScene accel(s, camera);
    PathContext ctx;
    ctx.accel = &accel;
    ctx.materials = make_materials(s.materials);
    const Environment uniform = make_uniform_environment(Vec3f(1));
    ctx.environment = &uniform;
    ctx.ambient = Vec3f(1);
    ctx.max_depth = 4;
    ctx.roulette_depth = 100;
    prepare_path_context(ctx);
    float a = ctx.materials[1].diffuse.y, b = ctx.materials[2].diffuse.y;
    ASSERT_GT(b - a, 0.3f);  // sRGB-decoded 0.5 and 0.9: about 0.21 and 0.79
    struct Block {
        int x0, x1;
        float mean_u;
    };
    // Rows 3..4 (|y| <= 0.25) see the tube's top; u = (x + 4) / 8.
    for (Block blk : {Block{4, 8, 0.0625f}, Block{18, 22, 0.5f}, Block{32, 36, 0.9375f}}) {
        BlockMean m = trace_block(ctx, camera, blk.x0, 3, blk.x1, 5, 16);
        EXPECT_EQ(m.coverage, 1.0);
        float expected = a + (b - a) * blk.mean_u;
        EXPECT_NEAR(m.radiance.y, expected, 0.01f) << "pixels " << blk.x0 << ".." << blk.x1;
        std::printf("[colour blend] block %d..%d: %.4f (expected %.4f; ends %.4f %.4f)\n", blk.x0,
                    blk.x1, m.radiance.y, expected, a, b);
    }
}

}  // namespace
}  // namespace cambium::render
