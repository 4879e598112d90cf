// SPDX-License-Identifier: Apache-2.0
// Tests of the view-file reader: values, defaults, line styles, lights and error locations.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "geom/label.h"
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

TEST(ViewFile, ReportsSeveralErrorsWithTheirPositionsAndReadsOn)
{
    Diagnostics sink(Diagnostics::Output::quiet);
    ScopedDiagnostics install(sink);
    try {
        parse_view_file("viewpoint: 0, x, 1\nscale factor: 0.9\nline style: wavy\n"
                        "tapered lines: maybe\nangle factor: 8\n",
                        "bad.v");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        std::string text = e.what();
        EXPECT_EQ(text.rfind("bad.v: error: 3 errors:", 0), 0u) << text;
        for (const char* part : {"bad.v:1:15: error: expected a number", "bad.v:3:", "bad.v:4:"})
            EXPECT_NE(text.find(part), std::string::npos) << part << " missing in: " << text;
    }
    std::vector<int> lines;
    for (const Diagnostic& d : sink.collected())
        if (d.severity == Severity::error)
            lines.push_back(d.loc.line);
    EXPECT_EQ(lines, (std::vector<int>{1, 3, 4}));
}

TEST(ViewFile, UnknownCommandIsNotAnError)
{
    set_warnings_enabled(false);
    ViewFile v = parse_view_file("frobnicate: 3\nangle factor: 4\n", "a.v");
    set_warnings_enabled(true);
    EXPECT_DOUBLE_EQ(v.angle_increment_deg, 90);
}

TEST(ViewFile, ContourCommandsKeepIdFileAndPlace)
{
    ViewFile v = parse_view_file("contour sides: 12\ncontour: 2 Stripe.con\n", "a.v");
    EXPECT_EQ(v.cylinders.sides, 12);
    ASSERT_EQ(v.cylinders.contours.size(), 1u);
    EXPECT_EQ(v.cylinders.contours[0].id, 2);
    EXPECT_EQ(v.cylinders.contours[0].file, "Stripe.con");  // case kept
    EXPECT_EQ(v.cylinders.contours[0].loc.line, 2);
    EXPECT_EQ(parse_view_file("polygonization level: 3\n", "a.v").cylinders.sides, 16);
}

TEST(ViewFile, TropismsAndTorquesInOrder)
{
    ViewFile v = parse_view_file("tropism: T: 0 4 0 I: 0.5 A: 30 E: 0.2 S: 0.05\n"
                                 "torque: T: 3,0,4 E: 1 A: 60\n"
                                 "tropism: T 0 -2 0 I: 9\n",
                                 "t.v");
    ASSERT_EQ(v.movements.size(), 3u);
    const Movement& a = v.movements[0];
    EXPECT_EQ(a.kind, Movement::Kind::tropism);
    EXPECT_NEAR(a.direction.y, 0.5, 1e-12);  // unit vector times the intensity
    EXPECT_DOUBLE_EQ(a.angle_deg, 30);
    EXPECT_DOUBLE_EQ(a.initial_elasticity, 0.2);
    EXPECT_DOUBLE_EQ(a.elasticity_step, 0.05);
    const Movement& b = v.movements[1];
    EXPECT_EQ(b.kind, Movement::Kind::torque);
    EXPECT_NEAR(b.direction.x, 0.6, 1e-12);
    EXPECT_NEAR(b.direction.z, 0.8, 1e-12);
    EXPECT_DOUBLE_EQ(b.angle_deg, 0);  // A: is ignored for torques
    // cpfg clamps I/|T| (not I) to [-1, 1]: T = (0,-2,0) with I = 9 keeps its length 2
    EXPECT_NEAR(v.movements[2].direction.y, -2, 1e-12);
}

TEST(ViewFile, TropismErrorsNameTheColumn)
{
    try {
        parse_view_file("tropism: E: 1\n", "t.v");
        FAIL() << "no error";
    } catch (const cambium::Error& e) {
        EXPECT_NE(std::string(e.what()).find("t.v:1:"), std::string::npos) << e.what();
    }
    try {
        parse_view_file("tropism: T: 0 0 0\n", "t.v");
        FAIL() << "no error";
    } catch (const cambium::Error& e) {
        EXPECT_NE(std::string(e.what()).find("t.v:1:10"), std::string::npos) << e.what();
    }
}

