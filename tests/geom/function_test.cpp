// SPDX-License-Identifier: Apache-2.0
// Tests of cpfg's function files and function sets: hand values of simple splines and
// values read off a corpus function.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "geom/function.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

// With 4 points the clamped B-spline is a Bézier curve.
const char* line_2x_plus_1 = "range: 0.0 1.0\npoints: 4\n0 1\n0.333333 1.666667\n0.666667 2.333333\n1 3\n";

}  // namespace

TEST(Function, LinearFunctionWithinCpfgTolerance)
{
    SplineFunction f = parse_function_text(line_2x_plus_1, "lin.func", 0, "lin");
    EXPECT_EQ(f.name(), "lin");
    EXPECT_EQ(f.samples(), 0);
    // Bisection stops when x is within 0.001, so y is within 2 * 0.001 (+ rounding).
    for (double x : {0.0, 0.1, 0.25, 0.5, 0.77, 1.0})
        EXPECT_NEAR(f.evaluate(x), 2 * x + 1, 2.1e-3) << x;
    EXPECT_DOUBLE_EQ(f.evaluate(-3), f.evaluate(0));  // clamped
    EXPECT_DOUBLE_EQ(f.evaluate(7), f.evaluate(1));
}

TEST(Function, FirstBisectionStepHitsMidParameter)
{
    // Bézier at t = 1/2: x = (0 + 3·0.2181 + 3·0.328571 + 1) / 8 = 0.3300016,
    // y = (1.100946 + 3·0.872272 + 3·0.817075 + 0.485892) / 8 = 0.8318599;
    // x is within 0.001 of 0.33 at once, so cpfg returns that y.
    SplineFunction f = parse_function_text(
        "range: 0.000000 1.000000\npoints: 4\n0.000000 1.100946\n0.218100 0.872272\n"
        "0.328571 0.817075\n1.000000 0.485892\n",
        "brangle.func", 0, "brangle");
    EXPECT_NEAR(f.evaluate(0.33), 0.8318599, 1e-6);
    SplineFunction::Point p = f.curve_point(0.5);
    EXPECT_NEAR(p.x, 0.3300016, 1e-6);
}

TEST(Function, PrecomputedSamplesInterpolateLinearly)
{
    // x(t) = t, y(t) = t³; with 3 samples: y(0) = 0, y(0.5) ≈ 0.125, y(1) ≈ 1.
    const char* cube = "range: 0 1\npoints: 4\n0 0\n0.333333333 0\n0.666666667 0\n1 1\n";
    SplineFunction exact = parse_function_text(cube, "c.func", 0, "c");
    SplineFunction sampled = parse_function_text(cube, "c.func", 3, "c");
    EXPECT_NEAR(exact.evaluate(0.25), 0.015625, 1e-3);
    EXPECT_NEAR(sampled.evaluate(0.25), 0.5 * exact.evaluate(0) + 0.5 * exact.evaluate(0.5), 1e-12);
    EXPECT_NEAR(sampled.evaluate(0.25), 0.0625, 1e-6);
    EXPECT_NEAR(sampled.evaluate(0.75), 0.5 * exact.evaluate(0.5) + 0.5 * exact.evaluate(1), 1e-12);
    EXPECT_DOUBLE_EQ(sampled.evaluate(1), exact.evaluate(1));
}

TEST(Function, Version101UsesFileSamplesAndMultiplicity)
{
    const char* text =
        "fver 1 1\nname: bump\nsamples: 5\nflip: off\npoints: 3\n0 0 2\n0.5 1 1\n1 0 2\n";
    SplineFunction f = parse_function_text(text, "b.func", 100, "ignored");
    EXPECT_EQ(f.name(), "bump");
    EXPECT_EQ(f.samples(), 5);  // the view file's 100 is ignored for version 1.01
    ASSERT_EQ(f.points().size(), 5u);
    // 0,0,0.5,1,1 in x: the clamped spline starts at the first and ends near the last point.
    EXPECT_DOUBLE_EQ(f.curve_point(0).x, 0);
    EXPECT_NEAR(f.curve_point(0.999999).x, 1, 1e-5);
    EXPECT_NEAR(f.evaluate(0.5), f.curve_point(0.5).y, 1e-12);  // symmetric: t = 1/2 is x = 1/2
}

TEST(Function, MarkersAndBackgroundLinesAreSkipped)
{
    const char* text = "fver 1 1\nname: m\nsamples: 0\nbackground: img.png\n0.5\nmarkers: 2\n"
                       "m1 0.1 0.2\nm2 0.3 0.4\nflip: on\npoints: 4\n0 0\n0.3 0.3\n0.6 0.6\n1 1\n";
    SplineFunction f = parse_function_text(text, "m.func", 0, "m");
    EXPECT_NEAR(f.evaluate(0.4), 0.4, 2e-3);
}

