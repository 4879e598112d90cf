// SPDX-License-Identifier: Apache-2.0
// The render layer's entry points: render a Scene to an Image (image_io.h writes it to a file).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>

#include "base/limits.h"
#include "geom/scene.h"
#include "render/camera.h"
#include "render/environment.h"
#include "render/image_io.h"
#include "render/pixel_filter.h"
#include "render/sampler.h"

namespace cambium::render {

class Denoiser;
class TextureSet;

/// The largest image rendered: 2^26 pixels (8192 x 8192, about 5 GiB of pixel state).
inline constexpr std::int64_t max_image_pixels = std::int64_t{1} << 26;

/// How far the render of a view has got (RenderSettings::progress).
struct RenderProgress {
    double fraction = 0;   ///< of the view's samples taken, 0 to 1
    /// Seconds since the view began (the first view: since the call, setup included).
    double elapsed_s = 0;
    bool finished = false;  ///< the view's last report: its passes have ended
};

/// How to render a frame.
struct RenderSettings {
    int width = 640, height = 480;  ///< cpfg's default window
    /// The pixels to render (empty = the whole image): render() returns an Image of the
    /// crop's size whose pixels equal, bit for bit, the same pixels of the whole image
    /// (tiles for --tile and --mpi). Every pixel is a function of its own samples; only
    /// adaptive sampling looks at neighbours, so the crop is sampled with a margin as
    /// wide as the convergence checks can reach (one pixel per pass) and the margin
    /// dropped. Not under a time budget, which depends on the machine's speed anyway.
    PixelRect crop;
    /// Samples per pixel; with a noise target or a time budget, the most any pixel gets.
    int samples_per_pixel = 64;
    /// Path segments at most: 1 = direct light only, 2 = one bounce, ...
    int max_depth = 6;
    /// Russian roulette starts after this many segments (1: from the first bounce, as
    /// Cycles' defaults do; integrator.cpp's roulette_keep_above keeps bright paths).
    int roulette_depth = 1;
    std::uint64_t seed = 0;
    /// Owen-scrambled Sobol (default) or white noise (for comparisons, --sampler).
    SampleSequence sampler = SampleSequence::sobol;
    int threads = 0;  ///< 0 = all cores
    /// Radiance (linear RGB) of the uniform environment that secondary rays see when they
    /// escape: the physically-based stand-in for cpfg's ambient term. Camera rays that
    /// miss see the background colour instead. Ignored when `environment` is set.
    geom::Rgb ambient{0.05f, 0.05f, 0.05f};
    /// Add cpfg's OpenGL ambient term (material ambient x the lights' ambient) where
    /// camera rays meet a surface (docs/materials.md).
    bool opengl_ambient = true;
    /// Light with the scene's lights (the view file's `light:`s, or cpfg's default light
    /// where it has none; a scene file's lights). Off (--no-view-lights): they are left
    /// out, with the OpenGL ambient term they bring, so a staged still is lit by its sky
    /// or map (and emissive surfaces) alone.
    bool view_lights = true;
    /// What escaping rays see instead of `ambient` (make_sky_environment,
    /// make_map_environment); null = the uniform ambient.
    std::shared_ptr<const Environment> environment;
    /// Sample emissive triangles, discs and spheres directly (next-event estimation,
    /// weighted against BSDF sampling by MIS). Off: only BSDF rays find them (the same
    /// image on average, noisier).
    bool area_lights = true;
    /// What one decoded texture may take (--max-memory): larger ones are refused from
    /// their header, before loading.
    std::uint64_t max_memory_bytes = default_max_memory_bytes();

    /// Reconstruction filter and its radius in pixels (0 = the filter's default: 1.5 for
    /// gaussian, 1.0 for blackman_harris; box is always 0.5). Default box: the same image
    /// as before filters existed, and cpfg's window is unfiltered too.
    PixelFilter filter = PixelFilter::box;
    float filter_radius = 0;

