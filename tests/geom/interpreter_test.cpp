// SPDX-License-Identifier: Apache-2.0
// Tests of string interpretation: segments, joints, branches, widths, colours, bounds.
#include <gtest/gtest.h>

#include <string>

#include "base/diagnostics.h"
#include "geom/interpreter.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

std::array<float, 4> key_of(const Scene& scene, std::size_t segment, int end)
{
    return scene.geometry.lines.keys[scene.geometry.lines.segments[segment] + static_cast<std::uint32_t>(end)];
}

}  // namespace

TEST(Interpreter, ConnectedSegmentsShareKeysAndNeighbourFlags)
{
    Scene scene = interpret_text("F+F(2)", "angle increment: 90\n");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 2u);
    EXPECT_EQ(scene.geometry.lines.keys.size(), 3u);
    EXPECT_EQ(scene.geometry.lines.flags[0], LinearCurves::neighbour_right);
    EXPECT_EQ(scene.geometry.lines.flags[1], LinearCurves::neighbour_left);
    auto end = key_of(scene, 1, 1);  // up 1, then left 2: (-2, 1, 0)
    EXPECT_NEAR(end[0], -2, 1e-6);
    EXPECT_NEAR(end[1], 1, 1e-6);
}

TEST(Interpreter, BranchReturnsToItsStartAndBreaksThePolyline)
{
    Scene scene = interpret_text("F[+F]F", "angle increment: 90\n");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 3u);
    // The branch continues the trunk's polyline; the segment after ']' starts anew.
    EXPECT_EQ(scene.geometry.lines.flags[1] & LinearCurves::neighbour_left, LinearCurves::neighbour_left);
    EXPECT_EQ(scene.geometry.lines.flags[2], 0);
    auto start = key_of(scene, 2, 0);
    auto end = key_of(scene, 2, 1);
    EXPECT_NEAR(start[1], 1, 1e-6);
    EXPECT_NEAR(end[1], 2, 1e-6);
    EXPECT_NEAR(end[0], 0, 1e-6);
}

TEST(Interpreter, MoveWithoutDrawingLeavesAGap)
{
    Scene scene = interpret_text("FfF", "");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 2u);
    EXPECT_NEAR(key_of(scene, 1, 0)[1], 2, 1e-6);
    EXPECT_EQ(scene.geometry.lines.flags[1], 0);
}

TEST(Interpreter, WidthIsTwiceTheRadiusAndFollowsHashAndBang)
{
    Scene scene = interpret_text("F#F!(0.5)F", "initial line width: 2\nline width increment: 1\n");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 3u);
    EXPECT_FLOAT_EQ(key_of(scene, 0, 0)[3], 1.0f);
    EXPECT_FLOAT_EQ(key_of(scene, 0, 1)[3], 1.5f);  // tapered: the top takes the new width
    EXPECT_FLOAT_EQ(key_of(scene, 1, 0)[3], 1.5f);
    EXPECT_FLOAT_EQ(key_of(scene, 2, 0)[3], 0.25f);
    EXPECT_FALSE(scene.line_radius_in_pixels);
    EXPECT_TRUE(interpret_text("F", "initial line width: 3 pixels\n").line_radius_in_pixels);
}

TEST(Interpreter, UntaperedLinesKeepTheirWidthAndBreakTheJoint)
{
    Scene scene = interpret_text("F#F", "initial line width: 2\nline width increment: 1\ntapered lines: off\n");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 2u);
    EXPECT_FLOAT_EQ(key_of(scene, 0, 1)[3], 1.0f);
    EXPECT_FLOAT_EQ(key_of(scene, 1, 0)[3], 1.5f);
    EXPECT_EQ(scene.geometry.lines.flags[1], 0);
}

TEST(Interpreter, WidthChangeInsideABranchDoesNotTaperTheTrunk)
{
    Scene scene = interpret_text("F[!(1)F]", "initial line width: 2\n");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 2u);
    EXPECT_FLOAT_EQ(key_of(scene, 0, 1)[3], 1.0f);
    EXPECT_FLOAT_EQ(key_of(scene, 1, 0)[3], 0.5f);
}

TEST(Interpreter, ColourWrapsOnceAroundTheTable)
{
    Scene scene = interpret_text(";(255);F,(0),F", "color increment: 1\n");
    EXPECT_EQ(scene.geometry.lines.material[0], 0);
    EXPECT_EQ(scene.geometry.lines.material[1], 255);
}

