// SPDX-License-Identifier: Apache-2.0
// The interposed Embree entry points, the ray logs and the raw replay (ray_replay.h).
#include "ray_replay.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <dlfcn.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <ctime>

#include "render/float_mode.h"
#include "render/sampler.h"

namespace cambium::bench {

Recorder recorder;

double process_cpu_seconds()
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

// ---- The logs --------------------------------------------------------------------------

void RayLog::prepare(std::size_t count, bool with_skips, std::size_t every_group)
{
    RTCRay sentinel{};
    sentinel.tnear = -1;
    rays.assign(count, sentinel);
    skips.assign(with_skips ? count : 0, {});
    chunks_taken = 0;
    every = std::max<std::size_t>(every_group, 1);
    epoch.fetch_add(1);
}

bool RayLog::take_chunk(LogCursor& at)
{
    if (at.next == full)  // no chunks left: not even the shared counter is touched
        return false;
    at.next = chunks_taken.fetch_add(1, std::memory_order_relaxed) * chunk;
    at.end = std::min(at.next + chunk, rays.size());
    if (at.next >= at.end) {  // full: record no more
        at.next = at.end = full;
        return false;
    }
    return true;
}

void RayLog::record_stream(const RTCRayHit* rayhit, unsigned m, std::size_t stride,
                           LogCursor& at)
{
    if (at.epoch != epoch.load(std::memory_order_relaxed))
        at = LogCursor{0, 0, 0, 0, false, epoch.load(std::memory_order_relaxed)};
    if (at.left == 0) {  // a new group of streams, of about `chunk` rays
        at.left = chunk;
        at.keeping = at.groups++ % every == 0;
    }
    at.left -= std::min<std::size_t>(at.left, m);
    if (!at.keeping || m == 0 || m > chunk)
        return;
    if (at.end - at.next < m && !take_chunk(at))  // whole streams only
        return;
    for (unsigned i = 0; i < m; ++i) {
        RTCRay r = reinterpret_cast<const RTCRayHit*>(reinterpret_cast<const char*>(rayhit) +
                                                      i * stride)->ray;
        r.id = i == 0 ? m : 0;
        rays[at.next++] = r;
    }
}

void RayLog::compact()
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

}  // namespace cambium::bench

// ---- The interposer --------------------------------------------------------------------

