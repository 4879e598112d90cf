// SPDX-License-Identifier: Apache-2.0
// The `cambium` command: derive a cpfg L-system, interpret it, path-trace it, write images.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string_view>

#include <unistd.h>

#include <fmt/format.h>

#include "app/command_line.h"
#include "app/distributed.h"
#include "app/light_report.h"
#include "app/tiles.h"
#include "app/pipeline.h"
#include "app/scene_assembly.h"
#include "app/scene_file.h"
#include "base/atomic_file.h"
#include "app/sequence.h"
#include "app/stats.h"
#include "app/terminal.h"
#include "app/video.h"
#include "base/diagnostics.h"
#include "base/subprocess.h"
#include "geom/rayshade_export.h"
#include "geom/view_volume.h"
#include "lsys/string_io.h"
#include "base/output_format.h"
#include "geom/mesh_export.h"
#include "render/denoise.h"
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

/// The render settings of the options, with the terminal's progress line and Ctrl-C.
render::RenderSettings command_render_settings(const Options& options,
                                               const std::vector<std::filesystem::path>& images)
{
    render::RenderSettings settings = render_settings(options, images);
    if (!options.quiet && isatty(fileno(stderr)))
        settings.progress = draw_progress_line;
    settings.cancel = install_interrupt_handler();
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

/// --assemble N: the tiles' pixels into the outputs, written as a single run writes them.
int assemble(const Options& options, const std::vector<std::filesystem::path>& images,
             const std::function<void(const std::string&)>& say)
{
    render::Image image =
        assemble_tiles(images.front(), *options.assemble, options.width, options.height);
    render::WriteOptions write = write_options(options);
    for (const auto& out : images) {
        render::write_image(image, out, write);
        say("wrote " + out.string());
    }
    return 0;
}

/// --tile I/N: band I of the still into its tile file (app/tiles.h).
void write_tile(const Options& options, const std::filesystem::path& first_output,
                const geom::Scene& scene, render::RenderSettings settings,
                const std::function<void(const std::string&)>& say)
{
    auto [index, count] = *options.tile;
    settings.crop = band(index, count, settings.width, settings.height);
    Tile tile{index, count, settings.width, settings.height, settings.crop,
              render::render(scene, settings)};
    std::filesystem::path file = tile_file(first_output, index, count);
    write_atomically(file, [&](std::ostream& out) {
        std::string bytes = encode_tile(tile);
        out.write(bytes.data(), std::streamsize(bytes.size()));
    });
    say(fmt::format("wrote {} (rows {} to {})", file.string(), tile.rect.y,
                    tile.rect.y + tile.rect.height - 1));
}


/// --stats and --stats-json, once the run's figures are in.
void report_stats(RunStats& stats, const Options& options)
{
    if (!options.stats && !options.stats_json)
        return;
    stats.peak_process_bytes = peak_process_bytes();
    if (options.stats)
        std::fprintf(stderr, "%s", format_stats(stats).c_str());
    if (options.stats_json)
        write_stats_json(stats, *options.stats_json);
}

/// A sequence, then --stats on the process that writes (rank 0 under --mpi, whose
/// figures are its own frames').
int run_sequence_with_stats(const Options& options, const SequenceOutputs& outputs)
{
    int status = run_sequence(options, outputs);
    if (!outputs.mpi || outputs.mpi->rank() == 0)
        report_stats(*outputs.stats, options);
    return status;
}

/// Renders a still of `scene` (the camera options applied first) and writes `images`: the
/// whole image, band I of --tile I/N into its tile file, or shared among --mpi's ranks
/// (rank 0 writes).
/// The outputs of the command, checked before any work: images by write_image's rules,
/// videos by ffmpeg's, meshes and drawings by their folder (per frame of an -a animation;
/// a turntable, one geometry, refuses them and -ray, -ps, -iv).
void check_outputs(const Options& options, const std::vector<std::filesystem::path>& outputs)
{
    if (options.organ_masks &&
        std::none_of(outputs.begin(), outputs.end(), [](const std::filesystem::path& out) {
            const OutputFormat* format = find_output_format(out);
            return format && format->keeps_layers;
        }))
        throw Error("--organ-masks writes its layers into EXR images: give an -o file.exr");
    if (options.shot.turntable > 0)
        for (const auto& [file, option] :
             {std::pair{options.rayshade, "-ray"}, {options.postscript, "-ps"}, {options.inventor, "-iv"}})
            if (file)
                throw Error(file->string() + ": a turntable turns one geometry: write " + option +
                            " from a still (without --turntable)");
    for (const auto& out : outputs) {
        const OutputFormat* format = find_output_format(out);
        if (is_geometry_output(out)) {
            // An -a animation writes a file per frame (its name's number field checked
            // with the frames'); a turntable turns one geometry, the still's.
            if (options.shot.turntable > 0 || (is_sequence(options) && options.scene))
                throw Error(out.string() + ": a turntable turns one geometry: write the " +
                            std::string(format->name) +
                            " file from a still (without --turntable)");
            std::error_code ec;
            if (out.has_parent_path() && !std::filesystem::is_directory(out.parent_path(), ec))
                throw Error(out.string() + ": the folder " + out.parent_path().string() +
                            " does not exist");
        } else if (!is_video(out)) {
            render::check_output_format(out);
        }
    }
}

/// -ray FILE: the scene as cpfg's rayshade file (`model`, when there is one, gives
/// `rayshade scale:` and the materials' transparency).
void write_rayshade_output(const geom::Scene& scene, const Options& options,
                           const std::filesystem::path& file, const Model* model,
                           const std::function<void(const std::string&)>& say)
{
    geom::write_rayshade(scene, file, rayshade_options(options, file, model));
    say("wrote " + file.string());
}

/// Writes the mesh and vector outputs among `outputs` from `scene` (rank 0 alone under
/// --mpi) and returns the others, the pictures to render.
std::vector<std::filesystem::path> write_meshes(const geom::Scene& scene, const Options& options,
                                                const std::vector<std::filesystem::path>& outputs,
                                                const std::function<void(const std::string&)>& say,
                                                bool writes)
{
    std::vector<std::filesystem::path> pictures;
    for (const auto& out : outputs) {
        if (!is_geometry_output(out)) {
            pictures.push_back(out);
            continue;
        }
        if (!writes)
            continue;
        write_geometry_output(scene, options, out);
        say("wrote " + out.string());
    }
    return pictures;
}

int render_and_write_still(geom::Scene& scene, const Options& options,
                           const std::vector<std::filesystem::path>& outputs,
                           const std::function<void(const std::string&)>& say, RunStats& stats,
                           Clock::time_point command_start, Mpi* mpi)
{
    const std::vector<std::filesystem::path> images =
        write_meshes(scene, options, outputs, say, !mpi || mpi->rank() == 0);
    if (images.empty()) {  // only the geometry was asked for
        report_stats(stats, options);
        return 0;
    }
    render::RenderSettings settings = command_render_settings(options, images);
    apply_camera_options(scene, options);
    if (options.tile) {
        write_tile(options, images.front(), scene, settings, say);
        return 0;
    }
    render::RenderReport report;
    if (mpi)
        mpi->checkpoint();
    double render_start_s = seconds_since(command_start);
    render::Image image = mpi ? render_still(*mpi, scene, settings, &report)
                              : render::render(scene, settings, &report);
    stats.add_render(report, render_start_s, options.width, options.height);
    if (mpi && mpi->rank() != 0)
        return 0;
    if (mpi)
        say(fmt::format("rendered {}x{} on {} ranks; rank 0's band in {:.2f} s{}", options.width,
                        options.height, mpi->size(), report.seconds,
                        report.cancelled ? " (interrupted)" : ""));
    else
        say(fmt::format("rendered {}x{}, {:.1f} samples per pixel on average, in {:.2f} s{}",
                        options.width, options.height,
                        double(report.samples) / (double(options.width) * options.height),
                        report.seconds, report.cancelled ? " (interrupted)" : ""));
    render::WriteOptions write = write_options(options);
    for (const auto& out : images) {
        render::write_image(image, out, write);
        say("wrote " + out.string());
    }
    report_stats(stats, options);
    if (report.cancelled)
        return 130;  // the image so far is written; the shell sees the interrupt
    return 0;
}

/// --light-report: the light each organ absorbs, traced and written (docs/light.md).
void write_light_report(const geom::Scene& scene, const Options& options,
                        const std::function<void(const std::string&)>& say)
{
    auto start = Clock::now();
    render::LightReport report = app::write_light_report(scene, options);
    say(fmt::format("wrote {}: {} organs, {} rays, absorbed {:.6g} of {:.6g} in {:.2f} s",
                    options.light_report->string(), report.organs.size(), report.rays,
                    report.absorbed, report.emitted, seconds_since(start)));
}

/// `cambium scene.json`: many plants placed by instances (docs/scenes.md).
int run_scene(Options options, const std::function<void(const std::string&)>& say,
              Clock::time_point command_start, Mpi* mpi)
{
    refuse_single_model_options(options);
    SceneFile file = read_scene_file(*options.scene, options);
    apply_scene_settings(file, options);
    if (options.steps)  // --steps derives every plant that many steps
        for (ScenePlant& plant : file.plants)
            plant.steps = {options.steps};
    std::vector<std::filesystem::path> images = image_outputs(options);
    check_outputs(options, images);  // fail before the work, not after
    if (options.light_report && is_sequence(options))
        throw Error("--light-report measures a still; not with --turntable");
    RunStats stats;
    auto make_scene = [&]() {
        AssemblyReport report;
        geom::Scene scene = assemble_scene(file, options, {}, &report);
        stats.add_assembly(report.load_s, report.derive_s, report.interpret_s, report.wall_s);
        stats.add_scene(scene);
        say(fmt::format("{} plants ({} models, {} derivations of {} steps, {} variants) in "
                        "{:.2f} s: load {:.2f} s, derive {:.2f} s, interpret {:.2f} s; {} "
                        "instances ({} of organs)",
                        report.plant_instances, report.models_loaded, report.derivations,
                        report.derivation_steps, report.variants,
                        report.wall_s, report.load_s, report.derive_s, report.interpret_s,
                        scene.instances.size(), report.organ_instances));
        return scene;
    };
    if (is_sequence(options)) {
        SequenceOutputs outputs{images, command_render_settings(options, images), {},     say,
                                mpi,    make_scene,                       &stats, command_start};
        return run_sequence_with_stats(options, outputs);
    }
    geom::Scene scene = make_scene();
    if (options.view_volume) {
        geom::write_view_volume(scene.bounds, *options.view_volume);
        say("wrote " + options.view_volume->string());
    }
    if (options.light_report && (!mpi || mpi->rank() == 0))  // each organ of each placement
        write_light_report(scene, options, say);
    if (options.rayshade)
        write_rayshade_output(scene, options, *options.rayshade, nullptr, say);
    if (options.postscript) {
        write_vector_output(scene, options, *options.postscript, VectorFormat::ps);
        say("wrote " + options.postscript->string());
    }
    if (options.inventor) {
        write_inventor_output(scene, options, *options.inventor);
        say("wrote " + options.inventor->string());
    }
    if (images.empty()) {
        report_stats(stats, options);
        return 0;
    }
    return render_and_write_still(scene, options, images, say, stats, command_start, mpi);
}

int run(const Options& options, Mpi* mpi, Clock::time_point command_start)
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
        return run_scene(options, say, command_start, mpi);
    std::vector<std::filesystem::path> images = image_outputs(options);
    check_outputs(options, images);  // fail before the work, not after
    if (options.assemble)
        return assemble(options, images, say);
    // With --mpi, rank 0 alone writes files.
    const bool writes = !mpi || mpi->rank() == 0;
    if (options.light_report && is_sequence(options))
        throw Error("--light-report measures a still; not with -a, --turntable or --inbetween");
    if (is_sequence(options)) {
        RunStats stats;
        auto strings = [&](const Model& model, const lsys::ModuleString& s, int step) {
            write_strings(model, s, options, step, say);
        };
        std::vector<std::filesystem::path> pictures, geometry;
        for (const auto& out : images)
            (is_geometry_output(out) ? geometry : pictures).push_back(out);
        SequenceOutputs outputs{pictures, command_render_settings(options, pictures), strings, say,
                                mpi,      {},     &stats,                               command_start};
        outputs.geometry = std::move(geometry);
        return run_sequence_with_stats(options, outputs);
    }

    RunStats stats;
    auto start = Clock::now();
    Model model = load_model(options);
    stats.load_s = seconds_since(start);
    auto lap = Clock::now();
    // the light report and organ masks name each organ's age: the lineage gives it
    StringOrigins provenance;
    lsys::ModuleString string =
        derive(model, options, options.light_report || options.organ_masks, provenance.ages);
    stats.derive_s = seconds_since(lap);
    say(fmt::format("derived {} modules in {:.3f} s", string.size(), seconds_since(start)));
    if (writes)
        write_strings(model, string, options,
                      options.steps.value_or(model.lsystem.derivation_length()), say);
    if (images.empty() && !options.light_report && !options.rayshade && !options.postscript &&
        !options.inventor) {
        // Only strings and the view volume are written: the turtle walks the string for
        // -vv without building geometry, and has nothing to do otherwise.
        if (options.view_volume && writes) {
            lap = Clock::now();
            geom::write_view_volume(view_volume(model, string, options), *options.view_volume);
            stats.interpret_s = seconds_since(lap);
            stats.interpreted = true;
            say("wrote " + options.view_volume->string());
        }
        stats.assemble_s = stats.load_s + stats.derive_s + stats.interpret_s;
        report_stats(stats, options);
        return 0;
    }

    lap = Clock::now();
    geom::Scene scene = interpret_with_provenance(model, string, options, provenance);
    string = lsys::ModuleString();  // freed before the geometry's BVH is built
    provenance = StringOrigins();
    stats.interpret_s = seconds_since(lap);
    stats.assemble_s = stats.load_s + stats.derive_s + stats.interpret_s;
    stats.add_scene(scene);
    const geom::Geometry& g = scene.geometry;
    say(fmt::format("interpreted {} {}, {} cylinder curves, {} spheres, {} discs, "
                    "{} triangles, {} instances",
                    g.lines.segment_count(),
                    scene.line_radius_in_pixels ? "pixel-width lines" : "cylinders",
                    g.curves.segment_count(), g.spheres.size(), g.discs.size(), g.mesh.size(),
                    scene.instances.size()));
    if (options.view_volume && writes) {
        // As cpfg, the view file's `box:` wins over the computed bounds.
        geom::write_view_volume(scene.view.box.value_or(scene.bounds), *options.view_volume);
        say("wrote " + options.view_volume->string());
    }
    if (options.rayshade && writes)
        write_rayshade_output(scene, options, *options.rayshade, &model, say);
    if (options.postscript && writes) {
        write_vector_output(scene, options, *options.postscript, VectorFormat::ps);
        say("wrote " + options.postscript->string());
    }
    if (options.inventor && writes) {
        write_inventor_output(scene, options, *options.inventor);
        say("wrote " + options.inventor->string());
    }
    if (options.light_report && writes)
        write_light_report(scene, options, say);
    if (images.empty()) {
        report_stats(stats, options);
        return 0;
    }
    return render_and_write_still(scene, options, images, say, stats, command_start, mpi);
}

