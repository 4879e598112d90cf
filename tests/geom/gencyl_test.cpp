// SPDX-License-Identifier: Apache-2.0
// Tests of generalized cylinders: Hermite and B-spline axes, radius profiles, frames,
// contour galleries, and the interpreter's @G modules producing HermiteCurves and meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <unistd.h>

#include "geom/gencyl.h"
#include "geom/interpreter.h"
#include "test_util.h"
#include "geom/turtle.h"
#include "geom/view_volume.h"
#include "lsys/string_io.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

Scene run(const std::string& text, const std::string& view_text = "line style: cylinder\n")
{
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, text);
    std::filesystem::path dir = temp_dir("gc_test");
    ViewFile view = parse_view_file(view_text, (dir / "t.v").string());
    view.path = dir / "t.v";
    return interpret(s, symbols, view);
}

/// A view file using the square contour (corners tripled) as contour 1.
std::string square_contour_view(const std::string& extra = "")
{
    std::filesystem::path dir = temp_dir("gc_test");
    std::ofstream(dir / "square.con") << "cver 1 1\nname: square\npoints: 4 12\ntype: closed\n"
                                         "1 1 0 3\n-1 1 0 3\n-1 -1 0 3\n1 -1 0 3\n";
    return "line style: cylinder\ncontour: 1 square.con\ncontour sides: 8\n" + extra;
}

void expect_key(const Float4& k, double x, double y, double z, double w)
{
    EXPECT_NEAR(k[0], x, 1e-5);
    EXPECT_NEAR(k[1], y, 1e-5);
    EXPECT_NEAR(k[2], z, 1e-5);
    EXPECT_NEAR(k[3], w, 1e-5);
}

double scalar_hermite(double a, double b, double ta, double tb, double s)
{
    return Vec3(hermite({a, 0, 0}, {b, 0, 0}, {ta, 0, 0}, {tb, 0, 0}, s)).x;
}

}  // namespace

TEST(GeneralizedCylinderMath, HermiteMidpointMatchesClosedForm)
{
    Vec3 p0{1, 2, 3}, p1{4, -1, 0.5}, t0{0.5, 3, -2}, t1{-1, 1, 4};
    // h(1/2) = (p0 + p1)/2 + (t0 - t1)/8;  h'(1/2) = 3/2 (p1 - p0) - (t0 + t1)/4.
    Vec3 m = hermite(p0, p1, t0, t1, 0.5);
    Vec3 d = hermite_derivative(p0, p1, t0, t1, 0.5);
    Vec3 m_expected = (p0 + p1) * 0.5 + (t0 - t1) * 0.125;
    Vec3 d_expected = (p1 - p0) * 1.5 - (t0 + t1) * 0.25;
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(m[i], m_expected[i], 1e-12);
        EXPECT_NEAR(d[i], d_expected[i], 1e-12);
    }
    Vec3 e0 = hermite_derivative(p0, p1, t0, t1, 0), e1 = hermite_derivative(p0, p1, t0, t1, 1);
    EXPECT_NEAR(e0.y, t0.y, 1e-12);
    EXPECT_NEAR(e1.z, t1.z, 1e-12);
}

TEST(GeneralizedCylinderMath, DefaultRadiusProfileIsLinear)
{
    RadiusProfile p = RadiusProfile::make(0.2, 0.1, {0, 0}, {0, 0}, false, 3);
    EXPECT_TRUE(p.linear());
    for (double s : {0.0, 0.25, 0.5, 0.9, 1.0}) {
        EXPECT_NEAR(p.u(s), s, 1e-12);
        EXPECT_NEAR(p.radius(s), 0.2 - 0.1 * s, 1e-12);
    }
}

TEST(GeneralizedCylinderMath, FourParameterRadiusTangents)
{
    // @Gr(30, 4.5, 0, 3.5): tangents (4.5 cos 30, 4.5 sin 30) and (3.5, 0).
    Turtle t;
    CylinderBuilder::set_radius_tangents(t, std::vector<float>{30, 4.5f, 0, 3.5f});
    EXPECT_NEAR(t.cylinder.radius_tangent[0][0], 4.5 * std::sqrt(3.0) / 2, 1e-6);
    EXPECT_NEAR(t.cylinder.radius_tangent[0][1], 2.25, 1e-6);
    EXPECT_NEAR(t.cylinder.radius_tangent[1][0], 3.5, 1e-6);
    EXPECT_NEAR(t.cylinder.radius_tangent[1][1], 0, 1e-6);
    RadiusProfile p = RadiusProfile::make(0.2, 0.1, t.cylinder.radius_tangent[0], t.cylinder.radius_tangent[1],
                                          false, 1.5);
    EXPECT_FALSE(p.linear());
    // Midpoints by the closed form (a + b)/2 + (ta - tb)/8.
    EXPECT_NEAR(p.u(0.5), 0.5 + (4.5 * std::sqrt(3.0) / 2 - 3.5) / 8, 1e-6);
    EXPECT_NEAR(p.radius(0.5), 0.15 + 2.25 / 8, 1e-6);
    EXPECT_NEAR(p.radius(1), 0.1, 1e-12);
}

