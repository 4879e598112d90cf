// SPDX-License-Identifier: Apache-2.0
// Render benchmark: BVH build, peak memory and path-tracer rays per second on a large
// synthetic plant, beside raw Embree rtcIntersect1 on the same rays. Prints one JSON object.
//
// Usage: render [--scale S] [--threads N] [--size WxH] [--spp N] [--depth N]
// Default (scale 1): 1 M round linear segments in 5 000 branches plus 100 000 instances
// of a 6-triangle leaf prototype; 320x240 at 16 spp, depth 4.
//
// The path tracer's rays are counted by interposing rtcIntersect1 / rtcOccluded1: this
// executable defines them, cambium_render (a static library) links to these definitions,
// and they forward to Embree's through dlsym(RTLD_NEXT). The interposer also records the
// first rays of each kind the render traces; when its one pass ends (on_pass, while the
// render's Embree scene and the buffers it shares are alive) they are replayed with raw
// rtcIntersect1 / rtcOccluded1 on that same scene and the same threads. The render builds
// the BVH once: build_s is the time from render() to its first ray. The replay's context
// carries "skip nothing", so the early-out self-hit filter of round shapes still runs
// there as in the render (its only cost is the call). path_tracer_fraction_of_raw compares
// wall-clock rates; path_tracer_fraction_of_raw_cpu compares the CPU seconds of the trace
// with raw Embree's CPU seconds for the same number of rays of each kind, which a loaded
// machine does not skew.
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <dlfcn.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/float_mode.h"
#include "render/render.h"
#include "render/ray_counter.h"
#include "render/sampler.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t)
{
    return std::chrono::duration<double>(Clock::now() - t).count();
}

/// CPU seconds of the whole process (all threads): on a loaded machine wall time also
/// measures the neighbours, CPU time only this process's work.
double cpu_seconds()
{
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double peak_rss_mb()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // KiB
}

// ---- The interposer ------------------------------------------------------------------

/// Slots for recorded rays, handed to each thread a chunk at a time: one atomic add per
/// chunk rather than per ray (a counter shared by all threads would charge the path tracer
/// for cache-line contention that only the benchmark causes). Slots never filled keep
/// the sentinel tnear = -1 and are dropped before the replay.
struct RayLog {
    static constexpr std::size_t chunk = 4096;
    /// A thread's next and end once the log is full (before, each later ray took a chunk
    /// number from the shared counter: contention charged to the path tracer).
    static constexpr std::size_t full = std::numeric_limits<std::size_t>::max();
    std::vector<RTCRay> rays;
    /// Beside each single ray, the primitive it skips (the one it leaves, which the round
    /// shapes' filters reject), so that the replay asks Embree the same question as the
    /// path tracer did; empty for the camera streams, which skip nothing.
    std::vector<cambium::render::PrimId> skips;
    std::atomic<std::size_t> chunks_taken{0};