TEST(ViewFile, LegacyTropism)
{
    ViewFile v = parse_view_file("tropism direction: 0.0,2.0,0.0\ninitial elasticity: 0.02\n"
                                 "elasticity increment: -0.02\n",
                                 "t.v");
    EXPECT_NEAR(v.legacy_tropism_direction.y, 1, 1e-12);
    EXPECT_DOUBLE_EQ(v.legacy_elasticity, 0.02);
    EXPECT_DOUBLE_EQ(v.legacy_elasticity_increment, -0.02);
}

TEST(ViewFile, TexturesKeepTheFileNameCase)
{
    ViewFile v = parse_view_file("texture: F: Bark.RGB H: linear L: mll E: decal R: 2.5\n"
                                 "texture: F:leaf.tga\n",
                                 "t.v");
    ASSERT_EQ(v.textures.size(), 2u);
    EXPECT_EQ(v.textures[0].file, "Bark.RGB");
    EXPECT_TRUE(v.textures[0].linear_filter);
    EXPECT_TRUE(v.textures[0].mipmap);
    EXPECT_TRUE(v.textures[0].decal);
    EXPECT_DOUBLE_EQ(v.texture_aspect_ratios[0], 2.5);
    EXPECT_EQ(v.textures[1].file, "leaf.tga");
    EXPECT_FALSE(v.textures[1].linear_filter);  // cpfg's default: nearest
    EXPECT_FALSE(v.textures[1].decal);
    EXPECT_DOUBLE_EQ(v.texture_aspect_ratios[1], 1);
    EXPECT_THROW(parse_view_file("texture: H: l\n", "t.v"), cambium::Error);
}

TEST(ViewFile, TranslucencyRanges)
{
    ViewFile v = parse_view_file("translucency: 5 0.3\ntranslucency: 10 20 0.5\n", "t.v");
    ASSERT_EQ(v.translucency.size(), 2u);
    EXPECT_EQ(v.translucency[0].first, 5);
    EXPECT_EQ(v.translucency[0].last, 5);
    EXPECT_FLOAT_EQ(v.translucency[0].amount, 0.3f);
    EXPECT_EQ(v.translucency[1].first, 10);
    EXPECT_EQ(v.translucency[1].last, 20);
    EXPECT_EQ(v.translucency[1].loc.line, 2);
    try {
        parse_view_file("\ntranslucency: 1 2 1.5\n", "t.v");
        FAIL() << "no error";
    } catch (const cambium::Error& e) {
        EXPECT_NE(std::string(e.what()).find("t.v:2:19"), std::string::npos) << e.what();
    }
    EXPECT_THROW(parse_view_file("translucency: 256 0.5\n", "t.v"), cambium::Error);
    EXPECT_THROW(parse_view_file("translucency: 7 3 0.5\n", "t.v"), cambium::Error);
    EXPECT_THROW(parse_view_file("translucency: 0.5\n", "t.v"), cambium::Error);
    EXPECT_THROW(parse_view_file("translucency: 1.5 0.5\n", "t.v"), cambium::Error);
}

TEST(ViewFileRanges, CameraAndLightValuesBeyondTheLimitAreErrorsAtTheirColumn)
{
    const std::pair<const char*, const char*> cases[] = {
        {"viewpoint: 0 1e300 0\n", "t.v:1:14: error: value 1e+300 is out of range"},
        {"view reference point: 1e11 0 0\n", "t.v:1:23: error: value 1e+11 is out of range"},
        {"front distance: -1e30\n", "t.v:1:17: error: value -1e+30 is out of range"},
        {"back distance: 1e30\n", "t.v:1:16: error"},
        {"box: x: 0,1 y: 0,2e10 z: 0,1\n", "t.v:1:18: error: value 2e+10 is out of range"},
        {"light: O: 0 0 1e99\n", "t.v:1:15: error"},
        {"light: V: 1e99 0 0\n", "t.v:1:11: error"},
        {"light: P: 1e99 0 0 1 2\n", "t.v:1:11: error"},
        {"light direction: 0 0 -1e20\n", "t.v:1:22: error: value -1e+20 is out of range: camera and light values "
                                         "must be within +-1e10"},
        {"viewpoint: nan 0 0\n", "t.v:1:12: error: expected a number, found 'nan'"},
    };
    for (const auto& [text, message] : cases) {
        try {
            parse_view_file(text, "t.v");
            ADD_FAILURE() << "no error for " << text;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
        }
    }
    // at the limit still fine
    EXPECT_NO_THROW(parse_view_file("viewpoint: 1e10 -1e10 0\n", "t.v"));
}