TEST(GeneralizedCylinderMath, TwoParameterAndFlagFormsOfGr)
{
    Turtle t;
    CylinderBuilder::set_radius_tangents(t, std::vector<float>{90, 2});
    EXPECT_NEAR(t.cylinder.radius_tangent[0][0], 0, 1e-6);
    EXPECT_NEAR(t.cylinder.radius_tangent[0][1], 2, 1e-6);
    EXPECT_NEAR(t.cylinder.radius_tangent[1][1], 2, 1e-6);  // the second equals the first
    EXPECT_FALSE(t.cylinder.scale_radius_tangents);
    CylinderBuilder::set_radius_tangents(t, std::vector<float>{1});
    EXPECT_TRUE(t.cylinder.scale_radius_tangents);
    // Scaling stretches the radius component by the segment length.
    RadiusProfile p = RadiusProfile::make(1, 1, {1, 0.5}, {1, 0.5}, true, 4);
    EXPECT_NEAR(p.t0[1], 2, 1e-12);
    EXPECT_NEAR(p.t1[1], 2, 1e-12);
    // A zero tangent means the linear one (1, r1 - r0).
    RadiusProfile q = RadiusProfile::make(1, 0.5, {0, 0}, {1, 2}, false, 1);
    EXPECT_NEAR(q.t0[0], 1, 1e-12);
    EXPECT_NEAR(q.t0[1], -0.5, 1e-12);
}

TEST(GeneralizedCylinderMath, RotationMinimisingFrameOnAPlanarArcDoesNotTwist)
{
    // A quarter circle in the x-y plane with up = +z: the frame keeps up = +z.
    Vec3 up{0, 0, 1};
    const int n = 64;
    for (int i = 1; i <= n; ++i) {
        double a0 = (i - 1) * std::numbers::pi / 2 / n, a1 = i * std::numbers::pi / 2 / n;
        Vec3 x0{std::cos(a0), std::sin(a0), 0}, x1{std::cos(a1), std::sin(a1), 0};
        Vec3 t0{-std::sin(a0), std::cos(a0), 0}, t1{-std::sin(a1), std::cos(a1), 0};
        up = rmf_step(x0, t0, up, x1, t1);
        EXPECT_NEAR(up.z, 1, 1e-12);
    }
}

TEST(GeneralizedCylinderMath, RotationMinimisingFrameOnAHelixIsContinuousAndOrthonormal)
{
    auto point = [](double a) { return Vec3{std::cos(a), std::sin(a), 0.3 * a}; };
    auto tangent = [](double a) { return normalize(Vec3{-std::sin(a), std::cos(a), 0.3}); };
    Vec3 up = normalize(cross(tangent(0), Vec3{0, 0, 1}));
    const int n = 200;
    const double step = 4 * std::numbers::pi / n;
    for (int i = 1; i <= n; ++i) {
        Vec3 next = rmf_step(point((i - 1) * step), tangent((i - 1) * step), up, point(i * step), tangent(i * step));
        EXPECT_NEAR(length(next), 1, 1e-9);
        EXPECT_NEAR(dot(next, tangent(i * step)), 0, 1e-9);
        // Consecutive frames turn by no more than the tangent does (~0.06 rad here).
        EXPECT_LT(std::acos(std::clamp(dot(next, up), -1.0, 1.0)), 0.1);
        up = next;
    }
}

TEST(GeneralizedCylinder, StraightCylinderKeysAreHandValues)
{
    // Width 2 at the start, 1 at the end, length 3, straight up (+y).
    Scene scene = run("!(2) @Gs F(3) !(1) @Ge(5)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 1u);  // a linear radius profile is one exact segment
    ASSERT_EQ(c.points.size(), 2u);
    expect_key(c.points[0], 0, 0, 0, 1);
    expect_key(c.points[1], 0, 3, 0, 0.5);
    // Tangents: heading x distance x 1.2; radius derivative r1 - r0.
    expect_key(c.tangents[0], 0, 3.6, 0, -0.5);
    expect_key(c.tangents[1], 0, 3.6, 0, -0.5);
    EXPECT_EQ(c.segments[0], 0u);
    EXPECT_EQ(c.flags[0], 0);
    EXPECT_TRUE(scene.geometry.mesh.positions.empty());
}

TEST(GeneralizedCylinder, ControlPointsMakeSegmentsThatShareEqualKeys)
{
    // @Gs does not make F a control point; three equal straight pieces have equal
    // tangents at the joints, so the keys are shared and the neighbour flags set.
    Scene scene = run("@Gs F @Gc F @Gc F @Ge");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 3u);
    EXPECT_EQ(c.points.size(), 4u);
    EXPECT_EQ(c.flags[0], CurveFlags::neighbour_right);
    EXPECT_EQ(c.flags[1], CurveFlags::neighbour_left | CurveFlags::neighbour_right);
    EXPECT_EQ(c.flags[2], CurveFlags::neighbour_left);
    expect_key(c.points[3], 0, 3, 0, 0.5);
    EXPECT_EQ(scene.geometry.lines.segment_count(), 3u);  // F still draws its line
}

