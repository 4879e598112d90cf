// SPDX-License-Identifier: Apache-2.0
// The `cambium` command: derive a cpfg L-system, interpret it, path-trace it, write images.
#include <chrono>
#include <cstdio>
#include <exception>

#include "app/command_line.h"
#include "base/diagnostics.h"
#include "geom/interpreter.h"
#include "geom/palette.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"
#include "render/render.h"

namespace cambium::app {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start)
{
    return std::chrono::duration<double>(Clock::now() - start).count();
}

geom::Palette load_palette(const Options& options)
{
    geom::Palette palette;
    for (const ColourFile& f : options.colour_files) {
        if (f.materials)
            palette.load_materials(f.block, f.file);
        else
            palette.load_colormap(f.block, f.file);
    }
    return palette;
}

/// Without -o, the image is named after the L-system file, in the current folder.
std::vector<std::filesystem::path> output_files(const Options& options)
{
    if (!options.outputs.empty())
        return options.outputs;
    return {options.lsystem.stem().string() + ".png"};
}

int run(const Options& options)
{
    auto say = [&](const std::string& text) {
        if (!options.quiet)
            std::printf("%s\n", text.c_str());
    };
    for (const auto& out : output_files(options))
        render::check_output_format(out);  // fail before the work, not after
    if (options.animation)
        warn(FileLoc{options.animation->string()},
             "animation files are not interpreted yet; rendering the last derivation step");

    auto start = Clock::now();
    geom::Palette palette = load_palette(options);
    geom::ViewFile view = geom::read_view_file(options.view);
    lsys::LSystem lsystem = lsys::LSystem::load(options.lsystem);
    lsys::ModuleString string = lsystem.derive();
    say("derived " + std::to_string(string.size()) + " modules in " +
        std::to_string(seconds_since(start)) + " s");

    geom::Scene scene = geom::interpret(string, lsystem.symbols(), view);
    scene.materials = palette.entries(options.colour_block);
    scene.background = palette.background(options.colour_block);
    say("interpreted " + std::to_string(scene.geometry.lines.segment_count()) + " segments");

    render::RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.samples_per_pixel = options.samples_per_pixel;
    settings.max_depth = options.max_depth;
    settings.seed = options.seed;
    settings.threads = options.threads;
    auto render_start = Clock::now();
    render::Image image = render::render(scene, settings);
    say("rendered " + std::to_string(options.width) + "x" + std::to_string(options.height) +
        " at " + std::to_string(options.samples_per_pixel) + " spp in " +
        std::to_string(seconds_since(render_start)) + " s");

    for (const auto& out : output_files(options)) {
        render::write_image(image, out);
        say("wrote " + out.string());
    }
    return 0;
}

}  // namespace
}  // namespace cambium::app

int main(int argc, char** argv)
{
    try {
        auto options = cambium::app::parse_command_line(argc, argv);
        if (!options)
            return 0;
        return cambium::app::run(*options);
    } catch (const cambium::Error& e) {
        std::fprintf(stderr, "cambium: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cambium: error: %s\n", e.what());
        return 1;
    }
}
