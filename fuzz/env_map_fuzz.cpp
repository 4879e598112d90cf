// SPDX-License-Identifier: Apache-2.0
// Environment maps (--env, a scene's environment.map): the bytes are written to a file
// named as an OpenEXR file when they start with EXR's magic number, else as Radiance HDR,
// and read as the command reads a map: through the image module (OpenImageIO, which tries
// every format it knows when the named one fails), into the sampled environment. The
// texel limit is 2^16 instead of the command's 2^25: a mutated header may declare any size
// up to the limit, and each such input would otherwise allocate 400 MB and take seconds.
#include <cstring>

#include "fuzz_input.h"
#include "render/environment.h"
#include "render/image_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        const bool exr = size >= 4 && std::memcmp(data, "\x76\x2f\x31\x01", 4) == 0;
        render::MapTexels map = render::image_codec().read_map(
            fuzz::write_input(data, size, exr ? "fuzz.exr" : "fuzz.hdr"), 1.5f, 1u << 16);
        render::Environment environment =
            render::make_map_environment(map.width, map.height, std::move(map.rgb));
        environment.sample(0.3f, 0.7f);
        environment.radiance({0, 1, 0});
    });
}
