// SPDX-License-Identifier: Apache-2.0
// fast_atan2 against the angle in double precision, over a dense sweep of the circle and
// of the ratios near its axes and diagonals, with its stated bound; quadrants and signed
// zeros exactly as std::atan2.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

#include "render/fast_atan.h"
#include "render/tube_angle.h"

namespace cambium::render {
namespace {

/// The error of fast_atan2(y, x) against the exact angle of the float point (y, x).
double error_at(float y, float x)
{
    return std::fabs(double(fast_atan2(y, x)) - std::atan2(double(y), double(x)));
}

TEST(FastAtan2, WithinItsBoundAllRoundTheCircle)
{
    // 4 M directions, at radii from tiny to huge (the ratio is what matters).
    constexpr int steps = 1 << 22;
    double worst = 0;
    for (int i = 0; i <= steps; ++i) {
        const double theta = -std::numbers::pi + 2 * std::numbers::pi * i / steps;
        const float radius = i % 3 == 0 ? 1.0f : (i % 3 == 1 ? 3e-20f : 7e15f);
        const float x = float(std::cos(theta)) * radius, y = float(std::sin(theta)) * radius;
        worst = std::max(worst, error_at(y, x));
    }
    EXPECT_LE(worst, fast_atan2_max_error);
    // Not looser than it needs to be: the bound is within 4x of the worst error seen.
    EXPECT_GT(worst, fast_atan2_max_error / 4);
}

TEST(FastAtan2, WithinItsBoundForEveryRatioNearTheAxesAndDiagonals)
{
    // Consecutive floats of the ratio where the reductions switch: 0, 1 and beyond.
    double worst = 0;
    for (float start : {0.0f, 1e-30f, 1e-7f, 0.4142f, 0.99999f, 1.0f}) {
        float a = start;
        for (int i = 0; i < 200000; ++i, a = std::nextafter(a, 2.0f))
            for (float sx : {1.0f, -1.0f})
                for (float sy : {1.0f, -1.0f}) {
                    worst = std::max(worst, error_at(sy * a, sx * 1.0f));
                    worst = std::max(worst, error_at(sy * 1.0f, sx * a));
                }
    }
    EXPECT_LE(worst, fast_atan2_max_error);
}

TEST(FastAtan2, QuadrantsAndSignedZerosAsStdAtan2)
{
    const float zero = 0.0f, one = 1.0f;
    for (float y : {zero, -zero, one, -one})
        for (float x : {zero, -zero, one, -one}) {
            const float want = std::atan2(y, x), got = fast_atan2(y, x);
            EXPECT_NEAR(got, want, fast_atan2_max_error) << y << ", " << x;
            EXPECT_EQ(std::signbit(got), std::signbit(want)) << y << ", " << x;
        }
    // On an axis the angle is the float nearest the exact one or a rounding away.
    EXPECT_NEAR(fast_atan2(-1e-30f, -1.0f), -std::numbers::pi_v<float>, 3e-7f);
    EXPECT_TRUE(std::isnan(fast_atan2(std::nanf(""), 1.0f)));
    EXPECT_TRUE(std::isnan(fast_atan2(0.0f, std::nanf(""))));
}

/// angle_around's definition in double precision: the normal's angle in the frame
/// make_basis builds around the normalized axis (the same formulas), over 2 pi, plus 1/2.
double angle_by_frame(const Vec3f& axis, const Vec3f& n)
{
    const double len = std::sqrt(double(axis.x) * axis.x + double(axis.y) * axis.y +
                                 double(axis.z) * axis.z);
    const double ux = axis.x / len, uy = axis.y / len, uz = axis.z / len;
    const double sign = std::copysign(1.0, uz), a = -1 / (sign + uz), c = ux * uy * a;
    const double t[3] = {1 + sign * ux * ux * a, sign * c, -sign * ux};
    const double b[3] = {c, sign + uy * uy * a, -uy};
    const double x = n.x * t[0] + n.y * t[1] + n.z * t[2];
    const double y = n.x * b[0] + n.y * b[1] + n.z * b[2];
    return std::atan2(y, x) / (2 * std::numbers::pi) + 0.5;
}

/// The distance between two values of s, which wraps at 1 (the texture repeats).
double s_distance(double a, double b)
{
    double d = std::fabs(a - b);
    return std::min(d, 1 - d);
}

TEST(AngleAround, MatchesTheFrameOfTheNormalizedAxisWithinItsBound)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1, 1);
    std::uniform_real_distribution<float> exponent(-6, 6);
    double worst = 0;
    for (int i = 0; i < 1000000; ++i) {
        Vec3f axis{u(rng), u(rng), u(rng)};
        // Axes near each coordinate axis too, where make_basis's own terms cancel.
        if (i % 4 == 1)
            axis = Vec3f{1, 1e-3f * u(rng), 1e-3f * u(rng)};
        else if (i % 4 == 2)
            axis = Vec3f{1e-4f * u(rng), 1e-4f * u(rng), i % 8 == 2 ? 1.0f : -1.0f};
        axis = axis * std::exp2(exponent(rng));  // any length
        // A tube's normal: across the axis, leaning along it by up to about 30 degrees.
        Vec3f r{u(rng), u(rng), u(rng)};
        Vec3f across = cross(axis, r);
        if (dot(across, across) == 0)
            continue;
        Vec3f n = normalize(normalize(across) + normalize(axis) * (0.5f * u(rng)));
        worst = std::max(worst, s_distance(angle_around(axis, n), angle_by_frame(axis, n)));
    }
    EXPECT_LE(worst, angle_around_max_error);
}

TEST(AngleAround, AZeroAxisTakesTheNormalsXAndYAsTheFrameDoes)
{
    // normalize leaves a zero axis zero and make_basis then gives t = x, b = y.
    const Vec3f n{-0.6f, 0.8f, 0};
    EXPECT_NEAR(angle_around(Vec3f(), n), std::atan2(0.8, -0.6) / (2 * std::numbers::pi) + 0.5,
                angle_around_max_error);
}

}  // namespace
}  // namespace cambium::render
