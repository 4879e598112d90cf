// SPDX-License-Identifier: Apache-2.0
// Render benchmark: BVH build, peak memory and path-tracer rays per second on a large
// synthetic plant, beside raw Embree rtcIntersect1 on the same rays. Prints one JSON object.
//
// Usage: render [--scale S] [--threads N] [--size WxH] [--spp N] [--depth N]
//               [--trace-empty-pixels]
// (--trace-empty-pixels: the camera rays of pixels no primitive reaches are traced too,
// RenderSettings::skip_empty_pixels off; the same image.)
// Default (scale 1): 1 M round linear segments in 5 000 branches plus 100 000 instances
// of a 6-triangle leaf prototype; 320x240 at 16 spp, depth 4.
//
// The path tracer renders the plant twice in one render_views call (one BVH build;
// bench::measure in ray_replay.h): the first render's rays are counted, hashed and
// recorded by the interposer, the second, the same render again (`same_render`), is timed
// with the interposer forwarding straight to Embree. At the end of its pass (on_pass,
// while its Embree scene and the buffers it shares are alive) the recorded rays are traced
// again with raw rtcIntersect1 / rtcIntersect1M / rtcOccluded1 on that scene and the
// same threads (camera rays: every one, as the same streams, up to 8 M, else a subsample
// of about 300 k in runs of whole streams; bounce and shadow rays: every one, up to 2 M of
// each; each kind replayed until it has taken 0.1 CPU s). build_s is the time from render_views() to the recording render's first
// ray; render_s adds the timed trace. path_tracer_fraction_of_raw compares wall-clock
// rates; path_tracer_fraction_of_raw_cpu compares the CPU seconds of the timed trace with
// raw Embree's CPU seconds for the same number of rays of each kind, which a loaded
// machine does not skew. recording_trace_cpu_s is the recording render's trace (with the
// interposer's work), raw_embree_first_round_cpu_s raw Embree's at each kind's first
// replay round alone.
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/render.h"
#include "render/sampler.h"
#include "ray_replay.h"

