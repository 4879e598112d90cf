// SPDX-License-Identifier: Apache-2.0
// The `cambium` command: derive a cpfg L-system, interpret it, path-trace it, write images.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>

#include <unistd.h>

#include <fmt/format.h>

#include "app/command_line.h"
#include "app/pipeline.h"
#include "app/scene_assembly.h"
#include "app/scene_file.h"
#include "base/atomic_file.h"
#include "app/sequence.h"
#include "app/video.h"
#include "base/diagnostics.h"
#include "base/subprocess.h"
#include "geom/view_volume.h"
#include "lsys/string_io.h"
#include "render/render.h"

namespace cambium::app {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start)
{
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Without -o (and without any other output), the image is named after the L-system
/// file, in the current folder.
std::vector<std::filesystem::path> image_outputs(const Options& options)
{
    if (!options.outputs.empty() || !options.renders())
        return options.outputs;
    return {(options.scene ? options.scene->stem() : options.lsystem.stem()).string() + ".png"};
}

render::PixelFilter pixel_filter(const std::string& name)
{
    if (name == "gaussian")
        return render::PixelFilter::gaussian;
    if (name == "blackman-harris")
        return render::PixelFilter::blackman_harris;
    return render::PixelFilter::box;
}

render::RenderSettings render_settings(const Options& options,
                                       const std::vector<std::filesystem::path>& images)
{
    render::RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.samples_per_pixel = options.samples_per_pixel;
    settings.max_depth = options.max_depth;
    settings.seed = options.seed;
    settings.threads = options.threads;
    settings.max_memory_bytes = options.max_memory_bytes;
    settings.filter = pixel_filter(options.filter);
    settings.filter_radius = options.filter_radius;
    settings.noise_target = options.noise_target;
    settings.time_budget_s = options.time_budget_s;
    settings.aperture_radius = options.aperture_radius;
    settings.focus_distance = options.focus_distance;
    settings.transparent_background = options.transparent;
    settings.ambient = {options.ambient, options.ambient, options.ambient};
    if (options.sky) {
        render::SkyParameters sky;
        if (!options.sun_direction.empty())
            sky.sun_direction = render::normalize(render::Vec3f(
                options.sun_direction[0], options.sun_direction[1], options.sun_direction[2]));
        sky.turbidity = options.turbidity;
        settings.environment = render::make_sky_environment(sky);
    } else if (options.environment_map) {
        settings.environment =
            render::make_map_environment(*options.environment_map, options.environment_scale);
    }
    if (settings.environment && options.environment_rotation != 0)
        settings.environment =
            render::make_rotated_environment(settings.environment, options.environment_rotation);
    settings.progress = !options.quiet && isatty(fileno(stderr));
    // The albedo, normal and depth layers cost a camera-ray intersection; only EXR keeps them.
    settings.aovs = std::any_of(images.begin(), images.end(), [](const auto& f) {
        std::string ext = f.extension().string();
        return ext == ".exr" || ext == ".EXR";
    });
    settings.cancel = render::install_interrupt_handler();
    apply_staging(settings, options);
    return settings;
}

/// Writes `file` through cambium::write_file_atomically, so a failure leaves nothing behind.
template <typename Write>
void write_atomically(const std::filesystem::path& file, Write write)
{
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (out)
            write(out);
        out.close();
        if (!out)
            throw Error(FileLoc{file.string()}, "cannot be written");
    });
}

/// -str and -strb: the derived string in cpfg's formats; names may be format strings
/// (plant%03d.str) that receive the derivation step.
void write_strings(const Model& model, const lsys::ModuleString& string, const Options& options,
                   int step, const std::function<void(const std::string&)>& say)
{
    if (options.string_text) {
        std::filesystem::path file = lsys::format_frame_name(options.string_text->string(), step);
        write_atomically(file, [&](std::ostream& out) {
            lsys::write_string_text(string, model.lsystem.symbols(), out);
        });
        say("wrote " + file.string());
    }
    if (options.string_binary) {
        std::filesystem::path file =
            lsys::format_frame_name(options.string_binary->string(), step);
        write_atomically(file, [&](std::ostream& out) {
            lsys::write_string_binary(string, model.lsystem.symbols(), out, step);
        });
        say("wrote " + file.string());
    }
}

/// Renders a still of `scene` to `images` (the camera options applied first).
int render_still(geom::Scene& scene, const Options& options,
                 const std::vector<std::filesystem::path>& images,
                 const std::function<void(const std::string&)>& say)
{
    render::RenderSettings settings = render_settings(options, images);
    apply_camera_options(scene, options);
    render::RenderReport report;
    render::Image image = render::render(scene, settings, &report);
    say(fmt::format("rendered {}x{}, {:.1f} samples per pixel on average, in {:.2f} s{}",
                    options.width, options.height,
                    double(report.samples) / (double(options.width) * options.height),
                    report.seconds, report.cancelled ? " (interrupted)" : ""));
    render::WriteOptions write = write_options(options);
    for (const auto& out : images) {
        render::write_image(image, out, write);
        say("wrote " + out.string());
    }
    if (report.cancelled)
        return 130;  // the image so far is written; the shell sees the interrupt
    return 0;
}

