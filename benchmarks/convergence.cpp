// SPDX-License-Identifier: Apache-2.0
// Convergence: how fast the path tracer's noise falls with samples on the benchmark plants.
// Each plant is rendered through the app pipeline (its model.json command line) at 1, 2,
// 4, ... max spp, and compared with its own high-spp reference (cached under the build
// folder): relative RMSE over the plant's pixels, the slope of log RMSE against log spp,
// the spp and time to reach a noise target (on the fitted line; the time interpolated
// between the measured renders, each with its set-up), samples/s and rays/s over all
// the renders (set-ups included), and peak memory. Prints one JSON object per plant and
// sampler; then, after every plant's series, one per plant with the path tracer against
// raw Embree on the same rays (below).
//
//   build/benchmarks/convergence [--plant NAME]... [--sampler sobol|white|both]
//       [--size WxH] [--threads N] [--max-spp N] [--reference-spp N] [--target NOISE]
//       [--adaptive NOISE] [--export-scene FOLDER] [--raw-embree-only | --no-raw-embree]
//       [--trace-empty-pixels] [--record-slots N] [--stage "WORDS" [--ground-target NOISE]]
//
// Defaults: the five plants below, both samplers, 320x240, 2 threads, up to 64 spp, a
// 1024-spp Sobol reference. The noise target (time_to_target_s) is, unless given, white
// noise's error at max spp when both samplers run (else Sobol's). Without the corpus
// (../shared/corpus, or $CAMBIUM_CORPUS) it prints {"skipped": ...} and exits 0.
//
// Noise: sqrt(mean over plant pixels and RGB of (value - reference)^2) / mean(reference),
// plant pixels being those the reference's camera rays hit at least half the time.
//
// Times: wall (`seconds`), the process's CPU time (user + sys, `cpu_seconds`: the robust
// figure on a loaded machine) and the set-up inside them (`setup_seconds`,
// `setup_cpu_seconds`: textures, the Embree build, lights), each per render; the time to
// the target with the set-up (wall, CPU) and without it (`time_to_target_render_s`,
// `time_to_target_render_cpu_s`).
//
// The path tracer against raw Embree (`"raw_embree_measurement":true` lines): two more
// renders of each plant at --max-spp, with Sobol (the renderer's default; white noise only
// when it alone is asked for) and the measured renders' settings, each in a single pass so
// that on_pass marks the end of its trace, in one render_views call (one BVH;
// bench::measure in ray_replay.h). The first, the recording render, has the interposer
// count its rays by kind, hash them and record every one (a pilot render at an eighth of
// the spp counts them first, to size the logs; where every ray would take more than 2 GiB,
// or with --record-slots N, a subsample: one run of rays in k, about 3/4 N of each kind). The second, the timed render,
// traces the same rays (same image, samples and renderer's ray count: `same_render`) with
// the interposer forwarding straight to Embree, and ends with the raw replay of the
// recorded rays on its scene and threads. Fields: the rays traced by kind (the recording's
// count) and their hashes (`ray_hashes`: singles, streams, shadow rays; equal at any
// thread count), what was recorded (`one_in`: one run of rays in k) and replayed,
// `trace_s` / `trace_cpu_s` (the timed render: first Embree call of the pixel loop to the
// end of the pass; `trace_window_s`: that span on the steady clock, CLOCK_MONOTONIC, for
// cutting a `perf record -k CLOCK_MONOTONIC` profile to it with benchmarks/embree_share.py),
// `recording_trace_cpu_s` (the recording render's, with the interposer's
// work), `raw_embree_cpu_s` (raw Embree's CPU seconds for the same numbers of rays of
// each kind; `raw_embree_first_round_cpu_s` at the first replay round's rates alone),
// `path_tracer_rays_per_s`, `raw_embree_rays_per_s` (wall) and
// `path_tracer_fraction_of_raw_cpu` (raw_embree_cpu_s / trace_cpu_s: the target is at
// least 0.8). These renders come after every series so that the logs' memory stays out
// of the series' peak RSS. --raw-embree-only runs only them (no references are needed);
// --no-raw-embree leaves them out.
// --trace-empty-pixels traces the camera rays of pixels no primitive reaches too
// (RenderSettings::skip_empty_pixels off: the same images).
//
// --adaptive NOISE instead renders once with adaptive sampling to that noise target (up
// to --max-spp) and prints its mean spp, wall and CPU seconds and the error reached:
// pixel_relative_error is the RMS of each plant pixel's relative luminance error, the
// quantity the target bounds.
//
// --export-scene FOLDER renders nothing: it writes each plant's interpreted scene as
// FOLDER/NAME.json (scene_export.h), which benchmarks/cycles/ builds in Blender.
//
// --stage "WORDS" stages each plant as a still: the words (--ground, --env, --perspective,
// --fit, --orbit, --no-view-lights, --background ...) are appended to its command line,
// and the renders take the app's render settings from it. Noise is then measured apart
// on the plant's pixels (relative_rmse, the noise target) and on the ground's
// (ground_relative_rmse, with --ground-target NOISE its spp and time to that noise); the
// reference is cached per staging; there is no raw-Embree measurement. With
// --export-scene the JSON gains the staging and FOLDER/NAME.region the two sets of pixels
// (make_staging), so that Cycles is measured on the same ones.

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/command_line.h"
#include "app/pipeline.h"
#include "app/sequence.h"
#include "render/render.h"
#include "render/ground.h"
#include "render/material.h"
#include "ray_replay.h"
#include "scene_export.h"

