// SPDX-License-Identifier: Apache-2.0
// cpfg's 3D turtle: its state and the rotations of manual 5.1.9.
#include "geom/turtle.h"

#include <numbers>

namespace cambium::geom {
namespace {

/// Rotates the pair (a, b) in their plane: a turns toward b by `degrees`. Like cpfg,
/// the frame is not re-orthonormalised afterwards, so positions match cpfg's.
void rotate_pair(Vec3& a, Vec3& b, double degrees)
{
    double radians = degrees * std::numbers::pi / 180.0;
    double c = std::cos(radians), s = std::sin(radians);
    Vec3 a2 = a * c + b * s;
    Vec3 b2 = b * c - a * s;
    a = a2;
    b = b2;
}

}  // namespace

void Turtle::turn(double degrees) { rotate_pair(heading, left, degrees); }

void Turtle::pitch(double degrees) { rotate_pair(heading, up, degrees); }

void Turtle::roll(double degrees) { rotate_pair(left, up, degrees); }

void Turtle::turn_around()
{
    heading = -heading;
    left = -left;
}

}  // namespace cambium::geom
