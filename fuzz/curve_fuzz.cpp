// SPDX-License-Identifier: Apache-2.0
// Curve files (curve:), read by length as curveX/Y/Z and curveGAL read them.
#include "fuzz_input.h"
#include "geom/curve.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        geom::SpaceCurve curve = geom::parse_curve_text(fuzz::text_of(data, size), "fuzz.crv");
        curve.length();
        for (double t : {-1.0, 0.0, 0.25, 0.5, 1.0, 2.0}) {
            curve.at_length_fraction(t);
            curve.at_parameter(t);
        }
    });
}
