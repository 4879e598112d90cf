// SPDX-License-Identifier: Apache-2.0
// Binary L-system strings (-strb files), read and written back in both formats.
#include <sstream>

#include "fuzz_input.h"
#include "lsys/string_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        lsys::SymbolTable symbols;
        std::istringstream in{std::string(fuzz::text_of(data, size))};
        int step = 0;
        lsys::ModuleString string = lsys::read_string_binary(in, symbols, "fuzz.strb", &step);
        std::ostringstream out;
        lsys::write_string_text(string, symbols, out);
        lsys::write_string_binary(string, symbols, out, step);
    });
}
