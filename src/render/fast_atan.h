// SPDX-License-Identifier: Apache-2.0
// atan2 for texture coordinates, inline: glibc's atan2f (a call, then atanf) was about 4%
// of a textured tube's trace, where s only needs the angle to a fraction of a texel.
#pragma once

#include <cmath>
#include <numbers>

namespace cambium::render {

/// The largest error of fast_atan2 against the exact angle, in radians (its test sweeps
/// the circle densely; 3.7e-7 is the worst seen): about 2 ulp of pi. In a texture's s
/// (the angle over 2 pi) that is 8e-8, a ten-thousandth of a texel of 1024 texels.
inline constexpr float fast_atan2_max_error = 5e-7f;

/// std::atan2(y, x) within fast_atan2_max_error, for finite y and x: the same quadrants
/// and signed zeros (atan2(+-0, -0) is +-pi). NaN in, NaN out; infinities are not handled.
inline float fast_atan2(float y, float x)
{
    if (std::isnan(x) || std::isnan(y))
        return x + y;
    const float ax = std::fabs(x), ay = std::fabs(y);
    const bool steep = ay > ax;
    const float big = steep ? ay : ax, small = steep ? ax : ay;
    const float a = big > 0 ? small / big : 0.0f;  // tan of the angle to the nearer axis
    // atan(a) on [0, 1] as a times an even polynomial: a least-squares fit weighted
    // towards minimax, 3.8e-8 from atan in exact arithmetic. Estrin's scheme: four short
    // chains in parallel instead of Horner's eight dependent steps (this is latency).
    const float z = a * a, z2 = z * z, z4 = z2 * z2;
    const float p01 = 0.9999993443489075f - 0.33329859375953674f * z;
    const float p23 = 0.19946566224098206f - 0.1390862911939621f * z;
    const float p45 = 0.0964219719171524f - 0.0559123195707798f * z;
    const float p67 = 0.021862953901290894f - 0.004054565913975239f * z;
    const float p = (p01 + z2 * p23) + z4 * (p45 + z2 * p67);
    float r = a * p;
    if (steep)
        r = std::numbers::pi_v<float> / 2 - r;
    if (std::signbit(x))
        r = std::numbers::pi_v<float> - r;
    return std::copysign(r, y);
}

}  // namespace cambium::render