namespace fs = std::filesystem;

// The series count rays with the renderer's own counter (RenderReport::rays). This
// executable's rtcIntersect1 / rtcIntersect1M / rtcOccluded1 are the interposer of
// ray_replay.h (cambium_render is static and links to them): they forward straight to
// Embree's except in the pilot (counting) and the recording render.
namespace {

using Clock = std::chrono::steady_clock;
namespace render = cambium::render;

/// Where a benchmark plant comes from: a corpus model (its model.json gives the command
/// line) or one of the project's own scenes (with its command line here).
struct PlantSource {
    std::string folder;   ///< under the corpus, or under the project's source folder
    std::string command;  ///< empty: the corpus model's model.json; else the project's
};

/// The benchmark plants: leaves (FernLeaf), thin twigs (WeepingBirch), instancing and a
/// faint glow (Lilac), textured generalized cylinders, and translucent leaves lit by two
/// lights (the project's default tree: `translucency:` passes a third of the leaves'
/// diffuse light through).
const std::map<std::string, PlantSource> plants = {
    {"FernLeaf", {"cpfg/10-manuals/15-VlabTools/FernLeaf", ""}},
    {"WeepingBirch", {"cpfg/10-manuals/11-CPFG/WeepingBirch", ""}},
    {"Lilac", {"cpfg/10-manuals/11-CPFG/Lilac", ""}},
    {"GeneralizedCylinder", {"cpfg/10-manuals/11-CPFG/GeneralizedCylinder", ""}},
    {"TranslucentTree", {"scenes/default", "cpfg -M plant.mat plant.l plant.v"}},
};

struct Settings {
    std::vector<std::string> plants;
    std::vector<render::SampleSequence> samplers{render::SampleSequence::white,
                                                render::SampleSequence::sobol};
    int width = 320, height = 240, threads = 2, max_spp = 64, reference_spp = 1024;
    double target = 0;
    double adaptive = 0;  ///< --adaptive: one adaptive render to this noise target instead
    fs::path export_folder;  ///< --export-scene: write the scenes instead of rendering
    int max_depth = 0;       ///< --max-depth: path segments (0: the renderer's default)
    fs::path save_folder;    ///< --save-images: each render as raw RGBA floats there
    bool series = true;      ///< the convergence series (off: --raw-embree-only)
    bool raw_embree = true;  ///< the raw-Embree measurement (off: --no-raw-embree)
    bool skip_empty_pixels = true;  ///< off: --trace-empty-pixels
    /// --record-slots: the raw-Embree measurement's log slots per kind of ray, for a
    /// subsample (about 3/4 of them are aimed at); 0 (the default): every ray.
    std::size_t record_slots = 0;
    /// --stage WORDS: Cambium options appended to each plant's command line (--ground,
    /// --env, --perspective, --fit, --orbit, --no-view-lights, --background ...): a staged
    /// still. Noise is then measured apart on the plant's pixels and the ground's.
    std::string stage;
    double ground_target = 0;  ///< --ground-target: the ground's noise target
};

/// A staged plant's render settings (the app's, from the staged command line) and which
/// pixels are the plant's (1) and the ground's (2), rows from the top.
struct Staging {
    render::RenderSettings base;
    std::vector<std::uint8_t> region;
};

/// The process's CPU time so far, user + sys, in seconds.
double cpu_seconds()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
    return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double peak_rss_mb()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

const char* name(render::SampleSequence s)
{
    return s == render::SampleSequence::white ? "white" : "sobol";
}

/// The plant's scene, through the same path as `cambium <model.json's command>`; the
/// current folder becomes the model's (its files are named relative to it).
cambium::geom::Scene load_plant(const fs::path& folder, std::string command,
                                const std::string& stage = "",
                                cambium::app::Options* staged_options = nullptr)
{
    if (command.empty()) {
        std::ifstream in(folder / "model.json");
        command = nlohmann::json::parse(in).at("command").get<std::string>();
    }
    std::istringstream words(command);
    std::vector<std::string> args;
    std::string word;
    words >> word;  // "cpfg"
    while (words >> word)
        args.push_back(word);
    std::istringstream stage_words(stage);
    while (stage_words >> word)
        args.push_back(word);
    args.push_back("-q");
    fs::current_path(folder);
    cambium::app::Options options = *cambium::app::parse_command_line(args);
    cambium::app::Model model = cambium::app::load_model(options);
    cambium::geom::Scene scene =
        cambium::app::interpret(model, cambium::app::derive(model, options), options);
    if (!stage.empty())
        cambium::app::apply_camera_options(scene, options);  // as a staged still frames it
    if (staged_options)
        *staged_options = options;
    return scene;
}

struct Run {
    render::Image image;
    double seconds = 0, cpu_seconds = 0, setup_seconds = 0, setup_cpu_seconds = 0;
    std::uint64_t rays = 0, samples = 0;
};

/// The measured renders' settings.
render::RenderSettings render_settings(const Settings& s, int spp, render::SampleSequence sampler,
                                       std::uint64_t seed, double noise_target = 0,
                                       const Staging* staging = nullptr)
{
    render::RenderSettings rs = staging ? staging->base : render::RenderSettings{};
    rs.width = s.width;
    rs.height = s.height;
    rs.threads = s.threads;
    rs.samples_per_pixel = spp;
    rs.sampler = sampler;
    rs.seed = seed;
    rs.aovs = false;
    if (s.max_depth > 0)
        rs.max_depth = s.max_depth;
    rs.noise_target = static_cast<float>(noise_target);
    rs.skip_empty_pixels = s.skip_empty_pixels;
    return rs;
}

Run render_at(const cambium::geom::Scene& scene, const Settings& s, int spp,
              render::SampleSequence sampler, std::uint64_t seed, double noise_target = 0,
              const Staging* staging = nullptr)
{
    render::RenderSettings rs = render_settings(s, spp, sampler, seed, noise_target, staging);
    auto start = Clock::now();
    double cpu_start = cpu_seconds();
    render::RenderReport report;
    Run run{render::render(scene, rs, &report)};
    run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    run.cpu_seconds = cpu_seconds() - cpu_start;
    run.setup_seconds = report.setup_seconds;
    run.setup_cpu_seconds = report.setup_cpu_seconds;
    run.rays = report.rays;  // the renderer's own count
    run.samples = report.samples;
    return run;
}

/// The reference image, cached as raw floats in `cache` (it costs most of the run).
std::vector<float> reference(const cambium::geom::Scene& scene, const Settings& s,
                             const fs::path& file, const Staging* staging = nullptr)
{
    std::size_t n = std::size_t(s.width) * s.height * 4;
    std::vector<float> rgba(n);
    std::ifstream in(file, std::ios::binary);
    if (in.read(reinterpret_cast<char*>(rgba.data()), std::streamsize(n * sizeof(float))) &&
        in.peek() == std::char_traits<char>::eof())
        return rgba;
    // A seed of its own: the reference's noise is independent of the measured renders'.
    rgba = render_at(scene, s, s.reference_spp, render::SampleSequence::sobol, 0x5eed, 0, staging)
               .image.rgba;
    fs::create_directories(file.parent_path());
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(rgba.data()), std::streamsize(n * sizeof(float)));
    return rgba;
}

