// SPDX-License-Identifier: Apache-2.0
// OBJ meshes (a scene's ground or scatter mesh): read as the scene reader reads them, then
// 100 plants scattered over the mesh's area.
#include "app/scene_file.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        app::SceneLimits limits;
        limits.max_mesh_line_bytes = 4096;  // smaller than the command's, so inputs reach it
        app::GroundMesh mesh =
            app::read_obj_mesh(fuzz::write_input(data, size, "fuzz.obj"), limits);
        app::ScatterSpec spec;
        spec.mesh = "fuzz.obj";
        spec.count = 100;
        spec.seed = 7;
        spec.min_spacing = 0.01;
        spec.rotate_y = true;
        app::scatter(spec, &mesh);
    });
}
