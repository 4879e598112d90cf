// SPDX-License-Identifier: Apache-2.0
// Animation files (.a): parse them and select the frames cpfg's animation mode records,
// for a few derivation lengths (the frame count is bounded as the command bounds it).
#include "fuzz_input.h"
#include "geom/animation_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        geom::AnimationFile animation =
            geom::parse_animation_file(fuzz::text_of(data, size), "fuzz.a");
        for (int length : {0, 1, 7, 1000})
            geom::select_frames(animation, length, 100'000);
    });
}