/// Relative RMSE over the plant's pixels (see the top of the file); staged, over the
/// pixels of `region` that are `which` (1: the plant's, 2: the ground's).
double relative_rmse(const std::vector<float>& image, const std::vector<float>& ref,
                     const std::vector<std::uint8_t>& region = {}, std::uint8_t which = 1)
{
    double sq = 0, sum = 0;
    std::size_t values = 0;
    for (std::size_t p = 0; p + 3 < ref.size(); p += 4) {
        if (region.empty() ? ref[p + 3] < 0.5f : region[p / 4] != which)
            continue;
        for (std::size_t c = 0; c < 3; ++c) {
            double d = double(image[p + c]) - ref[p + c];
            sq += d * d;
            sum += ref[p + c];
            ++values;
        }
    }
    return values > 0 && sum > 0 ? std::sqrt(sq / double(values)) / (sum / double(values)) : 0;
}

/// The staged settings of a plant and its regions: the plant's pixels are those its
/// camera rays hit at least half the time with neither ground nor environment (a
/// transparent film's coverage); the ground's, the others where the staged camera rays
/// hit something (a finite depth). 16 spp, one path segment: only the first hits count.
Staging make_staging(const cambium::geom::Scene& scene, const Settings& s,
                     const cambium::app::Options& options)
{
    Staging staging;
    staging.base = cambium::app::render_settings(options, {});
    render::RenderSettings cover = render_settings(s, 16, render::SampleSequence::sobol, 1, 0,
                                                   &staging);
    cover.max_depth = 1;
    render::RenderSettings depth = cover;
    cover.ground.enabled = false;
    cover.environment = nullptr;
    cover.transparent_background = true;
    depth.aovs = true;
    const render::Image plant = render::render(scene, cover);
    const render::Image hits = render::render(scene, depth);
    staging.region.assign(std::size_t(s.width) * s.height, 0);
    for (std::size_t i = 0; i < staging.region.size(); ++i)
        staging.region[i] = plant.rgba[4 * i + 3] >= 0.5f      ? 1
                            : std::isfinite(hits.depth[i]) ? 2
                                                           : 0;
    return staging;
}

