// SPDX-License-Identifier: Apache-2.0
// Tests of the interpreted symbols beyond F/f/+/-: @M @R @v, scale, spheres and discs,
// polygons, textures, tropisms, sub-L-systems, labels, queries, and the bounds cpfg keeps.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "geom/interpreter.h"
#include "test_util.h"
#include "geom/query.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

Vec3 end_of_last_segment(const Scene& scene)
{
    const auto& k = scene.geometry.lines.keys.back();
    return {k[0], k[1], k[2]};
}

void expect_vec(const Vec3& a, const Vec3& b, double tol = 1e-5)
{
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

double mesh_area(const TriangleMesh& mesh)
{
    double total = 0;
    for (const auto& t : mesh.triangles) {
        auto p = [&](int i) {
            const auto& q = mesh.positions[t[static_cast<std::size_t>(i)]];
            return Vec3{q[0], q[1], q[2]};
        };
        total += 0.5 * length(cross(p(1) - p(0), p(2) - p(0)));
    }
    return total;
}

}  // namespace

TEST(TurtleFeatures, MoveToSetsThePositionAndExtendsTheBounds)
{
    Scene scene = interpret_text("F @M(3,4,5) F");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 2u);
    expect_vec(end_of_last_segment(scene), {3, 5, 5});
    EXPECT_EQ(scene.geometry.lines.flags[1], 0);  // a new polyline
    EXPECT_DOUBLE_EQ(scene.bounds.hi.z, 5);
    Scene two = interpret_text("@M(1,2) F");
    expect_vec(end_of_last_segment(two), {1, 3, 0});
}

TEST(TurtleFeatures, SetHeadingDrawsAlongTheGivenVector)
{
    Scene scene = interpret_text("@R(0,0,3) F(2)");
    expect_vec(end_of_last_segment(scene), {0, 0, 2});
}

TEST(TurtleFeatures, ScaleCommandsScaleSteps)
{
    // @D(2): step 2; @Di with `scale multiplier: 3`: 6; @Dd(4): 1.5
    Scene scene = interpret_text("@D(2) F @Di F @Dd(4) F", "scale multiplier: 3\n");
    expect_vec(end_of_last_segment(scene), {0, 9.5, 0});
    Scene initial = interpret_text("F", "initial scale: 0.25\n");
    expect_vec(end_of_last_segment(initial), {0, 0.25, 0});
}

TEST(TurtleFeatures, SphereDiameterAndBounds)
{
    Scene scene = interpret_text("f(2) @D(0.5) @O(4)");
    ASSERT_EQ(scene.geometry.spheres.size(), 1u);
    const auto& c = scene.geometry.spheres.centres[0];
    EXPECT_FLOAT_EQ(c[1], 2);
    EXPECT_FLOAT_EQ(c[3], 1);  // diameter 4 * scale 0.5
    // cpfg's view volume: the cube around the sphere
    EXPECT_DOUBLE_EQ(scene.bounds.hi.y, 3);
    EXPECT_DOUBLE_EQ(scene.bounds.lo.x, -1);
    EXPECT_DOUBLE_EQ(scene.bounds.hi.z, 1);
}

TEST(TurtleFeatures, SphereDefaultsToTheLineWidth)
{
    Scene scene = interpret_text(";(7) @O", "initial line width: 3\n");
    ASSERT_EQ(scene.geometry.spheres.size(), 1u);
    EXPECT_FLOAT_EQ(scene.geometry.spheres.centres[0][3], 1.5f);
    EXPECT_EQ(scene.geometry.spheres.material[0], 7);
    Scene negative = interpret_text("@O(-2)");
    EXPECT_FLOAT_EQ(negative.geometry.spheres.centres[0][3], 1);
}

TEST(TurtleFeatures, ScreenDiscFacesTheViewer)
{
    Scene scene = interpret_text("@M(0,0,4) @o(2)", "viewpoint: 3,0,0\nview reference point: 1,0,0\n");
    ASSERT_EQ(scene.geometry.discs.size(), 1u);
    const auto& n = scene.geometry.discs.normals[0];
    EXPECT_FLOAT_EQ(n[0], 1);
    EXPECT_FLOAT_EQ(scene.geometry.discs.centres[0][3], 1);
    // cpfg's view volume puts @o's corners at z = 0
    EXPECT_DOUBLE_EQ(scene.bounds.lo.x, -1);
    EXPECT_DOUBLE_EQ(scene.bounds.hi.z, 4);  // from @M, not from the disc
}

TEST(TurtleFeatures, HLDiscFacesUpWithFrontAndBackMaterials)
{
    Scene scene = interpret_text(";(3) @;(9) & @c(1)", "angle increment: 90\ninitial color: 1 1\n");
    ASSERT_EQ(scene.geometry.discs.size(), 1u);
    const auto& n = scene.geometry.discs.normals[0];  // & by 90: H = -z, U = -y
    EXPECT_NEAR(n[1], -1, 1e-6);
    EXPECT_EQ(scene.geometry.discs.material[0], 3);
    EXPECT_EQ(scene.geometry.discs.back_material[0], 9);
}