TEST(Interpreter, ColourIndexSelectsTheMaterialOfEachSegment)
{
    Scene scene = interpret_text("F;F;(7)F,F", "initial color: 2\ncolor increment: 3\n");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 4u);
    EXPECT_EQ(scene.geometry.lines.material[0], 2);
    EXPECT_EQ(scene.geometry.lines.material[1], 5);
    EXPECT_EQ(scene.geometry.lines.material[2], 7);
    EXPECT_EQ(scene.geometry.lines.material[3], 4);
}

TEST(Interpreter, BoundsEncloseTheDrawnPoints)
{
    Scene scene = interpret_text("-(90)F(3)+(90)F(2)", "");
    EXPECT_NEAR(scene.bounds.lo.x, 0, 1e-9);
    EXPECT_NEAR(scene.bounds.hi.x, 3, 1e-9);
    EXPECT_NEAR(scene.bounds.hi.y, 2, 1e-9);
}

TEST(Interpreter, BoundsHoldTheOriginAndMovesWithoutDrawing)
{
    Scene scene = interpret_text("f(5)F", "");
    EXPECT_NEAR(scene.bounds.lo.y, 0, 1e-9);
    EXPECT_NEAR(scene.bounds.hi.y, 6, 1e-9);
}

TEST(Interpreter, DefaultLightIsCpfgsDirectionalLight)
{
    Scene scene = interpret_text("F", "");
    ASSERT_EQ(scene.lights.size(), 1u);
    EXPECT_EQ(scene.lights[0].kind, Light::Kind::directional);
    EXPECT_NEAR(scene.lights[0].direction.x, 1, 1e-12);
    scene = interpret_text("F", "light direction: 0,3,4\n");
    EXPECT_NEAR(scene.lights[0].direction.y, 0.6, 1e-12);
    scene = interpret_text("F", "light: V: 1 0 0\nlight: O: 0 5 0\n");
    EXPECT_EQ(scene.lights.size(), 2u);
}

TEST(Interpreter, UnbalancedPopIsIgnored)
{
    set_warnings_enabled(false);
    Scene scene = interpret_text("F]F", "");
    set_warnings_enabled(true);
    EXPECT_EQ(scene.geometry.lines.segment_count(), 2u);
}

TEST(Interpreter, SceneGeometryPastTheMemoryBudgetIsAnError)
{
    // a segment takes at least 16 (key) + 4 (segment) + 1 + 2 + 2 bytes: the first check,
    // after 4096 modules, finds over 100 KiB, past a budget of 64 KiB
    lsys::SymbolTable symbols;
    std::string text;
    for (int i = 0; i < 20000; ++i)
        text += "F";
    lsys::ModuleString s = text_modules(symbols, text);
    InterpretOptions options;
    options.max_memory_bytes = 64 << 10;
    try {
        interpret(s, symbols, parse_view_file("", "t.v"), options);
        FAIL() << "no error";
    } catch (const Error& e) {
        std::string message = e.what();
        EXPECT_EQ(message.rfind("error: the scene's geometry needs ", 0), 0u) << message;
        EXPECT_NE(message.find(" after 4096 modules of the string, more than the memory budget "
                               "of 64.0 KiB (--max-memory)"),
                  std::string::npos)
            << message;
    }
    options.max_memory_bytes = 64 << 20;  // the same string within a larger budget
    EXPECT_EQ(interpret(s, symbols, parse_view_file("", "t.v"), options)
                  .geometry.lines.segment_count(),
              20000u);
}

TEST(Interpreter, BranchStackPastTheMemoryBudgetIsAnError)
{
    // 20 000 nested '[' draw nothing, but each holds a turtle of some hundred bytes: the
    // first check, after 4096 modules, finds the stack past a budget of 64 KiB
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, std::string(20000, '[') + "F");
    InterpretOptions options;
    options.max_memory_bytes = 64 << 10;
    try {
        interpret(s, symbols, parse_view_file("", "t.v"), options);
        FAIL() << "no error";
    } catch (const Error& e) {
        std::string message = e.what();
        EXPECT_EQ(message.rfind("error: the turtle's branch stack of 4096 nested '[' needs ", 0), 0u)
            << message;
        EXPECT_NE(message.find(" after 4096 modules of the string, beside the geometry more than "
                               "the memory budget of 64.0 KiB (--max-memory)"),
                  std::string::npos)
            << message;
    }
    options.max_memory_bytes = 64 << 20;  // the same string within a larger budget
    EXPECT_EQ(interpret(s, symbols, parse_view_file("", "t.v"), options)
                  .geometry.lines.segment_count(),
              1u);
}

