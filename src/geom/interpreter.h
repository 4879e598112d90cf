// SPDX-License-Identifier: Apache-2.0
// Interprets an L-system string with the turtle and builds the renderer-independent Scene.
#pragma once

#include "geom/scene.h"
#include "geom/view_file.h"
#include "lsys/module_string.h"

namespace cambium::geom {

/// Walks `string` once with cpfg's turtle, emitting the geometry, the view and the
/// lights of `view` into a Scene. Materials and background are the caller's (they
/// come from the command line's colormap or material files).
Scene interpret(const lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                const ViewFile& view);

/// The lights render should use: the view file's `light:` commands, or cpfg's
/// default light when there are none.
std::vector<Light> effective_lights(const ViewFile& view);

}  // namespace cambium::geom
