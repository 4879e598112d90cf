// SPDX-License-Identifier: Apache-2.0
// The window's projection as vector shapes (render/vector_drawing.h): where a known scene's
// triangles land, computed here from the camera's definition, and that they are painted
// far to near whatever their order in the scene.
#include <gtest/gtest.h>

#include "render/camera.h"
#include "render/vector_drawing.h"

namespace cambium::render {
namespace {

/// Two triangles of different colours, the near one (z = 0) given before the far one
/// (z = -2), as a string order that a painter without sorting would get wrong.
geom::TriangleMesh near_then_far()
{
    geom::TriangleMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, -1, -2}, {1, -1, -2}, {0, 1, -2}};
    m.normals = std::vector<geom::Float3>(6, geom::Float3{0, 0, 1});
    m.triangles = {{0, 1, 2}, {3, 4, 5}};
    m.material = {1, 2};
    m.back_material = {1, 2};
    m.texture = {geom::no_texture, geom::no_texture};
    return m;
}

geom::Scene flat_scene()
{
    geom::Scene scene;
    scene.shading = geom::Shading::filled;  // the flat colours: nothing to light
    scene.materials[1].diffuse = {1, 0, 0};
    scene.materials[2].diffuse = {0, 0, 1};
    scene.background = {0.5f, 0.5f, 0.5f};
    return scene;
}

void expect_point(const PixelPoint& got, double x, double y)
{
    EXPECT_NEAR(got.x, x, 1e-9);
    EXPECT_NEAR(got.y, y, 1e-9);
}

TEST(VectorDrawing, ParallelViewProjectsAndPaintsFarToNear)
{
    // looking down -z at the origin, 0.01 world units a pixel, 200 x 100 pixels
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.01, 10, 200, 100);
    const VectorDrawing d = project_drawing(flat_scene(), near_then_far(), camera);
    EXPECT_EQ(d.width, 200);
    EXPECT_EQ(d.height, 100);
    EXPECT_FLOAT_EQ(d.background.g, 0.5f);
    ASSERT_EQ(d.shapes.size(), 2u);
    // x = 100 + X / 0.01, y = 50 - Y / 0.01: z does not move a parallel projection
    const VectorShape& far = d.shapes[0];
    EXPECT_EQ(far.colour, (geom::Rgb{0, 0, 1}));
    expect_point(far.points[0], 0, 150);
    expect_point(far.points[1], 200, 150);
    expect_point(far.points[2], 100, -50);
    const VectorShape& near = d.shapes[1];
    EXPECT_EQ(near.colour, (geom::Rgb{1, 0, 0}));
    expect_point(near.points[0], 100, 50);
    expect_point(near.points[1], 200, 50);
    expect_point(near.points[2], 100, -50);
    EXPECT_GT(far.depth, near.depth);
}

