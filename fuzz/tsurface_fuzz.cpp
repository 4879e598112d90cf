// SPDX-License-Identifier: Apache-2.0
// Triangulated surface files (tsurface:).
#include "fuzz_input.h"
#include "geom/surface.h"
#include "geom/tsurface.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        geom::SurfaceCommand command;
        command.kind = geom::SurfaceCommand::Kind::triangles;
        command.letter = 't';
        command.file = "fuzz.tri";
        geom::parse_tsurface_text(fuzz::text_of(data, size), "fuzz.tri", command);
    });
}
