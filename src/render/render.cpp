// SPDX-License-Identifier: Apache-2.0
// The render layer's entry points: render a Scene to an Image (image_io.h writes it to a file).
//
// Every pixel keeps its own running sums; a pass adds samples i = n .. target-1 to each
// pixel still sampled, in order, so the image is a pure function of (scene, settings,
// seed) whatever the thread count, tile order or number of passes. Adaptive sampling
// decides between passes from the pixels' own sums, which keeps it deterministic too.
#include "render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "render/accel.h"
#include "render/color.h"
#include "render/denoise.h"
#include "render/film.h"
#include "render/float_mode.h"
#include "render/integrator.h"
#include "render/labels.h"
#include "render/organ_masks.h"
#include "render/screen_mask.h"
#include "render/texture.h"

namespace cambium::render {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int tile_size = 16;
constexpr int first_pass_samples = 8;    // automatic passes: 8, 16, 32, ... spp

void check_settings(const RenderSettings& s)
{
    if (s.width <= 0 || s.height <= 0)
        throw Error("render: image size " + std::to_string(s.width) + "x" +
                    std::to_string(s.height) + " is empty");
    if (std::int64_t(s.width) * s.height > max_image_pixels)
        throw Error("render: image size " + std::to_string(s.width) + "x" +
                    std::to_string(s.height) + " is larger than 2^26 pixels");
    if (s.samples_per_pixel <= 0)
        throw Error("render: samples per pixel must be positive, not " +
                    std::to_string(s.samples_per_pixel));
    if (s.max_depth <= 0)
        throw Error("render: maximum path depth must be positive, not " +
                    std::to_string(s.max_depth));
    if (s.threads < 0)
        throw Error("render: thread count must not be negative");
    if (s.passes < 0)
        throw Error("render: the number of passes must not be negative, not " +
                    std::to_string(s.passes));
    if (!(s.noise_target >= 0) || !(s.time_budget_s >= 0))
        throw Error("render: the noise target and the time budget must not be negative");
    if (!(s.filter_radius >= 0) || s.filter_radius > 16)
        throw Error("render: the filter radius must be between 0 and 16 pixels");
    if (!(s.aperture_radius >= 0) || !(s.focus_distance >= 0))
        throw Error("render: the aperture and the focus distance must not be negative");
    const PixelRect& c = s.crop;
    if (s.denoiser && !c.empty())
        throw Error("render: --denoise needs the whole image; it cannot denoise a crop "
                    "(--tile, --mpi)");
    if (!c.empty() && (c.x < 0 || c.y < 0 || c.x > s.width - c.width || c.y > s.height - c.height))
        throw Error("render: the crop " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                    "+" + std::to_string(c.x) + "+" + std::to_string(c.y) +
                    " is not inside the image");
}

/// The pixels returned: the crop, or the whole image.
PixelRect output_rect(const RenderSettings& s)
{
    return s.crop.empty() ? PixelRect{0, 0, s.width, s.height} : s.crop;
}

/// The pixels sampled: the crop grown by the margin that adaptive sampling's decisions
/// can cross. A pixel stops when its 3x3 neighbourhood has converged, checked after
/// every pass but the last, so after pass k a pixel's sums depend on pixels up to k - 1
/// away; pixels at the margin's edge (which clamp their neighbourhood there, not at the
/// image's edge) may decide wrongly, but their error reaches only passes - 1 pixels in.
PixelRect sampled_rect(const RenderSettings& s, std::size_t passes)
{
    PixelRect out = output_rect(s);
    if (s.noise_target <= 0 || passes <= 1)
        return out;
    int margin = int(std::min<std::size_t>(passes - 1, std::size_t(std::max(s.width, s.height))));
    int x0 = std::max(0, out.x - margin), y0 = std::max(0, out.y - margin);
    int x1 = std::min(s.width, out.x + out.width + margin);
    int y1 = std::min(s.height, out.y + out.height + margin);
    return {x0, y0, x1 - x0, y1 - y0};
}

/// The organ a camera ray's first hit shows (provenance, docs/architecture.md): the
/// module that drew it, or placed its instance, in its plant placement (a scene file's;
/// no_plant for a single plant).
OrganKey organ_key_of(const geom::Scene& scene, const VisibleSurface& v)
{
    if (v.geom_id == ground_geom_id)
        return ground_organ;
    if (v.primitive == PrimId::none)
        return unattributed_organ;
    const PrimitiveKind kind = primitive_kind(v.shape);
    std::uint32_t module = geom::no_module, plant = geom::Instance::no_plant;
    if (v.instance == PrimId::none || v.instance >= scene.instances.size()) {
        const auto& m = modules_of(scene.geometry, kind);
        module = v.primitive < m.size() ? m[v.primitive] : geom::no_module;
    } else {
        const geom::Instance& in = scene.instances[v.instance];
        plant = in.plant;
        if (in.module != geom::no_module) {
            module = in.module;
        } else {
            const auto& m = modules_of(scene.prototypes[in.prototype].geometry, kind);
            module = v.primitive < m.size() ? m[v.primitive] : geom::no_module;
        }
    }
    return module == geom::no_module ? unattributed_organ : organ_key(plant, module);
}

/// The denoiser's organ id of a hit (render/denoise.h): the module for a single plant's
/// organ, a scene file's (plant, module) hashed into the ids below the reserved ones.
std::uint32_t organ_of(const geom::Scene& scene, const VisibleSurface& v)
{
    const OrganKey key = organ_key_of(scene, v);
    if (key == ground_organ)
        return organ_ground;
    if (key == unattributed_organ)
        return organ_unknown;
    if ((key >> 32) == geom::Instance::no_plant)
        return std::min(static_cast<std::uint32_t>(key), organ_unknown - 1);
    return std::min(static_cast<std::uint32_t>(mix64(key)), organ_unknown - 1);
}

/// What a camera ray that meets nothing adds to its pixel when that is the same in every
/// direction (no visible environment) and finite: take_sample's sums for camera_miss's
/// result, made once per view instead of once per sample (most samples of a plant miss).
struct FlatMiss {
    Vec3f radiance;
    double luminance = 0;
};

std::optional<FlatMiss> flat_miss(const PathContext& ctx, const RenderSettings& s)
{
    if (ctx.environment_visible)
        return std::nullopt;
    // camera_miss's radiance (the same addition), after take_sample's transparency.
    Vec3f radiance;
    if (ctx.max_depth > 0)
        radiance += ctx.background;
    if (s.transparent_background || s.ground.shadow_catcher)
        radiance = Vec3f();
    if (!std::isfinite(radiance.x + radiance.y + radiance.z))
        return std::nullopt;  // take_sample counts it as not finite
    return FlatMiss{radiance, luminance(radiance)};
}

/// Everything one sample needs, shared read-only by all threads.
struct RenderState {
    const PathContext& ctx;
    const EmbreeScene& accel;
    const Camera& camera;
    const RenderSettings& settings;
    FilterTable filter;
    bool lens = false;
    std::atomic<std::uint64_t>* nonfinite = nullptr;  // samples whose radiance was NaN or infinite
    /// Camera rays made in float (Camera::generate_rays_f): a pinhole perspective camera
    /// without clipping, and the box filter (whose image points are floats already).
    bool float_rays = camera.single_precision() && filter.box();
    /// A parallel camera's traced rays made in one vectorised pass (generate_parallel_rays:
    /// the same bits), for the box filter's float image points.
    bool parallel_rays = camera.projection() == Camera::Projection::parallel && filter.box();
    /// Camera rays that intersect_coherent need not check one by one: float rays start at
    /// the eye, which check_range put within reach of Embree; parallel ones where no front
    /// plane moves them out of it.
    bool rays_in_reach = float_rays || (parallel_rays && camera.parallel_rays_in_reach());
    bool adaptive = settings.noise_target > 0;
    /// Samples from two replicas (see replica_index): adaptive sampling and denoising.
    bool split = adaptive || settings.denoiser != nullptr;
    bool aovs = settings.aovs || settings.denoiser != nullptr || settings.organ_mask_depth > 0;
    /// The scene, for the organ of each pixel's nearest hit (denoising only; else null).
    const geom::Scene* organs = nullptr;
    /// Organ masks (RenderSettings::organ_mask_depth): the scene, and the film's organ
    /// counts, a pixel's at its extras' offset from `extras` (null: no masks).
    const geom::Scene* mask_scene = nullptr;
    OrganSamples* organ_samples = nullptr;
    const PixelExtras* extras = nullptr;
    std::optional<FlatMiss> miss = flat_miss(ctx, settings);
    /// The pixels that may meet the scene (screen_mask); the others take
    /// take_background_samples. Null: every pixel is traced.
    const ScreenMask* mask = nullptr;
};

/// A camera ray's cone: a parallel camera's rays are a pixel wide; a perspective one's
/// start at a point and widen by a pixel's angle.
RayCone camera_cone(const Camera& camera)
{
    if (camera.projection() == Camera::Projection::parallel)
        return {static_cast<float>(camera.pixel_size()), 0};
    return {0, static_cast<float>(camera.pixel_size_at(camera.origin() + camera.forward()))};
}

// Adaptive sampling needs each pixel's error, and the error of stratified (Sobol) samples
// is not the spread of the samples over sqrt(n): that holds for independent samples only
// and overstates a net's error many times (the render ran on long after its target). So
// an adaptive render draws two independently scrambled replicas of the sequence, even
// samples from one and odd from the other: the two replica means are independent and
// equally good, and half their difference estimates the error of their average without
// bias, whatever the stratification (randomised quasi-Monte Carlo's replica estimate).
// Each replica is a net of half the samples; a render without a noise target keeps one.

/// The index of sample i in its replica's sequence.
std::uint32_t replica_index(std::uint32_t i) { return i >> 1; }

/// The seed of sample i's replica.
std::uint64_t replica_seed(std::uint64_t seed, std::uint32_t i)
{
    return (i & 1u) ? mix64(seed ^ 0x6a09e667f3bcc909ULL) : seed;
}

/// The hashes pixel (x, y) draws its samples from: the seed's, and the odd replica's
/// (made for adaptive sampling only); made once per pixel and pass.
struct PixelReplicas {
    PixelSeeds even;
    std::optional<PixelSeeds> odd;
    PixelReplicas(int x, int y, std::uint64_t seed, bool adaptive)
        : even(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), seed)
    {
        if (adaptive)
            odd.emplace(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                        replica_seed(seed, 1));
    }
    const PixelSeeds& seeds(std::uint32_t replica) const { return replica ? *odd : even; }
};