TEST(TurtleFeatures, BackColourIncrementsWrap)
{
    Scene scene = interpret_text("@,(0) @, @c", "initial color: 1 1\ncolor increment: 1 5\n");
    EXPECT_EQ(scene.geometry.discs.back_material[0], 251);
}

TEST(TurtleFeatures, BackFollowsFrontUnlessInitialColorGivesTwoIndices)
{
    // Manual 5.1.9: sides differ only when `initial color:` has two parameters.
    Scene one = interpret_text(";(3) @;(9) @c(1)", "initial color: 1\n");
    EXPECT_EQ(one.geometry.discs.material[0], 3);
    EXPECT_EQ(one.geometry.discs.back_material[0], 3);
    Scene two = interpret_text(";(3) @;(9) @c(1)", "initial color: 1 2\n");
    EXPECT_EQ(two.geometry.discs.back_material[0], 9);
}

TEST(TurtleFeatures, PolygonFromFAndDotVertices)
{
    // f adds its end as a vertex; the start is not a vertex (cpfg's interpret.c)
    Scene scene = interpret_text(";(5) { f + f + f + f }", "angle increment: 90\n");
    EXPECT_EQ(scene.geometry.mesh.size(), 2u);
    EXPECT_NEAR(mesh_area(scene.geometry.mesh), 1, 1e-6);
    EXPECT_EQ(scene.geometry.mesh.material[0], 5);
    // the first vertex's colour, as cpfg's rayshade output takes it
    Scene later = interpret_text(";(5) { f ;(6) + f + f + f }", "angle increment: 90\n");
    EXPECT_EQ(later.geometry.mesh.material[0], 5);
    Scene three = interpret_text("{ f + f + f }", "angle increment: 90\n");
    EXPECT_NEAR(mesh_area(three.geometry.mesh), 0.5, 1e-6);
    Scene dots = interpret_text("{ . g . + g . + g . }", "angle increment: 90\n");
    EXPECT_NEAR(mesh_area(dots.geometry.mesh), 1, 1e-6);
}

TEST(TurtleFeatures, GMovesAddNoPolygonVertex)
{
    // vertices (0,1), (-1,0), (0,0): G's end (-1,1) is skipped
    Scene scene = interpret_text("{ f + G + f + f }", "angle increment: 90\n");
    EXPECT_NEAR(mesh_area(scene.geometry.mesh), 0.5, 1e-6);
}

TEST(TurtleFeatures, NestedPolygonsAcrossBranches)
{
    Scene scene = interpret_text("{ f [ { f + f + f } ] + f + f }", "angle increment: 90\n");
    const TriangleMesh& mesh = scene.geometry.mesh;
    ASSERT_EQ(mesh.size(), 2u);
    // the inner polygon is drawn first, above y = 1; the outer one below
    for (int i = 0; i < 3; ++i)
        EXPECT_GE(mesh.positions[mesh.triangles[0][static_cast<std::size_t>(i)]][1], 1 - 1e-6);
    for (int i = 0; i < 3; ++i)
        EXPECT_LE(mesh.positions[mesh.triangles[1][static_cast<std::size_t>(i)]][1], 1 + 1e-6);
    EXPECT_NEAR(mesh_area(mesh), 1, 1e-6);
}

TEST(TurtleFeatures, ConcavePolygonFromTheTurtle)
{
    // an L of area 3 traced with f moves and turns
    Scene scene = interpret_text("{ f(2) + f + f - f + f + f(2) }", "angle increment: 90\n");
    EXPECT_NEAR(mesh_area(scene.geometry.mesh), 3, 1e-5);
}

TEST(TurtleFeatures, PolygonTextureCoordinatesFromTheFirstVertex)
{
    // first vertex (0,1) with H = +y, R = -L = +x: u over x in [-1,0], v over y in [0,1]
    Scene scene = interpret_text("@Tx(1) { f + f + f + f }", "angle increment: 90\ntexture: F: a.png\n");
    const TriangleMesh& mesh = scene.geometry.mesh;
    ASSERT_EQ(mesh.positions.size(), 4u);
    EXPECT_NEAR(mesh.uvs[0][0], 1, 1e-6);  // (0,1)
    EXPECT_NEAR(mesh.uvs[0][1], 1, 1e-6);
    EXPECT_NEAR(mesh.uvs[1][0], 0, 1e-6);  // (-1,1)
    EXPECT_NEAR(mesh.uvs[2][1], 0, 1e-6);  // (-1,0)
    EXPECT_EQ(mesh.texture[0], 0);
}

