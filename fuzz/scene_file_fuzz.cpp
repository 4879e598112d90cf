// SPDX-License-Identifier: Apache-2.0
// Scene files (.json, docs/scenes.md): read and checked as `cambium scene.json` reads them,
// with the files the seeds name (model folders, a ground mesh, a map) present in the
// scratch folder, so that inputs get past the file checks to the placements.
#include <filesystem>
#include <fstream>

#include "app/scene_file.h"
#include "fuzz_input.h"

namespace {

namespace fs = std::filesystem;

void write(const fs::path& file, const char* text)
{
    fs::create_directories(file.parent_path().empty() ? fs::path(".") : file.parent_path());
    std::ofstream(file) << text;
}

/// The files of the seed scenes (scenes/field/field.json and fuzz/seeds/scene_file/).
void make_fixture()
{
    for (const char* plant : {"grass", "flower"}) {
        fs::path folder = fs::path("models") / plant;
        write(folder / (std::string(plant) + ".l"), "axiom: F\n");
        write(folder / (std::string(plant) + ".v"), "viewpoint: 0,0,1\n");
        write(folder / (std::string(plant) + ".mat"), "");
    }
    write("ground.obj", "v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nf 1 2 3 4\n");
    write("sky.exr", "");
    write("grass.png", "");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    static const bool fixture = (make_fixture(), true);
    (void)fixture;
    return fuzz::run(size, [&] {
        fs::path file = fuzz::write_input(data, size, "fuzz.json");
        // Scatters are linear in their count; a smaller limit than the command's keeps
        // each execution short without leaving any check unreached.
        app::SceneLimits limits;
        limits.max_instances = 100'000;
        limits.max_mesh_triangles = 100'000;
        app::read_scene_file(file, app::Options{}, limits);
    });
}