/// The sampler of sample i of a pixel: its replica's sequence at its index there.
Sampler sampler_of(const RenderState& f, const PixelReplicas& replicas, std::uint32_t i)
{
    return Sampler(replicas.seeds(f.split ? (i & 1u) : 0), f.split ? replica_index(i) : i,
                   f.settings.sampler);
}

/// A batch of camera samples traced together (trace_batch): made once per thread, in
/// RowBatches, not per pixel or tile (its members' initialisers cost a visible share of
/// the pixel loop).
struct CameraBatch {
    static constexpr std::uint32_t size = EmbreeScene::max_coherent_rays;
    std::array<float, size> jx, jy;  // film pairs, then (float rays) image points
    std::array<PixelPoint, size> points;
    std::array<CameraRay, size> camera_rays;
    /// Where each camera ray (traced in single precision from the near clipping plane)
    /// starts along the camera's ray.
    std::array<double, size> tnear;
    std::array<CameraRayF, size> rays;
    ParallelRays parallel;  // the traced rays instead, where RenderState::parallel_rays
    std::array<std::optional<SurfaceHit>, size> hits;
    /// Bit k set where hits[k] has a value (intersect_coherent's), so that add_batch
    /// reads only the hits there are (each flag lies in its own hit's cache line).
    std::uint32_t hit_bits = 0;

    /// The traced camera ray of sample k.
    CameraRayF ray(const RenderState& f, std::uint32_t k) const
    {
        return f.parallel_rays ? parallel.ray(k) : rays[k];
    }
};
static_assert(CameraBatch::size <= ParallelRays::capacity);

