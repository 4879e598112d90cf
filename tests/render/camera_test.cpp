// SPDX-License-Identifier: Apache-2.0
// Camera framing against hand-computed values from cpfg's rule (CalculateWindow, SetView).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "geom/scene_limits.h"
#include "render/camera.h"

namespace cambium::render {
namespace {

geom::Bounds3 box(const geom::Vec3& lo, const geom::Vec3& hi)
{
    geom::Bounds3 b;
    b.extend(lo);
    b.extend(hi);
    return b;
}

// Oracle 03-snowflake: box 0..81 x 0..23.3827, scale 0.9, 640x480. The width limits:
// 0.9 * 640 / 81 = 7.1111 px per unit, centred; cpfg's window shows x 32..607, y 157..323.
TEST(Camera, ParallelFitsSnowflakeAsCpfg)
{
    geom::View view;
    view.scale_factor = 0.9;
    Camera c = make_camera(view, box({0, -8.88178e-16, 0}, {81, 23.3827, 0}), 640, 480);
    EXPECT_NEAR(c.project({0, 0, 0}).x, 32.0, 1e-9);
    EXPECT_NEAR(c.project({81, 0, 0}).x, 608.0, 1e-9);
    double k = 0.9 * 640 / 81;
    EXPECT_NEAR(c.project({0, 0, 0}).y, 240 + (23.3827 / 2) * k, 1e-4);  // 323.14
    EXPECT_NEAR(c.project({0, 23.3827, 0}).y, 240 - (23.3827 / 2) * k, 1e-4);  // 156.86
    EXPECT_NEAR(c.pixel_size(), 1 / k, 1e-12);
}

// Oracle DragonCurve: box -10..5 x -5..18, scale 0.9. The height limits:
// k = 0.9 * 480 / 23 = 18.783; x = -10 lands at 320 - 7.5 k = 179.1 (image: 178..461).
TEST(Camera, ParallelHeightLimitedFit)
{
    geom::View view;
    view.scale_factor = 0.9;
    Camera c = make_camera(view, box({-10, -5, 0}, {5, 18, 0}), 640, 480);
    double k = 0.9 * 480 / 23;
    EXPECT_NEAR(c.project({-10, 6.5, 0}).x, 320 - 7.5 * k, 1e-9);
    EXPECT_NEAR(c.project({5, 6.5, 0}).x, 320 + 7.5 * k, 1e-9);
    EXPECT_NEAR(c.project({0, 18, 0}).y, 240 - 0.9 * 240, 1e-9);
    EXPECT_NEAR(c.project({0, -5, 0}).y, 240 + 0.9 * 240, 1e-9);
}

// Looking from +x at the origin: screen right is -z, up is +y. Box 0..1 x 0..2 x 0..4:
// projected extent 4 (z) x 2 (y), k = min(640/4, 480/2) = 160, so z = 4 -> 0, z = 0 -> 640.
TEST(Camera, ParallelFitsTheProjectedBox)
{
    geom::View view;
    view.viewpoint = {1, 0, 0};
    Camera c = make_camera(view, box({0, 0, 0}, {1, 2, 4}), 640, 480);
    EXPECT_NEAR(c.project({0.5, 1, 4}).x, 0.0, 1e-9);
    EXPECT_NEAR(c.project({0.5, 1, 0}).x, 640.0, 1e-9);
    EXPECT_NEAR(c.project({0.5, 2, 2}).y, 240 - 160, 1e-9);
    // Depth along the view does not move a point in a parallel view.
    EXPECT_NEAR(c.project({-7, 2, 2}).x, c.project({3, 2, 2}).x, 1e-9);
}

TEST(Camera, BoxOverridesBounds)
{
    geom::View view;
    view.box = box({-4, -2, -4}, {4, 7, 4});
    Camera c = make_camera(view, box({-1, -1, -1}, {1, 1, 1}), 640, 480);
    // k = min(640/8, 480/9) = 53.33; centre (0, 2.5).
    EXPECT_NEAR(c.project({0, 2.5, 0}).y, 240, 1e-9);
    EXPECT_NEAR(c.project({4, 2.5, 0}).x, 320 + 4 * 480.0 / 9, 1e-9);
}

TEST(Camera, PointBoxGetsUnitSpan)
{
    geom::View view;
    view.scale_factor = 0.5;  // cpfg ignores the scale when the box is a point
    Camera c = make_camera(view, box({0, 0, 0}, {0, 0, 0}), 640, 480);
    EXPECT_NEAR(c.project({1, 0, 0}).x, 640.0, 1e-9);
}

// Twist 90 degrees: the up vector turns counter-clockwise as the viewer sees it (+y -> -x),
// so a point above the centre moves to the right of the image.
TEST(Camera, TwistRotatesImageClockwise)
{
    geom::View view;
    view.twist_deg = 90;
    Camera c = make_camera(view, box({-1, -1, 0}, {1, 1, 0}), 480, 480);
    PixelPoint p = c.project({0, 1, 0});
    EXPECT_NEAR(p.y, 240, 1e-9);
    EXPECT_GT(p.x, 240 + 100);
}

// Perspective: eye = vrp + (vp - vrp) / scale = (0,0,80); fovy 20: a point 10 above the
// reference point is 10 / (80 tan 10deg) of the half height above the centre.
TEST(Camera, PerspectiveEyeMovesWithScaleFactor)
{
    geom::View view;
    view.perspective = true;
    view.viewpoint = {0, 0, 40};
    view.viewing_angle_deg = 20;
    view.scale_factor = 0.5;
    Camera c = make_camera(view, box({-1, -1, -1}, {1, 1, 1}), 640, 480);
    double t = std::tan(10 * std::numbers::pi / 180);
    EXPECT_NEAR(c.project({0, 0, 0}).x, 320, 1e-9);
    EXPECT_NEAR(c.project({0, 10, 0}).y, 240 - 10 / (80 * t) * 240, 1e-6);
    EXPECT_NEAR(c.project({10, 0, 0}).x, 320 + 10 / (80 * t) * 240, 1e-6);
    // Twice as far from the eye, half the offset.
    EXPECT_NEAR(c.project({0, 10, -80}).y, 240 - 5 / (80 * t) * 240, 1e-6);
    EXPECT_NEAR(c.pixel_size_at({0, 0, -80}), 2 * c.pixel_size(), 1e-12);
}

TEST(Camera, GeneratedRayPassesThroughProjectedPoint)
{
    for (bool perspective : {false, true}) {
        geom::View view;
        view.perspective = perspective;
        view.viewpoint = {3, 2, 10};
        view.reference_point = {0.5, 1, 0};
        view.twist_deg = 30;
        Camera c = make_camera(view, box({-2, -1, -3}, {2, 4, 1}), 320, 200);
        geom::Vec3 p{1.2, 2.5, -0.7};
        PixelPoint q = c.project(p);
        CameraRay r = c.generate_ray(q.x, q.y);
        geom::Vec3 to = p - r.org;
        double miss = geom::length(to - r.dir * geom::dot(to, r.dir));
        EXPECT_LT(miss, 1e-9) << (perspective ? "perspective" : "parallel");
        EXPECT_GT(geom::dot(to, r.dir), 0);
    }
}

// A thin lens: rays from different lens points through the same pixel meet on the
// plane in focus, where the pinhole ray passes too; the lens points lie within the
// aperture on the plane through the eye perpendicular to the view.
TEST(Camera, ThinLensRaysMeetOnTheFocusPlane)
{
    Camera pinhole = Camera::perspective({1, 2, 30}, {1, 2, 0}, {0, 1, 0}, 40, 80, 60);
    Camera lens = pinhole.with_lens(0.5, 12.0);
    EXPECT_DOUBLE_EQ(lens.focus_distance(), 12.0);
    EXPECT_DOUBLE_EQ(pinhole.with_lens(0.5).focus_distance(), 30.0);  // the reference point
    CameraRay centre = pinhole.generate_ray(13.3, 47.9);
    // The pinhole ray reaches depth 12 (along -z from the eye) at t = 12 / cos.
    geom::Vec3 target = centre.org + centre.dir * (12.0 / -centre.dir.z);
    for (double u : {0.0, 0.3, 0.999})
        for (double v : {0.1, 0.5, 0.8}) {
            CameraRay r = lens.generate_ray(13.3, 47.9, u, v);
            EXPECT_NEAR(r.org.z, 30.0, 1e-12);
            EXPECT_LE(std::hypot(r.org.x - 1, r.org.y - 2), 0.5 + 1e-12);
            geom::Vec3 p = r.org + r.dir * ((30.0 - 12.0 - r.org.z) / r.dir.z);
            EXPECT_NEAR(p.x, target.x, 1e-9);
            EXPECT_NEAR(p.y, target.y, 1e-9);
        }
    // A pinhole ignores the lens numbers.
    CameraRay same = pinhole.generate_ray(13.3, 47.9, 0.9, 0.1);
    EXPECT_EQ(same.org.x, centre.org.x);
    EXPECT_EQ(same.dir.y, centre.dir.y);
}

// A pinhole perspective camera without clipping makes its rays in float too: the same
// rays as the double ones within float rounding; any other camera keeps double precision.
TEST(Camera, SinglePrecisionRaysAreTheDoubleRaysRounded)
{
    Camera c = Camera::perspective({12, 14, 19}, {0, 10, 0}, {0, 1, 0}, 50, 320, 240);
    ASSERT_TRUE(c.single_precision());
    std::vector<float> xs, ys;
    for (float x : {0.0f, 0.37f, 159.99f, 160.0f, 271.5f, 319.999f})
        for (float y : {0.0f, 0.61f, 119.5f, 200.25f, 239.99f}) {
            xs.push_back(x);
            ys.push_back(y);
        }
    std::vector<CameraRayF> rays(xs.size());
    c.generate_rays_f(xs, ys, rays);
    for (std::size_t k = 0; k < xs.size(); ++k) {
        CameraRay d = c.generate_ray(xs[k], ys[k]);
        EXPECT_EQ(rays[k].org.x, float(d.org.x));
        EXPECT_EQ(rays[k].org.y, float(d.org.y));
        EXPECT_EQ(rays[k].org.z, float(d.org.z));
        // A few float roundings of a unit vector (2^-24 each), far below a pixel's angle
        // (50 degrees / 240 = 3.6e-3 rad).
        EXPECT_NEAR(rays[k].dir.x, d.dir.x, 4e-7) << k;
        EXPECT_NEAR(rays[k].dir.y, d.dir.y, 4e-7) << k;
        EXPECT_NEAR(rays[k].dir.z, d.dir.z, 4e-7) << k;
        EXPECT_TRUE(std::isinf(rays[k].tfar));
    }
    EXPECT_FALSE(c.with_lens(0.1).single_precision());
    EXPECT_FALSE(c.with_clipping(1, 100).single_precision());
    EXPECT_FALSE(Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.1, 10, 64, 48)
                     .single_precision());
}

// Camera::generate_parallel_rays for any number of image points, in blocks of
// ParallelRays::capacity (as the renderer's camera batches ask), gathered into CameraRayFs.
std::vector<CameraRayF> parallel_rays(const Camera& c, int x, int y, std::span<const float> xs,
                                      std::span<const float> ys, std::span<double> tnear)
{
    std::vector<CameraRayF> rays(xs.size());
    ParallelRays block;
    for (std::size_t k0 = 0; k0 < xs.size(); k0 += ParallelRays::capacity) {
        const std::size_t m = std::min(ParallelRays::capacity, xs.size() - k0);
        c.generate_parallel_rays(x, y, xs.subspan(k0, m), ys.subspan(k0, m),
                                 tnear.subspan(k0, m), block);
        for (std::size_t k = 0; k < m; ++k)
            rays[k0 + k] = block.ray(k);
    }
    return rays;
}

// A parallel camera's batch rays are traced_ray(generate_ray()) bit for bit: with and
// without clipping planes, in each frame (along an axis, twisted, one whose unit forward
// squares to just below 1), for whole blocks of 16 and the rest, and
// in the four places a front plane can be (behind the rays' start, in front, beyond
// the back plane) and the back plane behind the start (an empty interval).
TEST(Camera, ParallelBatchRaysAreTheTracedDoubleRays)
{
    geom::View view;
    view.viewpoint = {3.1, -2.7, 11.3};
    view.reference_point = {0.4, 1.9, -0.6};
    view.twist_deg = 17;
    Camera plain = make_camera(view, box({-2.3, -1.1, -3.7}, {4.9, 6.2, 1.3}), 320, 240);
    Camera axis = Camera::parallel({0.5, 0.25, 0}, {0, 0, -1}, {0, 1, 0}, 0.013, 9.5, 64, 48);
    // A view direction whose unit vector's squared length rounds to just below 1, which
    // the blocks divide by (where it is exactly 1 they need not).
    geom::View skewed = view;
    skewed.viewpoint = {-0.1, 0.07, 1.3};
    skewed.reference_point = {0, 0, 0};
    Camera skew = make_camera(skewed, box({-2.3, -1.1, -3.7}, {4.9, 6.2, 1.3}), 320, 240);
    ASSERT_EQ(plain.projection(), Camera::Projection::parallel);
    ASSERT_NE(geom::dot(skew.forward(), skew.forward()), 1.0);
    ASSERT_EQ(geom::dot(axis.forward(), axis.forward()), 1.0);
    constexpr double inf = std::numeric_limits<double>::infinity();
    std::vector<Camera> cameras;
    for (const Camera& c : {plain, axis, skew}) {
        cameras.push_back(c);
        for (auto [near, far] : std::vector<std::pair<double, double>>{
                 {-1, 2.5}, {-30, 40}, {-inf, 0.7}, {0.3, inf}, {1.5, 1.2}, {-40, -35}})
            cameras.push_back(c.with_clipping(near, far));
    }
    std::vector<float> xs, ys;
    for (float x : {0.0f, 0.37f, 63.99f, 160.0f, 271.5f, 319.999f, -2.0f})
        for (float y : {0.0f, 0.61f, 47.5f, 200.25f, 239.99f, 241.5f}) {
            xs.push_back(x);
            ys.push_back(y);
        }
    ASSERT_NE(xs.size() % 16, 0u);
    auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
    for (std::size_t i = 0; i < cameras.size(); ++i) {
        const Camera& c = cameras[i];
        std::vector<double> tnear(xs.size(), -1);
        // The image points of pixel (13, 7): 13 + xs[k] and 7 + ys[k], summed in float.
        const std::vector<CameraRayF> rays = parallel_rays(c, 13, 7, xs, ys, tnear);
        std::size_t clipped_front = 0, empty = 0;
        for (std::size_t k = 0; k < xs.size(); ++k) {
            double want_tnear = -1;
            CameraRayF want = traced_ray(c.generate_ray(13.0f + xs[k], 7.0f + ys[k]), want_tnear);
            EXPECT_EQ(bits(rays[k].org.x), bits(want.org.x)) << i << " " << k;
            EXPECT_EQ(bits(rays[k].org.y), bits(want.org.y)) << i << " " << k;
            EXPECT_EQ(bits(rays[k].org.z), bits(want.org.z)) << i << " " << k;
            EXPECT_EQ(bits(rays[k].dir.x), bits(want.dir.x)) << i << " " << k;
            EXPECT_EQ(bits(rays[k].dir.y), bits(want.dir.y)) << i << " " << k;
            EXPECT_EQ(bits(rays[k].dir.z), bits(want.dir.z)) << i << " " << k;
            EXPECT_EQ(bits(rays[k].tfar), bits(want.tfar)) << i << " " << k;
            EXPECT_EQ(std::bit_cast<std::uint64_t>(tnear[k]), std::bit_cast<std::uint64_t>(want_tnear))
                << i << " " << k;
            clipped_front += want_tnear > 0;
            empty += want.tfar <= 0;  // nothing to see: Embree takes no tfar below 0
        }
        // The cases are what they say: a front plane in front of the start moves it.
        bool front = !std::isinf(c.clip_near()) && c.clip_near() > -9;
        EXPECT_EQ(clipped_front, front ? xs.size() : 0u) << i;
        EXPECT_EQ(empty, c.clip_far() < -9 || c.clip_far() < c.clip_near() ? xs.size() : 0u) << i;
    }
    // Any other camera is refused: its rays are not parallel.
    Camera persp = Camera::perspective({12, 14, 19}, {0, 10, 0}, {0, 1, 0}, 50, 320, 240)
                       .with_clipping(2, 30);
    std::vector<double> tnear(xs.size());
    EXPECT_THROW(parallel_rays(persp, 2, 3, xs, ys, tnear), std::logic_error);
}

// A parallel camera's rays are all within Embree's reach unless a front plane far beyond
// the scene moves their starts out of it; the check holds at the image's corners.
TEST(Camera, ParallelRaysInReachUnlessAFrontPlaneTakesThemOut)
{
    Camera c = Camera::parallel({3e9, -2e9, 1e9}, {0.6, 0, -0.8}, {0, 1, 0}, 1e7, 4e9, 640, 480);
    c.check_range("test");
    // The largest coordinate of the starts of the rays through the image's corners
    // (two pixels outside it).
    auto reach = [](const Camera& cam) {
        std::vector<float> xs{-2, 642, -2, 642}, ys{-2, -2, 482, 482};
        std::vector<double> tnear(4);
        const std::vector<CameraRayF> rays = parallel_rays(cam, 0, 0, xs, ys, tnear);
        float most = 0;
        for (const CameraRayF& r : rays)
            most = std::max({most, std::abs(r.org.x), std::abs(r.org.y), std::abs(r.org.z)});
        return double(most);
    };
    for (const Camera& near : {c, c.with_clipping(-1e10, 5e10), c.with_clipping(1e11, 2e11)}) {
        EXPECT_TRUE(near.parallel_rays_in_reach());
        EXPECT_LE(reach(near), geom::max_ray_start);
    }
    // A front plane at 6e11 (0.8 of it along z): the rays start beyond Embree's reach,
    // though the camera itself passes check_range (its unclipped rays are within it).
    const Camera far_front = c.with_clipping(6e11, 7e11);
    far_front.check_range("test");
    EXPECT_FALSE(far_front.parallel_rays_in_reach());
    EXPECT_GT(reach(far_front), geom::max_ray_start);
    EXPECT_FALSE(Camera::perspective({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 40, 64, 48)
                     .parallel_rays_in_reach());
}

// Perspective clipping planes are at depths along the view direction: an oblique ray
// reaches them at depth / cos(angle).
TEST(Camera, PerspectiveClippingGivesRayIntervals)
{
    geom::View view;
    view.perspective = true;
    view.viewpoint = {0, 0, 10};
    view.front_distance = 4;
    view.back_distance = 9;
    Camera c = make_camera(view, box({-1, -1, -1}, {1, 1, 1}), 100, 100);
    CameraRay axis = c.generate_ray(50, 50);
    EXPECT_NEAR(axis.tnear, 4.0, 1e-9);
    EXPECT_NEAR(axis.tfar, 9.0, 1e-9);
    CameraRay corner = c.generate_ray(0, 0);
    double cos = -corner.dir.z;
    EXPECT_NEAR(corner.tnear, 4.0 / cos, 1e-9);
    EXPECT_NEAR(corner.tfar, 9.0 / cos, 1e-9);
    // Without planes, rays are unbounded.
    view.front_distance.reset();
    view.back_distance.reset();
    CameraRay open = make_camera(view, box({-1, -1, -1}, {1, 1, 1}), 100, 100).generate_ray(0, 0);
    EXPECT_EQ(open.tnear, 0.0);
    EXPECT_TRUE(std::isinf(open.tfar));
}

}  // namespace
}  // namespace cambium::render