/// What the scene export adds for a staged plant; its regions (make_staging) written to
/// `region_file` as one byte per pixel (0 neither, 1 plant, 2 ground), rows from the top,
/// so that the other renderer measures its noise on the same pixels.
cambium::bench::StageExport export_staging(const cambium::geom::Scene& scene, const Settings& s,
                                           const cambium::app::Options& options,
                                           const fs::path& region_file)
{
    const Staging staging = make_staging(scene, s, options);
    std::ofstream region(region_file, std::ios::binary | std::ios::trunc);
    region.write(reinterpret_cast<const char*>(staging.region.data()),
                 std::streamsize(staging.region.size()));
    if (!region)
        throw std::runtime_error("cannot write " + region_file.string());
    const render::RenderSettings& rs = staging.base;
    cambium::bench::StageExport e;
    e.view_lights = rs.view_lights;
    if (rs.ground.enabled) {
        if (!rs.ground.texture.empty() || rs.ground.shadow_catcher)
            throw std::runtime_error("--stage: only a plain --ground is exported");
        e.ground_height = rs.ground.height.value_or(render::lowest_point(scene));
        cambium::geom::Material soil;
        soil.diffuse = rs.ground.colour;  // as render.cpp's make_ground decodes it
        const render::Vec3f d = render::make_materials({soil}).front().diffuse;
        e.ground_diffuse = {d.x, d.y, d.z};
    }
    if (options.sky) {
        // Cycles' skies are other models: it gets this one's dome as a map and its sun
        // as a lamp of the same solid angle and radiance.
        const render::environment_kind::Sky* sky = rs.environment ? rs.environment->sky() : nullptr;
        if (sky == nullptr || rs.environment->rotation_degrees() != 0)
            throw std::runtime_error("--stage: only an unturned --sky is exported");
        e.environment_map = fs::absolute(region_file).replace_extension(".sky.exr");
        e.sun = cambium::bench::write_sky_dome_map(*sky, 1024, e.environment_map);
    }
    if (options.environment_map) {
        e.environment_map = fs::absolute(*options.environment_map);
        e.environment_scale = options.environment_scale;
        e.environment_rotation_deg = options.environment_rotation;
    }
    e.backdrop_environment = rs.backdrop == render::RenderSettings::Backdrop::environment;
    return e;
}

/// Least-squares line y = a + b x.
std::pair<double, double> fit_line(const std::vector<double>& x, const std::vector<double>& y)
{
    double n = double(x.size()), sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sx += x[i];
        sy += y[i];
        sxx += x[i] * x[i];
        sxy += x[i] * y[i];
    }
    double b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    return {(sy - b * sx) / n, b};
}

struct Curve {
    std::vector<double> spp, rmse, seconds, cpu_seconds, setup_seconds, setup_cpu_seconds;
    std::uint64_t rays = 0, samples = 0;
    double render_seconds = 0;
};

/// The time a render of `spp` samples takes, `seconds` being the measured runs' (wall,
/// CPU, or without set-up): interpolated between the measured runs, extrapolated past
/// the last at the last step's cost per spp.
double seconds_at(const Curve& c, const std::vector<double>& seconds, double spp)
{
    if (spp <= c.spp.front())
        return seconds.front() * spp / c.spp.front();
    std::size_t i = 1;
    while (i + 1 < c.spp.size() && c.spp[i] < spp)
        ++i;
    double per_spp = std::max(0.0, (seconds[i] - seconds[i - 1]) / (c.spp[i] - c.spp[i - 1]));
    return seconds[i - 1] + per_spp * (spp - c.spp[i - 1]);
}

std::string json_array(const std::vector<double>& v, const char* format)
{
    std::string out = "[";
    char buffer[64];
    for (std::size_t i = 0; i < v.size(); ++i) {
        std::snprintf(buffer, sizeof buffer, format, v[i]);
        if (i > 0)
            out += ',';
        out += buffer;
    }
    return out + "]";
}

/// A staged series' figures on the ground's pixels: its noise per render, the slope,
/// and the spp and times (set-up included and not) to the ground's noise target.
std::string ground_figures(const Curve& c, const std::vector<double>& rmse, double target)
{
    std::vector<double> log_spp, log_rmse, render_only, render_only_cpu;
    for (std::size_t i = 0; i < c.spp.size(); ++i) {
        log_spp.push_back(std::log(c.spp[i]));
        log_rmse.push_back(std::log(rmse[i]));
        render_only.push_back(c.seconds[i] - c.setup_seconds[i]);
        render_only_cpu.push_back(c.cpu_seconds[i] - c.setup_cpu_seconds[i]);
    }
    auto [a, slope] = fit_line(log_spp, log_rmse);
    double spp = target > 0 ? std::exp((std::log(target) - a) / slope) : 0;
    char buffer[512];
    std::snprintf(buffer, sizeof buffer,
                  ",\"ground_relative_rmse\":%s,\"ground_slope\":%.3f,"
                  "\"ground_target_noise\":%.5f,\"ground_spp_to_target\":%.1f,"
                  "\"ground_time_to_target_render_s\":%.3f,"
                  "\"ground_time_to_target_render_cpu_s\":%.3f",
                  json_array(rmse, "%.5f").c_str(), slope, target, spp,
                  target > 0 ? seconds_at(c, render_only, spp) : 0.0,
                  target > 0 ? seconds_at(c, render_only_cpu, spp) : 0.0);
    return buffer;
}

