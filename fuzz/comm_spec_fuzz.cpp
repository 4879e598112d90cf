// SPDX-License-Identifier: Apache-2.0
// Communication specification files (.e): read as `-e file.e` reads them, each turtle
// format applied to extreme values as the environmental step sends them, and the built-in
// the `executable:` line names made (its specification file, if named, is missing here).
#include <limits>

#include "env/builtins.h"
#include "env/comm_spec.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        env::CommSpec spec = env::read_comm_spec(fuzz::write_input(data, size, "fuzz.e"));
        const double values[3] = {-std::numeric_limits<float>::max(), 1e-40, 123456.789};
        float out[3];
        for (const auto* f : {&spec.position, &spec.heading, &spec.left, &spec.up,
                              &spec.line_width, &spec.scale_factor})
            if (*f)
                env::send_through_format(**f, values, (*f)->conversions, out);
        env::Context context;
        context.folder = ".";
        const std::vector<std::string> args(spec.executable.begin() + 1, spec.executable.end());
        env::make_builtin(spec.executable.front(), args, context);
    });
}