/// The film pairs of samples i0 .. i0 + n - 1 of a pixel (n at most CameraBatch::size),
/// into jx and jy: the values of sampler_of(f, replicas, i).get2d(film), made per replica
/// in one loop (sobol_pairs).
void film_pairs(const RenderState& f, const PixelReplicas& replicas, std::uint32_t i0,
                std::uint32_t n, CameraBatch& b)
{
    if (f.settings.sampler != SampleSequence::sobol) {
        for (std::uint32_t k = 0; k < n; ++k) {
            auto [u, v] = sampler_of(f, replicas, i0 + k).get2d(sample_dimension::film);
            b.jx[k] = u;
            b.jy[k] = v;
        }
        return;
    }
    if (!f.split) {
        sobol_pairs(replicas.even, sample_dimension::film, i0, n, b.jx.data(), b.jy.data());
        return;
    }
    // Even samples are the first replica's, odd ones the second's (replica_index).
    std::array<float, CameraBatch::size> x, y;
    for (std::uint32_t r = 0; r < 2; ++r) {
        std::uint32_t first = i0 + ((i0 ^ r) & 1u);  // the replica's first sample in the batch
        if (first >= i0 + n)
            continue;
        std::uint32_t count = (i0 + n - first + 1) / 2;
        sobol_pairs(replicas.seeds(r), sample_dimension::film, replica_index(first), count,
                    x.data(), y.data());
        for (std::uint32_t j = 0; j < count; ++j) {
            b.jx[first - i0 + 2 * j] = x[j];
            b.jy[first - i0 + 2 * j] = y[j];
        }
    }
}

/// The camera rays of samples i0 .. i0 + n - 1 of pixel (x, y) (n at most
/// CameraBatch::size) into b, in passes over the batch: film pairs, image points, camera
/// rays (in float where RenderState::float_rays; else in double, Camera::generate_rays
/// without a lens), their traced form (for a parallel camera, in the same pass).
void camera_samples(const RenderState& f, int x, int y, std::uint32_t i0, std::uint32_t n,
                    const PixelReplicas& replicas, CameraBatch& b)
{
    n = std::min(n, CameraBatch::size);
    film_pairs(f, replicas, i0, n, b);
    if (f.parallel_rays) {  // the image point x + jx in float, as below
        f.camera.generate_parallel_rays(x, y, std::span(b.jx.data(), n), std::span(b.jy.data(), n),
                                        std::span(b.tnear.data(), n), b.parallel);
        return;
    }
    if (f.float_rays) {
        for (std::uint32_t k = 0; k < n; ++k) {
            b.jx[k] += static_cast<float>(x);  // the image point, in float as below
            b.jy[k] += static_cast<float>(y);
            b.tnear[k] = 0;
        }
        f.camera.generate_rays_f(std::span(b.jx.data(), n), std::span(b.jy.data(), n),
                                 std::span(b.rays.data(), n));
        return;
    }
    for (std::uint32_t k = 0; k < n; ++k) {
        if (f.filter.box())  // in float, as before filters existed: the same images
            b.points[k] = {x + b.jx[k], y + b.jy[k]};
        else
            b.points[k] = {x + 0.5 + f.filter.offset(b.jx[k]), y + 0.5 + f.filter.offset(b.jy[k])};
    }
    if (!f.lens) {
        f.camera.generate_rays(std::span(b.points.data(), n), std::span(b.camera_rays.data(), n));
    } else {
        for (std::uint32_t k = 0; k < n; ++k) {
            auto [lens_u, lens_v] = sampler_of(f, replicas, i0 + k).get2d(sample_dimension::lens);
            b.camera_rays[k] = f.camera.generate_ray(b.points[k].x, b.points[k].y, lens_u, lens_v);
        }
    }
    for (std::uint32_t k = 0; k < n; ++k)
        b.rays[k] = traced_ray(b.camera_rays[k], b.tnear[k]);
}

/// Sample i (its camera ray `ray`, starting `tnear` along the camera's) added to its
/// pixel's sums (`ex`: its extra sums, null where the render keeps none); `camera_hit`:
/// its camera ray's first hit when already traced (null: trace_path traces it).
void take_sample(const RenderState& f, const PixelReplicas& replicas, double tnear,
                 const CameraRayF& ray, std::uint32_t i, PixelState& st, PixelExtras* ex,
                 const std::optional<SurfaceHit>* camera_hit = nullptr)
{
    const RenderSettings& s = f.settings;
    VisibleSurface first;
    PathResult r = camera_hit && !*camera_hit
                       ? camera_miss(f.ctx, ray.dir)
                       : trace_path(f.ctx, ray.org, ray.dir, sampler_of(f, replicas, i), ray.tfar,
                                    f.aovs ? &first : nullptr, camera_hit);
    if (first.hit) {  // (asked for with AOVs only, which keep extras)
        ex->albedo += first.albedo;
        ex->normal += first.normal;
        const float t = static_cast<float>(first.t + tnear);
        if (f.organs) {  // denoising
            if (t < ex->depth)
                ex->organ = organ_of(*f.organs, first);
            if (i & 1u) {
                ex->odd_albedo += first.albedo;
                ex->odd_normal += first.normal;
            }
        }
        ex->depth = std::min(ex->depth, t);
        if (f.organ_samples && r.hit)  // a sample counted in the pixel's alpha
            f.organ_samples[ex - f.extras].add(organ_key_of(*f.mask_scene, first));
    }
    if ((s.transparent_background || s.ground.shadow_catcher) && !r.hit)
        r.radiance = Vec3f();
    // One NaN or infinite sample would spoil its pixel for good: it counts as black
    // instead (pbrt does the same), and the render reports how many there were.
    if (!std::isfinite(r.radiance.x + r.radiance.y + r.radiance.z)) {
        r.radiance = Vec3f();
        f.nonfinite->fetch_add(1, std::memory_order_relaxed);
    }
    st.radiance += r.radiance;
    st.hits += r.hit ? 1 : 0;
    st.samples += 1;
    if (!ex)
        return;  // no shadow catcher (so no catcher's light), no adaptive sampling
    ex->caught += r.catcher ? 1 : 0;
    ex->lit_with += r.lit_with;
    ex->lit_without += r.lit_without;
    if (f.split && (i & 1u))
        ex->odd_radiance += r.radiance;
    if (!f.adaptive)
        return;  // only adaptive sampling reads the luminance sums (relative_error_squared)
    // Adaptive sampling watches a shadow catcher's light estimate (its colour is 0).
    double l = r.catcher ? r.lit_with : luminance(r.radiance);
    ex->replica_luminance[i & 1u] += l;
    ex->luminance_sq += l * l;
}

