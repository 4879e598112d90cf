// SPDX-License-Identifier: Apache-2.0
// Turntable framing, the command line's view changes and frame-interval object motion.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "render/framing.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using geom::Vec3;

/// A lopsided plant: tall, off the origin, deeper than wide.
geom::Bounds3 plant_bounds()
{
    geom::Bounds3 b;
    b.extend(Vec3{-0.5, 0, 1});
    b.extend(Vec3{2.5, 6, 4});
    return b;
}

std::array<Vec3, 8> corners(const geom::Bounds3& b)
{
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i)
        c[i] = {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
    return c;
}

void expect_inside_every_frame(const std::vector<Camera>& cameras, const geom::Bounds3& b)
{
    for (std::size_t k = 0; k < cameras.size(); ++k)
        for (const Vec3& p : corners(b)) {
            PixelPoint q = cameras[k].project(p);
            EXPECT_GE(q.x, 0) << "frame " << k;
            EXPECT_LE(q.x, cameras[k].width()) << "frame " << k;
            EXPECT_GE(q.y, 0) << "frame " << k;
            EXPECT_LE(q.y, cameras[k].height()) << "frame " << k;
        }
}

TEST(Turntable, ParallelFramingHoldsThePlantAtOneScale)
{
    geom::View view;  // cpfg's default: looking down -z
    for (std::optional<double> elevation : {std::optional<double>{}, std::optional<double>{35.0}}) {
        auto cameras = turntable_cameras(view, plant_bounds(), 36, elevation, 320, 240);
        ASSERT_EQ(cameras.size(), 36u);
        expect_inside_every_frame(cameras, plant_bounds());
        for (const Camera& c : cameras) {
            EXPECT_DOUBLE_EQ(c.pixel_size(), cameras[0].pixel_size());
            EXPECT_EQ(c.projection(), Camera::Projection::parallel);
        }
        // a quarter turn looks along a perpendicular horizontal direction
        Vec3 f0 = cameras[0].forward(), f9 = cameras[9].forward();
        EXPECT_NEAR(f0.x * f9.x + f0.z * f9.z, 0, 1e-9);
        EXPECT_NEAR(f0.y, f9.y, 1e-9);
        // the orbit keeps the vertical axis vertical in the image
        EXPECT_NEAR(cameras[9].right().y, 0, 1e-9);
    }
}

TEST(Turntable, ElevationTiltsTheViewDown)
{
    geom::View view;
    auto cameras = turntable_cameras(view, plant_bounds(), 4, 30.0, 320, 240);
    EXPECT_NEAR(cameras[0].forward().y, -std::sin(30 * std::numbers::pi / 180), 1e-9);
    EXPECT_NEAR(cameras[2].forward().y, cameras[0].forward().y, 1e-9);
}

TEST(Turntable, PerspectiveFramingHoldsThePlantAtOneDistance)
{
    geom::View view;
    view.perspective = true;
    view.viewing_angle_deg = 40;
    view.viewpoint = {0, 3, 20};
    view.reference_point = {0, 3, 0};
    auto cameras = turntable_cameras(view, plant_bounds(), 24, 20.0, 320, 240);
    expect_inside_every_frame(cameras, plant_bounds());
    Vec3 centre = plant_bounds().center();
    double d0 = geom::length(cameras[0].origin() - centre);
    for (const Camera& c : cameras) {
        EXPECT_NEAR(geom::length(c.origin() - centre), d0, 1e-9 * d0);
        EXPECT_NEAR(c.pixel_size(), cameras[0].pixel_size(), 1e-12);
    }
    // not needlessly far: the plant spans a good part of the frame
    PixelPoint top = cameras[0].project({centre.x, plant_bounds().hi.y, centre.z});
    PixelPoint bottom = cameras[0].project({centre.x, plant_bounds().lo.y, centre.z});
    EXPECT_GT(bottom.y - top.y, 0.4 * 240);
}