TEST(VectorDrawing, PerspectiveViewProjectsAndPaintsFarToNear)
{
    // eye at z = 5 looking at the origin, 90 degrees vertically over 200 pixels: the focus
    // plane z = 0 is 10 units high, 0.05 a pixel; a point at depth 5 - Z shrinks by 5 / (5 - Z)
    const Camera camera = Camera::perspective({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 90, 200, 200);
    const VectorDrawing d = project_drawing(flat_scene(), near_then_far(), camera);
    ASSERT_EQ(d.shapes.size(), 2u);
    auto x = [](double X, double Z) { return 100 + X * 5 / (5 - Z) / 0.05; };
    auto y = [](double Y, double Z) { return 100 - Y * 5 / (5 - Z) / 0.05; };
    const VectorShape& far = d.shapes[0];
    EXPECT_EQ(far.colour, (geom::Rgb{0, 0, 1}));
    expect_point(far.points[0], x(-1, -2), y(-1, -2));
    expect_point(far.points[1], x(1, -2), y(-1, -2));
    expect_point(far.points[2], x(0, -2), y(1, -2));
    const VectorShape& near = d.shapes[1];
    EXPECT_EQ(near.colour, (geom::Rgb{1, 0, 0}));
    expect_point(near.points[1], x(1, 0), y(0, 0));
    expect_point(near.points[2], x(0, 0), y(1, 0));
}

// A triangle behind the perspective eye or past the window is left out; one in front stays.
TEST(VectorDrawing, LeavesOutWhatTheWindowCannotShow)
{
    geom::TriangleMesh m = near_then_far();
    m.positions[3] = {-1, -1, 6};  // the far triangle now straddles the eye's plane
    const Camera camera = Camera::perspective({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 90, 200, 200);
    EXPECT_EQ(project_drawing(flat_scene(), m, camera).shapes.size(), 1u);
    geom::TriangleMesh off = near_then_far();
    for (geom::Float3& p : off.positions)
        p[0] += 100;  // far to the right of the window
    EXPECT_TRUE(project_drawing(flat_scene(), off, camera).shapes.empty());
}

// A triangle whose back the window sees is filled with its back material.
TEST(VectorDrawing, BackFacesShowTheBackMaterial)
{
    geom::Scene scene = flat_scene();
    scene.materials[3].diffuse = {0, 1, 0};
    geom::TriangleMesh m = near_then_far();
    m.back_material = {3, 3};
    m.normals[3] = m.normals[4] = m.normals[5] = {0, 0, -1};  // the far one faces away
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.01, 10, 200, 100);
    const VectorDrawing d = project_drawing(scene, m, camera);
    ASSERT_EQ(d.shapes.size(), 2u);
    EXPECT_EQ(d.shapes[0].colour, (geom::Rgb{0, 1, 0}));  // far: its back
    EXPECT_EQ(d.shapes[1].colour, (geom::Rgb{1, 0, 0}));  // near: its front
}

// Lit, a face turned to the light is brighter than one turned away at an angle, and a
// material's ambient term keeps the second from black; `filled` draws the flat colour.
TEST(VectorDrawing, ShadesByTheFirstLight)
{
    geom::Scene scene = flat_scene();
    scene.shading = geom::Shading::shaded;
    scene.materials[1].ambient = {0.2f, 0.2f, 0.2f};
    geom::Light light;
    light.kind = geom::Light::Kind::directional;
    light.direction = {0, 0, 1};
    light.ambient = {1, 1, 1};
    scene.lights = {light};
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.01, 10, 200, 100);
    const geom::Rgb facing = vector_colour(scene, 1, {0, 0, 1}, {}, camera);
    const geom::Rgb tilted = vector_colour(scene, 1, geom::normalize({1, 0, 1}), {}, camera);
    EXPECT_FLOAT_EQ(facing.r, 1.0f);  // 0.2 + 1 x 1, clamped
    EXPECT_NEAR(tilted.r, 0.2 + std::sqrt(0.5), 1e-6);
    EXPECT_FLOAT_EQ(tilted.g, 0.2f);
    scene.shading = geom::Shading::filled;
    EXPECT_EQ(vector_colour(scene, 1, geom::normalize({1, 0, 1}), {}, camera), (geom::Rgb{1, 0, 0}));
}

// `line style: pixel` lines are stroked segments of their width, sorted with the triangles.
TEST(VectorDrawing, PixelLinesAreStrokedSegments)
{
    geom::Scene scene = flat_scene();
    scene.line_radius_in_pixels = true;
    geom::LinearCurves& l = scene.geometry.lines;
    l.keys = {{0, 0, -1, 1.5f}, {0, 0.5f, -1, 1.5f}};
    l.segments = {0};
    l.flags = {0};
    l.material = {2};
    l.texture = {geom::no_texture};
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.01, 10, 200, 100);
    const VectorDrawing d = project_drawing(scene, near_then_far(), camera);
    ASSERT_EQ(d.shapes.size(), 3u);
    EXPECT_EQ(d.shapes[1].kind, VectorShape::Kind::line);  // between z = -2 and z = 0
    EXPECT_FLOAT_EQ(d.shapes[1].line_width, 3.0f);
    expect_point(d.shapes[1].points[0], 100, 50);
    expect_point(d.shapes[1].points[1], 100, 0);
}

}  // namespace
}  // namespace cambium::render
