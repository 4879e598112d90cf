// SPDX-License-Identifier: Apache-2.0
// Tests of the turtle's frame and rotations against hand-computed frames.
#include <gtest/gtest.h>

#include "geom/turtle.h"

using namespace cambium::geom;

namespace {
void expect_vec(const Vec3& a, const Vec3& b)
{
    EXPECT_NEAR(a.x, b.x, 1e-12);
    EXPECT_NEAR(a.y, b.y, 1e-12);
    EXPECT_NEAR(a.z, b.z, 1e-12);
}
}  // namespace

TEST(Turtle, InitialFrameIsCpfgs)
{
    Turtle t;
    expect_vec(t.heading, {0, 1, 0});
    expect_vec(t.left, {-1, 0, 0});
    expect_vec(t.up, {0, 0, -1});
    expect_vec(cross(t.left, t.heading), t.up);  // cpfg keeps U = L x H
}

TEST(Turtle, TurnLeftRotatesHeadingTowardLeft)
{
    Turtle t;
    t.turn(90);
    expect_vec(t.heading, {-1, 0, 0});
    expect_vec(t.left, {0, -1, 0});
    expect_vec(t.up, {0, 0, -1});
}

TEST(Turtle, PitchDownRotatesHeadingIntoTheScreen)
{
    Turtle t;
    t.pitch(90);
    expect_vec(t.heading, {0, 0, -1});
    expect_vec(t.up, {0, -1, 0});
    expect_vec(t.left, {-1, 0, 0});
}

TEST(Turtle, RollRightRotatesLeftTowardUp)
{
    Turtle t;
    t.roll(90);
    expect_vec(t.left, {0, 0, -1});
    expect_vec(t.up, {1, 0, 0});
    expect_vec(t.heading, {0, 1, 0});
}

TEST(Turtle, TurnAroundReversesHeadingAndLeft)
{
    Turtle t;
    t.turn(30);
    Turtle u = t;
    u.turn_around();
    expect_vec(u.heading, -t.heading);
    expect_vec(u.left, -t.left);
    expect_vec(u.up, t.up);
}

TEST(Turtle, RotationsKeepTheFrameOrthonormal)
{
    Turtle t;
    for (int i = 0; i < 1000; ++i) {
        t.turn(13.7);
        t.pitch(-21.1);
        t.roll(33.3);
    }
    EXPECT_NEAR(length(t.heading), 1, 1e-9);
    EXPECT_NEAR(dot(t.heading, t.left), 0, 1e-9);
    EXPECT_NEAR(dot(t.heading, t.up), 0, 1e-9);
    Vec3 u = cross(t.left, t.heading);
    EXPECT_NEAR(dot(u, t.up), 1, 1e-9);
}