/// take_sample for sample i whose camera ray met nothing, with a FlatMiss: the same sums,
/// the radiance's in `radiance` (the pixel's, held where the compiler can keep it in
/// registers across a batch's misses; the same additions in the same order).
void take_flat_miss(const RenderState& f, const FlatMiss& miss, std::uint32_t i, PixelState& st,
                    PixelExtras* ex, Vec3f& radiance)
{
    radiance += miss.radiance;
    st.samples += 1;
    if (f.split && (i & 1u))
        ex->odd_radiance += miss.radiance;
    if (!f.adaptive)
        return;
    ex->replica_luminance[i & 1u] += miss.luminance;
    ex->luminance_sq += miss.luminance * miss.luminance;
}

/// Camera samples i0 .. i0 + n - 1 of pixel (x, y) (n at most CameraBatch::size) made
/// and traced together into b: a pixel's rays are close and parallel (a coherent stream,
/// which Embree traces as SIMD packets), cheaper than one by one.
void trace_batch(const RenderState& f, int x, int y, std::uint32_t i0, std::uint32_t n,
                 const PixelReplicas& replicas, CameraBatch& b)
{
    camera_samples(f, x, y, i0, n, replicas, b);
    if (f.parallel_rays)  // (the stream filled from the rays' arrays)
        b.hit_bits = f.accel.intersect_coherent(b.parallel, n, std::span(b.hits.data(), n),
                                                f.rays_in_reach);
    else
        b.hit_bits = f.accel.intersect_coherent(std::span(b.rays.data(), n),
                                                std::span(b.hits.data(), n), f.rays_in_reach);
}

/// The traced batch b (samples i0 .. i0 + n - 1) added to its pixel's sums in order.
void add_batch(const RenderState& f, const PixelReplicas& replicas, std::uint32_t i0,
               std::uint32_t n, PixelState& st, PixelExtras* ex, const CameraBatch& b)
{
    Vec3f radiance = st.radiance;
    for (std::uint32_t k = 0; k < n; ++k) {
        if (f.miss && !(b.hit_bits >> k & 1u)) {
            take_flat_miss(f, *f.miss, i0 + k, st, ex, radiance);
            continue;
        }
        st.radiance = radiance;
        take_sample(f, replicas, b.tnear[k], b.ray(f, k), i0 + k, st, ex, &b.hits[k]);
        radiance = st.radiance;
    }
    st.radiance = radiance;
}

/// The radiance sum that take_background_samples made last (in a tile and pass): from
/// `from`, `count` samples of the background make `to` (bit patterns, so that -0 and 0
/// differ as they may in a sum).
struct BackgroundRun {
    using Bits = std::array<std::uint32_t, 3>;
    static Bits bits(const Vec3f& v)
    {
        return {std::bit_cast<std::uint32_t>(v.x), std::bit_cast<std::uint32_t>(v.y),
                std::bit_cast<std::uint32_t>(v.z)};
    }
    Bits from{}, to{};
    std::uint32_t count = 0;  // 0: none made yet
};

/// Samples i0 .. i1 - 1 of a pixel whose camera rays are known to meet nothing
/// (ScreenMask): each adds what a traced camera ray that missed adds (take_flat_miss),
/// with neither a sampler nor a ray. Without adaptive sampling a pixel's sums are then
/// its radiance and count only, and the empty pixels of a pass usually all start from
/// the same sum (0 in the first pass): `last` gives the result of the same additions
/// made for the pixel before, instead of a chain of as many dependent additions (a
/// float addition's latency per sample, for most of the samples of a plant's view).
void take_background_samples(const RenderState& f, std::uint32_t i0, std::uint32_t i1,
                             PixelState& st, PixelExtras* ex, BackgroundRun& last)
{
    const BackgroundRun::Bits from = BackgroundRun::bits(st.radiance);
    if (!f.split && i1 - i0 == last.count && from == last.from) {
        st.radiance = {std::bit_cast<float>(last.to[0]), std::bit_cast<float>(last.to[1]),
                       std::bit_cast<float>(last.to[2])};
        st.samples += i1 - i0;
        return;
    }
    Vec3f radiance = st.radiance;
    for (std::uint32_t i = i0; i < i1; ++i)
        take_flat_miss(f, *f.miss, i, st, ex, radiance);
    st.radiance = radiance;
    last = {from, BackgroundRun::bits(radiance), i1 - i0};
}

/// A tile row's camera batches and pixel hashes (take_row), made once per tile.
struct RowBatches {
    std::array<CameraBatch, tile_size> batch;
    std::array<std::optional<PixelReplicas>, tile_size> replicas;
    BackgroundRun background;  // the tile's last take_background_samples
};

/// Samples i0 .. i1 - 1 of pixel (x, y) in a scene with a ground plane, added to its sums
/// in order: camera rays meet the ground beside the Embree scene, so each path traces
/// its own.
void take_samples(const RenderState& f, int x, int y, std::uint32_t i0, std::uint32_t i1,
                  PixelState& st, PixelExtras* ex, CameraBatch& b, const PixelReplicas& replicas)
{
    for (std::uint32_t start = i0; start < i1; start += CameraBatch::size) {
        std::uint32_t n = std::min(CameraBatch::size, i1 - start);
        camera_samples(f, x, y, start, n, replicas, b);
        for (std::uint32_t k = 0; k < n; ++k)
            take_sample(f, replicas, b.tnear[k], b.ray(f, k), start + k, st, ex);
    }
}

/// Asks for the sums of pixels x0 .. x1 - 1 of row y of `film` (w wide) ahead of take_row:
/// a tile's rows lie an image row apart, a pattern the processor's prefetcher does not
/// follow, and the first look at each row's sums waited on memory.
void prefetch_row(const Film& film, int y, int x0, int x1, int w)
{
    constexpr std::uintptr_t line = 64;
    const auto* first = &film.px[std::size_t(y) * std::size_t(w) + std::size_t(x0)];
    const auto from = reinterpret_cast<std::uintptr_t>(first) & ~(line - 1);
    const auto to = reinterpret_cast<std::uintptr_t>(first + (x1 - x0));
    for (std::uintptr_t p = from; p < to; p += line)
        __builtin_prefetch(reinterpret_cast<const void*>(p));
}

/// The samples take_row took, and how many of them were of pixels the screen mask skips.
struct RowSamples {
    std::uint64_t taken = 0, background_only = 0;
};

