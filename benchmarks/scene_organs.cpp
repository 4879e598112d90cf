// SPDX-License-Identifier: Apache-2.0
// Organs of instanced plants (docs/architecture.md "Scenes of many plants"): a scene's
// plants with their own instances (objects, surfaces) composed into top-level instances
// or flattened into each plant's prototype. Prints one JSON line: assembly time, BVH
// build time, the time of a small render, instance and primitive counts and the
// process's peak memory. Run each mode in its own process (peak memory is per process).
//
//   build/benchmarks/scene_organs scene.json compose|flatten|automatic [--allow-file-access]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "app/scene_assembly.h"
#include "app/scene_file.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/render.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t)
{
    return std::chrono::duration<double>(Clock::now() - t).count();
}

std::size_t primitives(const cambium::geom::Geometry& g)
{
    return g.lines.segment_count() + g.curves.segment_count() + g.spheres.size() +
           g.discs.size() + g.mesh.size();
}

}  // namespace

int main(int argc, char** argv)
{
    namespace app = cambium::app;
    namespace render = cambium::render;
    if (argc < 3) {
        std::fprintf(stderr, "usage: scene_organs scene.json compose|flatten [--allow-file-access]\n");
        return 2;
    }
    try {
        app::Options options;
        options.allow_file_access = argc > 3 && std::strcmp(argv[3], "--allow-file-access") == 0;
        app::AssemblyOptions how;
        std::string mode = argv[2];
        how.organs = mode == "flatten"   ? app::OrganPlacement::flatten
                     : mode == "compose" ? app::OrganPlacement::compose
                                         : app::OrganPlacement::automatic;
        app::SceneFile file = app::read_scene_file(argv[1], options);
        auto t = Clock::now();
        app::AssemblyReport report;
        cambium::geom::Scene scene = app::assemble_scene(file, options, how, &report);
        double assemble = seconds_since(t);
        std::size_t prototype_primitives = primitives(scene.geometry), placed = primitives(scene.geometry);
        for (const auto& p : scene.prototypes)
            prototype_primitives += primitives(p.geometry);
        for (const auto& i : scene.instances)
            placed += primitives(scene.prototypes[i.prototype].geometry);

        render::RenderSettings settings;
        settings.width = 320;
        settings.height = 240;
        settings.samples_per_pixel = 4;
        settings.aovs = false;
        // Emissive materials (corpus .mat files often have some) would make every placed
        // primitive an area light: a cost of the light set, not of the organ placement.
        settings.area_lights = false;
        render::Camera camera = render::make_camera(scene.view, scene.bounds, settings.width,
                                                    settings.height);
        t = Clock::now();
        { render::EmbreeScene accel(scene, camera, nullptr); }
        double build = seconds_since(t);
        t = Clock::now();
        render::render(scene, camera, settings);
        double frame = seconds_since(t);
        rusage usage{};
        getrusage(RUSAGE_SELF, &usage);
        std::printf("{\"benchmark\":\"scene_organs\",\"mode\":\"%s\",\"plants\":%zu,"
                    "\"prototypes\":%zu,\"instances\":%zu,\"organ_instances\":%zu,"
                    "\"prototype_primitives\":%zu,\"placed_primitives\":%zu,"
                    "\"derive_interpret_s\":%.3f,\"assemble_s\":%.3f,\"bvh_build_s\":%.3f,"
                    "\"render_320x240x4_s\":%.3f,\"peak_rss_mib\":%.1f}\n",
                    argv[2], report.plant_instances, scene.prototypes.size(),
                    scene.instances.size(), report.organ_instances, prototype_primitives, placed,
                    report.derive_s + report.interpret_s + report.load_s, assemble, build, frame,
                    double(usage.ru_maxrss) / 1024.0);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "scene_organs: %s\n", e.what());
        return 1;
    }
    return 0;
}
