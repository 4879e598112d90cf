// SPDX-License-Identifier: Apache-2.0
// The raw-Embree measurement (ray_replay.h): the timed render traces the recorded rays
// without the interposer counting or recording them, at any thread count.
#include "ray_replay.h"

#include <ctime>

#include <gtest/gtest.h>

#include "test_scenes.h"

namespace cambium::bench {
namespace {

namespace t = render::testing;

/// A lattice of round segments in front of a parallel camera, lit by a directional light
/// with an ambient environment: camera streams, bounces and shadow rays.
geom::Scene lattice()
{
    geom::Scene s = t::empty_scene({-2, -2, -1}, {2, 2, 1});
    for (int i = -4; i <= 4; ++i) {
        t::add_segment(s, {-2, 0.45 * i, 0}, {2, 0.45 * i + 0.3, 0.2}, 0.12f);
        t::add_segment(s, {0.45 * i, -2, 0.3}, {0.45 * i - 0.2, 2, -0.2}, 0.08f);
    }
    s.materials[1].diffuse = {0.6f, 0.5f, 0.4f};
    s.lights.push_back(t::directional({0.3, 0.5, 1}));
    return s;
}

render::RenderSettings lattice_settings(int threads)
{
    render::RenderSettings rs = t::small(64, 48, 8, 4);
    rs.ambient = {0.3f, 0.3f, 0.3f};
    rs.threads = threads;
    return rs;
}

Measurement measure_lattice(int threads)
{
    const geom::Scene scene = lattice();
    const render::RenderSettings rs = lattice_settings(threads);
    recorder.prepare(100'000, 0, 0, 0);  // every ray (fewer than 75 000 of each kind)
    return measure(scene, render::make_camera(scene.view, scene.bounds, rs.width, rs.height),
                   rs);
}

TEST(RayReplay, TimedRenderTracesTheRecordedRaysAndCountsNone)
{
    const std::uint64_t before = recorder.intersections.total() + recorder.occlusions.total();
    const Measurement m = measure_lattice(2);
    const TraceFigures& f = m.trace;
    // Every kind was traced, and the renderer's own count agrees with the interposer's.
    EXPECT_GT(f.single_intersections(), 0u);
    EXPECT_GT(f.stream_intersections, 0u);
    EXPECT_GT(f.occlusions, 0u);
    EXPECT_EQ(m.recording.rays, f.rays());
    // The timed render made the same image with as many rays by the renderer's count...
    EXPECT_TRUE(m.same_render);
    EXPECT_TRUE(f.timed_forwarded);
    EXPECT_EQ(m.timed.rays, m.recording.rays);
    // ... and the interposer counted none of them: only the recording's rays were counted.
    EXPECT_EQ(recorder.intersections.total() + recorder.occlusions.total() - before, f.rays());
    // Both renders were timed, and the replay traced every recorded ray at least once.
    EXPECT_GT(f.trace_cpu_s, 0);
    EXPECT_GT(f.recording_trace_cpu_s, 0);
    EXPECT_EQ(recorder.singles.rays.size(), f.single_intersections());
    EXPECT_EQ(f.first_rays[0], f.single_intersections());
    EXPECT_GE(f.raw.singles, f.single_intersections());
    EXPECT_GE(f.raw.occlusions, f.occlusions);
    EXPECT_GE(f.raw.streams, f.stream_intersections);
    EXPECT_GT(f.raw.stream_hits, 0u);
    EXPECT_GT(f.raw_mix_cpu_s(), 0);
    EXPECT_GT(f.raw_mix_first_round_cpu_s(), 0);
    EXPECT_GT(f.path_tracer_fraction_of_raw_cpu(), 0);
}

/// The seconds on CLOCK_MONOTONIC, the clock `perf record -k CLOCK_MONOTONIC` stamps
/// samples with.
double monotonic_seconds()
{
    timespec t{};
    clock_gettime(CLOCK_MONOTONIC, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

TEST(RayReplay, TraceWindowIsTheTimedTraceOnTheMonotonicClock)
{
    const double before = monotonic_seconds();
    const TraceFigures f = measure_lattice(2).trace;
    const double after = monotonic_seconds();
    // A profile cut to this window holds the timed trace and nothing outside the run.
    EXPECT_LE(before, f.trace_window_s[0]);
    EXPECT_LT(f.trace_window_s[0], f.trace_window_s[1]);
    EXPECT_LE(f.trace_window_s[1], after);
    EXPECT_NEAR(f.trace_window_s[1] - f.trace_window_s[0], f.trace_s, 1e-6);
}

TEST(RayReplay, AfterAMeasurementTheEntryPointsCountNothing)
{
    measure_lattice(2);
    const std::uint64_t before = recorder.intersections.total() + recorder.occlusions.total();
    const geom::Scene scene = lattice();
    render::RenderReport report;
    render::render(scene, lattice_settings(2), &report);
    EXPECT_GT(report.rays, 0u);
    EXPECT_EQ(recorder.intersections.total() + recorder.occlusions.total(), before);
    // count() counts by kind until forward().
    recorder.count();
    render::render(scene, lattice_settings(2), &report);
    recorder.forward();
    EXPECT_EQ(recorder.intersections.total() + recorder.occlusions.total() - before, report.rays);
}

TEST(RayReplay, TheSameRaysAtAnyThreadCount)
{
    const TraceFigures one = measure_lattice(1).trace, two = measure_lattice(2).trace;
    EXPECT_EQ(one.intersections, two.intersections);
    EXPECT_EQ(one.stream_intersections, two.stream_intersections);
    EXPECT_EQ(one.occlusions, two.occlusions);
    EXPECT_EQ(one.singles_hash, two.singles_hash);
    EXPECT_EQ(one.streams_hash, two.streams_hash);
    EXPECT_EQ(one.occlusions_hash, two.occlusions_hash);
    EXPECT_NE(one.singles_hash, one.occlusions_hash);
    EXPECT_NE(one.streams_hash, 0u);
    // A render with other rays (fewer samples) has other sums.
    const geom::Scene scene = lattice();
    render::RenderSettings rs = lattice_settings(2);
    rs.samples_per_pixel = 4;
    recorder.prepare(100'000, 0, 0, 0);
    const TraceFigures fewer =
        measure(scene, render::make_camera(scene.view, scene.bounds, rs.width, rs.height), rs)
            .trace;
    EXPECT_NE(fewer.streams_hash, two.streams_hash);
    EXPECT_NE(fewer.singles_hash, two.singles_hash);
}

TEST(RayReplay, LogsSizedForEveryRayRecordEveryRay)
{
    const TraceFigures first = measure_lattice(2).trace;
    const geom::Scene scene = lattice();
    const render::RenderSettings rs = lattice_settings(2);
    recorder.prepare_every_ray(first.single_intersections(), first.occlusions,
                               first.stream_intersections);
    const TraceFigures f =
        measure(scene, render::make_camera(scene.view, scene.bounds, rs.width, rs.height), rs)
            .trace;
    EXPECT_EQ(recorder.singles.rays.size(), f.single_intersections());
    EXPECT_EQ(recorder.occlusion_rays.rays.size(), f.occlusions);
    EXPECT_EQ(recorder.streams.rays.size(), f.stream_intersections);
    EXPECT_EQ(f.first_rays[2], f.stream_intersections);
    // Every recorded ray's hash sums to the trace's: the logs hold the traced rays.
    std::uint64_t singles = 0, occlusions = 0, streams = 0;
    for (const RTCRay& r : recorder.streams.rays)  // (the id holds the stream's size)
        streams += ray_hash(r);
    for (std::size_t i = 0; i < recorder.singles.rays.size(); ++i)
        singles += ray_hash(recorder.singles.rays[i], recorder.singles.skips[i]);
    for (std::size_t i = 0; i < recorder.occlusion_rays.rays.size(); ++i)
        occlusions += ray_hash(recorder.occlusion_rays.rays[i], recorder.occlusion_rays.skips[i]);
    EXPECT_EQ(singles, f.singles_hash);
    EXPECT_EQ(occlusions, f.occlusions_hash);
    EXPECT_EQ(streams, f.streams_hash);
}

TEST(RayReplay, RayHashTellsRaysApart)
{
    RTCRay r{};
    r.org_x = 1;
    r.dir_z = -1;
    r.tfar = 10;
    r.mask = 0xffffffffu;
    const std::uint64_t h = ray_hash(r);
    EXPECT_EQ(ray_hash(r), h);
    RTCRay moved = r;
    moved.org_y = 0x1p-20f;
    EXPECT_NE(ray_hash(moved), h);
    RTCRay shorter = r;
    shorter.tfar = 9.999f;
    EXPECT_NE(ray_hash(shorter), h);
    RTCRay later = r;
    later.tnear = 1e-4f;
    EXPECT_NE(ray_hash(later), h);
    EXPECT_NE(ray_hash(r, render::PrimId{0, 3, render::PrimId::none}), h);
    EXPECT_NE(ray_hash(r, render::PrimId{0, 3, 1}), ray_hash(r, render::PrimId{0, 3, 2}));
    RTCRay labelled = r;  // the id is not the path tracer's: left out
    labelled.id = 7;
    EXPECT_EQ(ray_hash(labelled), h);
}

TEST(RayReplay, OneInKeepsAtMostTheAim)
{
    // Rounded down, 597 696 expected rays with room for 300 000 recorded every ray and
    // filled the log before the trace ended.
    EXPECT_EQ(one_in(300'000, 597'696), 2u);
    EXPECT_EQ(one_in(300'000, 600'000), 2u);
    EXPECT_EQ(one_in(300'000, 600'001), 3u);
    EXPECT_EQ(one_in(300'000, 300'000), 1u);
    EXPECT_EQ(one_in(300'000, 0), 1u);
    EXPECT_EQ(one_in(0, 1'000), 1u);
}

}  // namespace
}  // namespace cambium::bench
