// SPDX-License-Identifier: Apache-2.0
// Bicubic surface files (.s): patches, their subdivision and the surface's frame.
#include "fuzz_input.h"
#include "geom/surface.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        geom::SurfaceCommand command;  // subdivision from the file's PRECISION line
        command.letter = 'l';
        command.file = "fuzz.s";
        geom::parse_surface_text(fuzz::text_of(data, size), "fuzz.s", command);
    });
}
