// SPDX-License-Identifier: Apache-2.0
// The path tracer's rays against raw Embree on the same rays, shared by the render and
// convergence benchmarks.
//
// How it works: ray_replay.cpp defines rtcIntersect1, rtcIntersect1M and rtcOccluded1.
// cambium_render is a static library, so the executable's calls resolve to these
// definitions, which jump through a pointer to what they do now (Recorder below):
// Embree's own function (found with dlsym(RTLD_NEXT); the default), or a wrapper that
// counts each ray per thread, or one that also hashes it and records it, every ray or a
// systematic subsample, by kind: single intersection rays (bounces), occlusion (shadow) rays, and
// the camera rays the renderer traces as coherent streams (rtcIntersect1M, kept as whole
// streams).
//
// measure() renders the same view twice with the same settings in one render_views call
// (one BVH, each render a single pass). Renders are deterministic: the same rays for the
// same settings at any thread count (the rays' hashes agree; ray_replay_test checks it).
// - The recording render counts, hashes and records its rays. Its on_pass stops the
//   recording and sets the entry points to open the timed trace.
// - The timed render's first Embree call notes the time and sets every entry point to
//   Embree's own function: from then on the renderer's calls jump straight to Embree,
//   through one pointer, as a call through the PLT does. Its on_pass ends the trace and
//   replays the recorded rays with raw Embree calls on its scene, on its arena, singles
//   and shadow rays one at a time, streams as the same streams with a coherent context,
//   each ray with the primitive the path tracer's ray skipped.
// The two renders must make the same image with the same samples and the same ray count
// by the renderer's own counter (RenderReport::rays): `same_render`.
//
// The figures: the trace is the timed render's span from its first Embree call (the first
// ray of the pixel loop: the set-up traces none) to its on_pass, in wall and process CPU
// seconds; the rays it traced by kind are the recording render's counts. Each kind is
// replayed again and again until it has taken 0.1 CPU s (a replay of a few milliseconds
// is mostly thread wake-up). Raw Embree's CPU seconds for the same rays are, per kind, the
// traced count times the replay's CPU seconds per replayed ray;
// path_tracer_fraction_of_raw_cpu is their sum over the trace's CPU seconds (CPU time,
// unlike wall time, does not measure the neighbours on a loaded machine). The recording
// render's span is reported too (recording_trace_cpu_s): the trace with the interposer's
// counting, hashing and recording, which the timed render no longer pays.
//
// What recording costs (the recording render only, so the figures no longer depend on
// it): a relaxed load and a per-thread add per ray, a hash, and a 48-byte store (plus 12
// bytes for the skipped primitive) per recorded ray. Both benchmarks now record every ray
// (prepare_every_ray; render: the camera rays): a subsample's raw rate moved from run to
// run and with k by several percent (docs/benchmarks.md). For a subsample (prepare()),
// the recorder keeps every k-th group of each thread's rays (runs of
// RayLog::chunk consecutive rays, or of whole streams of about as many), k chosen per kind
// from the expected count; the slots are handed out a chunk at a time (one atomic add per
// chunk) and allocated and touched in prepare(), before the renders.
#pragma once

#include <embree3/rtcore.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/ray_counter.h"
#include "render/render.h"

namespace cambium::bench {

using Clock = std::chrono::steady_clock;

/// CPU seconds of the whole process (all threads): on a loaded machine wall time also
/// measures the neighbours, CPU time only this process's work.
double process_cpu_seconds();
/// The process's peak resident memory so far, in MB.
double peak_rss_mb();

/// Where one thread is in a RayLog: its chunk of slots [next, end), and the groups of
/// rays it has seen (for the subsample). A log's `epoch` tells a cursor left over from an
/// earlier recording to start afresh.
struct LogCursor {
    std::size_t next = 0, end = 0;
    std::size_t left = 0;     ///< rays still to see in the current group
    std::uint64_t groups = 0;  ///< groups seen (`chunk` rays, or whole streams of as many)
    bool keeping = false;      ///< whether the current group is recorded
    std::uint32_t epoch = 0;
};

/// Slots for recorded rays of one kind, handed to each thread a chunk at a time: one
/// atomic add per chunk rather than per ray (a counter shared by all threads would charge
/// the path tracer for cache-line contention that only the benchmark causes). Each thread
/// records one group of its rays in `every`, a group being `chunk` consecutive rays (or
/// consecutive whole streams of about as many rays): runs of neighbouring rays, so that the
/// replay keeps the locality between them that the trace had. Slots never filled keep the
/// sentinel tnear = -1 and are dropped before the replay.
struct RayLog {
    static constexpr std::size_t chunk = 4096;
    /// A thread's next and end once the log is full (before, each later ray took a chunk
    /// number from the shared counter: contention charged to the path tracer).
    static constexpr std::size_t full = SIZE_MAX;
    std::vector<RTCRay> rays;
    /// Beside each single ray, the primitive it skips (the one it leaves, which the round
    /// shapes' filters reject), so that the replay asks Embree the same question as the
    /// path tracer did; empty for the camera streams, which skip nothing.
    std::vector<render::PrimId> skips;
    std::atomic<std::size_t> chunks_taken{0};
    std::size_t every = 1;  ///< one group in `every` is recorded
    std::atomic<std::uint32_t> epoch{1};

