// SPDX-License-Identifier: Apache-2.0
// The `cambium` command line: cpfg's options that make sense offline, plus modern ones.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "base/limits.h"

namespace cambium::app {

/// The largest image side -w accepts (the image also has at most
/// render::max_image_pixels pixels).
inline constexpr int max_image_side = 32768;

/// A colormap (-m[n]) or material file (-M[n]) for colour-table block n.
struct ColourFile {
    int block = 1;
    bool materials = false;
    std::filesystem::path file;
};

/// How much cpfg-style tracing to print (-v warnings, -V verbose).
enum class Verbosity { normal, warnings, verbose };

/// Sequences and the camera (src/app/shot_options.cpp): cpfg's animation mode,
/// turntables, camera changes over the view file, and which frames to render.
struct ShotOptions {
    bool animate = false;                      ///< -a: the frames the animation selects
    int turntable = 0;                         ///< --turntable N frames (0 = none)
    std::optional<double> turntable_elevation; ///< --turntable-elevation DEG
    std::vector<double> orbit;                 ///< --orbit AZ EL (degrees)
    double zoom = 1;                           ///< --zoom K
    bool fit = false;                          ///< --fit
    std::optional<double> fov;                 ///< --fov DEG
    bool perspective = false, parallel = false;  ///< --perspective / --parallel
    std::optional<std::string> frames;         ///< --frames A-B (frame numbers)
    bool resume = false;                       ///< --resume: skip frames already written
    bool video = false;                        ///< --video: also <plant>.mp4
    int fps = 24;                              ///< --fps of video outputs
    std::string tonemap = "none";              ///< --tonemap none|filmic (display outputs)
    std::optional<std::string> background;     ///< --background COLOUR|sky|env
    std::optional<std::string> ground;         ///< --ground [COLOUR|FILE] ("": grey)
    bool shadow_catcher = false;               ///< --shadow-catcher
    int inbetween = 0;                         ///< --inbetween K frames between steps
};

struct Options {
    std::filesystem::path lsystem, view;
    /// A scene file (docs/scenes.md) given instead of plant.l plant.v: many plants.
    std::optional<std::filesystem::path> scene;
    /// A scene's per-plant seed of the L-system's random streams (not an option).
    std::optional<long> lsystem_seed;
    std::optional<std::filesystem::path> animation;
    std::vector<ColourFile> colour_files;
    int colour_block = 1;  ///< -c n

    // Language (cpfg options)
    std::string preprocessor = "cpp";          ///< -P
    std::size_t max_modules = 100'000'000;     ///< --max-modules
    /// --max-memory: derivation, interpretation and each texture (base/limits.h)
    std::uint64_t max_memory_bytes = default_max_memory_bytes();
    std::optional<int> steps;                  ///< --steps: derivation steps instead of the file's
    Verbosity verbosity = Verbosity::normal;
    std::optional<std::filesystem::path> environment_file;  ///< -e file.e (manual 7.4.1)
    bool allow_system_calls = false;           ///< @S runs commands only with this
    /// --allow-environment-program: a `.e` file may start the program it names (manual 7.4)
    bool allow_environment_program = false;
    /// --environment-messages DIR: each pass's messages to and from a program, as text
    std::optional<std::filesystem::path> environment_messages;
    bool allow_file_access = false;            ///< fopen outside the model's folder

    // Outputs besides images (cpfg options, file names may be format strings)
    std::optional<std::filesystem::path> string_text;    ///< -str
    std::optional<std::filesystem::path> string_binary;  ///< -strb
    bool homomorphism_in_string = false;                  ///< -homo
    std::optional<std::filesystem::path> view_volume;    ///< -vv
    std::optional<std::filesystem::path> rayshade;       ///< -ray: rayshade 4.0 scene
    std::optional<std::filesystem::path> postscript;     ///< -ps: the window as PostScript
    std::optional<std::filesystem::path> inventor;       ///< -iv: Inventor 2.1 scene
    // Statistics (app/stats.h): a readable block on stderr, and JSON
    bool stats = false;                                   ///< --stats
    std::optional<std::filesystem::path> stats_json;     ///< --stats-json FILE
    /// --light-report FILE: the light each organ absorbs (docs/light.md), .json or .csv
    std::optional<std::filesystem::path> light_report;
    /// --infinite-canopy: the light report repeats the scene sideways over its x-z bounds
    bool infinite_canopy = false;
    /// --canopy-tile X0 Z0 X1 Z1: the canopy's tile instead of those bounds (it implies it)
    std::vector<double> canopy_tile;
    std::uint64_t light_rays = 1'000'000;  ///< --light-rays N

