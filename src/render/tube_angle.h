// SPDX-License-Identifier: Apache-2.0
// A tube's texture s: the angle of a normal about the tube's axis, in the frame
// make_basis gives the axis, without normalizing the axis or building the frame.
#pragma once

#include <cmath>
#include <numbers>

#include "render/fast_atan.h"
#include "render/vecf.h"

namespace cambium::render {

/// How far angle_around may be from the exact s of make_basis(normalize(axis)) and
/// atan2 (its test compares them over random axes and normals). The worst seen is 9.7e-8,
/// as close as the float normalize, make_basis and std::atan2 it replaced (1.0e-7): in a
/// 1024-texel texture, a ten-thousandth of a texel.
inline constexpr float angle_around_max_error = 1.5e-7f;

/// Texture s around a tube: the angle of the normal n about the axis, in [0, 1], as
/// atan2(n . b, n . t) / 2 pi + 1/2 for make_basis(normalize(axis), t, b).
///
/// atan2 needs t and b only up to a common positive factor. Scaled by L^2 (1 + |u_z|),
/// with L the axis's length and u = axis / L, make_basis's frame is
///   t' = (A_y^2 + A_z^2 + L |A_z|,  -A_x A_y,                       -s h A_x)
///   b' = (-s A_x A_y,               s (A_x^2 + A_z^2 + L |A_z|),    -h A_y)
/// with s the sign of A_z and h = L + |A_z|: one square root, no division (the frame and
/// the normalization took four, in one dependent chain with the atan2's own), and no
/// cancellation in the diagonal terms (1 + s u_x^2 a in make_basis cancels when the axis
/// is near x).
inline float angle_around(const Vec3f& axis, const Vec3f& n)
{
    const float xx = axis.x * axis.x, yy = axis.y * axis.y, zz = axis.z * axis.z;
    const float length = std::sqrt(xx + yy + zz);
    float x = n.x, y = n.y;  // a zero axis: normalize leaves it, make_basis gives x and y
    if (length > 0) {
        const float s = std::copysign(1.0f, axis.z), az = std::fabs(axis.z);
        const float h = length + az, lz = length * az, xy = axis.x * axis.y;
        const Vec3f t{yy + zz + lz, -xy, -s * h * axis.x};
        const Vec3f b{-s * xy, s * (xx + zz + lz), -h * axis.y};
        x = dot(n, t), y = dot(n, b);
    }
    return fast_atan2(y, x) * (0.5f * std::numbers::inv_pi_v<float>) + 0.5f;
}

}  // namespace cambium::render