TEST(Interpreter, LabelTextPastTheMemoryBudgetIsAnError)
{
    // 100 labels of 12 formats padded to 99 characters: about 120 KiB of text, found at
    // the label that crosses a budget of 64 KiB, long before the first geometry check
    lsys::SymbolTable symbols;
    std::string text;
    for (int i = 0; i < 100; ++i)
        text += "@L(0)";
    lsys::ModuleString s = text_modules(symbols, text);
    std::string wide;
    for (int i = 0; i < 12; ++i)
        wide += "%99d";
    std::vector<std::string> strings{wide};
    InterpretOptions options;
    options.strings = strings;
    options.max_memory_bytes = 64 << 10;
    try {
        interpret(s, symbols, parse_view_file("", "t.v"), options);
        FAIL() << "no error";
    } catch (const Error& e) {
        std::string message = e.what();
        EXPECT_EQ(message.rfind("error: the @L labels need ", 0), 0u) << message;
        EXPECT_NE(message.find(" for 52 labels at module 51 of the string, more than the memory "
                               "budget of 64.0 KiB (--max-memory)"),
                  std::string::npos)
            << message;
    }
    options.max_memory_bytes = 64 << 20;  // the same labels within a larger budget
    Scene scene = interpret(s, symbols, parse_view_file("", "t.v"), options);
    ASSERT_EQ(scene.labels.size(), 100u);
    EXPECT_EQ(scene.labels[0].text.size(), 12u * 99u);
}

// Manual 5.2.3: `interpretation past %: on` (default) lets the turtle interpret past a %;
// off: the symbols after it (up to the end of its branch) are not interpreted.
TEST(Interpreter, InterpretationPastCutOnDrawsTheCutBranch)
{
    Scene scene = interpret_text("F[F%FF[F]F]F", "");
    EXPECT_EQ(scene.geometry.lines.segment_count(), 7u);
}

TEST(Interpreter, InterpretationPastCutOffSkipsToTheBranchEnd)
{
    // F [F %...] F: the skipped branch's ']' still restores the turtle, so the last F
    // starts at y = 1
    Scene scene = interpret_text("F[F%FF[F]F]F", "interpretation past %: off\n");
    ASSERT_EQ(scene.geometry.lines.segment_count(), 3u);
    EXPECT_NEAR(key_of(scene, 2, 0)[1], 1, 1e-6);
    EXPECT_NEAR(key_of(scene, 2, 1)[1], 2, 1e-6);
    // @mc(1) is a cut, @mc(0) is not; a cut outside any branch ends the string
    EXPECT_EQ(interpret_text("F[@mc(0)F]F@mc(1)FF", "interpretation past %: off\n")
                  .geometry.lines.segment_count(),
              3u);
    EXPECT_EQ(interpret_text("F%(2)F", "interpretation past %: off\n").geometry.lines.segment_count(), 2u);
}

namespace cambium::geom {
namespace {

TEST(Interpreter, BoundsOnlyWalkStoresNoGeometryAndFindsTheSameBounds)
{
    // Segments with a width change, a sphere, both discs and a polygon.
    const std::string text = "F(2)!(3)F[+(30)F@O(1.5)]@o(2)-(60)f(3)@c(1){.f.+(90)f.+(90)f.}F";
    const std::string view = "initial line width: 1\n";
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, text);
    ViewFile parsed = parse_view_file(view, "t.v");
    Scene full = interpret(s, symbols, parsed, InterpretOptions{});
    InterpretOptions walk;
    walk.bounds_only = true;
    Scene bounds = interpret(s, symbols, parsed, walk);
    EXPECT_GT(full.geometry.lines.segment_count(), 0u);
    EXPECT_GT(full.geometry.mesh.size(), 0u);
    EXPECT_EQ(bounds.geometry.lines.segment_count(), 0u);
    EXPECT_EQ(bounds.geometry.spheres.size(), 0u);
    EXPECT_EQ(bounds.geometry.discs.size(), 0u);
    EXPECT_EQ(bounds.geometry.mesh.size(), 0u);
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_EQ(bounds.bounds.lo[axis], full.bounds.lo[axis]) << axis;
        EXPECT_EQ(bounds.bounds.hi[axis], full.bounds.hi[axis]) << axis;
    }
}

}  // namespace
}  // namespace cambium::geom