    // Rendering
    int width = 640, height = 480;
    std::vector<std::filesystem::path> outputs;  ///< -o (and cpfg's -rgb / -tga)
    int samples_per_pixel = 64;
    int max_depth = 6;
    int threads = 0;
    // A render in pieces (docs/distributed.md)
    std::optional<std::pair<int, int>> tile;  ///< --tile I/N: band I of N bands (0-based)
    std::optional<int> assemble;              ///< --assemble N: the N tiles into the outputs
    bool mpi = false;                         ///< --mpi: shared among the ranks of an MPI job
    std::uint64_t seed = 0;
    std::string sampler = "sobol";     ///< --sampler sobol|white (hidden, for comparisons)
    bool quiet = false;
    std::string filter = "box";        ///< --filter box|gaussian|blackman-harris
    float filter_radius = 0;           ///< --filter-radius (0: the filter's default)
    float noise_target = 0;            ///< --noise-target: adaptive sampling (0 = off)
    bool denoise = false;              ///< --denoise: each frame denoised (docs/denoise.md)
    /// --organ-masks: EXR outputs get Cryptomatte layers and organ channels (docs/masks.md)
    bool organ_masks = false;
    double time_budget_s = 0;          ///< --time-budget seconds (0 = none)
    double aperture_radius = 0;        ///< --aperture: thin-lens radius (0 = pinhole)
    double focus_distance = 0;         ///< --focus-distance (0 = view reference point)
    float exposure = 0;                ///< --exposure stops, for PNG/TIFF/JPEG
    bool transparent = false;          ///< --transparent: no background, alpha = coverage
    /// --material-transparency: the L-system's materials keep their transparency (as in
    /// cpfg's rayshade output); by default they are opaque, as cpfg's window draws them.
    bool material_transparency = false;
    float ambient = 0.05f;             ///< --ambient: uniform environment radiance
    bool sky = false;                  ///< --sky: analytic sun and sky
    std::vector<float> sun_direction;  ///< --sun X Y Z (with --sky), or from --sun-at
    /// --sun-at LAT LON TIME: the place and local time the --sky's sun is computed for
    std::vector<std::string> sun_at;
    float turbidity = 3;               ///< --turbidity: sky haze, 1.7 .. 10 (with --sky)
    std::optional<std::filesystem::path> environment_map;  ///< --env file.exr|.hdr
    float environment_scale = 1;       ///< --env-scale
    float environment_rotation = 0;    ///< --env-rotate DEG about +y (with --env or --sky)
    /// --no-view-lights: the view file's lights (or cpfg's default light where it has no
    /// `light:`) are left out; the sky, the map, the ambient and emissive surfaces light.
    bool no_view_lights = false;

    ShotOptions shot;

    /// The options the command line gave (as spelled: "--spp", "-w"), so that a scene
    /// file's settings apply only where the command line is silent.
    std::vector<std::string> given;
    bool was_given(const std::string& name) const
    {
        for (const std::string& g : given)
            if (g == name)
                return true;
        return false;
    }

    /// Whether an image is to be rendered: an -o was given, or no other output was.
    bool renders() const
    {
        return !outputs.empty() ||
               (!string_text && !string_binary && !view_volume && !rayshade && !postscript &&
                !inventor && !light_report);
    }
};

/// Parses argv. Returns nullopt after printing help (exit 0); throws cambium::Error
/// on a malformed command line.
std::optional<Options> parse_command_line(int argc, char** argv);

/// The same from words (tests, and the corpus's recorded cpfg command lines), without
/// the program name.
std::optional<Options> parse_command_line(const std::vector<std::string>& args);

}  // namespace cambium::app