    /// Makes `count` sentinel slots (before the clock starts: they are touched here), with
    /// room for each ray's skipped primitive when `with_skips`.
    void prepare(std::size_t count, bool with_skips)
    {
        RTCRay sentinel{};
        sentinel.tnear = -1;
        rays.assign(count, sentinel);
        skips.assign(with_skips ? count : 0, {});
    }
    /// Records r (which skips `skip`) in the calling thread's chunk [next, end), taking a
    /// new one when full.
    void record(const RTCRay& r, std::size_t& next, std::size_t& end,
                const cambium::render::PrimId& skip = {})
    {
        if (next == end) {
            if (next == full)  // no chunks left: not even the shared counter is touched
                return;
            next = chunks_taken.fetch_add(1, std::memory_order_relaxed) * chunk;
            end = std::min(next + chunk, rays.size());
            if (next >= end) {  // full: record no more
                next = end = full;
                return;
            }
        }
        if (!skips.empty())
            skips[next] = skip;
        rays[next++] = r;
    }
    /// Records the m rays of one stream call together in the calling thread's chunk (a
    /// new chunk when they do not fit; the old one's rest stays empty), the first with
    /// its batch's size in `id` (Embree does not read it; the replay restores it).
    void record_batch(const RTCRayHit* rayhit, unsigned m, std::size_t stride, std::size_t& next,
                      std::size_t& end)
    {
        if (m == 0 || m > chunk)
            return;
        if (next != full && end - next < m)
            next = end;  // take a new chunk below
        for (unsigned i = 0; i < m; ++i) {
            RTCRay r = reinterpret_cast<const RTCRayHit*>(reinterpret_cast<const char*>(rayhit) +
                                                          i * stride)->ray;
            r.id = i == 0 ? m : 0;
            record(r, next, end);
            if (next == full)
                return;
        }
    }
    /// Drops the slots never filled.
    void compact()
    {
        std::size_t kept = 0;
        for (std::size_t i = 0; i < rays.size(); ++i)
            if (rays[i].tnear >= 0) {
                if (!skips.empty())
                    skips[kept] = skips[i];
                rays[kept++] = rays[i];
            }
        rays.resize(kept);
        if (!skips.empty())
            skips.resize(kept);
    }
    std::size_t bytes() const
    {
        return rays.size() * sizeof(RTCRay) + skips.size() * sizeof(cambium::render::PrimId);
    }
};

struct Recorder {
    cambium::render::RayCounter intersections, occlusions;  // per thread, uncontended
    cambium::render::RayCounter stream_intersections;  // of `intersections`: in streams
    std::atomic<bool> started{false};
    Clock::time_point first_call;
    double first_call_cpu = 0;
    double rss_at_first_call = 0;
    std::mutex mutex;
    RTCScene scene = nullptr;          // the render's: alive until render() returns
    /// The first rays traced, as given; stream_rays: those traced in streams
    /// (rtcIntersect1M: camera rays), each stream kept together.
    RayLog rays, occlusion_rays, stream_rays;
    std::atomic<bool> recording{false};
};
Recorder recorder;

using Intersect1 = void (*)(RTCScene, RTCIntersectContext*, RTCRayHit*);
using Occluded1 = void (*)(RTCScene, RTCIntersectContext*, RTCRay*);

Intersect1 real_intersect()
{
    static auto f = reinterpret_cast<Intersect1>(dlsym(RTLD_NEXT, "rtcIntersect1"));
    return f;
}

Occluded1 real_occluded()
{
    static auto f = reinterpret_cast<Occluded1>(dlsym(RTLD_NEXT, "rtcOccluded1"));
    return f;
}

/// The primitive a path tracer's ray skips, read from its context: render/accel.cpp's
/// SkipContext (Embree's context, then the PrimId), with which every context the path
/// tracer passes begins (as ReplayContext below assumes too).
cambium::render::PrimId skip_of(const RTCIntersectContext* context)
{
    struct Skipping {
        RTCIntersectContext context;
        cambium::render::PrimId skip;
    };
    return reinterpret_cast<const Skipping*>(context)->skip;
}

void note_call(RTCScene scene)
{
    if (!recorder.started.load(std::memory_order_relaxed)) {
        std::lock_guard lock(recorder.mutex);
        if (!recorder.started) {
            recorder.first_call = Clock::now();
            recorder.first_call_cpu = cpu_seconds();
            // Less the recorder's own buffers (allocated and touched before the render).
            recorder.rss_at_first_call =
                peak_rss_mb() - double(recorder.rays.bytes() + recorder.occlusion_rays.bytes() +
                                       recorder.stream_rays.bytes()) / (1024.0 * 1024.0);
            recorder.scene = scene;
            recorder.started = true;
        }
    }
}

}  // namespace

