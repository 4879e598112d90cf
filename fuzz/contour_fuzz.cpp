// SPDX-License-Identifier: Apache-2.0
// Contour files and galleries (contour:), resampled as generalized cylinders use them.
#include "fuzz_input.h"
#include "geom/contour.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        for (const geom::Contour& contour : geom::parse_contours(fuzz::text_of(data, size), "fuzz.con"))
            for (int sides : {3, 8, 61})
                geom::resample(contour, sides);
    });
}