    /// Progressive rendering: the samples are taken in passes over the whole image (each
    /// pass adds samples to every pixel still sampled), so `on_pass`, `cancel`, the time
    /// budget and adaptive sampling act on whole-image states and an interrupted render
    /// is sampled evenly. 0 = automatic: 8 spp first, doubling each pass; N = N equal
    /// passes (1 = a single pass). The image does not depend on the passes (each pixel
    /// sums its samples in the same order).
    int passes = 0;
    /// Adaptive sampling (0 = off): a pixel stops being sampled once the standard error
    /// of its mean luminance, relative to max(mean, 0.01), is at most this for it and
    /// its 8 neighbours (checked after each pass; 16 samples at least). e.g. 0.02.
    /// Deterministic: the same image for any thread count.
    float noise_target = 0;
    /// Stop after about this many seconds (0 = no limit): a first pass gives every
    /// pixel one sample whatever the budget (never an image with unsampled bands); after
    /// it, no pass is started that is predicted not to fit, and a pass still running at
    /// the limit stops at the next tile row. The image then depends on the machine's speed (not bit-reproducible);
    /// `samples_per_pixel` still caps it, so set that high.
    double time_budget_s = 0;

    /// Thin lens (perspective views): aperture radius in world units (0 = pinhole) and
    /// the distance from the eye to the plane in focus (0 = the view reference point).
    double aperture_radius = 0;
    double focus_distance = 0;

    /// Camera rays that miss contribute nothing instead of the background: RGB is
    /// premultiplied by the coverage alpha (Image::transparent) for PNG/TIFF/EXR output.
    bool transparent_background = false;
    /// What camera rays that miss see (--background): the view's background colour
    /// (cpfg's window; the environment shows there in perspective views), a colour of
    /// its own (display values, decoded from sRGB), or the environment in both
    /// projections (a parallel view sees the environment's radiance along its direction).
    enum class Backdrop { view, colour, environment };
    Backdrop backdrop = Backdrop::view;
    geom::Rgb backdrop_colour{0, 0, 0};

    /// A ground plane under the plant (--ground): the plane y = height, perpendicular to
    /// the view's up vector (+y), infinite, lit like the plant and receiving its shadows
    /// (render/ground.h).
    struct Ground {
        bool enabled = false;
        /// nullopt: the scene's lowest point (lowest_point). A sequence sets it once.
        std::optional<double> height;
        geom::Rgb colour{0.5f, 0.5f, 0.5f};  ///< display value: neutral mid grey
        /// Tiled over the ground, modulating `colour` (empty: none). Absolute, or
        /// relative to the working folder (it comes from the command line).
        std::filesystem::path texture;
        /// World units per texture repeat; 0: the scene's largest extent (at least 1e-3).
        double tile = 0;
        /// The ground only darkens (--shadow-catcher): camera rays that meet it give
        /// colour 0 and alpha 1 - (light with the plant / light without it), so the
        /// image composites over any background; no other ray sees it. Makes the image
        /// transparent (premultiplied) like transparent_background.
        bool shadow_catcher = false;
    };
    Ground ground;
    /// Textures opened once for a sequence whose frames share their texture definitions
    /// (load_textures of any of its scenes); null: each render opens its scene's own.
    std::shared_ptr<const TextureSet> textures;
    /// Compute the albedo, normal and depth layers (Image::albedo/normal/depth): one
    /// extra camera-ray intersection per sample.
    bool aovs = true;
    /// Pixels no primitive's projection reaches (ScreenMask) show the background without
    /// tracing their camera rays, where a ray that meets nothing shows one colour (no
    /// environment seen, no ground, no lens). The image is the same either way; off only
    /// to check that (tests) or to trace every ray (benchmarks).
    bool skip_empty_pixels = true;

    /// Denoise each frame (--denoise; render/denoise.h) with this denoiser, null: not.
    /// The samples are then drawn from two independently scrambled replicas (even and
    /// odd samples, as adaptive sampling draws them), whose difference gives each
    /// pixel's variance; the AOVs are computed whatever `aovs` says, with the organ id
    /// beside them. The Image's RGBA is the denoised frame, Image::noisy the raw one.
    /// Needs the whole image (no crop). Labels are drawn after denoising.
    std::shared_ptr<const Denoiser> denoiser;
    /// Organ masks (--organ-masks; render/organ_masks.h, docs/masks.md): 0, none; else
    /// the (id, coverage) pairs per pixel of each Cryptomatte layer (even, at most
    /// OrganSamples::slots), in Image::organ_masks. The film keeps 96 bytes a pixel more
    /// (counted against max_memory_bytes) and the AOVs' first hits are traced.
    int organ_mask_depth = 0;