    /// Makes `count` sentinel slots (before the clock starts: they are touched here), with
    /// room for each ray's skipped primitive when `with_skips`, recording one group in
    /// `every`; cursors of an earlier recording start afresh.
    void prepare(std::size_t count, bool with_skips, std::size_t every);
    /// Records r (which skips `skip`) if its group is kept.
    void record(const RTCRay& r, LogCursor& at, const render::PrimId& skip = {})
    {
        if (at.epoch != epoch.load(std::memory_order_relaxed))
            at = LogCursor{0, 0, 0, 0, false, epoch.load(std::memory_order_relaxed)};
        if (at.left == 0) {  // a new group
            at.left = chunk;
            at.keeping = at.groups++ % every == 0;
        }
        --at.left;
        if (at.keeping)
            store(r, at, skip);
    }
    /// Records the m rays of one stream call together in the calling thread's chunk (a
    /// new chunk when they do not fit; the old one's rest stays empty) if its group is
    /// kept, the first with its stream's size in `id` (Embree does not read it; the
    /// replay restores it).
    void record_stream(const RTCRayHit* rayhit, unsigned m, std::size_t stride, LogCursor& at);
    /// Drops the slots never filled.
    void compact();
    std::size_t bytes() const
    {
        return rays.size() * sizeof(RTCRay) + skips.size() * sizeof(render::PrimId);
    }

private:
    /// Stores r in the thread's chunk, taking a new one when it is full.
    void store(const RTCRay& r, LogCursor& at, const render::PrimId& skip)
    {
        if (at.next == at.end && !take_chunk(at))
            return;
        if (!skips.empty())
            skips[at.next] = skip;
        rays[at.next++] = r;
    }
    bool take_chunk(LogCursor& at);
};

/// One group in how many to record so that at most about `keep` of `expected` rays are
/// kept (rounded up: rounded down, a log of `keep` slots filled before the trace ended and
/// its last part was never replayed; 1 when expected is 0 or at most keep).
std::size_t one_in(std::size_t keep, std::uint64_t expected);

/// An order-independent fingerprint of rays: the sum of a hash of each ray's input (origin,
/// direction, span, mask, flags) and, for single rays, the primitive it skips. Equal sums
/// over two renders say they traced the same rays, whatever the threads' order.
std::uint64_t ray_hash(const RTCRay& r, const render::PrimId& skip = {});

/// Raw Embree on the recorded rays of each kind: rays replayed (each recorded ray as many
/// times as its kind was replayed), hits, wall and CPU seconds, and the first round's CPU
/// seconds alone (a round traces every recorded ray of its kind once).
struct RawFigures {
    std::size_t singles = 0, occlusions = 0, streams = 0;  ///< rays replayed
    std::uint64_t hits = 0, occluded = 0, stream_hits = 0;
    double intersect_s = 0, occluded_s = 0, stream_s = 0;
    double intersect_cpu_s = 0, occluded_cpu_s = 0, stream_cpu_s = 0;
    double intersect_first_cpu_s = 0, occluded_first_cpu_s = 0, stream_first_cpu_s = 0;
};

/// What the trace did and what raw Embree needs for the same rays (see the top).
struct TraceFigures {
    /// Traced in the recording render (the timed render traces the same rays).
    std::uint64_t intersections = 0, occlusions = 0;
    std::uint64_t stream_intersections = 0;  ///< of `intersections`: camera rays in streams
    /// ray_hash summed over the recording render's rays of each kind.
    std::uint64_t singles_hash = 0, occlusions_hash = 0, streams_hash = 0;
    double trace_s = 0, trace_cpu_s = 0;  ///< the timed render: first Embree call to its end
    /// The same span on the steady clock (CLOCK_MONOTONIC on Linux), in seconds: the window
    /// of a profile taken with `perf record -k CLOCK_MONOTONIC` that is the timed trace
    /// (benchmarks/embree_share.py).
    std::array<double, 2> trace_window_s{};
    /// Whether the timed render's calls went straight to Embree's own entry points from
    /// its first call to its end.
    bool timed_forwarded = false;
    /// The recording render's span (the trace with the interposer counting, hashing and
    /// recording every ray: what the timed render no longer pays).
    double recording_trace_s = 0, recording_trace_cpu_s = 0;
    RawFigures raw;
    /// Rays each kind's first replay round traced (singles, occlusions, streams): all
    /// that were recorded.
    std::array<std::size_t, 3> first_rays{};

