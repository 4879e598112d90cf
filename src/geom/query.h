// SPDX-License-Identifier: Apache-2.0
// Query modules ?P ?H ?L ?U (manual 5.1.9): the turtle's state written back into the string.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "geom/gls_polygons.h"
#include "geom/vec.h"
#include "geom/view_file.h"
#include "lsys/module_string.h"

namespace cambium::geom {

/// Interprets `string` with the same turtle as `interpret` and sets the parameters of
/// every `?P` `?H` `?L` `?U` module to the turtle's position, heading, left or up
/// vector there (the first two or three, as many as the module has), as cpfg's
/// interpretation step after each derivation step does. Other modules are unchanged.
void answer_queries(lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                    const ViewFile& view);

/// One query's answer: the module's index in the string and the vector's x, y, z.
struct QueryAnswer {
    std::size_t module;
    std::array<float, 3> values;
};

/// The answers of every query module, in string order (defined in interpreter.cpp,
/// which owns the turtle walk).
std::vector<QueryAnswer> collect_query_answers(const lsys::ModuleString& string,
                                               const lsys::SymbolTable& symbols,
                                               const ViewFile& view);

/// The turtle at one communication module `?E` (manual 7.1): what the environmental step
/// may send with it.
struct TurtleAtModule {
    std::size_t module;  ///< index in the string
    Vec3 position, heading, left, up;
    double line_width = 1;
    double scale = 1;
};

/// Modules [begin, end) of a string.
struct ModuleRange {
    std::size_t begin = 0, end = 0;
};

/// The turtle at every `?E` module, in string order (defined in interpreter.cpp). With
/// `polygons`, also the polygons each of `ranges` (sorted by begin; they may nest) draws,
/// as polygons[k] for ranges[k]: cpfg's `interpreted modules:` (manual 7.4.1).
std::vector<TurtleAtModule> collect_communication_turtles(
    const lsys::ModuleString& string, const lsys::SymbolTable& symbols, const ViewFile& view,
    std::span<const ModuleRange> ranges = {},
    std::vector<std::vector<GlsPolygon>>* polygons = nullptr);

}  // namespace cambium::geom