namespace {

using cambium::bench::recorder;
using Intersect1 = void (*)(RTCScene, RTCIntersectContext*, RTCRayHit*);
using Intersect1M = void (*)(RTCScene, RTCIntersectContext*, RTCRayHit*, unsigned int, size_t);
using Occluded1 = void (*)(RTCScene, RTCIntersectContext*, RTCRay*);

/// Embree's own entry points (the next definitions after this executable's).
struct EmbreeEntries {
    Intersect1 intersect;
    Intersect1M intersect_stream;
    Occluded1 occluded;
};

const EmbreeEntries& embree()
{
    static const EmbreeEntries e{
        reinterpret_cast<Intersect1>(dlsym(RTLD_NEXT, "rtcIntersect1")),
        reinterpret_cast<Intersect1M>(dlsym(RTLD_NEXT, "rtcIntersect1M")),
        reinterpret_cast<Occluded1>(dlsym(RTLD_NEXT, "rtcOccluded1"))};
    return e;
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

/// The first Embree call of a recording opens it: its time, CPU time, memory and scene.
void note_call(RTCScene scene)
{
    if (recorder.started.load(std::memory_order_relaxed))
        return;
    std::lock_guard lock(recorder.mutex);
    if (recorder.started)
        return;
    recorder.first_call = cambium::bench::Clock::now();
    recorder.first_call_cpu = cambium::bench::process_cpu_seconds();
    // Less the recorder's own logs (allocated and touched before the render).
    recorder.rss_at_first_call =
        cambium::bench::peak_rss_mb() - double(recorder.log_bytes()) / (1024.0 * 1024.0);
    recorder.scene = scene;
    recorder.started = true;
}

// What each entry point does now: Embree's own function (forwarding), or one of the
// wrappers below. The entry points jump through these pointers (a relaxed load of a
// pointer is a plain load), so forwarding costs what a call through the PLT does.
void forward_intersect(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh)
{
    embree().intersect(s, c, rh);
}
void forward_intersect_stream(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh, unsigned m,
                              size_t stride)
{
    embree().intersect_stream(s, c, rh, m, stride);
}
void forward_occluded(RTCScene s, RTCIntersectContext* c, RTCRay* r)
{
    embree().occluded(s, c, r);
}

// Before the first set_entries() they forward through embree() (resolved at first use).
std::atomic<Intersect1> intersect_entry{&forward_intersect};
std::atomic<Intersect1M> intersect_stream_entry{&forward_intersect_stream};
std::atomic<Occluded1> occluded_entry{&forward_occluded};

void set_entries(Intersect1 i, Intersect1M m, Occluded1 o)
{
    intersect_entry.store(i, std::memory_order_relaxed);
    intersect_stream_entry.store(m, std::memory_order_relaxed);
    occluded_entry.store(o, std::memory_order_relaxed);
}

/// Whether every entry point is Embree's own function.
bool forwarding()
{
    const EmbreeEntries& e = embree();
    return intersect_entry.load() == e.intersect &&
           intersect_stream_entry.load() == e.intersect_stream && occluded_entry.load() == e.occluded;
}

void set_forwarding()
{
    const EmbreeEntries& e = embree();
    set_entries(e.intersect, e.intersect_stream, e.occluded);
}

// ---- Counting (the pilot)

void count_intersect(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh)
{
    recorder.intersections.add();
    embree().intersect(s, c, rh);
}
void count_intersect_stream(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh, unsigned m,
                            size_t stride)
{
    recorder.intersections.add(m);
    recorder.stream_intersections.add(m);
    embree().intersect_stream(s, c, rh, m, stride);
}
void count_occluded(RTCScene s, RTCIntersectContext* c, RTCRay* r)
{
    recorder.occlusions.add();
    embree().occluded(s, c, r);
}

// ---- Recording: count, hash and record a subsample

void record_intersect(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh)
{
    recorder.intersections.add();
    note_call(s);
    const cambium::render::PrimId skip = skip_of(c);
    recorder.singles_hash.add(cambium::bench::ray_hash(rh->ray, skip));
    thread_local cambium::bench::LogCursor at;
    recorder.singles.record(rh->ray, at, skip);
    embree().intersect(s, c, rh);
}

// Camera rays are traced as coherent streams (EmbreeScene::intersect_coherent): counted
// apart and recorded stream by stream, so that the raw replay traces the same streams.
void record_intersect_stream(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh, unsigned m,
                             size_t stride)
{
    recorder.intersections.add(m);
    recorder.stream_intersections.add(m);
    note_call(s);
    std::uint64_t hash = 0;
    for (unsigned i = 0; i < m; ++i)
        hash += cambium::bench::ray_hash(
            reinterpret_cast<const RTCRayHit*>(reinterpret_cast<const char*>(rh) + i * stride)->ray);
    recorder.streams_hash.add(hash);
    thread_local cambium::bench::LogCursor at;
    recorder.streams.record_stream(rh, m, stride, at);
    embree().intersect_stream(s, c, rh, m, stride);
}

void record_occluded(RTCScene s, RTCIntersectContext* c, RTCRay* r)
{
    recorder.occlusions.add();
    note_call(s);
    const cambium::render::PrimId skip = skip_of(c);
    recorder.occlusions_hash.add(cambium::bench::ray_hash(*r, skip));
    thread_local cambium::bench::LogCursor at;
    recorder.occlusion_rays.record(*r, at, skip);
    embree().occluded(s, c, r);
}

// ---- The timed render: its first call notes the time, then every call forwards

void open_timed_trace(RTCScene scene)
{
    std::lock_guard lock(recorder.mutex);
    if (recorder.timed_started)
        return;
    recorder.timed_first_call = cambium::bench::Clock::now();
    recorder.timed_first_call_cpu = cambium::bench::process_cpu_seconds();
    recorder.scene = scene;
    set_forwarding();
    recorder.timed_started = true;
}

void timed_intersect(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh)
{
    open_timed_trace(s);
    embree().intersect(s, c, rh);
}
void timed_intersect_stream(RTCScene s, RTCIntersectContext* c, RTCRayHit* rh, unsigned m,
                            size_t stride)
{
    open_timed_trace(s);
    embree().intersect_stream(s, c, rh, m, stride);
}
void timed_occluded(RTCScene s, RTCIntersectContext* c, RTCRay* r)
{
    open_timed_trace(s);
    embree().occluded(s, c, r);
}

}  // namespace

extern "C" void rtcIntersect1(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit)
{
    intersect_entry.load(std::memory_order_relaxed)(scene, context, rayhit);
}

extern "C" void rtcIntersect1M(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit,
                               unsigned int m, size_t byte_stride)
{
    intersect_stream_entry.load(std::memory_order_relaxed)(scene, context, rayhit, m,
                                                           byte_stride);
}

extern "C" void rtcOccluded1(RTCScene scene, RTCIntersectContext* context, RTCRay* ray)
{
    occluded_entry.load(std::memory_order_relaxed)(scene, context, ray);
}

// ---- The replay --------------------------------------------------------------------------

namespace cambium::bench {
namespace {

/// The intersection context as render/accel.cpp extends it (SkipContext): Embree's, then
/// the primitive a ray must skip, the one the path tracer's ray skipped (the filters of
/// round shapes read it; camera rays skip none).
struct ReplayContext {
    RTCIntersectContext context;
    render::PrimId skip;
    ReplayContext() { rtcInitIntersectContext(&context); }
};

double seconds_since(Clock::time_point t)
{
    return std::chrono::duration<double>(Clock::now() - t).count();
}

/// A recorded ray as Embree takes it for intersection: no hit yet.
RTCRayHit unhit(const RTCRay& ray)
{
    RTCRayHit rh;
    rh.ray = ray;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

/// body(i, context) for i in [0, n), in parallel (grains of `grain`) on the caller's arena,
/// each task with the float modes the render's threads trace with (render/float_mode.h)
/// and its own replay context (`flags`); body returns the hits it found, summed into
/// `hits`. Returns the wall seconds.
template <class Body>
double replay_in_parallel(std::size_t n, std::size_t grain, RTCIntersectContextFlags flags,
                          std::uint64_t& hits, const Body& body)
{
    std::atomic<std::uint64_t> hit_count{0};
    auto t0 = Clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
        render::DenormalsFlushed flushed;
        ReplayContext c;
        c.context.flags = flags;
        std::uint64_t local = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            local += body(i, c);
        hit_count += local;
    });
    hits = hit_count;
    return seconds_since(t0);
}

/// Raw rtcIntersect1 (or rtcOccluded1) over the recorded rays, in parallel; returns seconds.
double replay(RTCScene scene, const RayLog& log, bool occlusion, std::uint64_t& hits)
{
    const std::vector<RTCRay>& rays = log.rays;
    return replay_in_parallel(rays.size(), 1024, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT, hits,
                              [&](std::size_t i, ReplayContext& c) -> std::uint64_t {
        if (!log.skips.empty())
            c.skip = log.skips[i];
        if (occlusion) {
            RTCRay ray = rays[i];
            embree().occluded(scene, &c.context, &ray);
            return ray.tfar < 0 ? 1 : 0;
        }
        RTCRayHit rh = unhit(rays[i]);
        embree().intersect(scene, &c.context, &rh);
        return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
    });
}

/// Raw rtcIntersect1M over the recorded streams (each as the path tracer traced it, with
/// a coherent context), in parallel; returns seconds.
double replay_streams(RTCScene scene, const std::vector<RTCRay>& rays, std::uint64_t& hits)
{
    std::vector<std::size_t> starts;  // each stream's first ray (its size in `id`)
    for (std::size_t i = 0; i < rays.size(); i += std::max<unsigned>(rays[i].id, 1))
        if (rays[i].id > 0 && i + rays[i].id <= rays.size())
            starts.push_back(i);
    return replay_in_parallel(starts.size(), 64, RTC_INTERSECT_CONTEXT_FLAG_COHERENT, hits,
                              [&](std::size_t b, ReplayContext& c) -> std::uint64_t {
        thread_local std::array<RTCRayHit, RayLog::chunk> batch;  // a stream fits its chunk
        const std::size_t first = starts[b];
        const unsigned m = rays[first].id;
        for (unsigned k = 0; k < m; ++k) {
            batch[k] = unhit(rays[first + k]);
            batch[k].ray.id = 0;
        }
        embree().intersect_stream(scene, &c.context, batch.data(), m, sizeof(RTCRayHit));
        std::uint64_t found = 0;
        for (unsigned k = 0; k < m; ++k)
            found += batch[k].hit.geomID != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
        return found;
    });
}

}  // namespace

std::size_t one_in(std::size_t keep, std::uint64_t expected)
{
    return keep > 0 && expected > keep ? std::size_t((expected + keep - 1) / keep) : 1;
}

std::uint64_t ray_hash(const RTCRay& r, const render::PrimId& skip)
{
    // RTCRay is twelve 4-byte fields; id (which the path tracer leaves unset) is left out.
    const std::array<float, 9> f{r.org_x, r.org_y, r.org_z, r.tnear, r.dir_x,
                                 r.dir_y, r.dir_z, r.time,  r.tfar};
    std::uint64_t h = 0x243f6a8885a308d3ULL;
    for (std::size_t i = 0; i < f.size(); i += 2) {
        std::uint32_t lo = 0, hi = 0;
        std::memcpy(&lo, &f[i], 4);
        if (i + 1 < f.size())
            std::memcpy(&hi, &f[i + 1], 4);
        h = render::mix64(h ^ (std::uint64_t{hi} << 32 | lo));
    }
    h = render::mix64(h ^ (std::uint64_t{r.mask} << 32 | r.flags));
    h = render::mix64(h ^ (std::uint64_t{skip.geom} << 32 | skip.prim));
    return render::mix64(h ^ skip.inst);
}

void Recorder::prepare(std::size_t keep, std::uint64_t expected_singles,
                       std::uint64_t expected_occlusions, std::uint64_t expected_streams)
{
    // A subsample aims at three quarters of the slots: the rest is room for part-filled
    // chunks (one per thread) and for a trace a little longer than expected.
    const std::size_t aim = keep / 4 * 3;
    singles.prepare(keep, true, one_in(aim, expected_singles));
    occlusion_rays.prepare(keep, true, one_in(aim, expected_occlusions));
    streams.prepare(keep, false, one_in(aim, expected_streams));
}

void Recorder::prepare_every_ray(std::uint64_t expected_singles,
                                 std::uint64_t expected_occlusions,
                                 std::uint64_t expected_streams)
{
    // Part-filled chunks: one per thread and, for streams, the end of each chunk a whole
    // stream did not fit in (at most max_coherent_rays - 1 slots of each).
    auto room = [](std::uint64_t expected) {
        return std::size_t(expected + expected / 4 + 64 * RayLog::chunk);
    };
    singles.prepare(room(expected_singles), true, 1);
    occlusion_rays.prepare(room(expected_occlusions), true, 1);
    streams.prepare(room(expected_streams), false, 1);
}

void Recorder::forward() { set_forwarding(); }

void Recorder::count() { set_entries(&count_intersect, &count_intersect_stream, &count_occluded); }

void Recorder::start()
{
    started = false;
    scene = nullptr;
    m_intersections0 = intersections.total();
    m_occlusions0 = occlusions.total();
    m_streams0 = stream_intersections.total();
    m_hashes0[0] = singles_hash.total();
    m_hashes0[1] = occlusions_hash.total();
    m_hashes0[2] = streams_hash.total();
    set_entries(&record_intersect, &record_intersect_stream, &record_occluded);
}

void Recorder::stop()
{
    const Clock::time_point end = Clock::now();
    const double end_cpu = process_cpu_seconds();
    set_forwarding();
    m_trace = {};
    m_trace.intersections = intersections.total() - m_intersections0;
    m_trace.occlusions = occlusions.total() - m_occlusions0;
    m_trace.stream_intersections = stream_intersections.total() - m_streams0;
    m_trace.singles_hash = singles_hash.total() - m_hashes0[0];
    m_trace.occlusions_hash = occlusions_hash.total() - m_hashes0[1];
    m_trace.streams_hash = streams_hash.total() - m_hashes0[2];
    if (started) {  // else the render traced no ray: no trace to time
        m_trace.recording_trace_s = std::chrono::duration<double>(end - first_call).count();
        m_trace.recording_trace_cpu_s = end_cpu - first_call_cpu;
    }
    singles.compact();
    occlusion_rays.compact();
    streams.compact();
}

void Recorder::start_timed()
{
    timed_started = false;
    scene = nullptr;
    set_entries(&timed_intersect, &timed_intersect_stream, &timed_occluded);
}

void Recorder::stop_timed()
{
    const Clock::time_point end = Clock::now();
    const double end_cpu = process_cpu_seconds();
    m_trace.timed_forwarded = timed_started && forwarding();
    set_forwarding();
    if (timed_started) {
        m_trace.trace_s = std::chrono::duration<double>(end - timed_first_call).count();
        m_trace.trace_cpu_s = end_cpu - timed_first_call_cpu;
        auto seconds = [](Clock::time_point t) {
            return std::chrono::duration<double>(t.time_since_epoch()).count();
        };
        m_trace.trace_window_s = {seconds(timed_first_call), seconds(end)};
    }
}

namespace {

/// Replays one kind's recorded rays (`once` traces them all and returns its wall seconds)
/// again and again until the replays have taken `min_cpu_s` CPU seconds (at most 32
/// rounds; a replay of a few milliseconds is mostly thread wake-up and scheduling noise),
/// adding up rays replayed, hits, wall and CPU seconds.
template <typename Once>
void replay_rounds(Once once, std::size_t recorded, std::size_t& replayed, std::uint64_t& hits,
                   double& seconds, double& cpu_seconds, double& first_cpu_seconds)
{
    constexpr double min_cpu_s = 0.1;
    for (int round = 0; recorded > 0 && round < 32 && cpu_seconds < min_cpu_s; ++round) {
        const double cpu0 = process_cpu_seconds();
        std::uint64_t round_hits = 0;
        seconds += once(round_hits);
        cpu_seconds += process_cpu_seconds() - cpu0;
        if (round == 0)
            first_cpu_seconds = cpu_seconds;
        hits += round_hits;
        replayed += recorded;
    }
}

}  // namespace

TraceFigures Recorder::replay()
{
    TraceFigures t = m_trace;
    RawFigures& raw = t.raw;
    if (!scene)
        return t;
    t.first_rays = {singles.rays.size(), occlusion_rays.rays.size(), streams.rays.size()};
    replay_rounds([&](std::uint64_t& hits) { return bench::replay(scene, singles, false, hits); },
                  singles.rays.size(), raw.singles, raw.hits, raw.intersect_s,
                  raw.intersect_cpu_s, raw.intersect_first_cpu_s);
    replay_rounds(
        [&](std::uint64_t& hits) { return bench::replay(scene, occlusion_rays, true, hits); },
        occlusion_rays.rays.size(), raw.occlusions, raw.occluded, raw.occluded_s,
        raw.occluded_cpu_s, raw.occluded_first_cpu_s);
    replay_rounds([&](std::uint64_t& hits) { return replay_streams(scene, streams.rays, hits); },
                  streams.rays.size(), raw.streams, raw.stream_hits, raw.stream_s,
                  raw.stream_cpu_s, raw.stream_first_cpu_s);
    return t;
}

// ---- The arithmetic ------------------------------------------------------------------------

namespace {

/// Raw Embree's seconds for `traced` rays of a kind, at its rate on the `replayed` ones
/// (none replayed, as with --depth 1's single rays: none to charge).
double raw_seconds_for(std::uint64_t traced, double replay_s, std::size_t replayed)
{
    return replayed > 0 && replay_s > 0 ? double(traced) * replay_s / double(replayed) : 0;
}

}  // namespace

double TraceFigures::raw_mix_s() const
{
    return raw_seconds_for(single_intersections(), raw.intersect_s, raw.singles) +
           raw_seconds_for(stream_intersections, raw.stream_s, raw.streams) +
           raw_seconds_for(occlusions, raw.occluded_s, raw.occlusions);
}

double TraceFigures::raw_mix_cpu_s() const
{
    return raw_seconds_for(single_intersections(), raw.intersect_cpu_s, raw.singles) +
           raw_seconds_for(stream_intersections, raw.stream_cpu_s, raw.streams) +
           raw_seconds_for(occlusions, raw.occluded_cpu_s, raw.occlusions);
}

double TraceFigures::raw_mix_first_round_cpu_s() const
{
    // A first round replays each recorded ray of its kind once (first_rays).
    return raw_seconds_for(single_intersections(), raw.intersect_first_cpu_s, first_rays[0]) +
           raw_seconds_for(stream_intersections, raw.stream_first_cpu_s, first_rays[2]) +
           raw_seconds_for(occlusions, raw.occluded_first_cpu_s, first_rays[1]);
}

double TraceFigures::raw_rays_per_s() const
{
    double s = raw_mix_s();
    return s > 0 ? double(rays()) / s : 0;
}

double TraceFigures::path_tracer_fraction_of_raw() const
{
    double raw_rate = raw_rays_per_s();
    return raw_rate > 0 && trace_s > 0 ? double(rays()) / trace_s / raw_rate : 0;
}

double TraceFigures::path_tracer_fraction_of_raw_cpu() const
{
    return trace_cpu_s > 0 ? raw_mix_cpu_s() / trace_cpu_s : 0;
}

}  // namespace cambium::bench