    std::uint64_t rays() const { return intersections + occlusions; }
    std::uint64_t single_intersections() const { return intersections - stream_intersections; }
    /// Raw Embree's wall seconds for the trace's mix of rays, at the replayed rates.
    double raw_mix_s() const;
    /// Raw Embree's CPU seconds for the trace's mix of rays, at the replayed rates.
    double raw_mix_cpu_s() const;
    /// The same at the rates of each kind's first (coldest) replay round alone.
    double raw_mix_first_round_cpu_s() const;
    double raw_rays_per_s() const;  ///< wall
    double path_tracer_fraction_of_raw() const;      ///< wall rates
    double path_tracer_fraction_of_raw_cpu() const;  ///< raw_mix_cpu_s / trace_cpu_s
};

/// The process's one recorder (the interposed entry points write into it). The entry
/// points do one of four things, set here (each a pointer they jump through):
/// - forward (the default): straight to Embree's own function, counting nothing;
/// - count(): count each ray by kind, then forward (the pilot render);
/// - start() .. stop(): count, hash and record a subsample (the recording render);
/// - start_timed() .. stop_timed(): the first call notes the time and switches to
///   forwarding, so the timed render's rays go straight to Embree.
struct Recorder {
    render::RayCounter intersections, occlusions;  // per thread, uncontended; every ray
    render::RayCounter stream_intersections;  // of `intersections`: in streams
    render::RayCounter singles_hash, occlusions_hash, streams_hash;  // sums of ray_hash
    RayLog singles, occlusion_rays, streams;
    std::atomic<bool> started{false};  ///< the first Embree call since start() was seen
    Clock::time_point first_call;
    double first_call_cpu = 0;
    double rss_at_first_call = 0;  ///< peak RSS then, less the logs
    std::atomic<bool> timed_started{false};  ///< the same since start_timed()
    Clock::time_point timed_first_call;
    double timed_first_call_cpu = 0;
    RTCScene scene = nullptr;      ///< the render's, alive until render() returns
    std::mutex mutex;

    /// Allocates and touches logs of `keep` slots for each kind. Given the count of a kind
    /// expected in the trace, one group in k is recorded so that at most about 3/4 keep
    /// are (0 or at most that many expected: every ray, up to `keep`).
    void prepare(std::size_t keep, std::uint64_t expected_singles,
                 std::uint64_t expected_occlusions, std::uint64_t expected_streams);
    /// Logs for every ray of each kind: room for the expected count and a quarter more
    /// (the expectation is a pilot's, scaled), plus part-filled chunks; one group in 1.
    void prepare_every_ray(std::uint64_t expected_singles, std::uint64_t expected_occlusions,
                           std::uint64_t expected_streams);
    /// The entry points forward every ray to Embree, counting nothing.
    void forward();
    /// The entry points count every ray by kind, then forward it.
    void count();
    /// Starts recording: the next Embree call opens the recording render's trace.
    void start();
    /// Ends recording (call it first thing in the recording render's on_pass), keeps the
    /// rays recorded and forwards from now on.
    void stop();
    /// The next Embree call opens the timed trace; every call goes straight to Embree.
    void start_timed();
    /// Ends the timed trace (first thing in the timed render's on_pass).
    void stop_timed();
    /// Raw Embree on the recorded rays, on the timed render's scene, in the caller's arena
    /// (in its on_pass, after stop_timed()). Returns the trace's figures.
    TraceFigures replay();
    /// The logs' memory.
    std::size_t log_bytes() const
    {
        return singles.bytes() + occlusion_rays.bytes() + streams.bytes();
    }

private:
    std::uint64_t m_intersections0 = 0, m_occlusions0 = 0, m_streams0 = 0;
    std::uint64_t m_hashes0[3] = {0, 0, 0};
    TraceFigures m_trace;
};

extern Recorder recorder;

/// The recording render and the timed render (one render_views call of two views of the
/// same camera: one BVH, the same settings and rays), with the raw replay at the timed
/// render's end. The logs must be prepared; settings.passes is set to 1 and on_pass used.
struct Measurement {
    TraceFigures trace;
    render::RenderReport recording, timed;  ///< each render's report (its own ray count)
    render::Image image;                    ///< the timed render's
    /// Whether the two renders made the same image, bit for bit, with the same samples
    /// and rays by the renderer's own count: the timed render traced the recorded rays.
    bool same_render = false;
};
Measurement measure(const geom::Scene& scene, const render::Camera& camera,
                    render::RenderSettings settings);


}  // namespace cambium::bench
