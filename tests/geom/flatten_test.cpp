// SPDX-License-Identifier: Apache-2.0
// flatten_small_instances: which instances are drawn in place, where their copies land
// and what they carry, and the prototypes that stay, renumbered.
#include <gtest/gtest.h>

#include "geom/flatten.h"

namespace cambium::geom {
namespace {

/// A prototype of one triangle in the xy plane, its material inherited.
Prototype triangle_prototype()
{
    Prototype p;
    p.name = "leaf";
    TriangleMesh& m = p.geometry.mesh;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    m.triangles = {{0, 1, 2}};
    m.material = {inherit_material};
    m.back_material = {inherit_material};
    m.texture = {no_texture};
    return p;
}

/// A prototype of one cylinder segment (never drawn in place).
Prototype segment_prototype()
{
    Prototype p;
    p.name = "twig";
    p.geometry.lines.keys = {{0, 0, 0, 0.1f}, {0, 1, 0, 0.1f}};
    p.geometry.lines.segments = {0};
    p.geometry.lines.material = {inherit_material};
    return p;
}

/// A translation by (x, 0, 0).
Instance placed(std::uint32_t prototype, float x, std::uint16_t material)
{
    Instance in;
    in.prototype = prototype;
    in.transform[9] = x;
    in.material = material;
    in.back_material = static_cast<std::uint16_t>(material + 1);
    return in;
}

Scene leaves_and_a_twig()
{
    Scene s;
    s.prototypes = {triangle_prototype(), segment_prototype()};
    s.instances = {placed(0, 10, 4), placed(1, 0, 9), placed(0, 20, 6)};
    return s;
}

TEST(Flatten, SmallMeshesAreDrawnInPlaceWithTheirInstancesMaterials)
{
    Scene s = leaves_and_a_twig();
    EXPECT_EQ(flatten_small_instances(s), 2u);
    // The twig's instance stays, its prototype renumbered to the only one left.
    ASSERT_EQ(s.instances.size(), 1u);
    ASSERT_EQ(s.prototypes.size(), 1u);
    EXPECT_EQ(s.prototypes[0].name, "twig");
    EXPECT_EQ(s.instances[0].prototype, 0u);
    EXPECT_EQ(s.instances[0].material, 9);
    // Two placed triangles in the scene's own mesh, in instance order.
    const TriangleMesh& m = s.geometry.mesh;
    ASSERT_EQ(m.size(), 2u);
    ASSERT_EQ(m.positions.size(), 6u);
    EXPECT_EQ(m.positions[m.triangles[0][1]], (Float3{11, 0, 0}));
    EXPECT_EQ(m.positions[m.triangles[1][2]], (Float3{20, 1, 0}));
    EXPECT_EQ(m.material, (std::vector<std::uint16_t>{4, 6}));
    EXPECT_EQ(m.back_material, (std::vector<std::uint16_t>{5, 7}));
    EXPECT_EQ(m.normals[m.triangles[1][0]], (Float3{0, 0, 1}));
}

TEST(Flatten, NothingChangesPastTheLimits)
{
    Scene s = leaves_and_a_twig();
    EXPECT_EQ(flatten_small_instances(s, {.max_prototype_triangles = 4096, .max_total_triangles = 1}), 0u);
    EXPECT_EQ(s.instances.size(), 3u);
    EXPECT_EQ(s.prototypes.size(), 2u);
    EXPECT_EQ(s.geometry.mesh.size(), 0u);
    EXPECT_EQ(flatten_small_instances(s, {.max_prototype_triangles = 0}), 0u);
    EXPECT_EQ(flatten_small_instances(s, {.max_bytes = 10}), 0u);
    EXPECT_EQ(s.instances.size(), 3u);
}

TEST(Flatten, OnlyTrianglesAreDrawnInPlace)
{
    Scene s;
    s.prototypes = {segment_prototype()};
    s.instances = {placed(0, 1, 2), placed(0, 2, 2)};
    EXPECT_EQ(flatten_small_instances(s), 0u);
    EXPECT_EQ(s.instances.size(), 2u);
}

}  // namespace
}  // namespace cambium::geom
