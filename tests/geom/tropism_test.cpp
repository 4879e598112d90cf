// SPDX-License-Identifier: Apache-2.0
// Tests of tropisms, torques and the no-twist frame adjustments against hand values.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "geom/tropism.h"

using namespace cambium::geom;

namespace {
void expect_vec(const Vec3& a, const Vec3& b, double tol = 1e-12)
{
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

Movement tropism(Vec3 t, double e, double angle = 0)
{
    Movement m;
    m.direction = t;
    m.initial_elasticity = e;
    m.angle_deg = angle;
    return m;
}
}  // namespace

TEST(Tropism, BendingAngleOfFormulaOne)
{
    // H perpendicular to T: e |H x T| = e
    EXPECT_NEAR(tropism_bending_angle({0, 1, 0}, {1, 0, 0}, 0.5, 0), 0.5, 1e-12);
    // 30 degrees between H and T: e sin 30
    Vec3 h{std::sin(std::numbers::pi / 6), std::cos(std::numbers::pi / 6), 0};
    EXPECT_NEAR(tropism_bending_angle(h, {0, 1, 0}, 0.2, 0), 0.1, 1e-12);
}

TEST(Tropism, BendingAngleOfFormulaTwo)
{
    // plagiotropism (90 degrees), H at 45 degrees from T: e (0 - cos45/sin45) sin45 = -e cos45
    double k = std::sqrt(0.5);
    EXPECT_NEAR(tropism_bending_angle({k, k, 0}, {0, 1, 0}, 0.5, 90), -0.5 * k, 1e-12);
    // diatropism at 60 degrees, H perpendicular to T: e cos 60
    EXPECT_NEAR(tropism_bending_angle({1, 0, 0}, {0, 1, 0}, 0.4, 60), 0.2, 1e-12);
}

TEST(Tropism, HeadingTurnsTowardTheVectorAndUpFollowsWithoutTwist)
{
    Turtle t;
    Movement m = tropism({1, 0, 0}, 0.5);
    t.elasticity[0] = 0.5;
    apply_movements(t, std::span<const Movement>(&m, 1));
    expect_vec(t.heading, {std::sin(0.5), std::cos(0.5), 0});
    expect_vec(t.up, {0, 0, -1});  // the rotation axis is U itself
    expect_vec(t.left, cross(t.heading, t.up));
}

TEST(Tropism, BendIsClampedToOneRadian)
{
    Turtle t;
    Movement m = tropism({1, 0, 0}, 5);
    t.elasticity[0] = 5;
    apply_movements(t, std::span<const Movement>(&m, 1));
    expect_vec(t.heading, {std::sin(1.0), std::cos(1.0), 0});
}

TEST(Tropism, TorqueRollsUpAroundHeadingAsCpfgDoes)
{
    // torque direction +x, e = 0.5: cpfg turns U by -0.5 rad around U x T = -y,
    // i.e. +0.5 rad around +y: (0,0,-1) -> (-sin .5, 0, -cos .5)
    Turtle t;
    Movement m = tropism({1, 0, 0}, 0.5);
    m.kind = Movement::Kind::torque;
    t.elasticity[0] = 0.5;
    apply_movements(t, std::span<const Movement>(&m, 1));
    expect_vec(t.heading, {0, 1, 0});
    expect_vec(t.up, {-std::sin(0.5), 0, -std::cos(0.5)});
    expect_vec(t.left, cross(t.heading, t.up));
}

TEST(TurtleFrame, RollToVerticalMakesLeftHorizontal)
{
    Turtle t;
    t.turn(-90);  // H = +x, L = +y
    t.roll(37);
    t.roll_to_vertical();
    expect_vec(t.heading, {1, 0, 0});
    expect_vec(t.left, {0, 0, -1});  // +y x H
    expect_vec(t.up, {0, -1, 0});    // L x H
}

TEST(TurtleFrame, RollToVerticalLeavesAVerticalHeading)
{
    Turtle t;
    t.roll(30);
    Vec3 left = t.left;
    t.roll_to_vertical();
    expect_vec(t.left, left);
}

TEST(TurtleFrame, SetHeadingTurnsTheFrameWithoutTwist)
{
    Turtle t;
    t.set_heading({2, 0, 0});
    expect_vec(t.heading, {1, 0, 0});
    expect_vec(t.up, {0, 0, -1});  // the turn is around U
    expect_vec(t.left, {0, 1, 0});
}

TEST(TurtleFrame, SetHeadingOppositeKeepsUp)
{
    Turtle t;
    t.set_heading({0, -1, 0});
    expect_vec(t.up, {0, 0, -1});
    expect_vec(t.left, {1, 0, 0});
}

TEST(TurtleFrame, SetHeadingAndUp)
{
    Turtle t;
    t.set_heading_and_up({0, 0, 2}, {0, 3, 0});
    expect_vec(t.heading, {0, 0, 1});
    expect_vec(t.up, {0, 1, 0});
    expect_vec(t.left, {-1, 0, 0});  // H x U
}

TEST(TurtleFrame, SetHeadingWithNonPerpendicularUpFallsBackToNoTwist)
{
    Turtle a, b;
    a.set_heading_and_up({1, 0, 0}, {1, 1, 0});
    b.set_heading({1, 0, 0});
    expect_vec(a.up, b.up);
    expect_vec(a.left, b.left);
}

TEST(TurtleFrame, PreventTwistCarriesTheLastSegmentsUp)
{
    Turtle t;
    t.remember_frame();
    t.roll(40);
    t.adjust_up_and_left();  // H unchanged: U stays as rolled (cpfg keeps it)
    double s40 = std::sin(40 * std::numbers::pi / 180), c40 = std::cos(40 * std::numbers::pi / 180);
    expect_vec(t.up, {s40, 0, -c40});
    t.pitch(30);
    t.adjust_up_and_left();  // H changed: U is the old up (0,0,-1) carried along
    expect_vec(t.left, cross(t.heading, t.up));
    EXPECT_NEAR(dot(t.up, t.heading), 0, 1e-12);
    EXPECT_NEAR(length(t.up), 1, 1e-12);
    // the rotation's axis k = (0,1,0) x H = (h.z, 0, -h.x) is fixed: U.k = (0,0,-1).k = h.x
    Vec3 k{t.heading.z, 0, -t.heading.x};
    EXPECT_NEAR(dot(t.up, k), t.heading.x, 1e-12);
    EXPECT_NEAR(t.heading.x, s40 * 0.5, 1e-12);
}

TEST(LegacyTropism, UnderscoreSetsOrAddsTheIncrement)
{
    // WeepingBirch: `initial elasticity: 0.4`, `elasticity increment: -0.06`, `_` at
    // every branching: each order is stiffer, then bends away from the tropism.
    Turtle t;
    t.legacy_elasticity = 0.4;
    change_legacy_elasticity(t, {}, -0.06);
    EXPECT_NEAR(t.legacy_elasticity, 0.34, 1e-12);
    const float set[] = {-0.1f};
    change_legacy_elasticity(t, set, -0.06);  // Sedge: `_(0-.1)` sets
    EXPECT_FLOAT_EQ(static_cast<float>(t.legacy_elasticity), -0.1f);
}