TEST(Turntable, ZoomMagnifiesTheFittedOrbit)
{
    // --zoom K multiplies the view's scale factor; the turntable honours it.
    for (bool perspective : {false, true}) {
        geom::View view;
        view.perspective = perspective;
        auto fitted = turntable_cameras(view, plant_bounds(), 4, 20.0, 320, 240);
        ViewOverrides zoom;
        zoom.zoom = 2;
        view = apply_overrides(view, zoom, plant_bounds());
        auto zoomed = turntable_cameras(view, plant_bounds(), 4, 20.0, 320, 240);
        Vec3 centre = plant_bounds().center();
        for (std::size_t k = 0; k < 4; ++k) {
            if (perspective) {
                EXPECT_NEAR(geom::length(zoomed[k].origin() - centre),
                            geom::length(fitted[k].origin() - centre) / 2, 1e-6);
            } else {
                EXPECT_DOUBLE_EQ(zoomed[k].pixel_size(), fitted[k].pixel_size() / 2);
            }
            // the plant's centre stays where it was in the image
            EXPECT_NEAR(zoomed[k].project(centre).x, fitted[k].project(centre).x, 1e-6);
        }
    }
}

TEST(ViewOverrides, OrbitTurnsTheViewpointAboutTheReferencePoint)
{
    geom::View view;
    view.viewpoint = {0, 0, 10};
    view.reference_point = {0, 0, 0};
    ViewOverrides o;
    o.orbit_azimuth_deg = 90;
    o.orbit_elevation_deg = 0;
    geom::View turned = apply_overrides(view, o, plant_bounds());
    EXPECT_NEAR(turned.viewpoint.x, 10, 1e-9);
    EXPECT_NEAR(turned.viewpoint.z, 0, 1e-9);
    o.orbit_azimuth_deg = 0;
    o.orbit_elevation_deg = 90;
    geom::View raised = apply_overrides(view, o, plant_bounds());
    EXPECT_NEAR(raised.viewpoint.y, 10, 1e-9);
}

TEST(ViewOverrides, ZoomFovProjectionAndFit)
{
    geom::View view;
    view.scale_factor = 2;
    geom::Bounds3 box;
    box.extend(Vec3{-1, -1, -1});
    box.extend(Vec3{1, 1, 1});
    view.box = box;
    ViewOverrides o;
    o.zoom = 1.5;
    EXPECT_DOUBLE_EQ(apply_overrides(view, o, plant_bounds()).scale_factor, 3);
    o.fit = true;
    geom::View fitted = apply_overrides(view, o, plant_bounds());
    EXPECT_FALSE(fitted.box.has_value());
    EXPECT_DOUBLE_EQ(fitted.scale_factor, 1.5);
    o = {};
    o.perspective = true;
    o.fov_deg = 30;
    o.fit = true;
    geom::View p = apply_overrides(view, o, plant_bounds());
    EXPECT_TRUE(p.perspective);
    EXPECT_DOUBLE_EQ(p.viewing_angle_deg, 30);
    Camera c = make_camera(p, plant_bounds(), 320, 240);
    for (const Vec3& q : corners(plant_bounds())) {
        PixelPoint s = c.project(q);
        EXPECT_TRUE(s.x >= 0 && s.x <= 320 && s.y >= 0 && s.y <= 240);
    }
}

TEST(ObjectMotion, TurnedCameraSeesTheTurnedObject)
{
    geom::View view;
    view.viewpoint = {1, 2, 10};
    Camera camera = make_camera(view, plant_bounds(), 320, 240);
    Vec3 rotation{20, 90, -35};
    Vec3 scale{2, 2, 2};
    Camera moved = transform_object_view(camera, rotation, scale, plant_bounds());
    // the object point p, turned (x, then y, then z) and scaled, seen by the original
    // camera, lands where the moved camera sees p itself
    auto turn = [](Vec3 v, Vec3 axis, double deg) {
        double a = deg * std::numbers::pi / 180, c = std::cos(a), s = std::sin(a);
        return v * c + geom::cross(axis, v) * s + axis * (geom::dot(axis, v) * (1 - c));
    };
    for (const Vec3& p : corners(plant_bounds())) {
        Vec3 q = turn(turn(turn(p, {1, 0, 0}, rotation.x), {0, 1, 0}, rotation.y), {0, 0, 1},
                      rotation.z) * 2.0;
        PixelPoint a = camera.project(q), b = moved.project(p);
        EXPECT_NEAR(a.x, b.x, 1e-6);
        EXPECT_NEAR(a.y, b.y, 1e-6);
    }
}