void report(const std::string& plant, const Settings& s, render::SampleSequence sampler,
            const Curve& c, double target, const std::string& extra = "")
{
    std::vector<double> log_spp, log_rmse;
    for (std::size_t i = 0; i < c.spp.size(); ++i) {
        log_spp.push_back(std::log(c.spp[i]));
        log_rmse.push_back(std::log(c.rmse[i]));
    }
    auto [a, slope] = fit_line(log_spp, log_rmse);
    double spp_to_target = std::exp((std::log(target) - a) / slope);
    double total_spp = 0;
    for (double spp : c.spp)
        total_spp += spp;
    std::vector<double> render_only, render_only_cpu;  // wall and CPU time less the set-up
    for (std::size_t i = 0; i < c.spp.size(); ++i) {
        render_only.push_back(c.seconds[i] - c.setup_seconds[i]);
        render_only_cpu.push_back(c.cpu_seconds[i] - c.setup_cpu_seconds[i]);
    }
    std::printf("{\"plant\":\"%s\",\"sampler\":\"%s\",\"image\":\"%dx%d\",\"threads\":%d,"
                "\"reference_spp\":%d,\"spp\":%s,\"relative_rmse\":%s,\"seconds\":%s,"
                "\"cpu_seconds\":%s,\"setup_seconds\":%s,\"setup_cpu_seconds\":%s,"
                "\"slope\":%.3f,\"target_noise\":%.5f,\"spp_to_target\":%.1f,"
                "\"time_to_target_s\":%.3f,\"time_to_target_cpu_s\":%.3f,"
                "\"time_to_target_render_s\":%.3f,\"time_to_target_render_cpu_s\":%.3f,"
                "\"samples_per_s\":%.0f,"
                "\"rays_per_s\":%.0f,\"peak_rss_mb\":%.0f%s}\n",
                plant.c_str(), name(sampler), s.width, s.height, s.threads, s.reference_spp,
                json_array(c.spp, "%.0f").c_str(), json_array(c.rmse, "%.5f").c_str(),
                json_array(c.seconds, "%.3f").c_str(), json_array(c.cpu_seconds, "%.3f").c_str(),
                json_array(c.setup_seconds, "%.3f").c_str(),
                json_array(c.setup_cpu_seconds, "%.3f").c_str(), slope, target, spp_to_target,
                seconds_at(c, c.seconds, spp_to_target),
                seconds_at(c, c.cpu_seconds, spp_to_target),
                seconds_at(c, render_only, spp_to_target),
                seconds_at(c, render_only_cpu, spp_to_target),
                double(s.width) * s.height * total_spp / c.render_seconds,
                double(c.rays) / c.render_seconds, peak_rss_mb(), extra.c_str());
    std::fflush(stdout);
}

/// --save-images: `rgba` as raw floats (width x height x 4, rows from the top) in
/// FOLDER/NAME.f32, for looking at where the error lies.
void save_image(const Settings& s, const std::string& name, const std::vector<float>& rgba)
{
    if (s.save_folder.empty())
        return;
    fs::create_directories(s.save_folder);
    std::ofstream out(s.save_folder / (name + ".f32"), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(rgba.data()),
              std::streamsize(rgba.size() * sizeof(float)));
}

/// RMS over the plant's pixels of the relative error of each pixel's luminance, the
/// quantity adaptive sampling's noise target bounds (render.cpp: relative_error).
double pixel_relative_error(const std::vector<float>& image, const std::vector<float>& ref)
{
    auto luminance = [](const std::vector<float>& v, std::size_t p) {
        return 0.2126 * v[p] + 0.7152 * v[p + 1] + 0.0722 * v[p + 2];
    };
    double sq = 0;
    std::size_t pixels = 0;
    for (std::size_t p = 0; p + 3 < ref.size(); p += 4) {
        if (ref[p + 3] < 0.5f)
            continue;
        double r = luminance(ref, p);
        double e = (luminance(image, p) - r) / std::max(r, 0.01);
        sq += e * e;
        ++pixels;
    }
    return pixels > 0 ? std::sqrt(sq / double(pixels)) : 0;
}

/// --adaptive: one render with the noise target (up to --max-spp), against the reference.
void run_adaptive(const std::string& plant, const cambium::geom::Scene& scene,
                  const std::vector<float>& ref, const Settings& s)
{
    Run run = render_at(scene, s, s.max_spp, render::SampleSequence::sobol, 0, s.adaptive);
    std::printf("{\"plant\":\"%s\",\"adaptive_target\":%.4f,\"image\":\"%dx%d\","
                "\"threads\":%d,\"max_spp\":%d,\"mean_spp\":%.1f,\"seconds\":%.3f,"
                "\"cpu_seconds\":%.3f,\"pixel_relative_error\":%.4f,\"relative_rmse\":%.5f}\n",
                plant.c_str(), s.adaptive, s.width, s.height, s.threads, s.max_spp,
                double(run.samples) / (double(s.width) * s.height), run.seconds,
                run.cpu_seconds, pixel_relative_error(run.image.rgba, ref),
                relative_rmse(run.image.rgba, ref));
    std::fflush(stdout);
}