extern "C" void rtcIntersect1(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit)
{
    if (recorder.recording.load(std::memory_order_relaxed)) {
        note_call(scene);
        recorder.intersections.add();
        thread_local std::size_t next = 0, end = 0;
        recorder.rays.record(rayhit->ray, next, end, skip_of(context));
    }
    real_intersect()(scene, context, rayhit);
}

// Camera rays are traced as coherent streams (EmbreeScene::intersect_coherent): counted
// apart and recorded stream by stream, so that the raw replay traces the same streams.
extern "C" void rtcIntersect1M(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit,
                               unsigned int m, size_t byte_stride)
{
    using Intersect1M = void (*)(RTCScene, RTCIntersectContext*, RTCRayHit*, unsigned int, size_t);
    static auto real = reinterpret_cast<Intersect1M>(dlsym(RTLD_NEXT, "rtcIntersect1M"));
    if (recorder.recording.load(std::memory_order_relaxed)) {
        note_call(scene);
        recorder.intersections.add(m);
        recorder.stream_intersections.add(m);
        thread_local std::size_t next = 0, end = 0;
        recorder.stream_rays.record_batch(rayhit, m, byte_stride, next, end);
    }
    real(scene, context, rayhit, m, byte_stride);
}

extern "C" void rtcOccluded1(RTCScene scene, RTCIntersectContext* context, RTCRay* ray)
{
    if (recorder.recording.load(std::memory_order_relaxed)) {
        note_call(scene);
        recorder.occlusions.add();
        thread_local std::size_t next = 0, end = 0;
        recorder.occlusion_rays.record(*ray, next, end, skip_of(context));
    }
    real_occluded()(scene, context, ray);
}

namespace {

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

/// The intersection context as render/accel.cpp extends it (SkipContext): Embree's, then
/// the primitive a ray must skip, the one the path tracer's ray skipped (the filters of
/// round shapes read it; camera rays skip none).
struct ReplayContext {
    RTCIntersectContext context;
    cambium::render::PrimId skip;
    ReplayContext() { rtcInitIntersectContext(&context); }
};

/// Raw rtcIntersect1 (or rtcOccluded1) over the recorded rays, in parallel; returns seconds.
double replay(RTCScene scene, const RayLog& log, bool occlusion, std::uint64_t& hits)
{
    const std::vector<RTCRay>& rays = log.rays;
    std::atomic<std::uint64_t> hit_count{0};
    auto t0 = Clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
        // The modes the render's threads trace with (render/float_mode.h).
        cambium::render::DenormalsFlushed flushed;
        ReplayContext c;
        std::uint64_t local = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (!log.skips.empty())
                c.skip = log.skips[i];
            if (occlusion) {
                RTCRay ray = rays[i];
                real_occluded()(scene, &c.context, &ray);
                local += ray.tfar < 0 ? 1 : 0;
                continue;
            }
            RTCRayHit rh;
            rh.ray = rays[i];
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            real_intersect()(scene, &c.context, &rh);
            local += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
        }
        hit_count += local;
    });
    hits = hit_count;
    return seconds_since(t0);
}

/// Raw rtcIntersect1M over the recorded streams (each as the path tracer traced it, with
/// a coherent context), in parallel; returns seconds.
double replay_streams(RTCScene scene, const std::vector<RTCRay>& rays, std::uint64_t& hits)
{
    using Intersect1M = void (*)(RTCScene, RTCIntersectContext*, RTCRayHit*, unsigned int, size_t);
    static auto real = reinterpret_cast<Intersect1M>(dlsym(RTLD_NEXT, "rtcIntersect1M"));
    std::vector<std::size_t> starts;  // each stream's first ray (its size in `id`)
    for (std::size_t i = 0; i < rays.size(); i += std::max<unsigned>(rays[i].id, 1))
        if (rays[i].id > 0 && i + rays[i].id <= rays.size())
            starts.push_back(i);
    std::atomic<std::uint64_t> hit_count{0};
    auto t0 = Clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, starts.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
        cambium::render::DenormalsFlushed flushed;
        ReplayContext c;
        c.context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        std::array<RTCRayHit, RayLog::chunk> batch;
        std::uint64_t local = 0;
        for (std::size_t b = r.begin(); b != r.end(); ++b) {
            const std::size_t first = starts[b];
            const unsigned m = rays[first].id;
            for (unsigned k = 0; k < m; ++k) {
                batch[k].ray = rays[first + k];
                batch[k].ray.id = 0;
                batch[k].hit.geomID = RTC_INVALID_GEOMETRY_ID;
                batch[k].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            }
            real(scene, &c.context, batch.data(), m, sizeof(RTCRayHit));
            for (unsigned k = 0; k < m; ++k)
                local += batch[k].hit.geomID != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
        }
        hit_count += local;
    });
    hits = hit_count;
    return seconds_since(t0);
}

