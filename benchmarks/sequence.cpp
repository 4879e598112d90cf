// SPDX-License-Identifier: Apache-2.0
// Sequences: what a turntable costs against rendering its frames one by one, and how
// many derivation steps an animation takes. Prints one JSON line per measurement.
//
//   build/benchmarks/sequence [plant.l plant.v [plant.mat]]   (default: scenes/default)
//
// turntable: 36 frames through render_views (one BVH) against 36 x (one frame's render
// minus its BVH build) + one build, each measured here; animation: the frames of cpfg's
// default animation (1 .. derivation length) derived incrementally, counting the steps
// the L-system takes (also with lineage tracked, as --inbetween does), against deriving
// every frame from the axiom.
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include "app/command_line.h"
#include "app/pipeline.h"
#include "app/sequence.h"
#include "render/accel.h"
#include "render/framing.h"
#include "render/render.h"

namespace {

using Clock = std::chrono::steady_clock;
using cambium::app::Model;

double seconds_since(Clock::time_point t)
{
    return std::chrono::duration<double>(Clock::now() - t).count();
}

void turntable(const Model& model, const cambium::app::Options& options, int frames)
{
    namespace render = cambium::render;
    cambium::geom::Scene scene = cambium::app::interpret(model, cambium::app::derive(model, options), options);
    render::RenderSettings settings;
    settings.width = 320;
    settings.height = 240;
    settings.samples_per_pixel = 16;
    settings.aovs = false;
    std::vector<render::Camera> cameras = render::turntable_cameras(
        scene.view, scene.bounds, frames, std::nullopt, settings.width, settings.height);

    auto t = Clock::now();
    for (int i = 0; i < 3; ++i)
        render::EmbreeScene accel(scene, cameras[0], nullptr);
    double build = seconds_since(t) / 3;
    t = Clock::now();
    render::render(scene, cameras[frames / 3], settings);
    double one_frame = seconds_since(t);  // its own BVH build included
    t = Clock::now();
    render::render_views(scene, cameras, settings,
                         [](std::size_t, render::Image&, const render::RenderReport&) { return true; });
    double total = seconds_since(t);
    double bound = frames * (one_frame - build) + build;
    std::printf("{\"benchmark\":\"turntable\",\"frames\":%d,\"image\":\"%dx%d\",\"spp\":%d,"
                "\"bvh_build_s\":%.4f,\"one_frame_s\":%.4f,\"turntable_total_s\":%.3f,"
                "\"frames_x_render_plus_one_build_s\":%.3f,\"total_over_bound\":%.3f,"
                "\"separate_renders_estimate_s\":%.3f}\n",
                frames, settings.width, settings.height, settings.samples_per_pixel, build,
                one_frame, total, bound, total / bound, frames * one_frame);
}

void animation(const cambium::app::Options& options)
{
    // The model with a step counter on its L-system.
    Model model = cambium::app::load_model(options);
    cambium::lsys::LoadOptions load;
    load.preprocessor = options.preprocessor;
    int steps_taken = 0;
    load.on_step = [&](int step, const cambium::lsys::ModuleString&) { steps_taken += step > 0; };
    model.lsystem = cambium::lsys::LSystem::load(options.lsystem, load);
    std::vector<cambium::geom::AnimationFrame> frames = cambium::app::animation_frames(model, options);

    auto t = Clock::now();
    std::size_t modules = 0;
    int last = cambium::app::derive_frames(model, frames,
        [&](const cambium::geom::AnimationFrame&, const cambium::lsys::ModuleString& s) {
            modules += s.size();
        });
    double incremental = seconds_since(t);
    int incremental_steps = steps_taken;

    // The same with lineage tracked (--inbetween): still each step once.
    steps_taken = 0;
    t = Clock::now();
    cambium::app::derive_frames_with_lineage(model, frames, true,
        [](const cambium::geom::AnimationFrame&, const cambium::lsys::ModuleString&,
           const std::vector<std::uint32_t>&) {});
    double with_lineage = seconds_since(t);
    int lineage_steps = steps_taken;

    steps_taken = 0;
    t = Clock::now();
    for (const auto& f : frames)
        modules -= model.lsystem.derive(f.number).size();
    double from_axiom = seconds_since(t);
    std::printf("{\"benchmark\":\"animation\",\"frames\":%zu,\"last_step\":%d,"
                "\"steps_derived\":%d,\"each_step_once\":%s,\"incremental_s\":%.4f,"
                "\"with_lineage_steps\":%d,\"with_lineage_s\":%.4f,"
                "\"from_axiom_steps\":%d,\"from_axiom_s\":%.4f,\"same_strings\":%s}\n",
                frames.size(), last, incremental_steps,
                incremental_steps == last ? "true" : "false", incremental, lineage_steps,
                with_lineage, steps_taken, from_axiom, modules == 0 ? "true" : "false");
}

}  // namespace

int main(int argc, char** argv)
{
    try {
        std::string folder = std::string(CAMBIUM_SOURCE_DIR) + "/scenes/default/";
        std::vector<std::string> words = {"-M", folder + "plant.mat", folder + "plant.l",
                                          folder + "plant.v"};
        if (argc >= 3) {
            words = {argv[1], argv[2]};
            if (argc >= 4)
                words.insert(words.begin(), {"-M", argv[3]});
        }
        cambium::app::Options options = *cambium::app::parse_command_line(words);
        Model model = cambium::app::load_model(options);
        turntable(model, options, 36);
        animation(options);
    } catch (const std::exception& e) {
        std::printf("{\"error\":\"%s\"}\n", e.what());
        return 1;
    }
    return 0;
}
