// SPDX-License-Identifier: Apache-2.0
// EmbreeScene on every Geometry kind: Hermite curves, spheres, discs, triangles with
// shading normals and two sides, prototypes placed by instances.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

#include "base/diagnostics.h"
#include "geom/scene_limits.h"
#include "render/accel.h"
#include "geom_scenes.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using namespace testing;

constexpr float inf = std::numeric_limits<float>::infinity();

Camera any_camera() { return top_camera(0, 0, 10, 10, 10); }

TEST(Primitives, HermiteCurveWithRadiusProfile)
{
    geom::Scene s;
    // Straight axis x -5..5; radius 1 -> 2, linear in u: tangent w = r1 - r0.
    add_hermite(s.geometry, {-5, 0, 0, 1}, {10, 0, 0, 1}, {5, 0, 0, 2}, {10, 0, 0, 1}, 4);
    EmbreeScene accel(s, any_camera());
    EXPECT_EQ(accel.segment_count(), 1u);
    auto hit = accel.intersect({0, 0, 10}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->shape, Shape::curve);
    EXPECT_EQ(hit->material, 4);
    // The exact envelope of spheres r(x) = 1.5 + x/10 tops out at 1.5076 above x = 0;
    // Embree's sweep approximates it by the radius at the axis point, 1.5.
    EXPECT_GT(hit->t, 10 - 1.51f);
    EXPECT_LT(hit->t, 10 - 1.49f);
    EXPECT_NEAR(hit->radius, 1.5f, 0.02f);
    EXPECT_GT(hit->normal.z, 0.99f);
    // Thin end: radius 1.1 at x = -4, nothing at y = 1.3 there; thick end hit at y = 1.3.
    EXPECT_FALSE(accel.intersect({-4, 1.3f, 10}, {0, 0, -1}, 0, inf));
    EXPECT_TRUE(accel.intersect({4, 1.3f, 10}, {0, 0, -1}, 0, inf));
}

