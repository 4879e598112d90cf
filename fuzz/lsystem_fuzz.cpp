// SPDX-License-Identifier: Apache-2.0
// The L-system language without the preprocessor: parse an already preprocessed .l text,
// derive a few steps, apply the homomorphism and interpret the string with the turtle.
#include <algorithm>

#include "fuzz_input.h"
#include "geom/interpreter.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"
#include "lsys/program.h"

namespace {

/// Bounds that keep one input fast: derivation stops with an Error past max_modules.
constexpr int max_steps = 3;
constexpr std::size_t max_modules = 2000;

const cambium::geom::ViewFile& default_view()
{
    static const cambium::geom::ViewFile view = cambium::geom::parse_view_file("", "fuzz.v");
    return view;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace cambium;
    return fuzz::run(size, [&] {
        lsys::LoadOptions options;
        options.max_modules = max_modules;
        lsys::LSystem lsystem =
            lsys::LSystem::from_preprocessed(fuzz::text_of(data, size), "fuzz.l", options);
        int steps = std::clamp(lsystem.derivation_length(), 0, max_steps);
        lsys::ModuleString derived = lsystem.derive(steps);
        lsys::ModuleString string =
            lsystem.interpretation_string(derived, lsys::ObjectHandling::keep);
        geom::InterpretOptions interpret;
        interpret.strings = lsystem.program().strings;
        interpret.is_object = [&](lsys::SymbolId s) { return lsystem.is_object_symbol(s); };
        interpret.expand_object = [&](lsys::ModuleRef m) { return lsystem.expand_object(m); };
        geom::interpret(string, lsystem.symbols(), default_view(), interpret);
    });
}