TEST(GeneralizedCylinder, DifferentTangentsDoNotShareKeys)
{
    Scene scene = run("@Gs f(1) @Gc f(2) @Ge");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 2u);
    EXPECT_EQ(c.points.size(), 4u);
    EXPECT_EQ(c.flags[0], 0);
    EXPECT_EQ(c.flags[1], 0);
    expect_key(c.tangents[1], 0, 1.2, 0, 0);
    expect_key(c.tangents[2], 0, 2.4, 0, 0);
}

TEST(GeneralizedCylinder, BranchesConnectToTheActiveControlPoint)
{
    Scene scene = run("@Gs f(1) @Gc [ +(90) f(1) @Ge ] -(90) f(1) @Ge");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 3u);
    for (std::size_t s = 1; s < 3; ++s)
        expect_key(c.points[c.segments[s]], 0, 1, 0, c.points[c.segments[s]][3]);
    // The branch ends to the left (-x), the main axis to the right (+x).
    expect_key(c.points[c.segments[1] + 1], -1, 1, 0, 0.5);
    expect_key(c.points[c.segments[2] + 1], 1, 1, 0, 0.5);
}

TEST(GeneralizedCylinder, TangentCoefficientsArriveAndLeave)
{
    // @Gt(a, b) before the second point: a scales the tangent arriving there; the tangent
    // leaving the first point keeps that point's coefficient (1.2).
    Scene arriving = run("@Gs f(2) @Gt(2,3) @Ge");
    expect_key(arriving.geometry.curves.tangents[0], 0, 2.4, 0, 0);
    expect_key(arriving.geometry.curves.tangents[1], 0, 4, 0, 0);
    // Before the first point, b scales the leaving tangent.
    Scene leaving = run("@Gt(1,3) @Gs f(2) @Ge");
    expect_key(leaving.geometry.curves.tangents[0], 0, 6, 0, 0);
    expect_key(leaving.geometry.curves.tangents[1], 0, 2, 0, 0);
}