TEST(TurtleFeatures, TextureVAlongCylindersContinues)
{
    // v grows by length / (pi width R): 3 / (2 pi 2), twice
    Scene scene = interpret_text("@Tx(1) F(3) F(3) @Tx(0) F", "initial line width: 2\ntexture: F: Bark.PNG R: 2\n");
    const LinearCurves& lines = scene.geometry.lines;
    ASSERT_EQ(lines.v.size(), lines.keys.size());
    double dv = 3 / (std::numbers::pi * 2 * 2);
    EXPECT_FLOAT_EQ(lines.v[lines.segments[0]], 0);
    EXPECT_NEAR(lines.v[lines.segments[1]], dv, 1e-6);
    EXPECT_NEAR(lines.v[lines.segments[1] + 1], 2 * dv, 1e-6);
    EXPECT_EQ(lines.texture[0], 0);
    EXPECT_EQ(lines.texture[2], no_texture);
    ASSERT_EQ(scene.textures.size(), 1u);
    EXPECT_EQ(scene.textures[0].file, "Bark.PNG");
}

TEST(TurtleFeatures, TropismBendsSegments)
{
    Scene scene = interpret_text("F", "tropism: T: 1 0 0 E: 0.5\n");
    expect_vec(end_of_last_segment(scene), {std::sin(0.5), std::cos(0.5), 0});
}

TEST(TurtleFeatures, ElasticityCommandsAndTheirScope)
{
    const char* view = "tropism: T: 1 0 0 E: 0 S: 0.25\n";
    expect_vec(end_of_last_segment(interpret_text("@Ts(1,0.5) F", view)), {std::sin(0.5), std::cos(0.5), 0});
    expect_vec(end_of_last_segment(interpret_text("@Ti(1) @Ti(1) F", view)), {std::sin(0.5), std::cos(0.5), 0});
    expect_vec(end_of_last_segment(interpret_text("@Ti(1,1) @Td(1) @Td(1,0.25) F", view)),
               {std::sin(0.5), std::cos(0.5), 0});
    // the elasticity is part of the turtle: ] restores it
    expect_vec(end_of_last_segment(interpret_text("[ @Ts(1,0.5) ] F", view)), {0, 1, 0});
}

TEST(TurtleFeatures, LegacyTropismBendsAfterEachMove)
{
    // T = (0,0,-1) = U at the start: after the first F, H pitches by asin(0.5) = 30 deg
    Scene scene = interpret_text("F F", "tropism direction: 0,0,-1\ninitial elasticity: 0.5\n");
    double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
    expect_vec(end_of_last_segment(scene), {0, 1 + c, -s});
}

TEST(TurtleFeatures, SubLsystemScalesItsPart)
{
    Scene scene = interpret_text("F ?(1,0.5) F $ F");
    expect_vec(end_of_last_segment(scene), {0, 2.5, 0});
}

TEST(TurtleFeatures, LabelsTakeTheirStringAndValues)
{
    Scene scene = interpret_text("F @L(1,2.5)", "", {"unused", "a=%g!"});
    ASSERT_EQ(scene.labels.size(), 1u);
    EXPECT_EQ(scene.labels[0].text, "a=2.5!");
    EXPECT_DOUBLE_EQ(scene.labels[0].position.y, 1);
    // conversions it cannot fill safely are copied as text
    Scene odd = interpret_text("@L(0,3,4)", "", {"%s and %5.1f%% %d"});
    EXPECT_EQ(odd.labels[0].text, "%s and   3.0% 4");
    // widths and precisions of more than 2 digits (the L-system printf's rule) too:
    // %999999999d would pad the label with a billion spaces
    Scene wide = interpret_text("@L(0,7,8,9)", "", {"%999999999d|%.123f|%99.99f"});
    EXPECT_EQ(wide.labels[0].text, "%999999999d|%.123f|7." + std::string(99, '0'));
}

TEST(TurtleFeatures, SystemCallsAndRayshadeModulesAreIgnored)
{
    Scene scene = interpret_text("@S(0) @I(0,2) @J(20,20,20) F");
    EXPECT_EQ(scene.geometry.lines.segment_count(), 1u);
}

TEST(TurtleFeatures, QueriesReceiveTheTurtleState)
{
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, "F + ?P(0,0,0) f ?H(0,0) ?L(9,9,9) ?U(0,0,0,7) X(5)");
    answer_queries(s, symbols, parse_view_file("angle increment: 90\n", "t.v"));
    std::vector<std::vector<float>> params;
    s.for_each([&](lsys::ModuleRef m) { params.emplace_back(m.params.begin(), m.params.end()); });
    ASSERT_EQ(params.size(), 8u);
    auto expect = [&](std::size_t i, std::vector<float> want) {
        ASSERT_EQ(params[i].size(), want.size()) << i;
        for (std::size_t k = 0; k < want.size(); ++k)
            EXPECT_NEAR(params[i][k], want[k], 1e-6) << i << "," << k;
    };
    expect(2, {0, 1, 0});       // ?P after F
    expect(4, {-1, 0});         // ?H after + (two parameters: x, y)
    expect(5, {0, -1, 0});      // ?L
    expect(6, {0, 0, -1, 7});   // ?U: the fourth parameter is left alone
    EXPECT_EQ(lsys::to_text(s, symbols).substr(0, 2), "F+");
    s.for_each([&](lsys::ModuleRef m) {
        if (symbols.name(m.symbol) == "X") {
            EXPECT_EQ(m.params[0], 5);
        }
    });
}