    /// Told how far each view has got (null: not told): at most 4 times a second while it
    /// renders, on whichever render thread finishes a tile first, never two calls at once;
    /// and once when its passes end. The command draws its progress line with it.
    std::function<void(const RenderProgress&)> progress;
    /// Checked every tile row: when it becomes true, render() stops and returns the image
    /// so far (each pixel averages the samples it got; pixels never reached are black
    /// with alpha 0). The command sets it on Ctrl-C.
    const std::atomic<bool>* cancel = nullptr;
    /// Called on the calling thread after each completed pass with the image so far
    /// (e.g. to write a preview).
    std::function<void(const Image&)> on_pass;
};

/// What happened during a render.
struct RenderReport {
    std::uint64_t samples = 0;  ///< camera samples taken in all
    int passes = 0;             ///< passes completed
    bool cancelled = false;     ///< stopped by `cancel`
    bool out_of_time = false;   ///< stopped by the time budget
    std::uint64_t nonfinite_samples = 0;  ///< samples with NaN or infinite radiance, counted as black
    std::uint64_t skipped_rays = 0;  ///< rays Embree could not take (EmbreeScene::skipped_rays)
    /// Camera samples of pixels known to show the background (RenderSettings::
    /// skip_empty_pixels): taken without a ray. And those pixels' share of the image.
    std::uint64_t background_only_samples = 0;
    double empty_pixel_share = 0;
    double seconds = 0;         ///< wall time, including the Embree build and denoising
    double denoise_seconds = 0; ///< of it, the denoiser's (RenderSettings::denoiser)
    /// --stats: from the call to the first sample (textures, the Embree build, lights),
    /// and of it the Embree build alone (the first view's; 0 for later views).
    double setup_seconds = 0;
    double build_seconds = 0;
    /// The process's CPU time (all its threads: std::clock) over setup_seconds.
    double setup_cpu_seconds = 0;
    std::uint64_t rays = 0;     ///< rays traced in this view: camera, bounce and shadow rays
    /// Bytes Embree allocated itself (BVHs, internal copies; not the shared buffers):
    /// after the build and at most so far.
    std::uint64_t embree_bytes = 0, embree_peak_bytes = 0;
    /// Of the buffers Embree reads in place, their bytes (EmbreeScene::shared_bytes), and
    /// the renderer's own buffers beside the Scene's (EmbreeScene::own_bytes).
    std::uint64_t embree_shared_bytes = 0, render_buffer_bytes = 0;
    /// Embree's heap its memory monitor does not see (EmbreeScene::embree_unmonitored_bytes).
    std::uint64_t embree_unmonitored_bytes = 0;
};

/// Renders the scene as cpfg frames it (make_camera, plus the settings' thin lens) with
/// a unidirectional path tracer. Without a time budget the result depends on the scene,
/// the settings and the seed, never on the thread count or pass count.
/// Throws cambium::Error on invalid settings or an Embree failure.
Image render(const geom::Scene& scene, const RenderSettings& settings,
             RenderReport* report = nullptr);

/// Renders with an explicit camera (tests, turntables); the settings' lens is not applied.
Image render(const geom::Scene& scene, const Camera& camera, const RenderSettings& settings,
             RenderReport* report = nullptr);

/// Called after each view of render_views() with its index, its image (which may be
/// moved from) and its report; returning false stops the sequence.
using ViewCallback = std::function<bool(std::size_t view, Image& image, const RenderReport&)>;

/// Renders one scene from several cameras (a turntable), loading its textures and
/// building its BVH once (once per view for `line style: pixel` lines, whose width
/// depends on the view). Every view uses the same sampling pattern (random numbers
/// hashed from pixel, sample and seed), so noise does not move between frames; the
/// time budget applies to each view; a cancel ends the sequence after the view it
/// interrupted. The first view's report counts the build.
void render_views(const geom::Scene& scene, std::span<const Camera> cameras,
                  const RenderSettings& settings, const ViewCallback& on_view);

/// The scene's textures followed by the ground's (settings.ground.texture), opened once:
/// share them between the frames of a sequence through RenderSettings::textures.
std::shared_ptr<const TextureSet> load_textures(const geom::Scene& scene,
                                                const RenderSettings& settings);

}  // namespace cambium::render