namespace cambium::bench {

Measurement measure(const geom::Scene& scene, const render::Camera& camera,
                    render::RenderSettings settings)
{
    Measurement m;
    settings.passes = 1;  // one pass a render: its on_pass is the end of its tracing
    int renders_ended = 0;
    settings.on_pass = [&](const render::Image&) {
        if (renders_ended++ == 0) {
            recorder.stop();
            recorder.start_timed();
        } else {
            recorder.stop_timed();
            m.trace = recorder.replay();  // in the render's arena: on its threads
        }
    };
    render::Image recorded;
    const std::array<render::Camera, 2> cameras{camera, camera};
    recorder.start();
    render::render_views(scene, cameras, settings,
                         [&](std::size_t view, render::Image& image, const render::RenderReport& r) {
        if (view == 0) {
            m.recording = r;
            recorded = std::move(image);
            return true;
        }
        m.timed = r;
        m.same_render = r.samples == m.recording.samples && r.rays == m.recording.rays &&
                        image.rgba.size() == recorded.rgba.size() &&
                        std::memcmp(image.rgba.data(), recorded.rgba.data(),
                                    image.rgba.size() * sizeof(float)) == 0;
        m.image = std::move(image);
        return true;
    });
    recorder.forward();  // whatever happened (a render with no pass calls no on_pass)
    return m;
}

}  // namespace cambium::bench
