// SPDX-License-Identifier: Apache-2.0
// Growth between derivation steps (--inbetween): strings interpolated along the lineage
// of their modules.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lsys/module_string.h"

namespace cambium::lsys {

/// In a lineage (Derivation::lineage()): the module has no parent in the previous
/// string; it appeared in that step.
inline constexpr std::uint32_t no_parent = 0xffffffffu;

/// How the modules of one symbol that appear in a step grow over the in-betweens.
struct Growth {
    bool from_zero = false;  ///< the first parameter scaled by t (a length or width)
    /// A module without parameters stands for one parameter of this value (F is F(1));
    /// 0: it stays as it is.
    float implied = 0;
};

/// The string a fraction `t` (0..1) of the way from `before` to `after`, where `after`
/// came from `before` by one Derivation::advance() whose lineage is `lineage` (one entry
/// per module of `after`). It has the modules of `after`, in order:
/// - a module that continues one of `before` with as many parameters has each parameter
///   interpolated linearly: (1 - t) before + t after;
/// - a module that appeared (no_parent), or continues one with another parameter count,
///   has its parameters of `after`, except that the symbols `growth` marks (indexed by
///   symbol id: lengths and widths such as F and !) have their first parameter scaled by
///   t, so they grow from nothing (a parameterless one gets its implied parameter times t).
/// Modules of `before` that nothing continues are gone from the first in-between.
ModuleString inbetween(const ModuleString& before, const ModuleString& after,
                       std::span<const std::uint32_t> lineage, float t,
                       const std::vector<Growth>& growth);

}  // namespace cambium::lsys
