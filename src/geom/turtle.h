// SPDX-License-Identifier: Apache-2.0
// cpfg's 3D turtle: its state and the rotations of manual 5.1.9.
#pragma once

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

    /// `+`: rotates H toward L around U (negative angles: `-`).
    void turn(double degrees);
    /// `&`: pitches H toward U, down into the screen at the start (negative: `^`).
    void pitch(double degrees);
    /// `/`: rolls L toward U around H (negative: backslash).
    void roll(double degrees);
    /// `|`: turns around U by 180 degrees (H and L reversed).
    void turn_around();
};

}  // namespace cambium::geom
