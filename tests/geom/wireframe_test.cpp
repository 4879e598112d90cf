// SPDX-License-Identifier: Apache-2.0
// `render mode: wireframe`: every primitive replaced by the edges cpfg's window draws.
#include "geom/wireframe.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_util.h"

namespace cambium::geom {
namespace {

const std::string wireframe_view = "angle increment: 90\nrender mode: wireframe\n";

Vec3 key_point(const LinearCurves& l, std::size_t segment, int end)
{
    const Float4& k = l.keys[l.segments[segment] + static_cast<std::uint32_t>(end)];
    return {k[0], k[1], k[2]};
}

double edge_length(const LinearCurves& l, std::size_t segment)
{
    return length(key_point(l, segment, 1) - key_point(l, segment, 0));
}

// cpfg draws a polygon as one GL_POLYGON: its wireframe is the outline, without the
// diagonal its two triangles share here.
TEST(Wireframe, PolygonShowsItsOutlineNotItsDiagonal)
{
    Scene scene = interpret_text(";(5) { f + f + f + f }", wireframe_view);
    ASSERT_EQ(scene.geometry.mesh.size(), 2u);
    draw_as_wireframe(scene, {});
    const LinearCurves& l = scene.geometry.lines;
    ASSERT_EQ(l.segment_count(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_NEAR(edge_length(l, i), 1.0, 1e-6);  // a side, never the diagonal (1.41)
        EXPECT_EQ(l.material[i], 5);
        EXPECT_EQ(l.keys[l.segments[i]][3], 0.5f);  // 1 pixel wide
    }
    EXPECT_TRUE(scene.line_radius_in_pixels);
    EXPECT_EQ(scene.geometry.mesh.size(), 0u);  // the faces are not drawn
}

// The outline is marked only for wireframe views; unmarked, both triangles' edges are
// drawn (the shared diagonal once).
TEST(Wireframe, UnmarkedTrianglesShowEveryEdgeOnce)
{
    Scene scene = interpret_text("{ f + f + f + f }", "angle increment: 90\n");
    EXPECT_TRUE(scene.geometry.mesh.hidden_edges.empty());
    draw_as_wireframe(scene, {});
    EXPECT_EQ(scene.geometry.lines.segment_count(), 5u);
}

// Corners on a side (here the midpoints of a 2 x 2 square) may be skipped by the
// triangulation: an edge along them is still outline, and nothing crosses the inside.
TEST(Wireframe, OutlineThroughCollinearCornersStaysDrawn)
{
    Scene scene = interpret_text("{ f f + f f + f f + f f }", wireframe_view);
    draw_as_wireframe(scene, {});
    const LinearCurves& l = scene.geometry.lines;
    double total = 0;
    for (std::size_t i = 0; i < l.segment_count(); ++i) {
        total += edge_length(l, i);
        Vec3 mid = (key_point(l, i, 0) + key_point(l, i, 1)) * 0.5;
        // the square spans x in [-2, 0] or [0, 2] and y in [0, 2]; its outline has
        // x or y at a bound
        double x = std::fabs(mid.x), y = mid.y;
        bool on_outline = x < 1e-6 || std::fabs(x - 2) < 1e-6 || y < 1e-6 || std::fabs(y - 2) < 1e-6;
        EXPECT_TRUE(on_outline) << "edge " << i << " crosses the polygon at " << mid.x << ", " << mid.y;
    }
    EXPECT_NEAR(total, 8.0, 1e-6);
}

// A cylinder is cpfg's strip of `sides` quads: per side its lengthwise edge, its
// diagonal and a piece of each end ring; every corner on the cylinder's surface.
TEST(Wireframe, CylinderIsItsTriangleStrip)
{
    Scene scene = interpret_text("F(3)", "line style: cylinder\ninitial line width: 2\n" + wireframe_view);
    ASSERT_EQ(scene.geometry.lines.segment_count(), 1u);
    draw_as_wireframe(scene, {.edge_width_px = 1, .sides = 6});
    const LinearCurves& l = scene.geometry.lines;
    ASSERT_EQ(l.segment_count(), 24u);
    int lengthwise = 0, diagonal = 0;
    for (std::size_t i = 0; i < l.segment_count(); ++i) {
        for (int end : {0, 1}) {
            Vec3 p = key_point(l, i, end);
            EXPECT_NEAR(std::hypot(p.x, p.z), 1.0, 1e-5);  // radius = width / 2
        }
        double dy = std::fabs(key_point(l, i, 1).y - key_point(l, i, 0).y);
        double len = edge_length(l, i);
        lengthwise += std::fabs(dy - 3) < 1e-5 && std::fabs(len - 3) < 1e-5;
        diagonal += std::fabs(dy - 3) < 1e-5 && len > 3 + 1e-3;
    }
    EXPECT_EQ(lengthwise, 6);
    EXPECT_EQ(diagonal, 6);
}

// Spheres: with a material file gluSphere's meridians (8 x 5 pieces) and inner
// parallels (4 x 8); with a colormap the octahedron subdivided once (32 triangles).
// Discs: their rim.
TEST(Wireframe, SpheresAndDiscs)
{
    Scene scene = interpret_text("@O(4)", wireframe_view);
    Scene octahedron = scene;
    draw_as_wireframe(scene, {.edge_width_px = 1, .sides = 8, .quadric_spheres = true});
    EXPECT_EQ(scene.geometry.lines.segment_count(), 72u);
    draw_as_wireframe(octahedron, {.edge_width_px = 1, .sides = 8, .quadric_spheres = false});
    EXPECT_EQ(octahedron.geometry.lines.segment_count(), 96u);
    for (const Scene* s : {&scene, &octahedron})
        for (const Float4& k : s->geometry.lines.keys)
            EXPECT_NEAR(std::sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]), 2.0, 1e-5);

