// SPDX-License-Identifier: Apache-2.0
// Tile files (--tile, --assemble): decoded from bytes as MPI ranks' tiles are, and read as
// tile 0 of 1 of a 16x8 image as --assemble reads tile files. A decoded tile must encode
// to bytes that decode to the same encoding.
#include <cstdlib>

#include "app/tiles.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        std::string bytes(fuzz::text_of(data, size));
        try {
            app::Tile tile = app::decode_tile(bytes, "fuzz.ctile");
            std::string encoded = app::encode_tile(tile);
            if (app::encode_tile(app::decode_tile(encoded, "encoded")) != encoded)
                std::abort();  // the format does not round-trip
        } catch (const Error&) {
        }
        fuzz::write_input(data, size, "out.tile0of1.ctile");
        app::assemble_tiles("out.png", 1, 16, 8);
    });
}