/// Under mpirun with --mpi, before MPI is initialised: whether this is a rank other than
/// 0 (Open MPI's and PMIx's environment), which leaves command-line errors, the same on
/// every rank, to rank 0 to print.
bool other_mpi_rank(int argc, char** argv)
{
    if (std::find(argv + 1, argv + argc, std::string_view("--mpi")) == argv + argc)
        return false;
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK"})
        if (const char* rank = std::getenv(name))
            return std::string_view(rank) != "0";
    return false;
}

}  // namespace
}  // namespace cambium::app

int main(int argc, char** argv)
{
    auto command_start = cambium::app::Clock::now();  // --stats: time to first pixel
    using cambium::app::Mpi;
    std::unique_ptr<Mpi> mpi;
    // With --mpi, an error ends every rank (Mpi::fail), printed once.
    auto fail = [&](const std::string& message) {
        if (mpi)
            mpi->fail(message);
        if (!cambium::app::other_mpi_rank(argc, argv))
            std::fprintf(stderr, "cambium: %s\n", message.c_str());
        return 1;
    };
    try {
        auto options = cambium::app::parse_command_line(argc, argv);
        if (!options)
            return 0;
        if (options->mpi) {
            mpi = std::make_unique<Mpi>(&argc, &argv);
            if (mpi->rank() != 0)
                options->quiet = true;  // messages, warnings and progress on rank 0 only
        }
        cambium::set_warnings_enabled(!options->quiet);  // -q: nothing but errors
        return cambium::app::run(*options, mpi.get(), command_start);
    } catch (const cambium::Interrupted& e) {
        fail(e.what());
        return 128 + e.signal();  // a child program was running; it is stopped
    } catch (const cambium::Error& e) {
        return fail(e.what());
    } catch (const std::bad_alloc&) {
        // The stages that hold most check --max-memory and name their input; what is
        // left is the system refusing memory within the budget (ulimit -v, memory in use).
        return fail("error: out of memory: the system refused an allocation within the memory budget "
                    "(--max-memory); an address-space limit (ulimit -v) or other programs hold the "
                    "rest: lower --max-memory to have the step that needs it named, or lower the "
                    "image size, samples or derivation length");
    } catch (const std::exception& e) {
        return fail(std::string("error: ") + e.what());
    }
}
