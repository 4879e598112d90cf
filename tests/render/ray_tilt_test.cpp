// SPDX-License-Identifier: Apache-2.0
// off_axis (its SSE form) against the rule written out component by component: every
// component below a millionth of the largest raised to that with its sign, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "render/ray_tilt.h"

namespace cambium::render {
namespace {

/// The rule, in plain scalar code, independent of the header's.
Vec3f tilted(const Vec3f& d)
{
    const float largest = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
    const float least = 1e-6f * largest;
    auto raise = [least](float c) {
        if (std::fabs(c) >= least)
            return c;
        return std::signbit(c) ? -least : least;
    };
    return {raise(d.x), raise(d.y), raise(d.z)};
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_tilt(const Vec3f& d)
{
    const Vec3f got = off_axis(d), want = tilted(d);
    EXPECT_TRUE(same_bits(got.x, want.x) && same_bits(got.y, want.y) &&
                same_bits(got.z, want.z))
        << "(" << d.x << ", " << d.y << ", " << d.z << ") gave (" << got.x << ", " << got.y
        << ", " << got.z << "), want (" << want.x << ", " << want.y << ", " << want.z << ")";
}

TEST(RayTilt, AxisDirectionsGetTinySignedComponents)
{
    // A parallel view's camera ray: down -z, the other two components zero.
    const Vec3f down = off_axis({0.0f, -0.0f, -1.0f});
    EXPECT_EQ(down.x, 1e-6f);
    EXPECT_EQ(down.y, -1e-6f);  // -0 keeps its sign
    EXPECT_EQ(down.z, -1.0f);
    // below 3e-6 of a largest component of 3 is raised, above it stays
    const Vec3f side = off_axis({3.0f, 2e-6f, -4e-6f});
    EXPECT_EQ(side.x, 3.0f);
    EXPECT_EQ(side.y, 1e-6f * 3.0f);
    EXPECT_EQ(side.z, -4e-6f);
    // a component of exactly a millionth of the largest stays
    EXPECT_EQ(off_axis({1.0f, 1e-6f, 0.5f}).y, 1e-6f);
}

TEST(RayTilt, MatchesTheRuleBitForBit)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::uniform_int_distribution<int> power(-12, 3);
    std::uniform_int_distribution<int> kind(0, 3);
    auto component = [&] {
        switch (kind(rng)) {
        case 0: return 0.0f;
        case 1: return -0.0f;
        case 2: return unit(rng) * std::ldexp(1.0f, -4 * power(rng));  // tiny to large
        default: return unit(rng);
        }
    };
    for (int i = 0; i < 200000; ++i)
        expect_tilt({component(), component(), component()});
    // each component the largest in turn, the others at and about the threshold
    for (float near : {0.999999e-6f, 1e-6f, 1.000001e-6f})
        for (int axis = 0; axis < 3; ++axis) {
            float c[3] = {near, -near, near};
            c[axis] = axis == 1 ? -1.0f : 1.0f;
            expect_tilt({c[0], c[1], c[2]});
        }
    expect_tilt({0.0f, 0.0f, 0.0f});
}

}  // namespace
}  // namespace cambium::render