TEST(GeneralizedCylinder, RadiusProfileGivesOneSegmentPerStrip)
{
    Scene scene = run("!(0.4) @Gs f(1) !(0.2) @Gr(10,1.5,-20,1) @Ge(4)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 4u);
    // Leaving the first point: linear (1, -0.1) (its @Gr was unset); arriving: @Gr's
    // first tangent, 1.5 (cos 10, sin 10).
    double t0u = 1, t0r = -0.1, t1u = 1.5 * std::cos(10 * std::numbers::pi / 180),
           t1r = 1.5 * std::sin(10 * std::numbers::pi / 180);
    double u = scalar_hermite(0, 1, t0u, t1u, 0.5);
    double r = scalar_hermite(0.2, 0.1, t0r, t1r, 0.5);
    double y = scalar_hermite(0, 1, 1.2, 1.2, u);  // the straight axis at u
    expect_key(c.points[c.segments[2]], 0, y, 0, r);
    expect_key(c.points[c.segments[3] + 1], 0, 1, 0, 0.1);
}

TEST(GeneralizedCylinder, BoundsHoldTheRingVertices)
{
    Scene scene = run("!(2) @Gs f(1) @Ge");
    EXPECT_NEAR(scene.bounds.lo.x, -1, 1e-6);
    EXPECT_NEAR(scene.bounds.hi.x, 1, 1e-6);
    EXPECT_NEAR(scene.bounds.lo.z, -1, 1e-6);
    EXPECT_NEAR(scene.bounds.hi.z, 1, 1e-6);
    EXPECT_NEAR(scene.bounds.hi.y, 1, 1e-6);
}

TEST(GeneralizedCylinder, PixelLinesDrawTheAxisAsLines)
{
    Scene scene = run("@Gs f(1) @Ge(4)", "line style: pixel\n");
    EXPECT_EQ(scene.geometry.curves.segment_count(), 0u);
    EXPECT_EQ(scene.geometry.lines.segment_count(), 4u);
}

TEST(GeneralizedCylinder, BraceCurvesTakeControlPointsFromMoves)
{
    // {(1) starts an open Hermite axis; each f after it is a control point.
    Scene scene = run("{(1) f(1) f(1) }(1)");
    EXPECT_EQ(scene.geometry.curves.segment_count(), 1u);
    expect_key(scene.geometry.curves.points.back(), 0, 2, 0, 0.5);
}

TEST(GeneralizedCylinder, SquareContourSweepsAMesh)
{
    Scene scene = run("!(2) @#(1) @Gs f(2) @Ge(3)", square_contour_view());
    const TriangleMesh& m = scene.geometry.mesh;
    EXPECT_EQ(scene.geometry.curves.segment_count(), 0u);
    ASSERT_EQ(m.positions.size(), 4u * 9u);  // 4 rings of 8 sides plus the seam
    EXPECT_EQ(m.size(), 3u * 8u * 2u);
    EXPECT_EQ(m.normals.size(), m.positions.size());
    EXPECT_EQ(m.uvs.size(), m.positions.size());
    // The first vertex lies along U = (0, 0, -1) at sqrt 2 times the radius 1.
    EXPECT_NEAR(m.positions[0][0], 0, 1e-5);
    EXPECT_NEAR(m.positions[0][2], -std::sqrt(2.0), 1e-5);
    for (const Float3& n : m.normals)
        EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1, 1e-5);
    // Faces point away from the axis (x = z = 0).
    for (const auto& t : m.triangles) {
        Vec3 a{m.positions[t[0]][0], m.positions[t[0]][1], m.positions[t[0]][2]};
        Vec3 b{m.positions[t[1]][0], m.positions[t[1]][1], m.positions[t[1]][2]};
        Vec3 c{m.positions[t[2]][0], m.positions[t[2]][1], m.positions[t[2]][2]};
        Vec3 centre = (a + b + c) / 3.0;
        Vec3 outward{centre.x, 0, centre.z};
        EXPECT_GT(dot(cross(b - a, c - a), outward), 0);
    }
    EXPECT_NEAR(scene.bounds.lo.z, -std::sqrt(2.0), 1e-5);
}

TEST(GeneralizedCylinder, ConsecutiveMeshSegmentsShareTheirRing)
{
    Scene scene = run("@#(1) @Gs f(1) @Gc(2) f(1) @Ge(2)", square_contour_view());
    EXPECT_EQ(scene.geometry.mesh.positions.size(), 5u * 9u);  // 3 + 3 rings, one shared
}

// cpfg (strip_to_mesh): the first strip of a control-point pair is in the start point's
// colour, the others in the end point's; `render mode: interpolated` blends the first.
TEST(GeneralizedCylinderColour, ColourChangeCutsTheSegmentAtTheFirstRing)
{
    Scene scene = run(";(1) @Gs f(1) ;(3) @Gc f(1) ;(5) @Ge");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 4u);  // each pair: its first strip, then the other three
    EXPECT_EQ(c.material, (std::vector<std::uint16_t>{1, 3, 3, 5}));
    EXPECT_TRUE(c.end_material.empty());  // flat colours
    // The cut is on the same cubic: y(s) of the straight axis with tangents 1.2, and the
    // tangents scaled by each piece's share of the parameter (1/4 and 3/4).
    double y = scalar_hermite(0, 1, 1.2, 1.2, 0.25);
    double dy = 6 * 0.25 * (1 - 0.25) + 1.2 * (3 * 0.0625 - 4 * 0.25 + 1) + 1.2 * (3 * 0.0625 - 2 * 0.25);
    expect_key(c.points[c.segments[0]], 0, 0, 0, 0.5);
    expect_key(c.tangents[c.segments[0]], 0, 1.2 * 0.25, 0, 0);
    expect_key(c.points[c.segments[0] + 1], 0, y, 0, 0.5);
    expect_key(c.tangents[c.segments[0] + 1], 0, dy * 0.25, 0, 0);
    expect_key(c.points[c.segments[1]], 0, y, 0, 0.5);
    expect_key(c.tangents[c.segments[1]], 0, dy * 0.75, 0, 0);
    expect_key(c.points[c.segments[1] + 1], 0, 1, 0, 0.5);
    expect_key(c.tangents[c.segments[1] + 1], 0, 1.2 * 0.75, 0, 0);
}

TEST(GeneralizedCylinderColour, InterpolatedRenderModeBlendsTheFirstStrip)
{
    Scene scene = run(";(1) @Gs f(1) ;(3) @Gc f(1) ;(5) @Ge",
                      "line style: cylinder\nrender mode: interpolated\n");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 4u);
    EXPECT_EQ(c.material, (std::vector<std::uint16_t>{1, 3, 3, 5}));
    EXPECT_EQ(c.end_material, (std::vector<std::uint16_t>{3, 3, 5, 5}));
}