/// Row y of a tile (pixels x0 .. x1 - 1 of `film`, w wide): each pixel's samples up to
/// `target`, in rounds of a batch per pixel. A round traces every pixel's batch before it
/// adds any to the sums, so the row's camera streams meet Embree back to back (its nodes
/// stay in cache) instead of between the paths of the hits (and the hits' paths follow
/// each other too); each pixel's sums take the same samples in the same order. (Rounds
/// over one row measured as fast as over two and faster than over four or a whole tile.)
/// Pixels the screen mask skips take their background samples at once.
RowSamples take_row(const RenderState& f, const PixelRect& region, int y, int x0, int x1,
                    std::uint32_t target, Film& film, int w, RowBatches& row)
{
    RowSamples taken;
    const std::size_t first = std::size_t(y) * std::size_t(w);  // the row's index in film
    // The row's pixels whose camera rays are traced, as offsets from x0, in order.
    std::array<std::uint8_t, tile_size> traced;
    std::size_t count = 0;
    for (int x = x0; x < x1; ++x) {
        PixelState& st = film.px[first + std::size_t(x)];
        if (st.done || st.samples >= target)
            continue;
        taken.taken += target - st.samples;
        if (f.mask && !f.mask->may_hit(region.x + x, region.y + y)) {
            taken.background_only += target - st.samples;
            take_background_samples(f, st.samples, target, st, film.extra(first + std::size_t(x)),
                                    row.background);
        } else {
            row.replicas[std::size_t(x - x0)].emplace(region.x + x, region.y + y, f.settings.seed,
                                                      f.split);
            traced[count++] = static_cast<std::uint8_t>(x - x0);
        }
    }
    auto pixel = [&](std::size_t k) -> PixelState& { return film.px[first + std::size_t(x0) + k]; };
    auto extra = [&](std::size_t k) { return film.extra(first + std::size_t(x0) + k); };
    if (f.ctx.ground) {  // no streams: each path traces its own camera ray
        for (std::size_t j = 0; j < count; ++j) {
            const std::size_t k = traced[j];
            take_samples(f, region.x + x0 + int(k), region.y + y, pixel(k).samples, target,
                         pixel(k), extra(k), row.batch[0], *row.replicas[k]);
        }
        return taken;
    }
    for (bool more = count > 0; more;) {
        more = false;
        for (std::size_t j = 0; j < count; ++j) {
            const std::size_t k = traced[j];
            const PixelState& st = pixel(k);
            if (st.samples < target)
                trace_batch(f, region.x + x0 + int(k), region.y + y, st.samples,
                            std::min(CameraBatch::size, target - st.samples), *row.replicas[k],
                            row.batch[k]);
        }
        for (std::size_t j = 0; j < count; ++j) {
            const std::size_t k = traced[j];
            PixelState& st = pixel(k);
            if (st.samples >= target)
                continue;
            add_batch(f, *row.replicas[k], st.samples, std::min(CameraBatch::size, target - st.samples),
                      st, extra(k), row.batch[k]);
            more |= st.samples < target;
        }
    }
    return taken;
}

/// The pixels whose camera rays may meet the scene, for a view where a camera ray that
/// meets nothing shows one background colour (a FlatMiss: no environment seen), with no
/// ground plane and no lens: elsewhere every pixel is traced.
ScreenMask screen_mask(const geom::Scene& scene, const RenderState& f)
{
    if (!f.settings.skip_empty_pixels || f.ctx.ground || !f.miss || f.lens)
        return {};
    return ScreenMask(scene, f.camera, f.filter.radius());
}

/// The pass schedule: cumulative samples per pixel at the end of each pass.
std::vector<int> pass_targets(const RenderSettings& s)
{
    int spp = s.samples_per_pixel;
    std::vector<int> targets;
    if (s.passes > 0) {
        for (int k = 1; k <= s.passes; ++k)
            targets.push_back(std::max(1, int(std::int64_t(spp) * k / s.passes)));
    } else {
        for (int n = std::min(spp, first_pass_samples);; n = std::min(spp, n * 2)) {
            targets.push_back(n);
            if (n == spp)
                break;
        }
    }
    // With a time budget, a first pass of one sample per pixel is the quickest way to a
    // complete image; the budget cannot stop it (see render()).
    if (s.time_budget_s > 0)
        targets.insert(targets.begin(), 1);
    targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
    return targets;
}

/// A view's samples taken, told to RenderSettings::progress at most 4 times a second by
/// whichever thread finishes a tile first (one at a time), and once at the end.
class ProgressReporter {
public:
    ProgressReporter(const RenderSettings& settings, Clock::time_point start)
        : m_report(settings.progress), m_start(start)
    {
    }

    void set_total(double total) { m_total.store(total); }
    void add(std::uint64_t samples)
    {
        std::uint64_t done = m_done.fetch_add(samples) + samples;
        if (!m_report)
            return;
        std::unique_lock lock(m_mutex, std::try_to_lock);
        if (!lock.owns_lock())
            return;
        auto now = Clock::now();
        if (now - m_last < std::chrono::milliseconds(250))
            return;
        m_last = now;
        report(double(done), false);
    }
    void finish()
    {
        if (!m_report)
            return;
        std::lock_guard lock(m_mutex);
        report(double(m_done.load()), true);  // 100% unless stopped early
    }
    std::uint64_t done() const { return m_done.load(); }

private:
    void report(double done, bool finished) const
    {
        double elapsed = std::chrono::duration<double>(Clock::now() - m_start).count();
        double total = m_total.load();
        double fraction = total > 0 ? std::min(1.0, done / total) : 0.0;
        m_report({fraction, elapsed, finished});
    }

    const std::function<void(const RenderProgress&)>& m_report;
    Clock::time_point m_start, m_last{};
    std::atomic<std::uint64_t> m_done{0};
    std::atomic<double> m_total{0};
    std::mutex m_mutex;
};

/// The layers beside RGBA that the settings ask of the film.
ImageLayers image_layers(const RenderSettings& s)
{
    return {s.transparent_background || s.ground.shadow_catcher, s.aovs || s.denoiser != nullptr,
            s.denoiser != nullptr, s.organ_mask_depth};
}