TEST(Primitives, SphereHitNormalAndRadius)
{
    geom::Scene s;
    add_sphere(s.geometry, {1, 2, 3}, 2, 9);
    EmbreeScene accel(s, any_camera());
    auto hit = accel.intersect({1, 2, 10}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 5, 1e-4f);
    EXPECT_NEAR(hit->normal.z, 1, 1e-4f);
    EXPECT_EQ(hit->material, 9);
    EXPECT_NEAR(hit->radius, 2, 1e-6f);
    // Off-axis: the normal is (p - c) / r.
    auto side = accel.intersect({2, 2, 10}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(side);
    EXPECT_NEAR(side->normal.x, 0.5f, 1e-4f);
    EXPECT_NEAR(side->normal.z, std::sqrt(0.75f), 1e-4f);
    EXPECT_FALSE(accel.intersect({3.1f, 2, 10}, {0, 0, -1}, 0, inf));
}

TEST(Primitives, DiscFrontAndBackMaterials)
{
    geom::Scene s;
    add_disc(s.geometry, {0, 0, 0}, 1, {0, 0, 1}, 3, 4);
    EmbreeScene accel(s, any_camera());
    auto front = accel.intersect({0.5f, 0, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(front);
    EXPECT_EQ(front->material, 3);
    EXPECT_FALSE(front->back);
    EXPECT_NEAR(front->normal.z, 1, 1e-5f);
    auto back = accel.intersect({0.5f, 0, -5}, {0, 0, 1}, 0, inf);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->material, 4);
    EXPECT_TRUE(back->back);
    EXPECT_NEAR(back->normal.z, -1, 1e-5f);
    EXPECT_FALSE(accel.intersect({1.1f, 0, 5}, {0, 0, -1}, 0, inf));
}

TEST(Primitives, TriangleSidesShadingNormalAndUv)
{
    geom::Scene s;
    // Vertex normals tilted toward -x, 0 and +x: the shading normal interpolates them.
    float a = 0.5f;
    std::uint32_t t = add_triangle(
        s.geometry, {{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}}},
        {{{-a, 0, 1}, {a, 0, 1}, {0, 0, 1}}}, {{{0, 0}, {1, 0}, {0, 1}}}, 5, 6, 0);
    EXPECT_EQ(t, 0u);
    EmbreeScene accel(s, any_camera());
    // At (2, 1): barycentrics u = 0.5 (vertex 1), v = 0.25 (vertex 2), w = 0.25.
    auto hit = accel.intersect({2, 1, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->material, 5);
    Vec3f n = normalize(Vec3f(-a * 0.25f + a * 0.5f, 0, 1));
    EXPECT_NEAR(hit->normal.x, n.x, 1e-5f);
    EXPECT_NEAR(hit->normal.z, n.z, 1e-5f);
    EXPECT_NEAR(hit->geometric_normal.z, 1, 1e-6f);
    EXPECT_EQ(hit->texture, 0);
    EXPECT_NEAR(hit->u, 0.5f, 1e-5f);
    EXPECT_NEAR(hit->v, 0.25f, 1e-5f);
    auto back = accel.intersect({2, 1, -5}, {0, 0, 1}, 0, inf);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->material, 6);
    EXPECT_TRUE(back->back);
    EXPECT_NEAR(back->normal.x, -n.x, 1e-5f);
    EXPECT_NEAR(back->normal.z, -n.z, 1e-5f);
}

// The front is where the vertex normals point, whatever the winding.
TEST(Primitives, TriangleFrontFollowsVertexNormalsNotWinding)
{
    geom::Scene s;
    geom::Float3 down{0, 0, -1};
    add_triangle(s.geometry, {{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}}}, {down, down, down},
                 {{{0, 0}, {1, 0}, {0, 1}}}, 5, 6);
    EmbreeScene accel(s, any_camera());
    auto from_above = accel.intersect({1, 1, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(from_above);
    EXPECT_EQ(from_above->material, 6);
    auto from_below = accel.intersect({1, 1, -5}, {0, 0, 1}, 0, inf);
    ASSERT_TRUE(from_below);
    EXPECT_EQ(from_below->material, 5);
}

TEST(Primitives, InstancesPlaceInheritAndTransformNormals)
{
    geom::Scene s;
    geom::Prototype p;
    // The plane x + z = 0 (normal (1, 0, 1)/sqrt 2) as one big triangle, inheriting.
    geom::Float3 n{0.70710678f, 0, 0.70710678f};
    add_triangle(p.geometry, {{{-4, -5, 4}, {4, -5, -4}, {0, 5, 0}}}, {n, n, n},
                 {{{0, 0}, {1, 0}, {0, 1}}}, geom::inherit_material, geom::inherit_material);
    add_sphere(p.geometry, {0, 0, 20}, 1, 11);
    s.prototypes.push_back(p);
    geom::Instance stretched;  // x scaled by 2, then moved to x = 10
    stretched.transform = transform({2, 0, 0, 0, 1, 0, 0, 0, 1}, {10, 0, 0});
    stretched.material = 7;
    stretched.back_material = 8;
    s.instances.push_back(stretched);
    geom::Instance plain;
    plain.transform = transform({1, 0, 0, 0, 1, 0, 0, 0, 1}, {-10, 0, 0});
    plain.material = 12;
    s.instances.push_back(plain);
    EmbreeScene accel(s, any_camera());

    // Stretched plane: x'/2 - 5 + z = 0 -> at x' = 11, z = -0.5; normal ~ (0.5, 0, 1).
    auto hit = accel.intersect({11, 0, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->position.z, -0.5f, 1e-4f);
    Vec3f expect = normalize(Vec3f(0.5f, 0, 1));
    EXPECT_NEAR(hit->normal.x, expect.x, 1e-5f);
    EXPECT_NEAR(hit->normal.z, expect.z, 1e-5f);
    EXPECT_EQ(hit->material, 7);
    auto back = accel.intersect({11, 0, -5}, {0, 0, 1}, 0, inf);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->material, 8);
    // The other instance: its own material; the sphere keeps its own and scales its radius.
    auto other = accel.intersect({-10, 0, 5}, {0, 0, -1}, 0, 10);
    ASSERT_TRUE(other);
    EXPECT_EQ(other->material, 12);
    EXPECT_NE(other->inst_id, hit->inst_id);
    auto sphere = accel.intersect({10, 0, 30}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(sphere);
    EXPECT_EQ(sphere->material, 11);
    EXPECT_EQ(sphere->shape, Shape::sphere);
    EXPECT_NEAR(sphere->t, 9, 1e-4f);
    EXPECT_NEAR(sphere->radius, std::cbrt(2.0f), 1e-5f);
    // Flat primitives are never skipped (rays leave them by their offset; no filter runs).
    auto flat = accel.intersect({11, 0, 5}, {0, 0, -1}, 0, inf, hit->prim());
    ASSERT_TRUE(flat);
    EXPECT_EQ(flat->prim_id, hit->prim_id);
    // Skipping one instance's sphere leaves the other instance's copy visible.
    auto skipped = accel.intersect({10, 0, 30}, {0, 0, -1}, 0, inf, sphere->prim());
    EXPECT_TRUE(!skipped || skipped->shape != Shape::sphere);
    auto other_sphere = accel.intersect({-10, 0, 30}, {0, 0, -1}, 0, inf, sphere->prim());
    ASSERT_TRUE(other_sphere);
    EXPECT_EQ(other_sphere->shape, Shape::sphere);
}

// The memory savings must not change what a hit reads: meshes fitted for Embree
// (positions and triangles read in place, all-zero uvs dropped) and instances that keep no
// placement beside the transform Embree holds shade exactly as the unfitted scene does,
// and each hit still names its instance in Scene::instances.
TEST(Primitives, FittedMeshesAndInstancesShadeAsBefore)
{
    geom::Scene s;
    s.prototypes.push_back(geom::Prototype{});  // empty: its instances are not built
    geom::Prototype leaf;  // untextured (uvs all zero), tilted vertex normals, inheriting
    float a = 0.5f;
    add_triangle(leaf.geometry, {{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}}},
                 {{{-a, 0, 1}, {a, 0, 1}, {0, 0, 1}}}, {{{0, 0}, {0, 0}, {0, 0}}},
                 geom::inherit_material, 6);
    s.prototypes.push_back(leaf);
    geom::Prototype mapped;  // its own texture and real uvs
    add_triangle(mapped.geometry, {{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}}},
                 {{{0, 0, 1}, {0, 0, 1}, {0, 0, 1}}}, {{{0, 0}, {1, 0}, {0, 1}}}, 9, 9, 2);
    s.prototypes.push_back(mapped);
    geom::Prototype plain;  // uvs set, but nothing textures it: no hit reads them
    add_triangle(plain.geometry, {{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}}},
                 {{{0, 0, 1}, {0, 0, 1}, {0, 0, 1}}}, {{{0, 0}, {1, 0}, {0, 1}}}, 10, 11);
    s.prototypes.push_back(plain);
    add_triangle(s.geometry, {{{0, 20, 0}, {4, 20, 0}, {0, 24, 0}}},
                 {{{0, a, 1}, {0, -a, 1}, {0, 0, 1}}}, {{{0, 0}, {0, 0}, {0, 0}}}, 4, 5);
    auto place = [&](std::uint32_t prototype, std::array<float, 12> t, std::uint16_t material,
                     std::int16_t texture) {
        geom::Instance i;
        i.prototype = prototype;
        i.transform = t;
        i.material = material;
        i.back_material = static_cast<std::uint16_t>(material + 1);
        i.texture = texture;
        s.instances.push_back(i);
    };
    place(0, transform({1, 0, 0, 0, 1, 0, 0, 0, 1}), 1, geom::no_texture);
    place(1, transform({0, -1, 0, 1, 0, 0, 0, 0, 1}, {0, 0, 0}), 7, 3);  // turned 90 deg
    place(0, transform({1, 0, 0, 0, 1, 0, 0, 0, 1}), 1, geom::no_texture);
    place(2, transform({1, 0, 0, 0, 1, 0, 0, 0, 1}, {20, 0, 0}), 1, geom::no_texture);
    place(1, transform({2, 0, 0, 0, 1, 0, 0, 0.5f, 1}, {40, 0, 0}), 8, geom::no_texture);
    place(3, transform({1, 0, 0, 0, 1, 0, 0, 0, 1}, {28, 10, 0}), 1, geom::no_texture);
    for (geom::Prototype& p : s.prototypes) {  // copied to Embree, as an unfitted Scene is
        p.geometry.mesh.positions.shrink_to_fit();
        p.geometry.mesh.triangles.shrink_to_fit();
    }
    s.geometry.mesh.positions.shrink_to_fit();
    s.geometry.mesh.triangles.shrink_to_fit();

    geom::Scene fitted = s;
    geom::fit_scene_buffers(fitted);
    EXPECT_TRUE(fitted.prototypes[1].geometry.mesh.uvs.empty());
    EXPECT_TRUE(fitted.geometry.mesh.uvs.empty());
    EXPECT_EQ(fitted.prototypes[2].geometry.mesh.uvs.size(), 3u);
    EXPECT_TRUE(fitted.prototypes[3].geometry.mesh.uvs.empty());
    EXPECT_TRUE(fitted.prototypes[3].geometry.mesh.texture.empty());
    EXPECT_EQ(fitted.prototypes[1].geometry.mesh.texture.size(), 0u);
    EXPECT_EQ(fitted.prototypes[2].geometry.mesh.texture.size(), 1u);
    EXPECT_TRUE(geom::padded_for_embree(fitted.prototypes[1].geometry.mesh.positions));
    EXPECT_TRUE(geom::padded_for_embree(fitted.geometry.mesh.triangles));
    EXPECT_FALSE(geom::padded_for_embree(s.prototypes[1].geometry.mesh.positions));

    EmbreeScene before(s, any_camera()), after(fitted, any_camera());
    EXPECT_EQ(after.shared_bytes() - before.shared_bytes(), 4 * (3 * 12 + 12u));
    EXPECT_LT(after.embree_bytes(), before.embree_bytes());
    std::map<std::uint32_t, int> hits_of_instance;
    for (float dz : {-1.0f, 1.0f})
        for (float x = -5.25f; x < 50; x += 0.5f)
            for (float y = -5.25f; y < 25; y += 0.5f) {
                Vec3f org(x, y, -5 * dz), dir(0.1f, 0.05f, dz);
                auto hb = before.intersect(org, dir, 0, inf);
                auto ha = after.intersect(org, dir, 0, inf);
                ASSERT_EQ(bool(hb), bool(ha)) << x << " " << y;
                if (!hb)
                    continue;
                ++hits_of_instance[ha->instance];
                EXPECT_EQ(ha->t, hb->t);
                auto same = [](const Vec3f& p, const Vec3f& q) {
                    return p.x == q.x && p.y == q.y && p.z == q.z;
                };
                EXPECT_TRUE(same(ha->normal, hb->normal));
                EXPECT_TRUE(same(ha->geometric_normal, hb->geometric_normal));
                EXPECT_TRUE(same(ha->dpds, hb->dpds));
                EXPECT_TRUE(same(ha->dpdt, hb->dpdt));
                EXPECT_EQ(ha->material, hb->material);
                EXPECT_EQ(ha->texture, hb->texture);
                EXPECT_EQ(ha->u, hb->u);
                EXPECT_EQ(ha->v, hb->v);
                EXPECT_EQ(ha->back, hb->back);
                EXPECT_EQ(ha->instance, hb->instance);
                EXPECT_EQ(ha->spawn_offset, hb->spawn_offset);
            }
    // The own triangle and instances 1, 3, 4 and 5 of Scene::instances are all hit.
    EXPECT_GT(hits_of_instance[PrimId::none], 0);
    EXPECT_GT(hits_of_instance[1], 0);
    EXPECT_GT(hits_of_instance[3], 0);
    EXPECT_GT(hits_of_instance[4], 0);
    EXPECT_GT(hits_of_instance[5], 0);
    EXPECT_EQ(hits_of_instance.size(), 5u);

    // What each instance's hit reads: its materials, its texture on the untextured
    // prototype (at the dropped uvs' zeros), the turned and sheared normals.
    auto turned = after.intersect({-1, 1, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(turned);
    EXPECT_EQ(turned->instance, 1u);
    EXPECT_EQ(turned->material, 7);
    EXPECT_EQ(turned->texture, 3);
    EXPECT_EQ(turned->u, 0);
    EXPECT_EQ(turned->v, 0);
    auto under = after.intersect({-1, 1, -5}, {0, 0, 1}, 0, inf);
    ASSERT_TRUE(under);
    EXPECT_EQ(under->material, 6);  // the prototype's own back material
    auto own = after.intersect({40.5f, 0.5f, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(own);
    EXPECT_EQ(own->instance, 4u);
    EXPECT_EQ(own->material, 8);
    EXPECT_LT(own->geometric_normal.y, -0.4f);  // z' = z + y / 2: the normal ~ (0, -0.5, 1)
}

// A large mesh's hits read one record per triangle, made when the scene is built, and a
// part whose primitives share their materials reads none per hit: the hits must be the
// ones the triangle's vertices and entries give. A patch of triangles (tilted vertex normals, some
// wound against them, away from the origin) is shot alone, a small mesh read through its
// indices, and again inside a mesh of 2^16 more triangles far off, with one material for
// every triangle and with materials that differ.
TEST(Primitives, LargeMeshesShadeAsSmallOnes)
{
    constexpr int cells = 12;
    auto add_patch = [&](geom::Geometry& g, bool uniform) {
        for (int i = 0; i < cells; ++i)
            for (int j = 0; j < cells; ++j) {
                float x = 100.3f + 1.1f * i, y = -40.7f + 0.9f * j, z = 0.37f * float((i * j) % 3);
                geom::Float3 p0{x, y, z}, p1{x + 1.1f, y, z + 0.2f}, p2{x, y + 0.9f, z - 0.1f};
                geom::Float3 n0{0.3f * float(i % 3), -0.2f, 1}, n1{-0.4f, 0.1f * float(j % 4), 1},
                    n2{0.05f, 0.5f, 0.9f};
                int k = i * cells + j;
                if (k % 7 == 3)
                    std::swap(p1, p2);  // wound against its vertex normals
                auto front = static_cast<std::uint16_t>(uniform ? 3 : 2 + k % 5);
                auto back = static_cast<std::uint16_t>(uniform ? 4 : 10 + k % 3);
                add_triangle(g, {{p0, p1, p2}}, {n0, n1, n2}, {{{0, 0}, {1, 0}, {0, 1}}}, front,
                             back);
            }
    };
    for (bool uniform : {true, false}) {
        geom::Scene small, large;
        add_patch(small.geometry, uniform);
        add_patch(large.geometry, uniform);
        geom::Float3 n{0, 0, 1};
        for (int k = 0; k < (1 << 16); ++k) {  // far below the patch
            auto x = float(k % 256), y = float(k / 256);
            add_triangle(large.geometry, {{{x, y, -500}, {x + 1, y, -500}, {x, y + 1, -500}}},
                         {n, n, n}, {{{0, 0}, {1, 0}, {0, 1}}}, uniform ? 3 : 20, uniform ? 4 : 21);
        }
        EmbreeScene a(small, any_camera()), b(large, any_camera());
        // The records are the renderer's own bytes (64 a triangle).
        EXPECT_GE(b.own_bytes(), a.own_bytes() + 64 * large.geometry.mesh.size());
        int hits = 0, backs = 0;
        for (float dz : {-1.0f, 1.0f})
            for (float x = 99.95f; x < 100.3f + 1.1f * cells; x += 0.25f)
                for (float y = -41.1f; y < -40.7f + 0.9f * cells; y += 0.25f) {
                    Vec3f org(x, y, -20 * dz), dir(0.02f, -0.03f, dz);
                    auto ha = a.intersect(org, dir, 0, 30);
                    auto hb = b.intersect(org, dir, 0, 30);
                    ASSERT_EQ(bool(ha), bool(hb)) << x << " " << y;
                    if (!ha)
                        continue;
                    ++hits;
                    backs += ha->back;
                    auto same = [](const Vec3f& p, const Vec3f& q) {
                        return p.x == q.x && p.y == q.y && p.z == q.z;
                    };
                    EXPECT_EQ(ha->t, hb->t);
                    EXPECT_TRUE(same(ha->position, hb->position));
                    EXPECT_TRUE(same(ha->normal, hb->normal));
                    EXPECT_TRUE(same(ha->geometric_normal, hb->geometric_normal));
                    EXPECT_EQ(ha->material, hb->material);
                    EXPECT_EQ(ha->back, hb->back);
                    EXPECT_EQ(ha->spawn_offset, hb->spawn_offset);
                    EXPECT_EQ(ha->prim_id, hb->prim_id);
                    // The entry of the side hit, as add_patch gave it.
                    int k = int(ha->prim_id);
                    int expected = uniform ? (ha->back ? 4 : 3) : (ha->back ? 10 + k % 3 : 2 + k % 5);
                    EXPECT_EQ(ha->material, expected);
                }
        EXPECT_GT(hits, 1000);
        EXPECT_GT(backs, 100);
        EXPECT_LT(backs, hits - 100);
        // The same mesh as a prototype gets none: scenes of many plants keep their memory.
        geom::Scene placed;
        placed.prototypes.push_back(geom::Prototype{"", large.geometry});
        placed.instances.push_back(geom::Instance{});
        EmbreeScene c(placed, any_camera());
        EXPECT_LT(c.own_bytes(), 64 * large.geometry.mesh.size());
        auto hc = c.intersect({105.1f, -37.8f, 20}, {0, 0, -1}, 0, 30);
        ASSERT_TRUE(hc);
        EXPECT_EQ(hc->material, uniform ? 3 : 2 + int(hc->prim_id) % 5);
    }
}

// An instance costs Cambium nothing beside what Embree keeps: 200 instances of a
// prototype leave the renderer's own bytes where one instance does. Embree's instance
// objects, which its memory monitor does not report (about 300 B each), are seen on the heap.
TEST(Primitives, InstancesKeepNoPlacementBesideEmbree)
{
    auto own_bytes = [](int instances, std::uint64_t* unmonitored = nullptr) {
        geom::Scene s;
        geom::Prototype p;
        add_sphere(p.geometry, {0, 0, 0}, 1, 3);
        s.prototypes.push_back(p);
        for (int i = 0; i < instances; ++i) {
            geom::Instance inst;
            inst.transform = transform({1, 0, 0, 0, 1, 0, 0, 0, 1}, {3.0 * i, 0, 0});
            inst.material = static_cast<std::uint16_t>(i % 2);
            s.instances.push_back(inst);
        }
        EmbreeScene accel(s, any_camera());
        if (unmonitored)
            *unmonitored = accel.embree_unmonitored_bytes();
        return accel.own_bytes();
    };
    std::uint64_t unmonitored = 0;
    EXPECT_EQ(own_bytes(2000, &unmonitored), own_bytes(2));
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)  // ASan's malloc reports no mallinfo
    EXPECT_GT(unmonitored, 2000u * 150);
    EXPECT_LT(unmonitored, 2000u * 1000);
#endif
}

// Texture coordinates: t along a line from its keys' v, (s, t) = longitude and latitude on
// a sphere; the texture index comes with them.
TEST(Primitives, CurveAndSphereTextureCoordinates)
{
    geom::Scene s;
    add_segment(s, {-5, 0, 0}, {5, 0, 0}, 1);
    s.geometry.lines.v = {0.0f, 2.0f};
    s.geometry.lines.texture = {3};
    add_sphere(s.geometry, {0, 10, 0}, 1);
    s.geometry.spheres.texture[0] = 4;
    EmbreeScene accel(s, any_camera());
    auto line = accel.intersect({2.5f, 0, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(line);
    EXPECT_EQ(line->texture, 3);
    EXPECT_NEAR(line->v, 1.5f, 1e-4f);
    auto top = accel.intersect({0, 10, 5}, {0, 0, -1}, 0, inf);
    ASSERT_TRUE(top);
    EXPECT_EQ(top->texture, 4);
    EXPECT_NEAR(top->v, 1.0f, 1e-3f);  // the north pole (+z)
    auto side = accel.intersect({0, 5, 0}, {0, 1, 0}, 0, inf);
    ASSERT_TRUE(side);
    EXPECT_NEAR(side->v, 0.5f, 1e-4f);  // the equator
    EXPECT_NEAR(side->u, 0.25f, 1e-4f);  // longitude of -y: atan2(-1, 0) / 2 pi + 1/2
}

TEST(Primitives, EmptyPartsAndUnplacedPrototypesAddNothing)
{
    geom::Scene s;
    geom::Prototype unplaced;
    add_sphere(unplaced.geometry, {0, 0, 0}, 5);
    s.prototypes.push_back(unplaced);
    s.prototypes.push_back(geom::Prototype{});  // empty, placed
    geom::Instance i;
    i.prototype = 1;
    s.instances.push_back(i);
    EmbreeScene accel(s, any_camera());
    EXPECT_FALSE(accel.intersect({0, 0, 10}, {0, 0, -1}, 0, inf));
    EXPECT_FALSE(accel.occluded({0, 0, 10}, {0, 0, -1}, 0, inf));
}

TEST(Primitives, RejectsBadIndices)
{
    geom::Scene tri;
    add_quad(tri.geometry, 0, 0, 1, 1, 0, 1, 1);
    tri.geometry.mesh.triangles[0][2] = 99;
    EXPECT_THROW(EmbreeScene(tri, any_camera()), Error);
    geom::Scene inst;
    inst.instances.push_back(geom::Instance{});
    EXPECT_THROW(EmbreeScene(inst, any_camera()), Error);
    geom::Scene curve;
    add_hermite(curve.geometry, {0, 0, 0, 1}, {1, 0, 0, 0}, {1, 0, 0, 1}, {1, 0, 0, 0});
    curve.geometry.curves.tangents.pop_back();
    EXPECT_THROW(EmbreeScene(curve, any_camera()), Error);
}

/// Diffuse rays leaving camera hits on s: how many hit the geometry again (all spurious for
/// a lone convex primitive), of how many.
std::pair<int, int> rehits(const geom::Scene& s, float extent)
{
    EmbreeScene accel(s, any_camera());
    int again = 0, n = 0;
    for (std::uint32_t i = 0; i < 3000; ++i) {
        Sampler sm(i, 1, 0, 3);
        Vec3f org((sm.next() * 2 - 1) * extent, (sm.next() * 2 - 1) * extent, 50);
        auto hit = accel.intersect(org, {0, 0, -1}, 0, inf);
        if (!hit)
            continue;
        ++n;
        BsdfSample bs = bsdf_sample(lambertian(Vec3f(1)), hit->normal, {0, 0, 1}, sm.next(),
                                    sm.next());
        Vec3f from = hit->position + hit->geometric_normal * hit->spawn_offset;
        again += accel.intersect(from, bs.wi, 0, inf, hit->prim()) ? 1 : 0;
    }
    return {again, n};
}

TEST(Primitives, SpawnedRaysDoNotHitTheirOwnSphereOrCurve)
{
    geom::Scene sphere;
    add_sphere(sphere.geometry, {0, 0, 0}, 0.01f);
    auto [a, n] = rehits(sphere, 0.007f);
    ASSERT_GT(n, 1000);
    EXPECT_EQ(a, 0) << a << " of " << n;
    geom::Scene curve;
    add_hermite(curve.geometry, {-1, 0, 0, 0.01f}, {2, 0, 0, 0}, {1, 0, 0, 0.01f}, {2, 0, 0, 0});
    auto [b, m] = rehits(curve, 0.009f);
    ASSERT_GT(m, 500);
    EXPECT_LE(b, m / 1000) << b << " of " << m;
}

/// Rays entering a closed primitive (diffuse transmission) and bouncing inside it.
struct InnerHits {
    int spurious = 0;  ///< hits closer than 1% of the radius, or not flagged `inside`
    int misses = 0;    ///< rays that left without meeting a wall
    int rays = 0;
};

/// Nothing is skipped, as the integrator does for rays that enter a volume.
InnerHits inner_hits(const geom::Scene& s, float extent, float radius)
{
    EmbreeScene accel(s, any_camera());
    InnerHits r;
    for (std::uint32_t i = 0; i < 2000; ++i) {
        Sampler sm(i, 2, 0, 3);
        Vec3f org((sm.next() * 2 - 1) * extent, (sm.next() * 2 - 1) * extent, 50);
        auto hit = accel.intersect(org, {0, 0, -1}, 0, inf);
        for (int bounce = 0; bounce < 3 && hit; ++bounce) {
            // Into the volume: about -normal from outside, about +normal (inward) inside.
            Vec3f axis = bounce == 0 ? -hit->normal : hit->normal;
            EXPECT_TRUE(hit->enters(axis));
            BsdfSample bs = bsdf_sample(lambertian(Vec3f(1)), axis, axis, sm.next(), sm.next());
            Vec3f side = dot(hit->geometric_normal, bs.wi) >= 0 ? hit->geometric_normal
                                                                : -hit->geometric_normal;
            Vec3f from = hit->position + side * hit->spawn_offset;
            hit = accel.intersect(from, bs.wi, 0, inf);
            ++r.rays;
            if (!hit)
                ++r.misses;
            else if (!hit->inside || hit->t < 0.01f * radius)
                ++r.spurious;
        }
    }
    return r;
}

TEST(Primitives, RaysInsideClosedPrimitivesMeetTheFarWall)
{
    geom::Scene sphere;
    add_sphere(sphere.geometry, {0, 0, 0}, 0.5f);
    InnerHits a = inner_hits(sphere, 0.3f, 0.5f);
    ASSERT_GT(a.rays, 1000);
    EXPECT_EQ(a.spurious + a.misses, 0);
    geom::Scene line;
    add_segment(line, {-1, 0, 0}, {1, 0, 0}, 0.1f);
    InnerHits b = inner_hits(line, 0.08f, 0.1f);
    ASSERT_GT(b.rays, 1000);
    EXPECT_LE(b.spurious + b.misses, b.rays / 1000);
    geom::Scene curve;
    add_hermite(curve.geometry, {-1, 0, 0, 0.1f}, {2, 0, 0, 0}, {1, 0, 0, 0.1f}, {2, 0, 0, 0});
    InnerHits c = inner_hits(curve, 0.08f, 0.1f);
    ASSERT_GT(c.rays, 1000);
    EXPECT_LE(c.spurious, c.rays / 1000);
    // Measured: Embree's cubic curves let a few rays running along the axis out through
    // the end without a hit (they escape: energy is kept, the exit point is wrong).
    EXPECT_LE(c.misses, c.rays / 100);
    std::printf("[inside] spurious/missed inner hits of rays: sphere %d/%d of %d, line %d/%d of "
                "%d, hermite %d/%d of %d\n",
                a.spurious, a.misses, a.rays, b.spurious, b.misses, b.rays, c.spurious,
                c.misses, c.rays);
}

}  // namespace
}  // namespace cambium::render
