// SPDX-License-Identifier: Apache-2.0
// cpfg's 3D turtle: its state and the rotations of manual 5.1.9.
#pragma once

#include <array>

#include "geom/gencyl.h"
#include "geom/vec.h"

namespace cambium::geom {

/// The operations interpreted symbols map to (turtle_symbols.def).
enum class TurtleOp : unsigned char {
    None,
#define X(op, name, doc) op,
#include "geom/turtle_symbols.def"
#undef X
};

/// The turtle: a small value type that `[` copies and `]` restores.
///
/// Frame: heading H, left L and up U with U = L x H, as cpfg keeps them. cpfg starts
/// with H = +y, L = -x, U = -z: seen from the default viewpoint on +z, the plant
/// grows up the screen, L points left and U into the screen.
struct Turtle {
    Vec3 position{0, 0, 0};
    Vec3 heading{0, 1, 0};
    Vec3 left{-1, 0, 0};
    Vec3 up{0, 0, -1};
    double line_width = 1;
    int color = 1;
    int back_color = 1;
    double scale = 1;
    int texture = -1;        ///< index into the view file's textures (`@Tx(i)` is i-1), -1: none
    double texture_v = 0;    ///< texture v reached along the axis (report 5.2)

    /// The heading and up of the last drawn segment (F, G): tropisms and `@Tp`
    /// keep the frame from twisting relative to them (cpfg's prev_heading/prev_up).
    Vec3 prev_heading{0, 1, 0};
    Vec3 prev_up{0, 0, -1};

    /// Elasticity of each view-file tropism/torque, in order (`@Ts`, `@Ti`, `@Td`).
    static constexpr std::size_t max_movements = 16;
    std::array<double, max_movements> elasticity{};
    /// Elasticity of the pre-3.0 tropism (`initial elasticity:`, cpfg's bend()).
    double legacy_elasticity = 0;

    /// Generalized cylinders (@G modules): their parameters and the active control
    /// point, carried with the turtle so that branches connect to it.
    CylinderState cylinder;

    /// `+`: rotates H toward L around U (negative angles: `-`).
    void turn(double degrees);
    /// `&`: pitches H toward U, down into the screen at the start (negative: `^`).
    void pitch(double degrees);
    /// `/`: rolls L toward U around H (negative: backslash).
    void roll(double degrees);
    /// `|`: turns around U by 180 degrees (H and L reversed).
    void turn_around();

    /// `@v`: rolls around H so that L is horizontal (L = +y x H, normalised) and
    /// U = L x H; no change when H is vertical.
    void roll_to_vertical();
    /// `@R(hx,hy,hz)`: sets H (normalised; +y when zero) and turns U and L by the
    /// rotation that takes the previous segment's heading to H (no twist).
    void set_heading(const Vec3& h);
    /// `@R(hx,hy,hz,ux,uy,uz)`: sets H and U; L = H x U. When U is zero or not
    /// exactly perpendicular to H, cpfg falls back to the no-twist adjustment.
    void set_heading_and_up(const Vec3& h, const Vec3& u);
    /// cpfg's adjust_up_and_left: U is prev_up turned by the rotation taking
    /// prev_heading to H; L = H x U.
    void adjust_up_and_left();
    /// Records the current H and U as the reference for later twist adjustments.
    void remember_frame()
    {
        prev_heading = heading;
        prev_up = up;
    }
};

/// Rotates v around the unit axis by `radians` (right-handed).
Vec3 rotate_about(const Vec3& v, const Vec3& unit_axis, double radians);

}  // namespace cambium::geom