TEST(RenderViews, EveryViewEqualsASeparateRender)
{
    // One BVH for all views must not change what each view sees, and the sampling
    // pattern is the same in every frame.
    geom::Scene scene = testing::empty_scene({-1, 0, -1}, {1, 4, 1});
    testing::add_segment(scene, {0, 0, 0}, {0, 3, 0}, 0.3f);
    testing::add_segment(scene, {0, 2, 0}, {1, 3.5, 0.5}, 0.15f);
    scene.materials[1].diffuse = {0.8f, 0.5f, 0.2f};
    scene.lights.push_back(testing::directional({1, 1, 1}));
    RenderSettings settings = testing::small(24, 18, 4, 2);
    std::vector<Camera> cameras =
        turntable_cameras(scene.view, scene.bounds, 3, 20.0, settings.width, settings.height);
    std::vector<Image> views;
    render_views(scene, cameras, settings, [&](std::size_t k, Image& image, const RenderReport&) {
        EXPECT_EQ(k, views.size());
        views.push_back(image);
        return true;
    });
    ASSERT_EQ(views.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k)
        EXPECT_EQ(views[k].rgba, render(scene, cameras[k], settings).rgba) << "view " << k;
    EXPECT_NE(views[0].rgba, views[1].rgba);  // the orbit does turn
    // returning false stops the sequence
    int calls = 0;
    render_views(scene, cameras, settings, [&](std::size_t, Image&, const RenderReport&) {
        ++calls;
        return false;
    });
    EXPECT_EQ(calls, 1);
}

TEST(RenderViews, PixelWideLinesAreSizedForEachView)
{
    // `line style: pixel`: a line is as many pixels wide in every view, near or far.
    geom::Scene scene = testing::empty_scene({-1, 0, -1}, {1, 4, 1});
    scene.line_radius_in_pixels = true;
    testing::add_segment(scene, {0, 0, 0}, {0, 3, 0}, 2.0f);
    scene.materials[1].diffuse = {0.8f, 0.5f, 0.2f};
    scene.lights.push_back(testing::directional({1, 1, 1}));
    RenderSettings settings = testing::small(40, 30, 2, 1);
    std::vector<Camera> cameras = {
        Camera::perspective({0, 1.5, 6}, {0, 1.5, 0}, {0, 1, 0}, 45, 40, 30),
        Camera::perspective({0, 1.5, 30}, {0, 1.5, 0}, {0, 1, 0}, 45, 40, 30)};
    std::vector<Image> views;
    render_views(scene, cameras, settings, [&](std::size_t, Image& image, const RenderReport&) {
        views.push_back(image);
        return true;
    });
    ASSERT_EQ(views.size(), 2u);
    EXPECT_EQ(views[1].rgba, render(scene, cameras[1], settings).rgba);
    // the far view's line is as wide as the near one's (in pixels)
    auto width = [](const Image& image) {
        int covered = 0;
        for (int x = 0; x < image.width; ++x)
            covered += image.at(x, 15, 3) > 0.5f ? 1 : 0;
        return covered;
    };
    EXPECT_GE(width(views[1]), 3);
    EXPECT_NEAR(width(views[1]), width(views[0]), 1);
}

}  // namespace
}  // namespace cambium::render

#include "render/tonemap.h"

namespace cambium::render {
namespace {

TEST(ToneMap, FilmicRollsHighlightsOffInsteadOfClipping)
{
    EXPECT_FLOAT_EQ(tone_map(ToneMap::none, 3.0f), 3.0f);  // clipped later by the encoder
    EXPECT_FLOAT_EQ(filmic(0.0f), 0.0f);
    EXPECT_FLOAT_EQ(filmic(-1.0f), 0.0f);
    float previous = 0;
    for (float x : {0.05f, 0.18f, 0.5f, 1.0f, 2.0f, 4.0f}) {
        float y = filmic(x);
        EXPECT_GT(y, previous) << x;  // strictly increasing: highlights keep detail
        EXPECT_LE(y, 1.0f) << x;
        previous = y;
    }
    EXPECT_LT(filmic(2.0f), 0.95f);   // a value twice white is not clipped yet
    EXPECT_GT(filmic(16.0f), 0.99f);  // very bright values reach white
    EXPECT_LE(filmic(100.0f), 1.0f);
    // Narkowicz's fit at mid-grey: 0.18 -> about 0.14 after his 0.6 exposure match
    EXPECT_NEAR(filmic(0.18f), 0.140f, 0.002f);
}

}  // namespace
}  // namespace cambium::render