TEST(Function, ErrorsNameTheLine)
{
    try {
        parse_function_text("range: 0 1\npoints: 3\n0 0\n0.5 0.5\n1 1\n", "few.func", 0, "few");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().line, 1);
    }
    try {
        parse_function_text("fver 1 1\nname: x\nsamples: 2\nflip: off\npoints: 4\n0 0\n0.5 oops\n", "b.func", 0, "x");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().line, 7);
        EXPECT_EQ(e.loc().column, 5);
    }
    EXPECT_THROW(parse_function_text("fver 2 0\n", "v.func", 0, "v"), Error);
    EXPECT_THROW(parse_function_text("hello\n", "h.func", 0, "h"), Error);
}

TEST(Function, TruncatedFilesThrowErrorsOnly)
{
    std::string text = "fver 1 1\nname: bump\nsamples: 5\nflip: off\npoints: 4\n0 0 1\n0.5 1 1\n0.7 1\n1 0 1\n";
    for (std::size_t n = 0; n < text.size(); ++n) {
        try {
            parse_function_text(text.substr(0, n), "t.func", 0, "t");
        } catch (const Error&) {
        }
    }
    std::string set = "funcgalleryver 1 1\nitems: 2\n" + text + text;
    for (std::size_t n = 0; n < set.size(); n += 2) {
        try {
            parse_function_set_text(set.substr(0, n), "t.fset");
        } catch (const Error&) {
        }
    }
}

TEST(FunctionSet, ViewCommandsOrderIdsAndDefines)
{
    std::filesystem::path dir = std::filesystem::temp_directory_path() / "cambium_function_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "lin.func") << line_2x_plus_1;
    std::ofstream(dir / "set.fset")
        << "funcgalleryver 1 1\nitems: 2\n"
           "fver 1 1\nname: Width\nsamples: 0\nflip: off\npoints: 4\n0 5\n0.3 5\n0.6 5\n1 5\n"
           "fver 1 1\nname: turn\nsamples: 10\nflip: off\npoints: 4\n0 7\n0.3 7\n0.6 7\n1 7\n";
    auto commands = [](const std::string& text) { return parse_view_file(text, "v.v").functions; };
    FunctionSet fs = FunctionSet::from_view_commands(commands("function: lin.func 20\n"), dir);
    ASSERT_EQ(fs.size(), 1u);
    EXPECT_EQ(fs.function(1).samples(), 20);
    EXPECT_NEAR(fs.evaluate(1, 0.5), 2, 3e-3);
    EXPECT_TRUE(fs.define_names().empty());
    set_warnings_enabled(false);
    EXPECT_EQ(fs.evaluate(2, 0.5), 0);  // no such function
    set_warnings_enabled(true);

    FunctionSet set =
        FunctionSet::from_view_commands(commands("function: lin.func\nfunction set: set.fset\n"), dir);
    ASSERT_EQ(set.size(), 2u);  // the set replaces what came before
    EXPECT_NEAR(set.evaluate(1, 0.3), 5, 1e-9);
    EXPECT_NEAR(set.evaluate(2, 0.9), 7, 1e-9);
    EXPECT_EQ(set.define_names(), (std::vector<std::string>{"WIDTH=1", "TURN=2"}));
    EXPECT_THROW(FunctionSet::from_view_commands(commands("function: missing.func\n"), dir), Error);
    std::filesystem::remove_all(dir);
}

TEST(FunctionConformance, CorpusFunctionSetReads)
{
    std::filesystem::path file = corpus() / "cpfg/10-manuals/15-VlabTools/LilyLeaf/functions.fset";
    if (!std::filesystem::exists(file))
        GTEST_SKIP() << "corpus not found";
    std::vector<SplineFunction> fs = read_function_set_file(file);
    ASSERT_EQ(fs.size(), 5u);
    EXPECT_EQ(fs[0].name(), "WIDTH");
    EXPECT_EQ(fs[0].samples(), 100);
    // WIDTH starts at its first point and ends at its last (0.071815 .. 0.009332).
    EXPECT_NEAR(fs[0].evaluate(0), 0.071815, 1e-3);
    EXPECT_NEAR(fs[0].evaluate(1), 0.009332, 1e-2);  // steep end: x within 0.001
}

TEST(FunctionConformance, EveryCorpusFunctionFileReads)
{
    std::filesystem::path root = corpus() / "cpfg";
    if (!std::filesystem::exists(root))
        GTEST_SKIP() << "corpus not found";
    int files = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
        std::string ext = entry.path().extension().string();
        if (ext == ".func") {
            EXPECT_NO_THROW(read_function_file(entry.path(), 0)) << entry.path();
            ++files;
        } else if (ext == ".fset") {
            EXPECT_NO_THROW(read_function_set_file(entry.path())) << entry.path();
            ++files;
        }
    }
    EXPECT_GE(files, 100);
}