/// Rays of each kind a render traces.
struct RayCounts {
    std::uint64_t singles = 0, occlusions = 0, streams = 0;
};

/// The rays of each kind a render at --max-spp will trace, from a pilot render at an eighth
/// of the spp: what sets the recorder's subsample.
RayCounts expected_rays(const cambium::geom::Scene& scene, const Settings& s,
                        render::SampleSequence sampler)
{
    using cambium::bench::recorder;
    const int pilot_spp = std::max(1, s.max_spp / 8);
    const std::uint64_t i0 = recorder.intersections.total(), o0 = recorder.occlusions.total(),
                        m0 = recorder.stream_intersections.total();
    recorder.count();
    render_at(scene, s, pilot_spp, sampler, 0);
    recorder.forward();
    const double scale = double(s.max_spp) / pilot_spp;
    auto scaled = [scale](std::uint64_t n) { return std::uint64_t(double(n) * scale); };
    const std::uint64_t streams = recorder.stream_intersections.total() - m0;
    return {scaled(recorder.intersections.total() - i0 - streams),
            scaled(recorder.occlusions.total() - o0), scaled(streams)};
}

/// One `"raw_embree_measurement":true` line (see the top of the file).
void report_raw_embree(const std::string& plant, const Settings& s,
                       render::SampleSequence sampler, const cambium::bench::Measurement& m)
{
    const cambium::bench::Recorder& r = cambium::bench::recorder;
    const cambium::bench::TraceFigures& t = m.trace;
    const cambium::bench::RawFigures& raw = t.raw;
    std::printf("{\"plant\":\"%s\",\"sampler\":\"%s\",\"raw_embree_measurement\":true,"
                "\"image\":\"%dx%d\",\"threads\":%d,\"spp\":%d,\"samples\":%llu,"
                "\"intersect_rays\":%llu,\"stream_intersect_rays\":%llu,"
                "\"occlusion_rays\":%llu,\"ray_hashes\":[\"%016llx\",\"%016llx\",\"%016llx\"],"
                "\"recorded\":{\"intersect_rays\":%zu,"
                "\"stream_rays\":%zu,\"occlusion_rays\":%zu,\"one_in\":[%zu,%zu,%zu]},"
                "\"raw_embree\":{\"intersect_rays\":%zu,\"intersect_cpu_s\":%.3f,"
                "\"stream_rays\":%zu,\"stream_cpu_s\":%.3f,\"occlusion_rays\":%zu,"
                "\"occlusion_cpu_s\":%.3f,\"first_round_cpu_s\":[%.4f,%.4f,%.4f]},"
                "\"timed_render\":\"the second of two identical renders, not recorded\","
                "\"same_render\":%s,\"renderer_rays\":%llu,"
                "\"trace_s\":%.3f,\"trace_cpu_s\":%.3f,\"recording_trace_cpu_s\":%.3f,"
                "\"trace_window_s\":[%.6f,%.6f],"
                "\"raw_embree_cpu_s\":%.3f,\"raw_embree_first_round_cpu_s\":%.3f,"
                "\"path_tracer_rays_per_s\":%.0f,\"raw_embree_rays_per_s\":%.0f,"
                "\"path_tracer_fraction_of_raw\":%.3f,"
                "\"path_tracer_fraction_of_raw_cpu\":%.3f}\n",
                plant.c_str(), name(sampler), s.width, s.height, s.threads, s.max_spp,
                static_cast<unsigned long long>(m.timed.samples),
                static_cast<unsigned long long>(t.intersections),
                static_cast<unsigned long long>(t.stream_intersections),
                static_cast<unsigned long long>(t.occlusions),
                static_cast<unsigned long long>(t.singles_hash),
                static_cast<unsigned long long>(t.streams_hash),
                static_cast<unsigned long long>(t.occlusions_hash), r.singles.rays.size(),
                r.streams.rays.size(), r.occlusion_rays.rays.size(), r.singles.every,
                r.streams.every, r.occlusion_rays.every, raw.singles, raw.intersect_cpu_s,
                raw.streams, raw.stream_cpu_s, raw.occlusions, raw.occluded_cpu_s,
                raw.intersect_first_cpu_s, raw.stream_first_cpu_s, raw.occluded_first_cpu_s,
                m.same_render ? "true" : "false",
                static_cast<unsigned long long>(m.timed.rays), t.trace_s, t.trace_cpu_s,
                t.recording_trace_cpu_s, t.trace_window_s[0], t.trace_window_s[1],
                t.raw_mix_cpu_s(), t.raw_mix_first_round_cpu_s(),
                t.trace_s > 0 ? double(t.rays()) / t.trace_s : 0.0, t.raw_rays_per_s(),
                t.path_tracer_fraction_of_raw(), t.path_tracer_fraction_of_raw_cpu());
    std::fflush(stdout);
}