TEST(GeneralizedCylinderColour, OneStripIsOneSegment)
{
    Scene flat = run(";(1) @Gs f(1) ;(3) @Ge(1)");
    EXPECT_EQ(flat.geometry.curves.material, (std::vector<std::uint16_t>{1}));
    EXPECT_TRUE(flat.geometry.curves.end_material.empty());
    Scene blended = run(";(1) @Gs f(1) ;(3) @Ge(1)", "line style: cylinder\nrender mode: interpolated\n");
    EXPECT_EQ(blended.geometry.curves.material, (std::vector<std::uint16_t>{1}));
    EXPECT_EQ(blended.geometry.curves.end_material, (std::vector<std::uint16_t>{3}));
}

TEST(GeneralizedCylinderColour, OneColourIsOneSegmentPerPairWithoutEndMaterials)
{
    Scene scene = run(";(2) @Gs f(1) @Gc f(1) @Ge");
    EXPECT_EQ(scene.geometry.curves.segment_count(), 2u);
    EXPECT_TRUE(scene.geometry.curves.end_material.empty());
}

TEST(GeneralizedCylinderColour, FirstBlendedSegmentPadsEarlierOnes)
{
    Scene scene = run(";(2) @Gs f(1) @Gc f(2) ;(4) @Ge(1)", "line style: cylinder\nrender mode: interpolated\n");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 2u);
    EXPECT_EQ(c.end_material, (std::vector<std::uint16_t>{2, 4}));
}