/// The ground plane of the settings under `scene`: its material appended to `materials`,
/// its texture after the scene's (load_textures).
GroundPlane make_ground(const geom::Scene& scene, const RenderSettings& settings,
                        std::vector<SurfaceMaterial>& materials)
{
    const RenderSettings::Ground& g = settings.ground;
    if (materials.size() >= geom::inherit_material)
        throw Error("render: no material index is left for the ground");
    geom::Material surface;
    surface.diffuse = g.colour;
    materials.push_back(make_materials({surface}).front());
    GroundPlane plane;
    plane.height = static_cast<float>(g.height.value_or(lowest_point(scene)));
    plane.material = static_cast<std::uint16_t>(materials.size() - 1);
    if (!g.texture.empty())
        plane.texture = static_cast<std::int16_t>(scene.textures.size());
    double tile = g.tile;
    if (!(tile > 0)) {
        geom::Vec3 e = scene.bounds.empty() ? geom::Vec3{} : scene.bounds.extent();
        tile = std::max({e.x, e.y, e.z, 1e-3});
    }
    plane.tile = static_cast<float>(tile);
    plane.shadow_catcher = g.shadow_catcher;
    return plane;
}

/// The image denoised in place: RGBA the denoiser's, the raw frame kept in `noisy`.
void denoise(const Denoiser& denoiser, Image& image)
{
    DenoiseInput in;
    in.width = image.width;
    in.height = image.height;
    in.beauty = image.rgba;
    in.variance = image.variance;
    in.albedo = image.albedo;
    in.normal = image.normal;
    in.depth = image.depth;
    in.organ = image.organ;
    in.feature_variance = image.feature_variance;
    std::vector<float> clean = denoiser.denoise(in);
    image.noisy = std::move(image.rgba);
    image.rgba = std::move(clean);
}

/// Throws when denoising would take more memory than --max-memory allows: the layers it
/// adds to the film and the image, and the denoiser's own working memory.
void check_denoise_memory(const RenderSettings& s)
{
    if (!s.denoiser)
        return;
    const std::uint64_t pixels = std::uint64_t(s.width) * std::uint64_t(s.height);
    // Film extras (odd radiance, organ, albedo, normal, depth, ...), then the image's
    // noisy, variance, organ, albedo, normal, depth and denoised layers.
    const std::uint64_t per_pixel = sizeof(PixelExtras) + (4 + 3 + 2 + 1 + 3 + 3 + 1 + 4) * 4;
    const std::uint64_t bytes = pixels * per_pixel + s.denoiser->working_bytes(s.width, s.height);
    if (bytes > s.max_memory_bytes)
        throw Error("render: denoising a " + std::to_string(s.width) + "x" +
                    std::to_string(s.height) + " image takes " + byte_size_text(bytes) +
                    ", more than the memory budget of " + byte_size_text(s.max_memory_bytes) +
                    " (--max-memory)");
}

/// Throws when organ masks would take more memory than --max-memory allows: their film
/// counts and image layers, beside the film's extras they need.
void check_organ_mask_memory(const RenderSettings& s)
{
    if (s.organ_mask_depth <= 0)
        return;
    if (s.organ_mask_depth % 2 != 0 || std::size_t(s.organ_mask_depth) > OrganSamples::slots)
        throw Error("render: the organ masks' rank depth must be even, from 2 to " +
                    std::to_string(OrganSamples::slots) + ", not " +
                    std::to_string(s.organ_mask_depth));
    const std::uint64_t pixels = std::uint64_t(s.width) * std::uint64_t(s.height);
    const std::uint64_t bytes =
        pixels * (organ_mask_bytes_per_pixel(s.organ_mask_depth) + sizeof(PixelExtras));
    if (bytes > s.max_memory_bytes)
        throw Error("render: organ masks of a " + std::to_string(s.width) + "x" +
                    std::to_string(s.height) + " image take " + byte_size_text(bytes) +
                    ", more than the memory budget of " + byte_size_text(s.max_memory_bytes) +
                    " (--max-memory)");
}

/// Throws on settings or cameras render_views cannot take.
void check_views(const RenderSettings& settings, std::span<const Camera> cameras)
{
    check_settings(settings);
    check_denoise_memory(settings);
    check_organ_mask_memory(settings);
    for (const Camera& camera : cameras) {
        if (camera.width() != settings.width || camera.height() != settings.height)
            throw Error("render: the camera's image size differs from the settings'");
        camera.check_range("view");
    }
}

/// A path tracer's context and the area lights it samples (which it points to).
struct PreparedContext {
    std::unique_ptr<AreaLights> area_lights;
    PathContext ctx;
};

/// The scene's path tracer context under the settings, over its BVH and textures, for
/// every view: materials, lights, ground, background and environment, prepared
/// (prepare_path_context). A view sets its camera's part (aim_context).
PreparedContext make_path_context(const geom::Scene& scene, const RenderSettings& settings,
                                  const EmbreeScene& accel, const TextureSet* textures)
{
    PreparedContext prepared;
    PathContext& ctx = prepared.ctx;
    ctx.accel = &accel;
    ctx.textures = textures;
    const std::vector<geom::Light> no_lights;
    const std::vector<geom::Light>& scene_lights = settings.view_lights ? scene.lights : no_lights;
    // Without the scene's lights there is no OpenGL ambient term either (an empty
    // list would mean cpfg's default light to opengl_ambient_light).
    ctx.materials = make_materials(scene.materials,
                                   settings.opengl_ambient && settings.view_lights
                                       ? opengl_ambient_light(scene.lights)
                                       : geom::Rgb{0, 0, 0});
    if (scene.colour_index_light) {
        ctx.index_light = *scene.colour_index_light;
        ctx.index_ramps = make_index_ramps(scene.materials, ctx.index_light);
    }
    if (settings.ground.enabled)
        ctx.ground = make_ground(scene, settings, ctx.materials);
    ctx.lights = make_lights(scene_lights);
    if (settings.area_lights) {
        prepared.area_lights = std::make_unique<AreaLights>(scene, ctx.materials);
        ctx.area_lights = prepared.area_lights.get();
    }
    ctx.background = decode_display(settings.backdrop == RenderSettings::Backdrop::colour
                                        ? settings.backdrop_colour
                                        : scene.background);
    ctx.environment = settings.environment.get();
    ctx.ambient = {settings.ambient.r, settings.ambient.g, settings.ambient.b};
    ctx.max_depth = settings.max_depth;
    ctx.unlit = scene.shading == geom::Shading::filled || scene.shading == geom::Shading::wireframe;
    ctx.facet_normals = scene.shading == geom::Shading::flat;
    ctx.roulette_depth = settings.roulette_depth;
    if (!scene.bounds.empty())
        ctx.scene_radius = static_cast<float>(0.5 * geom::length(scene.bounds.hi - scene.bounds.lo));
    prepare_path_context(ctx);
    return prepared;
}

