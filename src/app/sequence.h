// SPDX-License-Identifier: Apache-2.0
// Sequences of frames: cpfg's animation mode (-a with the .a file) and turntables, plus
// the command line's camera options for stills.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/distributed.h"
#include "app/pipeline.h"
#include "app/stats.h"
#include "base/output_format.h"
#include "geom/animation_file.h"
#include "render/render.h"

namespace cambium::app {

/// What a sequence writes besides images, and how it talks: the command's own
/// string writer (-str, -strb with their frame numbers) and message printer.
struct SequenceOutputs {
    std::vector<std::filesystem::path> images;  ///< patterns with a number field
    render::RenderSettings settings;
    std::function<void(const Model&, const lsys::ModuleString&, int step)> write_strings;
    std::function<void(const std::string&)> say;
    /// --mpi: the frames are shared among the job's ranks (app/distributed.h); rank 0
    /// writes every file. Null: every frame here.
    Mpi* mpi = nullptr;
    /// A scene file's scene (docs/scenes.md): when set, a turntable renders it instead
    /// of the options' L-system.
    std::function<geom::Scene()> make_scene;
    /// --stats: the figures of every frame rendered here go there (app/stats.h), timed
    /// from `command_start`.
    RunStats* stats = nullptr;
    std::chrono::steady_clock::time_point command_start{};
    /// -o meshes and vector drawings (is_geometry_output), patterns with a number
    /// field: one file of each -a frame's geometry.
    std::vector<std::filesystem::path> geometry{};
    /// Each frame's image with its number, after its files are written: a caller that
    /// keeps the frames (the Python module's sequences). Null: files only.
    std::function<void(const render::Image&, int number)> frame_images{};
    /// Each file of an -a frame's geometry (-o meshes and drawings, -ray, -ps, -iv) once it
    /// is written whole: a caller that lists them (the Python module's exports). Null: none.
    std::function<void(const std::filesystem::path&)> geometry_written{};
};

/// Whether the command renders a sequence (-a or --turntable) instead of a still.
bool is_sequence(const Options& options);

/// Renders the sequence; returns the exit status (130 when interrupted).
int run_sequence(const Options& options, const SequenceOutputs& outputs);

/// The frames -a selects: those of the animation file, else cpfg's defaults (frames 1
/// to the derivation length, or --steps).
std::vector<geom::AnimationFrame> animation_frames(const Model& model, const Options& options);

/// Derives the frames' strings incrementally, each derivation step once, calling
/// `on_frame` with every frame and its string (what -str writes). The End block runs
/// after the last frame. Returns the number of steps derived.
int derive_frames(const Model& model, const std::vector<geom::AnimationFrame>& frames,
                  const std::function<void(const geom::AnimationFrame&,
                                           const lsys::ModuleString&)>& on_frame);

/// A frame, its string and, when asked for, its lineage from the previous frame's string
/// (lsys::Derivation::lineage(); empty when not tracked).
using FrameWithLineage = std::function<void(const geom::AnimationFrame&, const lsys::ModuleString&,
                                            const std::vector<std::uint32_t>& lineage)>;

/// derive_frames(), tracking each frame's lineage when `lineage` (for --inbetween).
int derive_frames_with_lineage(const Model& model,
                               const std::vector<geom::AnimationFrame>& frames, bool lineage,
                               const FrameWithLineage& on_frame);

/// The staging options' part of the render settings: --background, --ground,
/// --shadow-catcher.
void apply_staging(render::RenderSettings& settings, const Options& options);

/// The --sky (its sun from --sun or --sun-at) or --env map around the scene, turned by
/// --env-rotate; none without either. Throws cambium::Error for a map it cannot read.
std::shared_ptr<const render::Environment> make_environment(const Options& options);

/// The render settings of the options for `images` (the albedo, normal and depth layers
/// only when one of them keeps them), staging included; without a progress line or a
/// cancel flag, which the caller sets (the command: the terminal and Ctrl-C).
render::RenderSettings render_settings(const Options& options,
                                       const std::vector<std::filesystem::path>& images);

/// How images are written: --exposure and --tonemap.
render::WriteOptions write_options(const Options& options);

/// The scene's view with --orbit, --zoom, --fit, --fov, --perspective / --parallel.
void apply_camera_options(geom::Scene& scene, const Options& options);

/// Whether the -o `file` holds geometry (a mesh: OBJ, PLY, glTF, GLS; or a vector
/// drawing: PostScript, SVG, PDF) rather than a picture.
bool is_geometry_output(const std::filesystem::path& file);

/// Writes `scene` to the geometry output `file` in the format its extension names
/// (textures found beside the view file or scene file), within --max-memory.
void write_geometry_output(const geom::Scene& scene, const Options& options,
                           const std::filesystem::path& file);

/// -iv: `scene` as an Inventor 2.1 file (geom/inventor_export.h), within --max-memory.
void write_inventor_output(const geom::Scene& scene, const Options& options,
                           const std::filesystem::path& file);

/// Writes `scene` as the window shows it (the camera options applied) as a vector drawing
/// in `format` (-ps, or an -o named .ps, .svg or .pdf): every primitive tessellated and
/// projected, sorted far to near (render/vector_drawing.h). Throws cambium::Error when
/// the drawing would pass --max-memory.
void write_vector_output(const geom::Scene& scene, const Options& options,
                         const std::filesystem::path& file, VectorFormat format);

}  // namespace cambium::app