TEST(LabelFont, XFontNamesAndWinfontGiveFamilySizeAndStyle)
{
    LabelFont d = parse_view_file("", "t.v").font;
    EXPECT_EQ(d.family, "courier");  // cpfg's default: -*-courier-bold-r-*-12-*
    EXPECT_EQ(d.pixel_size, 12);
    EXPECT_TRUE(d.bold);
    LabelFont x = parse_view_file("font: -adobe-helvetica-medium-o-normal-*-24-*-*-*-*-*-*-*\n", "t.v").font;
    EXPECT_EQ(x.family, "helvetica");
    EXPECT_EQ(x.pixel_size, 24);
    EXPECT_FALSE(x.bold);
    EXPECT_TRUE(x.italic);
    LabelFont points = parse_view_file("font: -*-times-bold-r-*-*-*-140-*-*-*-*-*-*\n", "t.v").font;
    EXPECT_EQ(points.pixel_size, 14);  // decipoints
    LabelFont w = parse_view_file("winfont: \"Times New Roman\" 18 Ib\n", "t.v").font;
    EXPECT_EQ(w.family, "Times New Roman");
    EXPECT_EQ(w.pixel_size, 18);
    EXPECT_TRUE(w.bold);
    EXPECT_TRUE(w.italic);
}

namespace {

/// The message of the error a one-line view file gives ("" when it reads).
std::string error_of(const std::string& line)
{
    try {
        parse_view_file(line + "\n", "t.v");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(ViewFile, RenderAndShadeModesAreTyped)
{
    auto mode = [](const char* text) { return parse_view_file(text, "t.v").render_mode; };
    EXPECT_EQ(mode("").shading, Shading::shaded);
    EXPECT_EQ(mode("render mode: fast\n").shading, Shading::filled);
    EXPECT_EQ(mode("render mode: flat\n").shading, Shading::flat);
    EXPECT_EQ(mode("render mode: shadows\n").shading, Shading::shaded);
    EXPECT_TRUE(mode("render mode: interpolated\n").interpolated);
    EXPECT_EQ(mode("shade mode: 7\n").shading, Shading::wireframe);
    EXPECT_TRUE(mode("render mode: wireframe\nshade mode: 2\n").interpolated);  // the last wins
    EXPECT_EQ(mode("shade mode: 2\nrender mode: wireframe\n").shading, Shading::wireframe);
}

TEST(ViewFile, DrawingCommandsWithBadValuesAreErrorsAtTheirColumn)
{
    EXPECT_NE(error_of("render mode: glossy").find("t.v:1:14: error: expected 'fast'"), std::string::npos);
    EXPECT_NE(error_of("shade mode: 9").find("t.v:1:13: error: shade mode must be"), std::string::npos);
    EXPECT_NE(error_of("interpretation past %: maybe").find("t.v:1:24: error: expected 'on' or 'off'"),
              std::string::npos);
    EXPECT_NE(error_of("twist of cylinders: yes").find("t.v:1:21:"), std::string::npos);
    EXPECT_NE(error_of("contour: 0 leaf.con").find("t.v:1:10: error: a contour id"), std::string::npos);
    EXPECT_NE(error_of("contour: 1").find("t.v:1:"), std::string::npos);
    EXPECT_NE(error_of("curve: c.crv 1").find("t.v:1:14: error: curve samples"), std::string::npos);
    EXPECT_NE(error_of("diffuse reflection: much").find("t.v:1:21: error: diffuse reflection: expected a number"),
              std::string::npos);
    EXPECT_NE(error_of("font:").find("t.v:1:"), std::string::npos);
    EXPECT_EQ(error_of("z buffer: on"), "");  // cpfg's window alone: no effect, no error
}

TEST(ViewFile, FileCommandsKeepTheirFilesInOrder)
{
    ViewFile v = parse_view_file("function: a.func 20\nfunction set: b.fset\ncurve: c.crv 3\n"
                                 "background scene: one.dat, two.dat;three.dat\n"
                                 "interpretation past %: off\ndiffuse reflection: 300\n",
                                 "t.v");
    ASSERT_EQ(v.functions.size(), 2u);
    EXPECT_EQ(v.functions[0].samples, 20);
    EXPECT_TRUE(v.functions[1].is_set);
    ASSERT_EQ(v.curves.size(), 1u);
    EXPECT_EQ(v.curves[0].samples, 3);
    ASSERT_EQ(v.background_scenes.size(), 1u);
    EXPECT_EQ(v.background_scenes[0].files,
              (std::vector<std::filesystem::path>{"one.dat", "two.dat", "three.dat"}));
    EXPECT_FALSE(v.interprets_past_cut);
    EXPECT_EQ(v.colour_index_shading.diffuse_reflection, 255);  // beyond the colour indices
    EXPECT_EQ(named_files(v).size(), 6u);  // two functions, a curve, three scenes
}
