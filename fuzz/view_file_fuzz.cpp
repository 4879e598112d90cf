// SPDX-License-Identifier: Apache-2.0
// The view file (.v): parse it, read the commands kept for later stages that need no
// other file, and interpret a fixed string that uses the turtle's view-dependent state.
#include <sstream>

#include "fuzz_input.h"
#include "geom/gencyl.h"
#include "geom/interpreter.h"
#include "geom/object_instancing.h"
#include "geom/surface.h"
#include "geom/view_file.h"
#include "lsys/string_io.h"

namespace {

/// Lines, turns, widths, colours, tropisms, a generalized cylinder with a contour, a
/// polygon, a sphere and a surface: what the view file's settings change.
constexpr const char* turtle_walk =
    "F(1)+(30)F(2)[&(20)!(0.5)F(1)@Gs@Gc(4)F(1)F(1)@Ge]^;'@Tx(1)@Ts(1)"
    "{.f(1).+f(1).+f(1).}@O(0.3)@c(0.2)~l(1)@Gc(12)@#(2)F(1)@v$F(1)\n";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        geom::ViewFile view = geom::parse_view_file(fuzz::text_of(data, size), "fuzz.v");
        geom::cylinder_settings(view);
        geom::effective_lights(view);
        lsys::SymbolTable symbols;
        std::istringstream walk(turtle_walk);
        lsys::ModuleString string = lsys::read_string_text(walk, symbols);
        geom::interpret(string, symbols, view);
    });
}
