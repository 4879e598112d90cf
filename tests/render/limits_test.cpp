// SPDX-License-Identifier: Apache-2.0
// Hostile numbers at the renderer: cameras that would make invalid rays are refused,
// rays Embree cannot take are skipped (never an abort), NaN samples are counted.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "geom/scene_limits.h"
#include "render/accel.h"
#include "render/camera.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using testing::add_segment;
using testing::empty_scene;
using testing::small;

constexpr float inf = std::numeric_limits<float>::infinity();
constexpr float nan_value = std::numeric_limits<float>::quiet_NaN();

std::string error_of(const geom::Scene& s, const RenderSettings& settings)
{
    try {
        render(s, settings);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(RenderLimits, CamerasWhoseRaysWouldStartOutOfRangeAreRefused)
{
    geom::Scene s = empty_scene({-1, -1, -1}, {1, 1, 1});
    add_segment(s, {0, -1, 0}, {0, 1, 0}, 0.1f);
    // parallel: a tiny scale factor widens the window to 1e300 units
    s.view.scale_factor = 1e-300;
    EXPECT_NE(error_of(s, small(8, 8, 1)).find("view: the camera's rays would start"), std::string::npos);
    // perspective: the eye goes to reference + (viewpoint - reference) / scale factor
    s.view.perspective = true;
    s.view.scale_factor = 1e-12;
    std::string err = error_of(s, small(8, 8, 1));
    EXPECT_NE(err.find("beyond 1e+11; check the viewpoint, view reference point, scale factor and box"),
              std::string::npos)
        << err;
    // and within range the same scene renders
    s.view.scale_factor = 1;
    EXPECT_EQ(error_of(s, small(8, 8, 1)), "no error");
}

TEST(RenderLimits, RaysEmbreeWouldAbortOnAreSkippedAndCounted)
{
    geom::Scene s = empty_scene({-1, -1, -1}, {1, 1, 1});
    add_segment(s, {-1, 0, 0}, {1, 0, 0}, 0.5f);
    EmbreeScene accel(s, make_camera(s.view, s.bounds, 16, 16));
    EXPECT_FALSE(accel.intersect({0, 0, 5}, {nan_value, 0, -1}, 0, inf));
    EXPECT_FALSE(accel.intersect({0, 0, 1e30f}, {0, 0, -1}, 0, inf));
    EXPECT_FALSE(accel.occluded({0, 0, 5}, {0, 0, -1}, nan_value, inf));
    EXPECT_FALSE(accel.occluded({inf, 0, 5}, {0, 0, -1}, 0, inf));
    EXPECT_EQ(accel.skipped_rays(), 4u);
    // a good ray still hits
    EXPECT_TRUE(accel.intersect({0, 0, 5}, {0, 0, -1}, 0, inf));
    EXPECT_EQ(accel.skipped_rays(), 4u);
}

// A front clipping plane far beyond the scene moves a parallel view's rays out of
// Embree's reach: each is skipped and counted, not traced, and shows the background.
TEST(RenderLimits, ParallelRaysMovedOutOfReachByAFrontPlaneAreSkipped)
{
    geom::Scene s = empty_scene({-2, -2, -2}, {2, 2, 2});
    add_segment(s, {-2, 0, 0}, {2, 0, 0}, 1.0f, 3);
    s.background = {0.25f, 0.5f, 0.75f};
    const Camera camera =
        Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.5, 10, 8, 8).with_clipping(5e11, 6e11);
    ASSERT_FALSE(camera.parallel_rays_in_reach());
    RenderReport report;
    ::testing::internal::CaptureStderr();
    Image img = render(s, camera, small(8, 8, 2), &report);
    ::testing::internal::GetCapturedStderr();
    EXPECT_GT(report.skipped_rays, 0u);
    EXPECT_EQ(report.skipped_rays + report.background_only_samples, report.samples);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x)
            EXPECT_EQ(img.at(x, y, 3), 0.0f) << x << " " << y;  // nothing met
}

/// `rays` (at most 16, all along rays[0]'s direction) by component.
ParallelRays by_components(const std::vector<CameraRayF>& rays)
{
    ParallelRays out;
    out.dir = rays.front().dir;
    for (std::size_t k = 0; k < rays.size(); ++k) {
        out.org_x[k] = rays[k].org.x;
        out.org_y[k] = rays[k].org.y;
        out.org_z[k] = rays[k].org.z;
        out.tfar[k] = rays[k].tfar;
    }
    return out;
}