/// The path tracer against raw Embree on the same rays (ray_replay.h): two renders at
/// --max-spp, as the measured renders but each in one pass, in one render_views call (one
/// BVH): the first records its rays (every one, or a subsample, see the top), the second, the same render again, is timed with the interposer out of its way and ends
/// with the raw replay on its scene and threads.
void run_raw_embree(const std::string& plant, const cambium::geom::Scene& scene,
                    const Settings& s, render::SampleSequence sampler)
{
    using cambium::bench::recorder;
    const RayCounts expected = expected_rays(scene, s, sampler);
    render::RenderSettings rs = render_settings(s, s.max_spp, sampler, 0);
    // As render(scene, settings) frames it (these settings have no lens).
    const render::Camera camera = render::make_camera(scene.view, scene.bounds, s.width, s.height);
    // The logs are allocated and touched here, before the renders.
    // Every ray, unless its logs would pass 2 GiB (a large --size or --max-spp): then a
    // subsample of about 300 k of each kind.
    const double every_ray_bytes =
        1.25 * (double(expected.singles + expected.occlusions) *
                    double(sizeof(RTCRay) + sizeof(render::PrimId)) +
                double(expected.streams) * double(sizeof(RTCRay)));
    const std::size_t slots =
        s.record_slots > 0 ? s.record_slots : every_ray_bytes > 0x1p31 ? 400'000 : 0;
    if (slots > 0)
        recorder.prepare(slots, expected.singles, expected.occlusions, expected.streams);
    else
        recorder.prepare_every_ray(expected.singles, expected.occlusions, expected.streams);
    report_raw_embree(plant, s, sampler, cambium::bench::measure(scene, camera, rs));
}

void run_plant(const std::string& plant, const fs::path& folder, const std::string& command,
               const Settings& s,
               const fs::path& cache)
{
    cambium::app::Options options;
    cambium::geom::Scene scene = load_plant(folder, command, s.stage, &options);
    std::optional<Staging> staging;
    std::string stage_tag;
    if (!s.stage.empty()) {
        staging = make_staging(scene, s, options);
        // The staged reference is cached per staging (an FNV-1a hash of its words).
        std::uint64_t h = 0xcbf29ce484222325ull;
        for (unsigned char ch : s.stage)
            h = (h ^ ch) * 0x100000001b3ull;
        char hex[24];
        std::snprintf(hex, sizeof hex, "-stage%016llx", static_cast<unsigned long long>(h));
        stage_tag = hex;
    }
    const Staging* st = staging ? &*staging : nullptr;
    std::vector<float> ref = reference(
        scene, s,
        cache / (plant + "-" + std::to_string(s.width) + "x" + std::to_string(s.height) + "-" +
                 std::to_string(s.reference_spp) +
                 (s.max_depth > 0 ? "-depth" + std::to_string(s.max_depth) : "") + stage_tag +
                 ".f32"),
        st);
    save_image(s, plant + "-reference", ref);
    if (s.adaptive > 0) {
        run_adaptive(plant, scene, ref, s);
        return;
    }
    const std::vector<std::uint8_t> no_region;
    const std::vector<std::uint8_t>& region = st ? st->region : no_region;
    std::map<render::SampleSequence, Curve> curves;
    std::map<render::SampleSequence, std::vector<double>> ground_rmse;
    for (render::SampleSequence sampler : s.samplers) {
        Curve& c = curves[sampler];
        for (int spp = 1; spp <= s.max_spp; spp *= 2) {
            Run run = render_at(scene, s, spp, sampler, 0, 0, st);
            save_image(s, plant + "-" + name(sampler) + "-" + std::to_string(spp),
                       run.image.rgba);
            c.spp.push_back(spp);
            c.rmse.push_back(relative_rmse(run.image.rgba, ref, region, 1));
            if (st)
                ground_rmse[sampler].push_back(relative_rmse(run.image.rgba, ref, region, 2));
            c.seconds.push_back(run.seconds);
            c.cpu_seconds.push_back(run.cpu_seconds);
            c.setup_seconds.push_back(run.setup_seconds);
            c.setup_cpu_seconds.push_back(run.setup_cpu_seconds);
            c.rays += run.rays;
            c.render_seconds += run.seconds;
        }
    }
    double target = s.target;
    if (!(target > 0)) {
        const Curve& basis = curves.count(render::SampleSequence::white)
                                 ? curves[render::SampleSequence::white]
                                 : curves.begin()->second;
        target = basis.rmse.back();
    }
    for (const auto& [sampler, curve] : curves)
        report(plant, s, sampler, curve, target,
               st ? ground_figures(curve, ground_rmse[sampler], s.ground_target) : "");
}

/// The plant's folder: under the corpus, or the project's own.
fs::path plant_folder(const PlantSource& source, const fs::path& corpus)
{
    return source.command.empty() ? corpus / source.folder
                                  : fs::path(CAMBIUM_SOURCE_DIR) / source.folder;
}