/// `cambium scene.json`: many plants placed by instances (docs/scenes.md).
int run_scene(Options options, const std::function<void(const std::string&)>& say)
{
    if (options.shot.animate)
        throw Error("-a animates one L-system; a scene file has no animation (try --turntable)");
    if (options.string_text || options.string_binary)
        throw Error("-str and -strb write one L-system's string; not with a scene file");
    if (!options.colour_files.empty())
        throw Error("-m and -M name one model's colours; each plant of a scene names its own "
                    "in its command");
    SceneFile file = read_scene_file(*options.scene, options);
    apply_scene_settings(file, options);
    if (options.steps)  // --steps derives every plant that many steps
        for (ScenePlant& plant : file.plants)
            plant.steps = {options.steps};
    std::vector<std::filesystem::path> images = image_outputs(options);
    for (const auto& out : images)
        if (!is_video(out))
            render::check_output_format(out);  // fail before the work, not after
    auto make_scene = [&]() {
        AssemblyReport report;
        geom::Scene scene = assemble_scene(file, options, {}, &report);
        say(fmt::format("{} plants ({} models, {} derivations) in {:.2f} s: load {:.2f} s, "
                        "derive {:.2f} s, interpret {:.2f} s; {} instances ({} of organs)",
                        report.plant_instances, report.models_loaded, report.derivations,
                        report.wall_s, report.load_s, report.derive_s, report.interpret_s,
                        scene.instances.size(), report.organ_instances));
        return scene;
    };
    if (is_sequence(options)) {
        SequenceOutputs outputs{images, render_settings(options, images), {}, say, make_scene};
        return run_sequence(options, outputs);
    }
    geom::Scene scene = make_scene();
    if (options.view_volume) {
        geom::write_view_volume(scene.bounds, *options.view_volume);
        say("wrote " + options.view_volume->string());
    }
    if (images.empty())
        return 0;
    return render_still(scene, options, images, say);
}

int run(const Options& options)
{
    // One sink for the whole command, render threads included; -q keeps warnings quiet.
    Diagnostics diagnostics(options.quiet ? Diagnostics::Output::quiet
                                          : Diagnostics::Output::print);
    ScopedDiagnostics install(diagnostics, ScopedDiagnostics::Reach::process);
    auto say = [&](const std::string& text) {
        if (!options.quiet)
            std::printf("%s\n", text.c_str());
    };
    if (options.scene)
        return run_scene(options, say);
    std::vector<std::filesystem::path> images = image_outputs(options);
    for (const auto& out : images)
        if (!is_video(out))
            render::check_output_format(out);  // fail before the work, not after
    if (options.environment_requested)
        warn("-e: no environmental program is connected; ?E modules keep their parameters");
    if (is_sequence(options)) {
        SequenceOutputs outputs{images, render_settings(options, images), {}, say, {}};
        outputs.write_strings = [&](const Model& model, const lsys::ModuleString& s, int step) {
            write_strings(model, s, options, step, say);
        };
        return run_sequence(options, outputs);
    }

    auto start = Clock::now();
    Model model = load_model(options);
    lsys::ModuleString string = derive(model, options);
    say(fmt::format("derived {} modules in {:.3f} s", string.size(), seconds_since(start)));
    write_strings(model, string, options,
                  options.steps.value_or(model.lsystem.derivation_length()), say);

    geom::Scene scene = interpret(model, string, options);
    const geom::Geometry& g = scene.geometry;
    say(fmt::format("interpreted {} cylinders, {} cylinder curves, {} spheres, {} discs, "
                    "{} triangles, {} instances",
                    g.lines.segment_count(), g.curves.segment_count(), g.spheres.size(),
                    g.discs.size(), g.mesh.size(), scene.instances.size()));
    if (options.view_volume) {
        // As cpfg, the view file's `box:` wins over the computed bounds.
        geom::write_view_volume(scene.view.box.value_or(scene.bounds), *options.view_volume);
        say("wrote " + options.view_volume->string());
    }
    if (images.empty())
        return 0;

    return render_still(scene, options, images, say);
}

}  // namespace
}  // namespace cambium::app

int main(int argc, char** argv)
{
    try {
        auto options = cambium::app::parse_command_line(argc, argv);
        if (!options)
            return 0;
        cambium::set_warnings_enabled(!options->quiet);  // -q: nothing but errors
        return cambium::app::run(*options);
    } catch (const cambium::Interrupted& e) {
        std::fprintf(stderr, "cambium: %s\n", e.what());
        return 128 + e.signal();  // a helper program was running; it is stopped
    } catch (const cambium::Error& e) {
        std::fprintf(stderr, "cambium: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cambium: error: %s\n", e.what());
        return 1;
    }
}
