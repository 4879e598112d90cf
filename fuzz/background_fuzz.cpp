// SPDX-License-Identifier: Apache-2.0
// Background scene files (background scene:), parsed and built into geometry.
#include "fuzz_input.h"
#include "geom/background_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        auto statements = geom::parse_background_text(fuzz::text_of(data, size), "fuzz.scene");
        geom::build_background_scene(statements, geom::Material{});
    });
}
