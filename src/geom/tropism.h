// SPDX-License-Identifier: Apache-2.0
// Tropisms and torques (report section 6, manual 5.2.7): bending of F/G/f/g segments.
#pragma once

#include <span>
#include <vector>

#include "geom/turtle.h"

namespace cambium::geom {

/// One `tropism:` or `torque:` of the view file (or the legacy `tropism direction:`).
struct Movement {
    enum class Kind { tropism, torque };
    Kind kind = Kind::tropism;
    /// T: times clamp(I / |T|, -1, 1), as cpfg's read_movement scales it (so with the
    /// default I = 1 it is the unit vector; I above |T| leaves T as given).
    Vec3 direction{0, 1, 0};
    double angle_deg = 0;           ///< A: the angle the segments try to reach with T
    double initial_elasticity = 0;  ///< E:
    double elasticity_step = 0;     ///< S: the default step of @Ti / @Td
};

/// The angle (radians) by which a segment with unit heading `h` turns toward `t`
/// under one tropism with elasticity `e` and angle `gamma_deg` (report formula 2;
/// gamma = 0 gives formula 1, e |H x T|), before cpfg's clamp to one radian.
double tropism_bending_angle(const Vec3& h, const Vec3& t, double e, double gamma_deg);

/// cpfg's movement_adjust: turns the turtle's heading toward the weighted sum of all
/// tropisms (at most one radian, U and L following without twist), then rolls U
/// toward the torques' direction. Elasticities are the turtle's, one per movement.
void apply_movements(Turtle& turtle, std::span<const Movement> movements);

/// `_` and `_(e)` (manual 5.2.7): sets the pre-3.0 tropism's elasticity to e, or adds
/// the view file's `elasticity increment:` (negative increments decrease it).
void change_legacy_elasticity(Turtle& turtle, std::span<const float> p, double increment);

}  // namespace cambium::geom