/// The context's part that depends on the view's camera.
void aim_context(PathContext& ctx, const Camera& camera, const RenderSettings& settings)
{
    // A parallel camera looks along one direction: its misses would all see the same
    // environment radiance, so they keep cpfg's background there.
    ctx.environment_visible =
        settings.environment != nullptr &&
        (settings.backdrop == RenderSettings::Backdrop::environment ||
         (settings.backdrop == RenderSettings::Backdrop::view &&
          camera.projection() == Camera::Projection::perspective));
    ctx.camera_cone = camera_cone(camera);
}

/// What every view of render_views shares: the pass schedule and the pixels.
struct ViewPlan {
    const geom::Scene& scene;
    const RenderSettings& settings;
    std::vector<int> targets;  ///< pass_targets
    /// The sampled pixels, in image coordinates (the film holds them row by row), and
    /// the pixels returned.
    PixelRect region, out;
    Clock::time_point start;  ///< of the view: its time budget and seconds
};

/// The view's samples, its stop checks and progress, for the passes over its tiles.
struct PassRun {
    const ViewPlan& plan;
    const RenderState& state;
    Film& film;
    ProgressReporter progress;
    std::atomic<bool> stop{false}, cancelled{false}, out_of_time{false};
    std::atomic<std::uint64_t> background_samples{0};
    /// The time budget may stop a render only once every pixel has a sample: an
    /// image with unsampled (black) bands is never the result of a budget.
    bool budget_applies = false;
    // Each thread's camera batches, made on its first tile (not once per tile: their
    // members' initialisers, ~60 kB of stores a tile, were a tenth of the pixel loop).
    tbb::enumerable_thread_specific<std::unique_ptr<RowBatches>> thread_rows;

    PassRun(const ViewPlan& p, const RenderState& s, Film& f)
        : plan(p), state(s), film(f), progress(p.settings, p.start)
    {
    }
    double elapsed() const { return std::chrono::duration<double>(Clock::now() - plan.start).count(); }

    bool should_stop()
    {
        const RenderSettings& settings = plan.settings;
        if (settings.cancel && settings.cancel->load(std::memory_order_relaxed)) {
            cancelled = true;
            stop = true;
        }
        if (budget_applies && settings.time_budget_s > 0 && elapsed() > settings.time_budget_s) {
            out_of_time = true;
            stop = true;
        }
        return stop.load(std::memory_order_relaxed);
    }

    /// Tile t's pixels sampled up to `target`, a row at a time.
    void take_tile(int t, std::uint32_t target, RowBatches& row)
    {
        const int w = plan.region.width, h = plan.region.height;
        const int tiles_x = (w + tile_size - 1) / tile_size;
        int x0 = (t % tiles_x) * tile_size, y0 = (t / tiles_x) * tile_size;
        RowSamples tile;
        row.background = {};  // (a pure function of the view's miss, so per tile)
        const int x1 = std::min(x0 + tile_size, w);
        const int y1 = std::min(y0 + tile_size, h);
        prefetch_row(film, y0, x0, x1, w);
        // Checked every row, so even passes of thousands of samples stop soon.
        for (int y = y0; y < y1 && !should_stop(); ++y) {
            if (y + 1 < y1)
                prefetch_row(film, y + 1, x0, x1, w);
            RowSamples taken = take_row(state, plan.region, y, x0, x1, target, film, w, row);
            tile.taken += taken.taken;
            tile.background_only += taken.background_only;
        }
        progress.add(tile.taken);
        background_samples.fetch_add(tile.background_only, std::memory_order_relaxed);
    }

    /// One pass: every tile's pixels sampled up to `target`, in parallel.
    void take_pass(std::uint32_t target)
    {
        const int w = plan.region.width, h = plan.region.height;
        const int tiles = ((w + tile_size - 1) / tile_size) * ((h + tile_size - 1) / tile_size);
        // Each tile writes only its own pixels; no exception leaves a task.
        tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& r) {
            // Taken from the thread's slot while in use: a task this one waits on inside
            // (nested parallelism) may run another tile on this thread, with its own.
            std::unique_ptr<RowBatches> row = std::move(thread_rows.local());
            if (!row)
                row = std::make_unique_for_overwrite<RowBatches>();  // no zero fill
            for (int t = r.begin(); t != r.end(); ++t)
                take_tile(t, target, *row);
            thread_rows.local() = std::move(row);
        });
    }

    /// The passes of the schedule until the last, a stop or the time budget; the passes
    /// completed and why they ended into `rep`.
    void run(RenderReport& rep)
    {
        const RenderSettings& settings = plan.settings;
        double last_pass_s = 0;
        std::uint64_t last_pass_samples = 0;
        for (std::size_t pass = 0; pass < plan.targets.size(); ++pass) {
            const std::uint32_t target = static_cast<std::uint32_t>(plan.targets[pass]);
            // Samples still to take to reach the end of the render, for the progress reports.
            std::uint64_t pass_samples = 0, remaining = 0;
            for (const PixelState& st : film.px)
                if (!st.done) {
                    pass_samples += target > st.samples ? target - st.samples : 0;
                    remaining += std::uint32_t(settings.samples_per_pixel) - st.samples;
                }
            if (pass_samples == 0)
                break;
            progress.set_total(double(progress.done() + remaining));
            if (settings.time_budget_s > 0 && pass > 0 && last_pass_samples > 0) {
                double predicted = last_pass_s * double(pass_samples) / double(last_pass_samples);
                if (elapsed() + predicted > settings.time_budget_s) {
                    out_of_time = true;
                    break;
                }
            }
            budget_applies = pass > 0;
            auto pass_start = Clock::now();
            take_pass(target);
            if (stop)
                break;
            last_pass_s = std::chrono::duration<double>(Clock::now() - pass_start).count();
            last_pass_samples = pass_samples;
            rep.passes += 1;
            if (settings.noise_target > 0)
                mark_converged(film, plan.region.width, plan.region.height, settings.noise_target);
            if (settings.on_pass)
                settings.on_pass(resolve(film, plan.region, plan.out, image_layers(settings), plan.scene));
        }
        progress.finish();
        rep.cancelled = cancelled;
        rep.out_of_time = out_of_time;
        rep.background_only_samples = background_samples.load();
    }
};

