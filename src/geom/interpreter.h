// SPDX-License-Identifier: Apache-2.0
// Interprets an L-system string with the turtle and builds the renderer-independent Scene.
#pragma once

#include <span>
#include <string>

#include "geom/scene.h"
#include "geom/view_file.h"
#include "lsys/module_string.h"

namespace cambium::geom {

/// Walks `string` once with cpfg's turtle, emitting the geometry, the view and the
/// lights of `view` into a Scene. Materials and background are the caller's (they
/// come from the command line's colormap or material files).
Scene interpret(const lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                const ViewFile& view);

/// What interpretation needs beyond the string, the symbols and the view file.
struct InterpretOptions {
    /// The L-system's string constants (lsys::Program::strings): `@L("text")` holds
    /// the index of its text there as its first parameter. Empty: labels get no text.
    std::span<const std::string> strings;
};

Scene interpret(const lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                const ViewFile& view, const InterpretOptions& options);

/// The lights render should use: the view file's `light:` commands, or cpfg's
/// default light when there are none.
std::vector<Light> effective_lights(const ViewFile& view);

}  // namespace cambium::geom