    Scene disc = interpret_text("@o(2)", wireframe_view);
    draw_as_wireframe(disc, {});
    const LinearCurves& l = disc.geometry.lines;
    ASSERT_EQ(l.segment_count(), 8u);
    for (std::size_t i = 0; i < 8; ++i)
        EXPECT_NEAR(edge_length(l, i), 2 * std::sin(std::numbers::pi / 8), 1e-5);  // a side of the octagon of radius 1
}

// Generalized cylinders are meshed in wireframe views so their strips show.
TEST(Wireframe, GeneralizedCylindersAreMeshed)
{
    Scene round = interpret_text("@Gs F @Ge", "line style: cylinder\n");
    EXPECT_GT(round.geometry.curves.segment_count(), 0u);
    Scene wire = interpret_text("@Gs F @Ge", "line style: cylinder\n" + wireframe_view);
    EXPECT_EQ(wire.geometry.curves.segment_count(), 0u);
    EXPECT_GT(wire.geometry.mesh.size(), 0u);
}

// Pixel lines keep their own width; the edges get cpfg's wireframe width.
TEST(Wireframe, PixelLinesKeepTheirWidth)
{
    Scene scene = interpret_text("F ;(3) { f + f + f }", "initial line width: 4 pixels\n" + wireframe_view);
    draw_as_wireframe(scene, {});
    const LinearCurves& l = scene.geometry.lines;
    ASSERT_EQ(l.segment_count(), 4u);
    EXPECT_EQ(l.keys[l.segments[0]][3], 2.0f);
    for (std::size_t i = 1; i < 4; ++i)
        EXPECT_EQ(l.keys[l.segments[i]][3], 0.5f);
}

// cpfg: glLineWidth(view volume x extent / window width / 10), at least one pixel.
TEST(Wireframe, EdgeWidthFollowsCpfgsFormula)
{
    Bounds3 b;
    b.extend(Vec3{0, 0, 0});
    b.extend(Vec3{100, 5, 0});
    EXPECT_EQ(wireframe_edge_width(b, 640), 1.0);
    b.extend(Vec3{19200, 0, 0});
    EXPECT_DOUBLE_EQ(wireframe_edge_width(b, 640), 3.0);
    EXPECT_EQ(wireframe_edge_width(Bounds3{}, 640), 1.0);
}

// A wireframe that would be too large is refused before anything is allocated.
TEST(Wireframe, TooManyEdgesIsAnError)
{
    Scene scene;
    for (int i = 0; i < 70; ++i) {  // 70 spheres of 1000 x 1001 edges each
        scene.geometry.spheres.centres.push_back({float(i), 0, 0, 1});
        scene.geometry.spheres.material.push_back(1);
    }
    EXPECT_THROW(draw_as_wireframe(scene, {.edge_width_px = 1, .sides = 1000, .quadric_spheres = true}), Error);
    EXPECT_EQ(scene.geometry.spheres.size(), 70u);
}

}  // namespace
}  // namespace cambium::geom