/// The BVH's figures for the view's report, and warnings for samples and rays lost.
void report_accel(const EmbreeScene& accel, RenderReport& rep)
{
    rep.skipped_rays = accel.skipped_rays();
    rep.embree_bytes = accel.embree_bytes();
    rep.embree_peak_bytes = accel.embree_peak_bytes();
    rep.embree_shared_bytes = accel.shared_bytes();
    rep.render_buffer_bytes = accel.own_bytes();
    rep.embree_unmonitored_bytes = accel.embree_unmonitored_bytes();
    if (rep.nonfinite_samples > 0)
        warn("render: " + std::to_string(rep.nonfinite_samples) +
             " sample(s) with a radiance that is not finite were counted as black");
    if (rep.skipped_rays > 0)
        warn("render: " + std::to_string(rep.skipped_rays) +
             " ray(s) not finite or starting too far from the origin were skipped");
}

/// The view's image from the film: resolved, denoised where asked, its labels drawn.
Image finish_image(const ViewPlan& plan, const Film& film, const Camera& camera,
                   const EmbreeScene& accel, RenderReport& rep)
{
    const RenderSettings& settings = plan.settings;
    Image image = resolve(film, plan.region, plan.out, image_layers(settings), plan.scene);
    if (settings.denoiser) {
        auto denoise_start = Clock::now();
        denoise(*settings.denoiser, image);
        rep.denoise_seconds = std::chrono::duration<double>(Clock::now() - denoise_start).count();
    }
    // Labels over the image, as cpfg's window draws them (on the crop's pixels).
    draw_labels(image, plan.scene, camera, accel,
                LabelCanvas{plan.out.x, plan.out.y, settings.width, settings.height},
                LabelLimits{settings.max_memory_bytes});
    return image;
}

}  // namespace

std::shared_ptr<const TextureSet> load_textures(const geom::Scene& scene,
                                                const RenderSettings& settings)
{
    std::vector<geom::TextureDef> defs = scene.textures;
    if (settings.ground.enabled && !settings.ground.texture.empty())
        defs.push_back({settings.ground.texture, false, true, true});
    // The readers made every texture path absolute (view files, scene files) or left
    // it as the user gave it on the command line (the ground's: the current folder's).
    return std::make_shared<const TextureSet>(defs, std::filesystem::path{},
                                              settings.max_memory_bytes);
}

Image render(const geom::Scene& scene, const RenderSettings& settings, RenderReport* report)
{
    check_settings(settings);
    Camera camera = make_camera(scene.view, scene.bounds, settings.width, settings.height);
    if (settings.aperture_radius > 0)
        camera = camera.with_lens(settings.aperture_radius, settings.focus_distance);
    return render(scene, camera, settings, report);
}

Image render(const geom::Scene& scene, const Camera& camera, const RenderSettings& settings,
             RenderReport* report)
{
    Image image;
    render_views(scene, std::span<const Camera>(&camera, 1), settings,
                 [&](std::size_t, Image& frame, const RenderReport& rep) {
        image = std::move(frame);
        if (report)
            *report = rep;
        return true;
    });
    return image;
}

void render_views(const geom::Scene& scene, std::span<const Camera> cameras,
                  const RenderSettings& settings, const ViewCallback& on_view)
{
    check_views(settings, cameras);
    if (cameras.empty())
        return;
    const Clock::time_point start = Clock::now();
    const std::clock_t cpu_start = std::clock();
    ViewPlan plan{scene, settings, pass_targets(settings), {}, output_rect(settings), start};
    plan.region = sampled_rect(settings, plan.targets.size());
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    ArenaDenormalsFlushed flush_workers(arena);  // as Embree asks (render/float_mode.h)
    arena.execute([&] {
        DenormalsFlushed flush_here;
        std::shared_ptr<const TextureSet> textures = settings.textures;
        if (!textures && (!scene.textures.empty() || !settings.ground.texture.empty()))
            textures = load_textures(scene, settings);
        // Embree builds with TBB too, so the build also stays within the arena. One
        // build serves every view, except for pixel-wide lines, whose width is the view's.
        auto accel = std::make_unique<EmbreeScene>(scene, cameras.front(), textures.get());
        PreparedContext prepared = make_path_context(scene, settings, *accel, textures.get());
        PathContext& ctx = prepared.ctx;
        std::uint64_t rays_before = 0;
        for (std::size_t view = 0; view < cameras.size(); ++view) {
            const Camera& camera = cameras[view];
            if (view > 0 && scene.line_radius_in_pixels) {
                accel.reset();  // one BVH at a time
                accel = std::make_unique<EmbreeScene>(scene, camera, textures.get());
                ctx.accel = accel.get();
                rays_before = 0;  // a new scene counts its rays from 0
            }
            aim_context(ctx, camera, settings);
            std::atomic<std::uint64_t> nonfinite{0};
            RenderState state{ctx, *accel, camera, settings,
                              FilterTable(settings.filter, settings.filter_radius),
                              camera.aperture_radius() > 0 &&
                                  camera.projection() == Camera::Projection::perspective,
                              &nonfinite};
            state.organs = settings.denoiser ? &scene : nullptr;
            Film film(std::size_t(plan.region.width) * std::size_t(plan.region.height),
                      state.aovs || state.adaptive || (ctx.ground && ctx.ground->shadow_catcher),
                      settings.organ_mask_depth > 0);
            if (!film.organs.empty()) {
                state.mask_scene = &scene;
                state.organ_samples = film.organs.data();
                state.extras = film.extras.data();
            }
            const ScreenMask mask = screen_mask(scene, state);
            state.mask = &mask;
            RenderReport rep;
            if (view == 0) {
                rep.setup_seconds = std::chrono::duration<double>(Clock::now() - plan.start).count();
                rep.setup_cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
                rep.build_seconds = accel->build_seconds();
            }
            PassRun(plan, state, film).run(rep);
            rep.empty_pixel_share = mask.empty_share();
            rep.rays = accel->rays_traced() - rays_before;
            rays_before += rep.rays;
            rep.nonfinite_samples = nonfinite.load();
            report_accel(*accel, rep);
            for (const PixelState& st : film.px)
                rep.samples += st.samples;
            Image image = finish_image(plan, film, camera, *accel, rep);
            rep.seconds = std::chrono::duration<double>(Clock::now() - plan.start).count();
            if (!on_view(view, image, rep) || rep.cancelled)
                break;
            plan.start = Clock::now();  // the next view's time budget and seconds
        }
    });
}

}  // namespace cambium::render
