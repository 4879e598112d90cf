// SPDX-License-Identifier: Apache-2.0
// Tests of bicubic patches: basis evaluation against hand values, tessellation, @PS/@PC/@PD.
#include <gtest/gtest.h>

#include "geom/patch.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

// Control points P[i][j] = (j, i, z) with z = 8 at (1, 2) only.
PatchControl grid_with_bump()
{
    PatchControl c{};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            c[static_cast<std::size_t>(4 * i + j)] = {double(j), double(i), (i == 1 && j == 2) ? 8.0 : 0.0};
    return c;
}

}  // namespace

TEST(Patch, BezierMidpointIsDeCasteljau)
{
    // At 1/2 the Bernstein weights are 1/8, 3/8, 3/8, 1/8: x = y = 1.5, z = 8 * 3/8 * 3/8.
    Vec3 p = patch_point(PatchBasis::bezier, grid_with_bump(), 0.5, 0.5);
    expect_near(p, {1.5, 1.5, 9.0 / 8.0}, 1e-12);
}

TEST(Patch, BezierInterpolatesCorners)
{
    PatchControl c = grid_with_bump();
    expect_near(patch_point(PatchBasis::bezier, c, 0, 0), c[0], 1e-12);
    expect_near(patch_point(PatchBasis::bezier, c, 0, 1), c[3], 1e-12);
    expect_near(patch_point(PatchBasis::bezier, c, 1, 0), c[12], 1e-12);
    expect_near(patch_point(PatchBasis::bezier, c, 1, 1), c[15], 1e-12);
}

TEST(Patch, BsplineAveragesAsUniformCubic)
{
    // Uniform cubic B-spline of 0,1,2,3 at t = 0: (0 + 4 + 2) / 6 = 1; at 1/2: 1.5.
    PatchControl c = grid_with_bump();
    for (auto& p : c)
        p.z = 0;
    expect_near(patch_point(PatchBasis::bspline, c, 0, 0), {1, 1, 0}, 1e-12);
    expect_near(patch_point(PatchBasis::bspline, c, 0.5, 0.5), {1.5, 1.5, 0}, 1e-12);
}

TEST(Patch, CardinalInterpolatesInnerPoints)
{
    PatchControl c = grid_with_bump();
    expect_near(patch_point(PatchBasis::cardinal, c, 0, 0), c[5], 1e-12);   // P[1][1]
    expect_near(patch_point(PatchBasis::cardinal, c, 1, 1), c[10], 1e-12);  // P[2][2]
}

TEST(Patch, DerivativesOfFlatGrid)
{
    PatchControl c = grid_with_bump();
    for (auto& p : c)
        p.z = 0;
    // x(s,t) = (3t, 3s, 0) for the Bézier basis (linear precision).
    expect_near(patch_ds(PatchBasis::bezier, c, 0.3, 0.6), {0, 3, 0}, 1e-12);
    expect_near(patch_dt(PatchBasis::bezier, c, 0.3, 0.6), {3, 0, 0}, 1e-12);
}

TEST(Patch, TessellationCountsNormalsAndWinding)
{
    PatchControl c = grid_with_bump();
    for (auto& p : c)
        p.z = 0;
    TriangleMesh mesh;
    tessellate_patch(PatchBasis::bezier, c, 3, 2, 7, 9, 4, mesh);
    EXPECT_EQ(mesh.positions.size(), 4u * 3u);
    EXPECT_EQ(mesh.size(), 2u * 3u * 2u);
    ASSERT_EQ(mesh.material.size(), mesh.size());
    EXPECT_EQ(mesh.material[0], 7);
    EXPECT_EQ(mesh.back_material[0], 9);
    EXPECT_EQ(mesh.texture[0], 4);
    // n = dx/dt x dx/ds = +x cross +y = +z; every triangle turns counter-clockwise about it.
    for (const Float3& n : mesh.normals)
        expect_near(v3(n), {0, 0, 1}, 1e-6);
    for (const auto& t : mesh.triangles) {
        Vec3 a = v3(mesh.positions[t[0]]), b = v3(mesh.positions[t[1]]), d = v3(mesh.positions[t[2]]);
        EXPECT_GT(cross(b - a, d - a).z, 0);
    }
    // uv = (s, t): the last vertex is s = 1, t = 1 at the point (3, 3, 0).
    EXPECT_FLOAT_EQ(mesh.uvs.back()[0], 1);
    EXPECT_FLOAT_EQ(mesh.uvs.back()[1], 1);
    expect_near(v3(mesh.positions.back()), {3, 3, 0}, 1e-6);
    expect_near(v3(mesh.positions[1]), {1.5, 0, 0}, 1e-6);  // s = 0, t = 1/2 of 3 units
}

TEST(Patch, StepsAreClampedToCpfgRange)
{
    PatchGrid g = sample_patch(PatchBasis::bezier, grid_with_bump(), 0, 50);
    EXPECT_EQ(g.s_steps, 1);
    EXPECT_EQ(g.t_steps, max_patch_steps);
}

TEST(Patch, LsystemPatchNeedsAllSixteenPoints)
{
    set_warnings_enabled(false);
    LsystemPatches patches;
    TriangleMesh mesh;
    patches.start(1, 0);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 3; ++c)
            patches.set_control_point(1, r, c, {double(c), double(r), 0}, {});
    EXPECT_FALSE(patches.draw(1, 2, 2, 1, 2, no_texture, mesh, {}));
    EXPECT_EQ(mesh.size(), 0u);
    for (int r = 0; r < 4; ++r)
        patches.set_control_point(1, r, 3, {3, double(r), 0}, {});
    patches.set_control_point(1, 4, 0, {100, 100, 100}, {});  // out of range: ignored
    EXPECT_TRUE(patches.draw(1, 2, 3, 1, 2, no_texture, mesh, {}));
    EXPECT_EQ(mesh.size(), 2u * 2u * 3u);
    EXPECT_FALSE(patches.draw(2, 2, 2, 1, 2, no_texture, mesh, {}));  // never defined
    // Default steps are cpfg's 5 x 5.
    TriangleMesh more;
    EXPECT_TRUE(patches.draw(1, 0, 0, 1, 2, no_texture, more, {}));
    EXPECT_EQ(more.size(), 2u * 5u * 5u);
    // @PS resets the points.
    patches.start(1, 2);
    EXPECT_FALSE(patches.draw(1, 2, 2, 1, 2, no_texture, more, {}));
    set_warnings_enabled(true);
}

TEST(Patch, LsystemPatchUsesItsBasis)
{
    LsystemPatches patches;
    patches.start(5, 3);  // cardinal: the drawn surface spans P[1][1] .. P[2][2]
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            patches.set_control_point(5, r, c, {double(c), double(r), 0}, {});
    TriangleMesh mesh;
    ASSERT_TRUE(patches.draw(5, 1, 1, 0, 0, no_texture, mesh, {}));
    expect_near(v3(mesh.positions.front()), {1, 1, 0}, 1e-6);
    expect_near(v3(mesh.positions.back()), {2, 2, 0}, 1e-6);
}
