// SPDX-License-Identifier: Apache-2.0
// `@L` label text: the input's first byte says how many float values follow (0 to 7), the
// rest is the label's format. The text must stay within what the format's width and
// precision limits allow (at most 2 digits each: no conversion is longer than ~140
// characters). The same text is read as a view file for its `font:`/`winfont:` lines.
#include <cstdlib>
#include <cstring>
#include <vector>

#include "fuzz_input.h"
#include "geom/label.h"
#include "geom/view_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        if (size == 0)
            return;
        std::size_t count = data[0] % 8;
        std::size_t at = 1;
        std::vector<float> params{0};  // the string's index, then its values
        for (std::size_t i = 0; i < count && at + sizeof(float) <= size; ++i, at += sizeof(float)) {
            float v;
            std::memcpy(&v, data + at, sizeof v);
            params.push_back(v);
        }
        std::vector<std::string> strings{std::string(fuzz::text_of(data + at, size - at))};
        std::optional<std::string> text = geom::label_text(params, strings);
        if (!text || text->size() > 160 * (strings[0].size() + 1))
            std::abort();  // a label must be the format with bounded conversions
        geom::parse_view_file(strings[0], "fuzz.v");
    });
}