Settings parse(int argc, char** argv)
{
    Settings s;
    for (int i = 1; i < argc; ++i) {
        std::string arg = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc)
                throw std::runtime_error(arg + " needs a value");
            return argv[++i];
        };
        if (arg == "--plant") {
            std::string p = value();
            if (!plants.count(p))
                throw std::runtime_error("unknown plant " + p);
            s.plants.push_back(p);
        } else if (arg == "--sampler") {
            std::string v = value();
            if (v == "sobol")
                s.samplers = {render::SampleSequence::sobol};
            else if (v == "white")
                s.samplers = {render::SampleSequence::white};
            else if (v != "both")
                throw std::runtime_error("--sampler: sobol, white or both");
        } else if (arg == "--size") {
            if (std::sscanf(value().c_str(), "%dx%d", &s.width, &s.height) != 2)
                throw std::runtime_error("--size WxH");
        } else if (arg == "--threads") {
            s.threads = std::stoi(value());
        } else if (arg == "--max-spp") {
            s.max_spp = std::stoi(value());
        } else if (arg == "--reference-spp") {
            s.reference_spp = std::stoi(value());
        } else if (arg == "--target") {
            s.target = std::stod(value());
        } else if (arg == "--adaptive") {
            s.adaptive = std::stod(value());
        } else if (arg == "--max-depth") {
            s.max_depth = std::stoi(value());
        } else if (arg == "--save-images") {
            s.save_folder = fs::absolute(value());
        } else if (arg == "--raw-embree-only") {
            s.series = false;
        } else if (arg == "--no-raw-embree") {
            s.raw_embree = false;
        } else if (arg == "--record-slots") {
            s.record_slots = std::stoul(value());
            if (s.record_slots > 0 && s.record_slots < cambium::bench::RayLog::chunk)
                throw std::runtime_error("--record-slots: 0 (every ray) or at least 4096");
        } else if (arg == "--trace-empty-pixels") {
            s.skip_empty_pixels = false;
        } else if (arg == "--stage") {
            s.stage = value();
        } else if (arg == "--ground-target") {
            s.ground_target = std::stod(value());
        } else if (arg == "--export-scene") {
            s.export_folder = fs::absolute(value());
        } else {
            throw std::runtime_error("unknown argument " + arg);
        }
    }
    if (s.plants.empty())
        for (const auto& [plant, folder] : plants)
            s.plants.push_back(plant);
    if (!s.stage.empty() && s.series)
        s.raw_embree = false;  // the raw-Embree measurement renders the plants unstaged
    if (!s.series && !s.raw_embree)
        throw std::runtime_error("--raw-embree-only and --no-raw-embree leave nothing to do");
    return s;
}

}  // namespace

int main(int argc, char** argv)
{
    try {
        Settings s = parse(argc, argv);
        const char* env = std::getenv("CAMBIUM_CORPUS");
        fs::path corpus = fs::absolute(env ? env : CAMBIUM_CORPUS_DEFAULT);
        fs::path cache = fs::absolute(CAMBIUM_BUILD_DIR) / "convergence-cache";
        std::vector<std::string> found;  // the plants whose model is there
        for (const std::string& plant : s.plants) {
            const PlantSource& source = plants.at(plant);
            const fs::path folder = plant_folder(source, corpus);
            if (source.command.empty() && !fs::exists(folder / "model.json")) {
                std::printf("{\"plant\":\"%s\",\"skipped\":\"no corpus model at %s\"}\n",
                            plant.c_str(), folder.string().c_str());
                continue;
            }
            found.push_back(plant);
            if (!s.export_folder.empty()) {
                fs::create_directories(s.export_folder);
                std::ofstream out(s.export_folder / (plant + ".json"));
                cambium::app::Options options;
                cambium::geom::Scene scene = load_plant(folder, source.command, s.stage, &options);
                std::optional<cambium::bench::StageExport> stage;
                if (!s.stage.empty())
                    stage = export_staging(scene, s, options,
                                           s.export_folder / (plant + ".region"));
                cambium::bench::write_scene_json(scene, s.width, s.height, folder, out, stage);
                if (!out)
                    throw std::runtime_error("cannot write " +
                                             (s.export_folder / plant).string());
            } else if (s.series) {
                run_plant(plant, folder, source.command, s, cache);
            }
        }
        // After every plant's series, so that the logs' memory is not in their peak RSS.
        if (s.raw_embree && s.export_folder.empty() && !(s.adaptive > 0)) {
            // The renderer's default sampler unless only white noise was asked for.
            const render::SampleSequence sampler =
                std::count(s.samplers.begin(), s.samplers.end(), render::SampleSequence::sobol)
                    ? render::SampleSequence::sobol
                    : s.samplers.front();
            for (const std::string& plant : found) {
                const PlantSource& source = plants.at(plant);
                run_raw_embree(plant, load_plant(plant_folder(source, corpus), source.command),
                               s, sampler);
            }
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "convergence: %s\n", e.what());
        return 1;
    }
    return 0;
}
