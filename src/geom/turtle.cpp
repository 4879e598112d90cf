// SPDX-License-Identifier: Apache-2.0
// cpfg's 3D turtle: its state and the rotations of manual 5.1.9.
#include "geom/turtle.h"

#include <algorithm>
#include <cmath>
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

Vec3 rotate_about(const Vec3& v, const Vec3& k, double radians)
{
    // Rodrigues' formula
    double c = std::cos(radians), s = std::sin(radians);
    return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

void Turtle::roll_to_vertical()
{
    if (!(heading.y < 1.0 && heading.y > -1.0))
        return;
    left = normalize(cross(Vec3{0, 1, 0}, heading));
    up = cross(left, heading);
}

void Turtle::adjust_up_and_left()
{
    // The rotation taking prev_heading to heading, applied to prev_up; cpfg
    // measures its angle as asin |H x H_prev| (pi minus that past 90 degrees).
    Vec3 axis = cross(prev_heading, heading);
    double len = length(axis);
    if (len > 1e-6) {
        double angle = std::asin(std::min(len, 1.0));
        if (dot(heading, prev_heading) < 0)
            angle = std::numbers::pi - angle;
        up = rotate_about(prev_up, axis / len, angle);
    }
    left = cross(heading, up);
}

void Turtle::set_heading(const Vec3& h)
{
    heading = dot(h, h) == 0 ? Vec3{0, 1, 0} : normalize(h);
    adjust_up_and_left();
}

void Turtle::set_heading_and_up(const Vec3& h, const Vec3& u)
{
    heading = dot(h, h) == 0 ? Vec3{0, 1, 0} : normalize(h);
    if (dot(u, u) == 0 || dot(u, heading) != 0) {
        adjust_up_and_left();
        return;
    }
    up = normalize(u);
    left = cross(heading, up);
}

}  // namespace cambium::geom