TEST(GeneralizedCylinderColour, RadiusProfilePiecesAfterTheFirstTakeTheEndColour)
{
    Scene scene = run("!(0.4) ;(2) @Gs f(1) !(0.2) ;(6) @Gr(10,1.5,-20,1) @Ge(4)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 4u);
    EXPECT_EQ(c.material, (std::vector<std::uint16_t>{2, 6, 6, 6}));
    EXPECT_EQ(c.points.size(), 5u);  // equal spans share their keys
}

TEST(GeneralizedCylinderColour, MeshStripsAfterTheFirstTakeTheEndColour)
{
    Scene scene = run(";(2) @#(1) @Gs f(2) ;(7) @Ge(4)", square_contour_view());
    const TriangleMesh& m = scene.geometry.mesh;
    ASSERT_EQ(m.size(), 4u * 8u * 2u);  // 4 strips of 8 sides, two triangles each
    for (std::size_t t = 0; t < m.size(); ++t)
        EXPECT_EQ(m.material[t], t < 8u * 2u ? 2 : 7) << "triangle " << t;
}

TEST(GeneralizedCylinderColour, AxisLinesAfterTheFirstTakeTheEndColour)
{
    Scene scene = run(";(2) @Gs f(1) ;(7) @Ge(4)", "line style: pixel\n");
    EXPECT_EQ(scene.geometry.lines.material, (std::vector<std::uint16_t>{2, 7, 7, 7}));
}

TEST(GeneralizedCylinder, TwistIsMinimisedUnlessAskedFor)
{
    // A roll of 90 degrees between the points: U turns from (0,0,-1) to (1,0,0).
    Scene minimised = run("@#(1) @Gs f(1) /(90) @Ge(2)", square_contour_view());
    const TriangleMesh& a = minimised.geometry.mesh;
    std::size_t last_ring = 2 * 9;
    EXPECT_NEAR(a.positions[last_ring][0], 0, 1e-5);
    EXPECT_NEAR(a.positions[last_ring][2], -std::sqrt(2.0) / 2, 1e-5);  // radius 0.5

    Scene twisted = run("@#(1) @Gs f(1) /(90) @Ge(2)", square_contour_view("twist of cylinders: on\n"));
    const TriangleMesh& b = twisted.geometry.mesh;
    EXPECT_NEAR(b.positions[last_ring][0], std::sqrt(2.0) / 2, 1e-5);
    EXPECT_NEAR(b.positions[last_ring][2], 0, 1e-5);
    // Halfway the twist is half done: 45 degrees from U toward the new U.
    std::size_t middle = 9;
    EXPECT_NEAR(b.positions[middle][0], b.positions[middle][2] * -1, 1e-5);
}

TEST(GeneralizedCylinderMath, BsplineSegmentAsHermiteIsTheSameCubic)
{
    // The uniform cubic B-spline at u = 1/2 weighs its points (1, 23, 23, 1) / 48; u = 1/4
    // is checked against the basis polynomials.
    Vec3 p0{0, 0, 0}, p1{1, 2, -1}, p2{3, 2, 4}, p3{4, -1, 2};
    std::array<Vec3, 4> h = bspline_as_hermite(p0, p1, p2, p3);
    Vec3 mid = hermite(h[0], h[1], h[2], h[3], 0.5);
    Vec3 expected = (p0 + p1 * 23 + p2 * 23 + p3) / 48.0;
    EXPECT_NEAR(length(mid - expected), 0, 1e-12);
    double u = 0.25, v = 1 - u;
    Vec3 quarter = (p0 * (v * v * v) + p1 * (3 * u * u * u - 6 * u * u + 4) +
                    p2 * (-3 * u * u * u + 3 * u * u + 3 * u + 1) + p3 * (u * u * u)) / 6.0;
    EXPECT_NEAR(length(hermite(h[0], h[1], h[2], h[3], u) - quarter), 0, 1e-12);
}

TEST(GeneralizedCylinder, BsplineAxisStartsAtTheSixthWeightsOfItsControlPoints)
{
    // Control points P0..P3 = (0,1), (-1,1), (-1,0), (0,0) (f and left turns); the one
    // segment runs from (P0 + 4 P1 + P2) / 6 to (P1 + 4 P2 + P3) / 6 with tangents
    // (P2 - P0) / 2 and (P3 - P1) / 2.
    Scene scene = run("{(3) f(1) +(90) f(1) +(90) f(1) +(90) f(1) }(3)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 1u);
    expect_key(c.points[0], -5.0 / 6, 5.0 / 6, 0, 0.5);
    expect_key(c.points[1], -5.0 / 6, 1.0 / 6, 0, 0.5);
    expect_key(c.tangents[0], -0.5, -0.5, 0, 0);
    expect_key(c.tangents[1], 0.5, -0.5, 0, 0);
}

TEST(GeneralizedCylinder, OpenBsplineDoesNotReachItsEndPoints)
{
    // Five points along +y at 1..5: two segments from y = 2 to 4 (n - 3 segments).
    Scene scene = run("{(3) f(1) f(1) f(1) f(1) f(1) }(3)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 2u);
    EXPECT_EQ(c.points.size(), 3u);  // equal tangents at the joint share the key
    expect_key(c.points[0], 0, 2, 0, 0.5);
    expect_key(c.points[1], 0, 3, 0, 0.5);
    expect_key(c.points[2], 0, 4, 0, 0.5);
    expect_key(c.tangents[0], 0, 1, 0, 0);
    // Three points draw nothing.
    EXPECT_EQ(run("{(3) f(1) f(1) f(1) }(3)").geometry.curves.segment_count(), 0u);
}

TEST(GeneralizedCylinder, BsplineSegmentsTakeTheMiddlePointsWidths)
{
    // Widths 1, 2, 3, 4 at P0..P3: the segment goes from P1's radius (1) to P2's (1.5).
    Scene scene = run("{(3) !(1) f(1) !(2) f(1) !(3) f(1) !(4) f(1) }(3)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 1u);
    expect_key(c.points[0], 0, 2, 0, 1);
    expect_key(c.points[1], 0, 3, 0, 1.5);
}

TEST(GeneralizedCylinder, ClosedBsplineAddsItsFirstThreePoints)
{
    // The square's four corners: four segments, the last ending where the first starts.
    Scene scene = run("{(4) f(1) +(90) f(1) +(90) f(1) +(90) f(1) }(4)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 4u);
    expect_key(c.points[c.segments[0]], -5.0 / 6, 5.0 / 6, 0, 0.5);
    expect_key(c.points[c.segments[3] + 1], -5.0 / 6, 5.0 / 6, 0, 0.5);
    // The second segment starts where the first ends.
    expect_key(c.points[c.segments[1]], -5.0 / 6, 1.0 / 6, 0, 0.5);
}

TEST(GeneralizedCylinder, BsplineBranchesCopyTheirControlPoints)
{
    // A branch after the third point continues the same axis; the main axis goes on
    // without the branch's points.
    Scene scene = run("{(3) f(1) f(1) f(1) [ +(90) f(1) ] f(1) }(3)");
    const HermiteCurves& c = scene.geometry.curves;
    ASSERT_EQ(c.segment_count(), 2u);
    // Both start at (P0 + 4 P1 + P2) / 6 = (0, 2, 0).
    expect_key(c.points[c.segments[0]], 0, 2, 0, 0.5);
    expect_key(c.points[c.segments[1]], 0, 2, 0, 0.5);
    // The branch ends at (P1 + 4 P2 + (-1, 3)) / 6, the main axis at y = 3.
    expect_key(c.points[c.segments[0] + 1], -1.0 / 6, 17.0 / 6, 0, 0.5);
    expect_key(c.points[c.segments[1] + 1], 0, 3, 0, 0.5);
}

TEST(GeneralizedCylinder, ContourGalleryItemsTakeConsecutiveIds)
{
    std::filesystem::path dir = temp_dir("gc_test");
    std::ofstream(dir / "shapes.cset") << "contourgalleryver 1 1\nitems: 2\n"
                                          "cver 1 1\nname: square\npoints: 4 4\ntype: closed\n"
                                          "1 1 0 1\n-1 1 0 1\n-1 -1 0 1\n1 -1 0 1\n"
                                          " cver 1 1\nname: large\npoints: 4 4\ntype: closed\n"
                                          "3 3 0 1\n-3 3 0 1\n-3 -3 0 1\n3 -3 0 1\n";
    ViewFile view = parse_view_file("line style: cylinder\ncontour: 5 shapes.cset\ncontour sides: 8\n",
                                    (dir / "g.v").string());
    view.path = dir / "g.v";
    CylinderSettings settings = cylinder_settings(view);
    ASSERT_EQ(settings.contours.size(), 2u);
    EXPECT_EQ(settings.contours.at(5).name, "square");
    EXPECT_EQ(settings.contours.at(6).name, "large");

    // @#(6) sweeps the large item. The rings' farthest vertices from the axis are the
    // spline's corners (P0 + 4 P1 + P2) / 6 (the first vertex lies on one): distance
    // sqrt(8) / 3 for the square item and three times that for the large one, at radius 1.
    auto farthest = [&](const char* modules) {
        lsys::SymbolTable symbols;
        Scene scene = interpret(text_modules(symbols, modules), symbols, view);
        double d = 0;
        for (const Float3& p : scene.geometry.mesh.positions)
            d = std::max(d, std::hypot(double(p[0]), double(p[2])));
        EXPECT_GT(scene.geometry.mesh.size(), 0u);
        return d;
    };
    EXPECT_NEAR(farthest("!(2) @#(5) @Gs f(1) @Ge(1)"), std::sqrt(8.0) / 3, 1e-5);
    EXPECT_NEAR(farthest("!(2) @#(6) @Gs f(1) @Ge(1)"), std::sqrt(8.0), 1e-5);
}

namespace {

/// Interprets a corpus model's homomorphism string (cpfg's own -h output) with its view
/// file and compares the bounds with cpfg's view volume (-vv).
void expect_corpus_bounds(const std::string& model, const std::string& view_name,
                          const std::string& string_name = "string.homo.str", bool meshes = true)
{
    const char* env = std::getenv("CAMBIUM_CORPUS");
    std::filesystem::path corpus = env ? env : CAMBIUM_CORPUS_DEFAULT;
    std::filesystem::path oracle = corpus / "oracle" / model;
    if (!std::filesystem::exists(oracle / "view.vv") || !std::filesystem::exists(oracle / string_name))
        GTEST_SKIP() << "corpus model not found: " << model;
    set_warnings_enabled(false);
    lsys::SymbolTable symbols;
    lsys::ModuleString s = lsys::read_string_text(oracle / string_name, symbols);
    ViewFile view = read_view_file(corpus / "cpfg" / model / view_name);
    Scene scene = interpret(s, symbols, view);
    set_warnings_enabled(true);
    if (meshes)
        EXPECT_GT(scene.geometry.mesh.size(), 0u) << model;  // the contours were swept
    else
        EXPECT_GT(scene.geometry.curves.segment_count(), 0u) << model;
    std::ifstream in(oracle / "view.vv");
    std::string line;
    std::getline(in, line);
    Bounds3 expected = parse_view_volume(line, "view.vv");
    Vec3 size = expected.extent();
    double tolerance = 1e-5 * std::max({size.x, size.y, size.z});  // cpfg prints 6 digits
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(scene.bounds.lo[i], expected.lo[i], tolerance) << model << " axis " << i;
        EXPECT_NEAR(scene.bounds.hi[i], expected.hi[i], tolerance) << model << " axis " << i;
    }
}

}  // namespace

TEST(GeneralizedCylinderCorpus, FernLeafBounds) { expect_corpus_bounds("10-manuals/15-VlabTools/FernLeaf", "plant.v"); }
TEST(GeneralizedCylinderCorpus, LilyLeafBounds) { expect_corpus_bounds("10-manuals/15-VlabTools/LilyLeaf", "plant.v"); }
TEST(GeneralizedCylinderCorpus, TropismsBounds) { expect_corpus_bounds("10-manuals/11-CPFG/Tropisms", "view.v"); }
TEST(GeneralizedCylinderCorpus, PaintbrushBounds)
{
    expect_corpus_bounds("11-CPFG/03-inverse-modeling/05-paintbrush.field", "plant.v");
}
TEST(GeneralizedCylinderCorpus, PallaeaBounds) { expect_corpus_bounds("11-CPFG/03-inverse-modeling/03-pallaea", "plant.v"); }
TEST(GeneralizedCylinderCorpus, FernLeaf2Bounds) { expect_corpus_bounds("11-CPFG/03-inverse-modeling/02-fern-leaf", "plant.v"); }
TEST(GeneralizedCylinderCorpus, HorneophytonBounds)
{
    // Circular contours only: HermiteCurves, bounds from the rings cpfg would draw.
    expect_corpus_bounds("10-manuals/11-CPFG/Horneophyton", "plant.v", "string.str", false);
}

TEST(GeneralizedCylinderCorpus, LilyLeafTrianglesAreCpfgs)
{
    // cpfg's rayshade export lists the generalized cylinder's triangles (an open leaf
    // contour, twist on, @Gr profile): the same count, and every vertex is one of ours.
    const char* env = std::getenv("CAMBIUM_CORPUS");
    std::filesystem::path corpus = env ? env : CAMBIUM_CORPUS_DEFAULT;
    std::string model = "10-manuals/15-VlabTools/LilyLeaf";
    std::filesystem::path oracle = corpus / "oracle" / model;
    if (!std::filesystem::exists(oracle / "scene.ray"))
        GTEST_SKIP() << "corpus model not found";
    set_warnings_enabled(false);
    lsys::SymbolTable symbols;
    lsys::ModuleString s = lsys::read_string_text(oracle / "string.homo.str", symbols);
    Scene scene = interpret(s, symbols, read_view_file(corpus / "cpfg" / model / "plant.v"));
    set_warnings_enabled(true);
    const TriangleMesh& m = scene.geometry.mesh;

    std::ifstream in(oracle / "scene.ray");
    std::string word;
    std::size_t triangles = 0, matched = 0, normals_agree = 0;
    while (in >> word) {
        if (word != "triangle")
            continue;
        ++triangles;
        for (int v = 0; v < 3; ++v) {
            double p[3], n[3];
            in >> p[0] >> p[1] >> p[2] >> n[0] >> n[1] >> n[2];
            for (std::size_t i = 0; i < m.positions.size(); ++i) {
                const Float3& q = m.positions[i];
                if (std::abs(q[0] - p[0]) < 2e-6 && std::abs(q[1] - p[1]) < 2e-6 && std::abs(q[2] - p[2]) < 2e-6) {
                    ++matched;
                    const Float3& o = m.normals[i];
                    if (o[0] * n[0] + o[1] * n[1] + o[2] * n[2] > 0.7)
                        ++normals_agree;
                    break;
                }
            }
        }
    }
    EXPECT_EQ(triangles, m.size());
    EXPECT_EQ(matched, 3 * triangles);
    // Smooth normals within 45 degrees of cpfg's (measured: all but the 6 at the tip).
    EXPECT_GE(normals_agree, matched * 99 / 100);
}

TEST(GencylHostileNumbers, ParametersNoIntHoldsAreIgnoredOrClampedWithAMessage)
{
    testing::internal::CaptureStderr();
    Scene scene = run("{(1e30) f @#(1e30) @#(nan) @!(nan) @Gs F @Ge(nan)");
    std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find("'{(1e+30)': the cylinder type must be 1 to 4; ignored"), std::string::npos) << err;
    EXPECT_NE(err.find("contour id 1e+30 is not defined in the view file; the circle is used"),
              std::string::npos)
        << err;
    // @Ge(nan) falls back to the default strips: one round cylinder piece
    EXPECT_EQ(scene.geometry.curves.segment_count(), 1u);
}

TEST(GencylHostileNumbers, ViewFileCountsBeyondTheirRangeAreErrors)
{
    try {
        parse_view_file("contour sides: 1e30\npolygonization level: -1e30\n", "t.v");
        FAIL() << "no error";
    } catch (const Error& e) {
        std::string err = e.what();
        EXPECT_NE(err.find("t.v:1:16: error: contour sides must be a whole number from 3 to 100000"),
                  std::string::npos)
            << err;
        EXPECT_NE(err.find("t.v:2:23: error: polygonization level must be a whole number from 1 to 16"),
                  std::string::npos)
            << err;
    }
}

TEST(GencylHostileNumbers, OversizedMeshSegmentsGetFewerStrips)
{
    // 10 000 strips of a 20 000-sided contour would be 2e8 vertices in one segment
    testing::internal::CaptureStderr();
    Scene scene = run("@#(1) @!(20000) @Gs f(1) @Ge(1e30)", square_contour_view());
    std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find("a generalized-cylinder segment of 10000 strips and 20000 sides is drawn with 48 strips "
                       "(at most 1000000 vertices a segment)"),
              std::string::npos)
        << err;
    EXPECT_LE(scene.geometry.mesh.positions.size(), 1'000'000u);
    EXPECT_GT(scene.geometry.mesh.positions.size(), 900'000u);
}
