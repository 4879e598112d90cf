// SPDX-License-Identifier: Apache-2.0
// --stats and --stats-json: where a run's time and memory went, from the files to the
// first pixel and through the render.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "geom/scene.h"
#include "render/render.h"

namespace cambium::app {

/// Primitives by kind, as Embree builds them.
struct PrimitiveCounts {
    std::uint64_t cylinders = 0;       ///< shaded linear segments (F, G)
    /// Linear segments drawn as lines a number of pixels wide (`line style: pixel`, and
    /// every edge of `render mode: wireframe`): unlit, with no caps or joints.
    std::uint64_t lines = 0;
    std::uint64_t curve_segments = 0;  ///< generalized-cylinder Hermite segments
    std::uint64_t spheres = 0, discs = 0, triangles = 0;

    std::uint64_t total() const
    {
        return cylinders + lines + curve_segments + spheres + discs + triangles;
    }
    PrimitiveCounts& operator+=(const PrimitiveCounts& o);
};

/// `pixel_lines`: the geometry's linear segments are pixel-width lines
/// (geom::Scene::line_radius_in_pixels), counted as lines, not cylinders.
PrimitiveCounts count_primitives(const geom::Geometry& g, bool pixel_lines);

/// One frame of a sequence (-a, --turntable, --inbetween): what it cost beyond the
/// work shared by every frame (a turntable's load, derivation and interpretation).
struct FrameStats {
    int number = 0;  ///< the image number, as in the file names
    /// derive: the derivation steps since the previous frame (an in-between's blending);
    /// interpret: the turtle, including a fixed camera's first pass over the frame.
    double derive_s = 0, interpret_s = 0, build_s = 0, render_s = 0;
    std::uint64_t primitives = 0;  ///< as placed
    std::uint64_t samples = 0, rays = 0;
    /// Of the samples, those of pixels no primitive reaches: taken without a ray.
    std::uint64_t background_only_samples = 0;
    std::uint64_t embree_bytes = 0;
    std::uint64_t peak_process_bytes = 0;  ///< the process's peak so far, after the frame
};

/// One run's statistics. Times are wall seconds; `first_pixel_s` counts from the start
/// of the command (main), so it holds load, derive, interpret and build and whatever lies
/// between (string outputs, textures, lights).
struct RunStats {
    /// For a scene file, whose plants are loaded, derived and interpreted in parallel,
    /// load, derive and interpret are summed over threads and `assemble_s` is the wall
    /// time of the whole; for one model, `assemble_s` is their sum.
    double load_s = 0, derive_s = 0, interpret_s = 0, assemble_s = 0, build_s = 0;
    double first_pixel_s = 0;
    double render_s = 0;  ///< sampling, after the first pixel (denoising included)
    double denoise_s = 0;  ///< of render_s, the denoiser's (--denoise)
    bool interpreted = false, rendered = false;

    /// Built once: the scene's own geometry and its prototypes'.
    PrimitiveCounts primitives;
    /// As drawn: the scene's own plus each instance's prototype.
    PrimitiveCounts placed_primitives;
    std::uint64_t instances = 0, prototypes = 0;

    std::uint64_t embree_bytes = 0, embree_peak_bytes = 0;
    std::uint64_t cambium_bytes = 0;  ///< the Scene's primitive buffers (capacities)
    /// The renderer's buffers beside the Scene's (caps, joints, placements), and of all
    /// Cambium's buffers those Embree reads in place instead of copying.
    std::uint64_t render_buffer_bytes = 0, embree_shared_bytes = 0;
    /// Embree's instance geometries, which its memory monitor does not report.
    std::uint64_t embree_unmonitored_bytes = 0;
    std::uint64_t peak_process_bytes = 0;

    int width = 0, height = 0;
    std::uint64_t samples = 0, rays = 0;
    /// Of the samples, those of pixels no primitive reaches (render::ScreenMask): taken
    /// without a ray.
    std::uint64_t background_only_samples = 0;

    /// A sequence: its frames rendered by this process, in order. The run's times, samples
    /// and rays are then sums over them plus the shared work; its primitive counts and
    /// Embree memory those of the largest frame.
    bool sequence = false;
    std::size_t sequence_frames = 0;  ///< frames in the sequence, rendered here or not
    std::vector<FrameStats> frames;

    /// A scene file's assembly: thread-summed load, derive and interpret, and its wall time.
    void add_assembly(double load, double derive, double interpret, double wall);
    /// Counts the scene's primitives, instances and buffer bytes.
    void add_scene(const geom::Scene& scene);
    /// Takes the render's build time, rays, samples and Embree memory; `render_start_s`
    /// is when render() was called, counted from the start of the command.
    void add_render(const render::RenderReport& report, double render_start_s, int w, int h);
    /// A frame of a sequence rendered (its interpretation and derivation in `frame`):
    /// `scene` is what was rendered, `render_start_s` as for add_render().
    void add_frame(FrameStats frame, const geom::Scene& scene, const render::RenderReport& report,
                   double render_start_s, int w, int h);
};

/// The process's peak resident memory (VmHWM; getrusage's ru_maxrss where /proc is absent).
std::uint64_t peak_process_bytes();

/// The readable block --stats prints.
std::string format_stats(const RunStats& stats);

/// The JSON --stats-json writes (keys in docs/architecture.md, "Statistics").
nlohmann::json stats_json(const RunStats& stats);

/// Writes stats_json() to `file` atomically. Throws cambium::Error naming the file.
void write_stats_json(const RunStats& stats, const std::filesystem::path& file);

}  // namespace cambium::app