// A coherent stream checks its rays as intersect() does, every float of every ray (all of
// them at once, then one by one where some ray fails): each ray that one float makes
// untraceable is skipped and counted, and the stream's other rays hit as intersect()'s do.
TEST(RenderLimits, CoherentStreamsSkipEachRayEmbreeWouldAbortOn)
{
    geom::Scene s = empty_scene({-1, -1, -1}, {1, 1, 1});
    add_segment(s, {-1, 0, 0}, {1, 0, 0}, 0.5f);
    EmbreeScene accel(s, make_camera(s.view, s.bounds, 16, 16));
    const float reach = static_cast<float>(geom::max_ray_start);
    std::vector<CameraRayF> rays;
    std::uint64_t skipped = 0;
    for (float far : {100.0f, inf})  // (clipped or not)
    for (std::size_t n : {std::size_t{16}, std::size_t{5}})
        for (std::size_t bad = 0; bad < n; ++bad)
            for (int field = 0; field < 7; ++field)
                for (float value : {nan_value, inf, -inf, reach, std::nextafter(reach, inf)}) {
                    rays.clear();
                    for (std::size_t k = 0; k < n; ++k)
                        rays.push_back({{-0.9f + 0.1f * float(k), 0.1f, 5}, {0, 0, -1}, far});
                    CameraRayF& r = rays[bad];
                    float* floats[7] = {&r.org.x, &r.org.y, &r.org.z, &r.dir.x,
                                        &r.dir.y, &r.dir.z, &r.tfar};
                    *floats[field] = value;
                    // expected: what intersect() makes of each ray
                    std::vector<std::optional<SurfaceHit>> expected;
                    for (const CameraRayF& q : rays)
                        expected.push_back(accel.intersect(q.org, q.dir, 0, q.tfar, {}, true));
                    const std::uint64_t single = accel.skipped_rays() - skipped;
                    std::vector<std::optional<SurfaceHit>> hits(n);
                    accel.intersect_coherent(rays, hits);
                    const std::uint64_t streamed = accel.skipped_rays() - skipped - single;
                    skipped = accel.skipped_rays();
                    EXPECT_EQ(streamed, single) << n << " " << bad << " " << field << " " << value;
                    // origins beyond reach, directions not finite, a NaN tfar: skipped
                    bool traceable = field < 3   ? std::fabs(value) <= reach
                                     : field < 6 ? std::isfinite(value)
                                                 : !std::isnan(value);
                    EXPECT_EQ(single, traceable ? 0u : 1u) << field << " " << value;
                    for (std::size_t k = 0; k < n; ++k) {
                        ASSERT_EQ(bool(hits[k]), bool(expected[k])) << n << " " << bad << " " << k;
                        if (hits[k]) {
                            EXPECT_EQ(hits[k]->t, expected[k]->t);
                        }
                    }
                    EXPECT_TRUE(hits[(bad + 1) % n]);  // the others hit the segment
                    if (field >= 3 && field < 6)
                        continue;  // (rays by component share one direction)
                    // The same rays by component (a parallel view's hand-off): the same.
                    std::vector<std::optional<SurfaceHit>> by_component(n);
                    accel.intersect_coherent(by_components(rays), n, by_component);
                    EXPECT_EQ(accel.skipped_rays() - skipped, single) << field << " " << value;
                    skipped = accel.skipped_rays();
                    for (std::size_t k = 0; k < n; ++k) {
                        ASSERT_EQ(bool(by_component[k]), bool(expected[k])) << n << " " << k;
                        if (by_component[k]) {
                            EXPECT_EQ(by_component[k]->t, expected[k]->t);
                            EXPECT_EQ(by_component[k]->position, expected[k]->position);
                        }
                    }
                }
    // Rays the caller vouches for (`checked`), by component or not: the same hits.
    for (std::size_t n : {std::size_t{16}, std::size_t{5}}) {
        rays.clear();
        for (std::size_t k = 0; k < n; ++k)
            rays.push_back({{-0.9f + 0.1f * float(k), 0.1f - 0.05f * float(k), 5}, {0, 0, -1}, 100});
        std::vector<std::optional<SurfaceHit>> hits(n), by_component(n);
        accel.intersect_coherent(rays, hits, true);
        accel.intersect_coherent(by_components(rays), n, by_component, true);
        for (std::size_t k = 0; k < n; ++k) {
            ASSERT_EQ(bool(by_component[k]), bool(hits[k])) << n << " " << k;
            if (hits[k]) {
                EXPECT_EQ(by_component[k]->t, hits[k]->t);
                EXPECT_EQ(by_component[k]->position, hits[k]->position);
                EXPECT_EQ(by_component[k]->normal, hits[k]->normal);
            }
        }
    }
}

TEST(RenderLimits, NotFiniteSamplesCountAsBlackAndAreReported)
{
    geom::Scene s = empty_scene({-2, -2, -2}, {2, 2, 2});
    add_segment(s, {-2, 0, 0}, {2, 0, 0}, 1.0f, 3);
    // a light no view file could give (display colours are clamped, so NaN must come
    // from a direction): its shadow rays are skipped, its radiance is NaN
    s.lights.push_back(testing::directional({nan_value, 0, 1}));
    RenderReport report;
    ::testing::internal::CaptureStderr();
    Image img = render(s, small(8, 8, 2), &report);
    std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_GT(report.nonfinite_samples, 0u);
    EXPECT_LT(report.nonfinite_samples, report.samples);  // the background ones are fine
    for (float v : img.rgba)
        EXPECT_TRUE(std::isfinite(v));
    EXPECT_GT(report.skipped_rays, 0u);
    EXPECT_NE(err.find("ray(s) not finite or starting too far from the origin were skipped"), std::string::npos)
        << err;
    EXPECT_NE(err.find("render: " + std::to_string(report.nonfinite_samples) +
                       " sample(s) with a radiance that is not finite were counted as black"),
              std::string::npos)
        << err;
}

}  // namespace
}  // namespace cambium::render
