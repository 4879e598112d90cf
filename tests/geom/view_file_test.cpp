// SPDX-License-Identifier: Apache-2.0
// Tests of the view-file reader: values, defaults, line styles, lights and error locations.
#include <gtest/gtest.h>

#include "geom/view_file.h"

using namespace cambium;
using namespace cambium::geom;

TEST(ViewFile, DefaultsAreCpfgs)
{
    ViewFile v = parse_view_file("", "empty.v");
    EXPECT_DOUBLE_EQ(v.angle_increment_deg, 45);
    EXPECT_EQ(v.line_style, LineStyle::pixel);
    EXPECT_FALSE(v.view.perspective);
    EXPECT_DOUBLE_EQ(v.view.scale_factor, 1);
    EXPECT_TRUE(v.lights.empty());
}

TEST(ViewFile, AngleFactorDividesFullTurn)
{
    ViewFile v = parse_view_file("angle factor: 12\n", "a.v");
    EXPECT_DOUBLE_EQ(v.angle_increment_deg, 30);
    v = parse_view_file("angle factor: 12\nangle increment: 7.5\n", "a.v");
    EXPECT_DOUBLE_EQ(v.angle_increment_deg, 7.5);  // the last command wins
}

TEST(ViewFile, LineWidthSuffixAndLineStyle)
{
    EXPECT_EQ(parse_view_file("initial line width: 2 pixels\n", "a.v").line_style, LineStyle::pixel);
    EXPECT_EQ(parse_view_file("initial line width: 0.5\n", "a.v").line_style, LineStyle::polygon);
    EXPECT_EQ(parse_view_file("initial line width: 0.5 s\n", "a.v").line_style, LineStyle::cylinder);
    ViewFile v = parse_view_file("initial line width: 3 p\nline style: cylinder\n", "a.v");
    EXPECT_EQ(v.line_style, LineStyle::cylinder);
    EXPECT_DOUBLE_EQ(v.initial_line_width, 3);
}

TEST(ViewFile, ViewCommandsWithCommasAndComments)
{
    ViewFile v = parse_view_file(
        "viewpoint: 0,0,30 /* eye */\n"
        "view reference point: 1, 2 ,3\n"
        "twist: 900\n"
        "// projection: perspective\n"
        "scale factor: 0.9\n"
        "box: x: 0,81 y: -1,23.5 z: 0,0\n",
        "a.v");
    EXPECT_DOUBLE_EQ(v.view.viewpoint.z, 30);
    EXPECT_DOUBLE_EQ(v.view.reference_point.y, 2);
    EXPECT_DOUBLE_EQ(v.view.reference_point.z, 3);
    EXPECT_DOUBLE_EQ(v.view.twist_deg, 90);  // tenths of degrees
    EXPECT_FALSE(v.view.perspective);        // commented out
    EXPECT_DOUBLE_EQ(v.view.scale_factor, 0.9);
    ASSERT_TRUE(v.view.box.has_value());
    EXPECT_DOUBLE_EQ(v.view.box->hi.x, 81);
    EXPECT_DOUBLE_EQ(v.view.box->lo.y, -1);
}

TEST(ViewFile, LightSubcommandsWithAndWithoutColons)
{
    ViewFile v = parse_view_file(
        "light: V: -0.5,-1.0,-2.0 A: 0.6 0.6 0.6 D 0.25 0.5 0.75\n"
        "light: O: 4.0 5.0 8.0  A:0 0 0 D: 1 0.3 0.3  P: -4 -4 -8 0 4 T: 1 0.5 0.25\n",
        "a.v");
    ASSERT_EQ(v.lights.size(), 2u);
    EXPECT_EQ(v.lights[0].kind, Light::Kind::directional);
    EXPECT_DOUBLE_EQ(v.lights[0].direction.z, -2.0);
    EXPECT_FLOAT_EQ(v.lights[0].diffuse.b, 0.75f);
    EXPECT_EQ(v.lights[1].kind, Light::Kind::spot);
    EXPECT_DOUBLE_EQ(v.lights[1].position.x, 4.0);
    EXPECT_FLOAT_EQ(v.lights[1].spot_cutoff_deg, 4.0f);
    EXPECT_FLOAT_EQ(v.lights[1].attenuation_quadratic, 0.25f);
}

TEST(ViewFile, MalformedNumberNamesLineAndColumn)
{
    try {
        parse_view_file("angle factor: 8\nscale factor: 0.9\nviewpoint: 0, x, 1\n", "bad.v");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().file, "bad.v");
        EXPECT_EQ(e.loc().line, 3);
        EXPECT_EQ(e.loc().column, 15);
        EXPECT_NE(std::string(e.what()).find("bad.v:3:15: error: expected a number"), std::string::npos)
            << e.what();
    }
}

TEST(ViewFile, UnknownCommandIsNotAnError)
{
    set_warnings_enabled(false);
    ViewFile v = parse_view_file("frobnicate: 3\nangle factor: 4\n", "a.v");
    set_warnings_enabled(true);
    EXPECT_DOUBLE_EQ(v.angle_increment_deg, 90);
}

TEST(ViewFile, DeferredCommandsAreKept)
{
    ViewFile v = parse_view_file("contour: 1 stripe.con\n", "a.v");
    ASSERT_EQ(v.deferred.size(), 1u);
    EXPECT_EQ(v.deferred[0].name, "contour");
    EXPECT_EQ(v.deferred[0].loc.line, 1);
}
