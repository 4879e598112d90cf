// SPDX-License-Identifier: Apache-2.0
// Tropisms and torques (report section 6, manual 5.2.7): bending of F/G/f/g segments.
#include "geom/tropism.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cambium::geom {
namespace {

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

/// The vector the heading bends toward: the sum over tropisms of
/// e cos(gamma) T + e sin(gamma) / |H x T| * T x (H x T), as cpfg sums it.
Vec3 desired_direction(const Turtle& turtle, std::span<const Movement> movements)
{
    Vec3 sum{0, 0, 0};
    for (std::size_t i = 0; i < movements.size() && i < Turtle::max_movements; ++i) {
        const Movement& m = movements[i];
        if (m.kind != Movement::Kind::tropism)
            continue;
        double e = turtle.elasticity[i];
        double cos_g = std::cos(radians(m.angle_deg)), sin_g = std::sin(radians(m.angle_deg));
        sum += m.direction * (e * cos_g);
        if (sin_g == 0)
            continue;
        Vec3 h_x_t = cross(turtle.heading, m.direction);
        double len = length(h_x_t);
        if (len < 1e-7) {  // H along T: cpfg turns around L instead
            h_x_t = turtle.left;
            len = 1;
        }
        sum += cross(m.direction, h_x_t) * (e * sin_g / len);
    }
    return sum;
}

/// Turns H around H x d by min(|H x d|, 1) radians, then U and L without twist.
void bend_toward(Turtle& turtle, const Vec3& d)
{
    Vec3 axis = cross(turtle.heading, d);
    double len = length(axis);
    if (len < 1e-6)
        return;
    turtle.heading = rotate_about(turtle.heading, axis / len, std::min(len, 1.0));
    turtle.adjust_up_and_left();
}

/// Rolls U around H toward the projection of the torques' summed direction.
void twist(Turtle& turtle, std::span<const Movement> movements)
{
    Vec3 dir{0, 0, 0};
    for (std::size_t i = 0; i < movements.size() && i < Turtle::max_movements; ++i)
        if (movements[i].kind == Movement::Kind::torque)
            dir += movements[i].direction * turtle.elasticity[i];
    double strength = length(dir);
    if (strength == 0)
        return;
    Vec3 h_x_d = cross(turtle.heading, dir / strength);
    if (dot(h_x_d, h_x_d) <= 1e-8)
        return;  // H along the torque direction
    Vec3 target = cross(h_x_d, turtle.heading) * strength;
    Vec3 axis = cross(turtle.up, target);
    double len = length(axis);
    if (len >= 1e-7) {
        // cpfg's rotate_to_vector turns U by -|U x target| around U x target (its
        // quaternion rotation is q^-1 v q): positive elasticities roll U away from
        // the target. Kept as cpfg draws it.
        turtle.up = rotate_about(turtle.up, axis / len, -std::min(len, 1.0));
        turtle.left = cross(turtle.heading, turtle.up);
    }
    turtle.remember_frame();  // the twist is wanted: later adjustments keep it
}

}  // namespace

double tropism_bending_angle(const Vec3& h, const Vec3& t, double e, double gamma_deg)
{
    double h_x_t = length(cross(h, t));
    return e * (std::cos(radians(gamma_deg)) - std::sin(radians(gamma_deg)) * dot(h, t) / h_x_t) *
           h_x_t;
}

void apply_movements(Turtle& turtle, std::span<const Movement> movements)
{
    if (movements.empty())
        return;
    bend_toward(turtle, desired_direction(turtle, movements));
    twist(turtle, movements);
}

void change_legacy_elasticity(Turtle& turtle, std::span<const float> p, double increment)
{
    if (p.empty())
        turtle.legacy_elasticity += increment;
    else
        turtle.legacy_elasticity = static_cast<double>(p[0]);
}

}  // namespace cambium::geom