namespace {

using cambium::bench::Clock;
using cambium::bench::peak_rss_mb;
using cambium::bench::recorder;

double seconds_since(Clock::time_point t)
{
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// ---- The synthetic plant ------------------------------------------------------------

struct Random {
    std::uint64_t state;
    float next()
    {
        state += 0x9e3779b97f4a7c15ULL;
        return static_cast<float>(cambium::render::mix64(state) >> 40) * 0x1.0p-24f;
    }
    float range(float lo, float hi) { return lo + (hi - lo) * next(); }
};

using cambium::geom::Vec3;

/// Appends a polyline of round linear segments with neighbour flags closing its joints.
void add_polyline(cambium::geom::LinearCurves& lines, const std::vector<Vec3>& points,
                  float r0, float r1, std::uint16_t material)
{
    auto first = static_cast<std::uint32_t>(lines.keys.size());
    std::size_t n = points.size();
    for (std::size_t i = 0; i < n; ++i) {
        float r = r0 + (r1 - r0) * float(i) / float(n - 1);
        lines.keys.push_back({float(points[i].x), float(points[i].y), float(points[i].z), r});
    }
    for (std::size_t i = 0; i + 1 < n; ++i) {
        lines.segments.push_back(first + static_cast<std::uint32_t>(i));
        std::uint8_t flags = 0;
        if (i > 0)
            flags |= cambium::geom::CurveFlags::neighbour_left;
        if (i + 2 < n)
            flags |= cambium::geom::CurveFlags::neighbour_right;
        lines.flags.push_back(flags);
        lines.material.push_back(material);
    }
}

/// A flat diamond leaf of 6 triangles in the xy plane, base at the origin, tip at y = 1.
cambium::geom::Prototype leaf_prototype()
{
    cambium::geom::Prototype p;
    p.name = "leaf";
    auto& m = p.geometry.mesh;
    m.positions = {{0, 0, 0}, {-0.25f, 0.35f, 0}, {0, 0.4f, 0}, {0.25f, 0.35f, 0},
                   {-0.2f, 0.7f, 0}, {0.2f, 0.7f, 0}, {0, 1, 0}};
    m.normals.assign(m.positions.size(), {0, 0, 1});
    m.uvs.assign(m.positions.size(), {0, 0});
    m.triangles = {{0, 2, 1}, {0, 3, 2}, {1, 2, 4}, {2, 3, 5}, {2, 5, 4}, {4, 5, 6}};
    m.material.assign(m.triangles.size(), cambium::geom::inherit_material);
    m.back_material.assign(m.triangles.size(), cambium::geom::inherit_material);
    m.texture.assign(m.triangles.size(), cambium::geom::no_texture);
    return p;
}

/// A rotation by `angle` about the unit `axis`, scaled, then moved to `at`: Embree's
/// column-major 3x4 layout.
std::array<float, 12> placement(const Vec3& axis, double angle, double scale, const Vec3& at)
{
    double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    double x = axis.x, y = axis.y, z = axis.z;
    double r[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                      {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                      {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
    std::array<float, 12> m{};
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row)
            m[std::size_t(col * 3 + row)] = static_cast<float>(r[row][col] * scale);
    m[9] = float(at.x);
    m[10] = float(at.y);
    m[11] = float(at.z);
    return m;
}

/// A tree: a trunk and wandering branches of 200 segments each, leaves on the branches.
cambium::geom::Scene make_plant(std::size_t segments, std::size_t leaves)
{
    cambium::geom::Scene s;
    Random rng{42};
    constexpr int per_branch = 200;
    constexpr double height = 20;
    std::vector<Vec3> trunk;
    for (int i = 0; i <= per_branch; ++i)
        trunk.push_back({0.3 * std::sin(i * 0.05), height * i / per_branch, 0});
    add_polyline(s.geometry.lines, trunk, 0.6f, 0.15f, 1);
    std::vector<Vec3> tips;  // where leaves go
    std::size_t branches = segments > per_branch ? segments / per_branch - 1 : 0;
    for (std::size_t b = 0; b < branches; ++b) {
        double y0 = rng.range(0.25f, 0.95f) * height;
        double phi = rng.range(0, 6.2831853f);
        Vec3 dir = cambium::geom::normalize(
            Vec3{std::cos(phi), rng.range(0.1f, 0.8f), std::sin(phi)});
        std::vector<Vec3> points{{0.3 * std::sin(y0 / height * per_branch * 0.05), y0, 0}};
        double step = 0.05 * (1.2 - y0 / height);
        for (int i = 0; i < per_branch; ++i) {
            Vec3 wobble{rng.range(-0.15f, 0.15f), rng.range(-0.1f, 0.15f),
                        rng.range(-0.15f, 0.15f)};
            dir = cambium::geom::normalize(dir + wobble);
            points.push_back(points.back() + dir * step);
        }
        add_polyline(s.geometry.lines, points, 0.06f, 0.008f, 1);
        for (int i = per_branch / 2; i <= per_branch; i += 10)
            tips.push_back(points[std::size_t(i)]);
    }
    if (leaves > 0 && !tips.empty()) {
        s.prototypes.push_back(leaf_prototype());
        for (std::size_t i = 0; i < leaves; ++i) {
            Vec3 at = tips[i % tips.size()];
            Vec3 axis = cambium::geom::normalize(
                Vec3{rng.range(-1, 1), rng.range(-1, 1), rng.range(-1, 1)} + Vec3{0, 0, 1e-3});
            cambium::geom::Instance inst;
            inst.prototype = 0;
            inst.transform = placement(axis, rng.range(0, 6.2831853f), 0.5, at);
            inst.material = inst.back_material = 2;
            s.instances.push_back(inst);
        }
    }
    for (const auto& k : s.geometry.lines.keys)
        s.bounds.extend(Vec3{k[0], k[1], k[2]});
    s.materials[1].diffuse = {0.45f, 0.33f, 0.2f};
    s.materials[2].diffuse = {0.25f, 0.6f, 0.2f};
    s.background = {0.8f, 0.85f, 0.95f};
    cambium::geom::Light sun;
    sun.kind = cambium::geom::Light::Kind::directional;
    sun.direction = {0.4, 1, 0.6};
    s.lights.push_back(sun);
    // Perspective, off every axis (axis-parallel rays are a slow case for curves).
    s.view.perspective = true;
    s.view.viewpoint = {12, 14, 19};
    s.view.reference_point = {0, 10, 0};
    s.view.viewing_angle_deg = 50;
    return s;
}

/// Whether the acceleration structure draws instances: one leaf in front of a camera.
bool accel_draws_instances()
{
    cambium::geom::Scene s;
    s.prototypes.push_back(leaf_prototype());
    cambium::geom::Instance inst;
    inst.material = inst.back_material = 2;
    s.instances.push_back(inst);  // identity: the leaf in the xy plane, y 0..1
    s.bounds.extend(Vec3{-1, -1, -1});
    s.bounds.extend(Vec3{1, 1, 1});
    auto camera = cambium::render::make_camera(s.view, s.bounds, 16, 16);
    cambium::render::EmbreeScene accel(s, camera);
    return accel.intersect({0, 0.5f, 5}, {0, 0, -1}, 0, 100).has_value();
}

int run(int argc, char** argv)
{
    double scale = 1;
    int threads = 0, width = 320, height = 240, spp = 16, depth = 4;
    bool skip_empty_pixels = true;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc)
                throw std::runtime_error(a + " needs a value");
            return argv[++i];
        };
        if (a == "--scale")
            scale = std::stod(value());
        else if (a == "--threads")
            threads = std::stoi(value());
        else if (a == "--spp")
            spp = std::stoi(value());
        else if (a == "--depth")
            depth = std::stoi(value());
        else if (a == "--trace-empty-pixels")
            skip_empty_pixels = false;
        else if (a == "--size") {
            std::string v = value();
            if (std::sscanf(v.c_str(), "%dx%d", &width, &height) != 2)
                throw std::runtime_error("--size wants WxH");
        } else
            throw std::runtime_error("unknown option " + a +
                                     " (--scale S --threads N --size WxH --spp N --depth N "
                                     "--trace-empty-pixels)");
    }
    if (!(scale > 0) || scale > 100)
        throw std::runtime_error("--scale must be in (0, 100]");
    auto segments = static_cast<std::size_t>(1'000'000 * scale);
    auto leaves = static_cast<std::size_t>(100'000 * scale);

    auto t0 = Clock::now();
    cambium::geom::Scene scene = make_plant(segments, leaves);
    double generate_s = seconds_since(t0);
    bool instances = accel_draws_instances();

    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    cambium::render::RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.samples_per_pixel = spp;
    settings.max_depth = depth;
    settings.threads = threads;
    settings.ambient = {0.1f, 0.1f, 0.1f};
    settings.aovs = false;  // the path tracer alone
    settings.skip_empty_pixels = skip_empty_pixels;
    auto camera = cambium::render::make_camera(scene.view, scene.bounds, width, height);
    std::size_t built_segments = 0;
    arena.execute([&] {
        // Counted apart, on the scene's own geometry (no BVH is built).
        built_segments =
            scene.geometry.lines.segment_count() + scene.geometry.curves.segment_count();
    });

    // The path tracer twice, the first render recorded by the interposer, the second timed
    // without it; the raw replay at the end of the second, while its Embree scene is alive.
    // The logs are allocated and touched here, before the renders. Camera rays (streams):
    // every one (up to 8 M; more: one run of streams in k, about 300 k rays). Bounces and
    // shadow rays: every one, up to 2 M of each (their count is not known before).
    const std::uint64_t camera_rays =
        std::uint64_t(width) * std::uint64_t(height) * std::uint64_t(spp);
    recorder.singles.prepare(2'000'000, true, 1);
    recorder.occlusion_rays.prepare(2'000'000, true, 1);
    if (camera_rays <= 8'000'000)  // every one (48 bytes each, with room for part-filled chunks)
        recorder.streams.prepare(camera_rays + 64 * cambium::bench::RayLog::chunk, false, 1);
    else
        recorder.streams.prepare(400'000, false, cambium::bench::one_in(300'000, camera_rays));
    auto r0 = Clock::now();
    const cambium::bench::Measurement m = cambium::bench::measure(scene, camera, settings);
    const cambium::bench::TraceFigures& t = m.trace;
    // From render_views() to the recording render's first ray (the BVH's build).
    double build_s = std::chrono::duration<double>(recorder.first_call - r0).count();
    double render_s = build_s + t.trace_s;  // as if the timed render had built the BVH
    double covered = 0;
    for (std::size_t i = 3; i < m.image.rgba.size(); i += 4)
        covered += m.image.rgba[i];

    const cambium::bench::RawFigures& raw = t.raw;
    auto rate = [](std::size_t n, double s) { return s > 0 ? double(n) / s : 0.0; };
    const double rays = double(t.rays());
    std::printf(
        "{\"scale\":%g,\"threads\":%d,\"segments\":%zu,\"embree_segments\":%zu,"
        "\"instances\":%zu,\"instances_in_accel\":%s,\"generate_s\":%.3f,\"build_s\":%.3f,"
        "\"peak_rss_mb_after_build\":%.1f,\"image\":\"%dx%d\",\"spp\":%d,\"max_depth\":%d,"
        "\"render_s\":%.3f,\"trace_s\":%.3f,\"paths\":%llu,\"coverage\":%.3f,"
        "\"intersect_rays\":%llu,\"occlusion_rays\":%llu,\"rays_per_s\":%.0f,"
        "\"paths_per_s\":%.0f,\"raw_embree\":{\"intersect_rays\":%zu,\"intersect_s\":%.3f,"
        "\"intersect_rays_per_s\":%.0f,\"hit_fraction\":%.3f,\"occlusion_rays\":%zu,"
        "\"occlusion_s\":%.3f,\"occlusion_rays_per_s\":%.0f,\"stream_rays\":%zu,"
        "\"stream_s\":%.3f,\"stream_rays_per_s\":%.0f,\"rays_per_s\":%.0f},"
        "\"stream_intersect_rays\":%llu,"
        "\"path_tracer_intersect_rays_per_s\":%.0f,\"path_tracer_fraction_of_raw\":%.3f,"
        "\"timed_render\":\"the second of two identical renders, not recorded\","
        "\"same_render\":%s,\"ray_hashes\":[\"%016llx\",\"%016llx\",\"%016llx\"],"
        "\"trace_cpu_s\":%.3f,\"recording_trace_cpu_s\":%.3f,\"raw_embree_cpu_s\":%.3f,"
        "\"raw_embree_first_round_cpu_s\":%.3f,"
        "\"path_tracer_fraction_of_raw_cpu\":%.3f,\"peak_rss_mb\":%.1f}\n",
        scale, threads, scene.geometry.lines.segment_count(), built_segments,
        scene.instances.size(), instances ? "true" : "false", generate_s, build_s,
        recorder.rss_at_first_call, width, height, spp, depth, render_s, t.trace_s,
        static_cast<unsigned long long>(m.timed.samples), covered / (double(width) * height),
        static_cast<unsigned long long>(t.intersections),
        static_cast<unsigned long long>(t.occlusions), rays / t.trace_s,
        double(m.timed.samples) / t.trace_s, raw.singles, raw.intersect_s,
        rate(raw.singles, raw.intersect_s),
        raw.singles == 0 ? 0.0 : double(raw.hits) / double(raw.singles), raw.occlusions,
        raw.occluded_s, rate(raw.occlusions, raw.occluded_s), raw.streams, raw.stream_s,
        rate(raw.streams, raw.stream_s), t.raw_rays_per_s(),
        static_cast<unsigned long long>(t.stream_intersections),
        double(t.intersections) / t.trace_s, t.path_tracer_fraction_of_raw(),
        m.same_render ? "true" : "false", static_cast<unsigned long long>(t.singles_hash),
        static_cast<unsigned long long>(t.streams_hash),
        static_cast<unsigned long long>(t.occlusions_hash), t.trace_cpu_s,
        t.recording_trace_cpu_s, t.raw_mix_cpu_s(), t.raw_mix_first_round_cpu_s(),
        t.path_tracer_fraction_of_raw_cpu(), peak_rss_mb());
    return 0;
}

}  // namespace

int main(int argc, char** argv)
{
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::printf("{\"error\":\"%s\"}\n", e.what());
        return 1;
    }
}
