// SPDX-License-Identifier: Apache-2.0
// Interprets an L-system string with the turtle and builds the renderer-independent Scene.
#pragma once

#include <functional>
#include <span>
#include <string>

#include "base/limits.h"
#include "geom/scene.h"
#include "geom/turtle.h"
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

    /// `-o>` object productions (manual 8.1). When both hooks are set, a module whose
    /// symbol `is_object` is left unexpanded in the string and `expand_object` gives
    /// its homomorphism successor. The first module with a given key (its symbol and
    /// parameters printed with the view file's `rayshade objects:` format, default %g,
    /// plus line width, scale, colours and texture with `turtle considered`) becomes a
    /// Scene prototype built in the turtle's starting frame with the turtle's width,
    /// scale, colours and texture; each occurrence places an instance with the turtle's
    /// frame, and the turtle moves through the module's own expansion as if it were
    /// inline (so what follows, and the bounds, are as with `-->`). `expand_object` must
    /// depend on the module alone (it is called once per distinct module). Modules of an
    /// expansion are never objects again. Unset: the string is interpreted as it is.
    std::function<bool(lsys::SymbolId)> is_object;
    std::function<lsys::ModuleString(lsys::ModuleRef)> expand_object;

    /// What the Scene's primitive arrays may take (--max-memory): interpretation stops
    /// with an error once they grow past it (checked every few thousand modules).
    std::uint64_t max_memory_bytes = default_max_memory_bytes();
    /// `@S("command")`: called with the command, in string order, when set (the user
    /// allowed system calls); unset, @S is ignored with a warning.
    std::function<void(const std::string&)> system_call;
    /// Only the view volume (Scene::bounds, what -vv writes) is wanted: the turtle walks
    /// the string as usual, but segments, spheres, discs, polygons, patches and surface
    /// instances are not stored (generalized cylinders are, as their sweep makes the
    /// bounds). The bounds equal a full interpretation's.
    bool bounds_only = false;
    /// Added to the colour indices of predefined surfaces and patches, whose colormap
    /// lighting differs from other primitives' (pipeline: 256 in colormap mode with
    /// lighting, where the materials 256..511 are the surface-lit copies).
    std::uint16_t surface_material_offset = 0;
    /// Where a predefined surface's patch colours (PatchColours) past 255 take their
    /// materials: colour c is material next_colormap_material_offset + c - 256 (pipeline:
    /// 512, the next colormap's entries, surface-lit). Patch colours 1..255 are
    /// surface_material_offset + c; with surface_material_offset 0 (no colormap-mode
    /// lighting) patch colours are not used, as in cpfg.
    std::uint16_t next_colormap_material_offset = 0;
    /// The turtles saved at fragment starts over the derivation (manual 5.1.9), by index:
    /// `%(par, index)` sets the turtle to fragment_turtles[index] (save_fragment_turtles).
    std::span<const Turtle> fragment_turtles;

    /// Provenance (docs/architecture.md): each primitive's `module` entry and instance's
    /// `module` name the module that drew it, and Scene::modules its symbol and age.
    /// Off: the `module` arrays stay empty (the turtle passes between steps).
    bool provenance = true;
    /// For each module of the string, its index in the derived string
    /// (lsys::TurtleString::origins, through the homomorphism); empty: the string is the
    /// derived one (or the indices are the string's own).
    std::span<const std::uint32_t> origins;
    /// The derived string `origins` point into: its modules' symbols name the organs
    /// (X of X --> F F names both segments). Null: the string's own symbols.
    const lsys::ModuleString* derived = nullptr;
    /// Per module of the derived string, the step at which it appeared (lsys::module_ages);
    /// empty: ages are unknown_age.
    std::span<const std::uint16_t> ages;
    /// Record each organ's branch order (ModuleTable::orders: the turtle's open `[` where
    /// the module's successor begins): 2 bytes a record, for organ masks.
    bool branch_orders = false;
    /// Per module of the derived string, its index where it appeared (ModuleTable::births;
    /// an animation's organ masks); empty: not recorded.
    std::span<const std::uint32_t> births;
};

Scene interpret(const lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                const ViewFile& view, const InterpretOptions& options);

/// Fragmentation's turtle pass (manual 5.1.9 `%(par)`; lsys::LoadOptions::fragment_pass):
/// walks `string` as `interpret` does (geometry aside), the turtle set to saved[index] at
/// each `%(par, index)`. At each one-parameter `%` it reaches, the turtle is saved as
/// saved[first + k] (saved is cut to `first` turtles before: a new run starts at 0).
/// Returns the indices of those modules in `string`, in the order reached. Throws
/// cambium::Error when `saved` would hold more than `limit` turtles.
std::vector<std::uint32_t> save_fragment_turtles(const lsys::ModuleString& string,
                                                 const lsys::SymbolTable& symbols,
                                                 const ViewFile& view, std::vector<Turtle>& saved,
                                                 std::uint32_t first, std::uint32_t limit);

/// The lights render should use: the view file's `light:` commands, or cpfg's
/// default light when there are none.
std::vector<Light> effective_lights(const ViewFile& view);

}  // namespace cambium::geom