/// Raw Embree on the recorded rays of both kinds.
struct RawFigures {
    std::uint64_t hits = 0, occluded = 0, stream_hits = 0;
    double intersect_s = 0, occluded_s = 0, stream_s = 0;
    double intersect_cpu_s = 0, occluded_cpu_s = 0, stream_cpu_s = 0;
};

int run(int argc, char** argv)
{
    double scale = 1;
    int threads = 0, width = 320, height = 240, spp = 16, depth = 4;
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
        else if (a == "--size") {
            std::string v = value();
            if (std::sscanf(v.c_str(), "%dx%d", &width, &height) != 2)
                throw std::runtime_error("--size wants WxH");
        } else
            throw std::runtime_error("unknown option " + a +
                                     " (--scale S --threads N --size WxH --spp N --depth N)");
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
    settings.passes = 1;    // one pass: its end (on_pass) is the end of tracing
    auto camera = cambium::render::make_camera(scene.view, scene.bounds, width, height);
    std::size_t built_segments = 0;
    arena.execute([&] {
        // Counted apart, on the scene's own geometry (no BVH is built).
        built_segments =
            scene.geometry.lines.segment_count() + scene.geometry.curves.segment_count();
    });

    // The path tracer, counted by the interposer; the raw replay at the end of its pass,
    // while its Embree scene is alive.
    recorder.rays.prepare(2'000'000, true);  // touched here, before the clock starts
    recorder.occlusion_rays.prepare(2'000'000, true);
    recorder.stream_rays.prepare(2'000'000, false);
    recorder.recording = true;
    Clock::time_point trace_end;
    double trace_end_cpu = 0;
    std::uint64_t intersections = 0, occlusions = 0, stream_intersections = 0;
    RawFigures raw;
    settings.on_pass = [&](const cambium::render::Image&) {
        trace_end = Clock::now();
        trace_end_cpu = cpu_seconds();
        recorder.recording = false;
        intersections = recorder.intersections.total();
        occlusions = recorder.occlusions.total();
        stream_intersections = recorder.stream_intersections.total();
        recorder.rays.compact();
        recorder.occlusion_rays.compact();
        recorder.stream_rays.compact();
        arena.execute([&] {
            double cpu0 = cpu_seconds();
            raw.intersect_s = replay(recorder.scene, recorder.rays, false, raw.hits);
            double cpu1 = cpu_seconds();
            raw.occluded_s =
                replay(recorder.scene, recorder.occlusion_rays, true, raw.occluded);
            double cpu2 = cpu_seconds();
            raw.stream_s = replay_streams(recorder.scene, recorder.stream_rays.rays, raw.stream_hits);
            raw.intersect_cpu_s = cpu1 - cpu0;
            raw.occluded_cpu_s = cpu2 - cpu1;
            raw.stream_cpu_s = cpu_seconds() - cpu2;
        });
    };
    auto r0 = Clock::now();
    cambium::render::RenderReport report;
    cambium::render::Image image = cambium::render::render(scene, camera, settings, &report);
    double build_s = std::chrono::duration<double>(recorder.first_call - r0).count();
    double trace_s = std::chrono::duration<double>(trace_end - recorder.first_call).count();
    double render_s = std::chrono::duration<double>(trace_end - r0).count();
    double covered = 0;
    for (std::size_t i = 3; i < image.rgba.size(); i += 4)
        covered += image.rgba[i];

    double rays = double(intersections + occlusions);
    // Raw Embree's time for the path tracer's mix of rays, at the replayed rates.
    auto rate = [](std::size_t n, double s) { return s > 0 ? double(n) / s : 0.0; };
    // Rays traced one by one and in streams (camera rays) are replayed as they were traced.
    const std::uint64_t single_intersections = intersections - stream_intersections;
    double raw_intersect_rate = rate(recorder.rays.rays.size(), raw.intersect_s);
    double raw_stream_rate = rate(recorder.stream_rays.rays.size(), raw.stream_s);
    double raw_occluded_rate = rate(recorder.occlusion_rays.rays.size(), raw.occluded_s);
    double raw_mix_s =
        (raw_intersect_rate > 0 ? double(single_intersections) / raw_intersect_rate : 0) +
        (raw_stream_rate > 0 ? double(stream_intersections) / raw_stream_rate : 0) +
        (raw_occluded_rate > 0 ? double(occlusions) / raw_occluded_rate : 0);
    double raw_rays_per_s = raw_mix_s > 0 ? rays / raw_mix_s : 0;
    // The same in CPU seconds (the measure that holds on a loaded machine).
    double trace_cpu_s = trace_end_cpu - recorder.first_call_cpu;
    // Raw Embree's CPU seconds for `traced` rays of a kind, at its rate on the `recorded`
    // ones replayed (none recorded, as with --depth 1's single rays: none to charge).
    auto raw_cpu_for = [](double traced, double replay_cpu_s, std::size_t recorded) {
        return recorded > 0 && replay_cpu_s > 0 ? traced * replay_cpu_s / double(recorded) : 0;
    };
    double raw_mix_cpu_s =
        raw_cpu_for(double(single_intersections), raw.intersect_cpu_s, recorder.rays.rays.size()) +
        raw_cpu_for(double(stream_intersections), raw.stream_cpu_s,
                    recorder.stream_rays.rays.size()) +
        raw_cpu_for(double(occlusions), raw.occluded_cpu_s, recorder.occlusion_rays.rays.size());
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
        "\"trace_cpu_s\":%.3f,\"raw_embree_cpu_s\":%.3f,"
        "\"path_tracer_fraction_of_raw_cpu\":%.3f,\"peak_rss_mb\":%.1f}\n",
        scale, threads, scene.geometry.lines.segment_count(), built_segments,
        scene.instances.size(), instances ? "true" : "false", generate_s, build_s,
        recorder.rss_at_first_call, width, height, spp, depth, render_s, trace_s,
        static_cast<unsigned long long>(report.samples), covered / (double(width) * height),
        static_cast<unsigned long long>(intersections),
        static_cast<unsigned long long>(occlusions), rays / trace_s,
        double(report.samples) / trace_s, recorder.rays.rays.size(), raw.intersect_s,
        raw_intersect_rate,
        recorder.rays.rays.empty() ? 0.0 : double(raw.hits) / double(recorder.rays.rays.size()),
        recorder.occlusion_rays.rays.size(), raw.occluded_s, raw_occluded_rate,
        recorder.stream_rays.rays.size(), raw.stream_s, raw_stream_rate, raw_rays_per_s,
        static_cast<unsigned long long>(stream_intersections),
        double(intersections) / trace_s,
        raw_rays_per_s > 0 ? rays / trace_s / raw_rays_per_s : 0.0, trace_cpu_s, raw_mix_cpu_s,
        trace_cpu_s > 0 ? raw_mix_cpu_s / trace_cpu_s : 0.0, peak_rss_mb());
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
