// SPDX-License-Identifier: Apache-2.0
// Tests of the view file's `curve:` files (curveX/curveY/curveZ/curveGAL): the curve
// editor's "version: 1.4" format, its spline types, cpfg's arc-length reading, the
// corpus curve against values computed by hand from its control points, and the corpus
// model that walks it against cpfg's derived string.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iterator>
#include <memory>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "geom/curve.h"
#include "geom/function.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"
#include "lsys/module_string.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

/// A curve file of the editor's format with the given type and "x y z m" lines.
std::string curve_text(const std::string& type, const std::string& points, int count)
{
    return "version: 1.4\ncontact: 0 0 0\nend: 0 0 0\nheading: 0 1 0\nup: 0 0 -1\nsize: 1\n"
           "points: " + std::to_string(count) + "\nrange: 0.0 1.0\ndimension: 4\ntype: " + type + "\n" +
           points;
}

using Kind = SpaceCurve::Kind;

SpaceCurve make(Kind kind, std::vector<Vec3> points, int samples = 100)
{
    std::vector<SpaceCurve::ControlPoint> cps;
    for (const Vec3& p : points)
        cps.push_back({p, 1});
    return SpaceCurve(cps, kind, samples);
}

}  // namespace

TEST(Curve, UniformBsplineStartsAndEndsAtTheSixthWeights)
{
    // One segment: from (P0 + 4 P1 + P2) / 6 to (P1 + 4 P2 + P3) / 6.
    Vec3 p0{0, 0, 0}, p1{1, 2, 0}, p2{3, 2, 1}, p3{4, 0, 2};
    SpaceCurve c = make(Kind::bspline, {p0, p1, p2, p3});
    expect_near(c.at_parameter(0), (p0 + p1 * 4 + p2) * (1.0 / 6), 1e-12);
    // cpfg's parameter stops 1e-6 short of the end.
    expect_near(c.at_parameter(1), (p1 + p2 * 4 + p3) * (1.0 / 6), 1e-5);
    // The middle of the segment: basis (1, 23, 23, 1) / 48.
    expect_near(c.at_parameter(0.5), (p0 + p1 * 23 + p2 * 23 + p3) * (1.0 / 48), 1e-5);
}

TEST(Curve, EvenlySpacedCollinearPointsGiveArcLengthEqualToParameter)
{
    // Five points on the x axis, 1 apart: the uniform spline is the straight line from
    // x = 1 to x = 3 at constant speed, so a length fraction t is at x = 1 + 2 t.
    SpaceCurve c = make(Kind::bspline, {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}});
    EXPECT_NEAR(c.length(), 2, 1e-5);
    for (double t : {0.0, 0.1, 0.25, 0.5, 0.9, 1.0})
        EXPECT_NEAR(c.at_length_fraction(t).x, 1 + 2 * t, 1e-5) << t;
    EXPECT_NEAR(c.at_length_fraction(-3).x, 1, 1e-12);  // clamped
    EXPECT_NEAR(c.at_length_fraction(7).x, 3, 1e-5);
}

TEST(Curve, TripledEndPointsReachTheEndsAndArcLengthIsUniform)
{
    // (0,0) and (3,0) each three times: the spline runs from 0 to 3 with varying speed;
    // read by length, t = 0.5 is half way.
    SpaceCurve::ControlPoint a{{0, 0, 0}, 3}, b{{3, 0, 0}, 3};
    SpaceCurve c({a, b}, Kind::bspline);
    EXPECT_EQ(c.expanded_points().size(), 6u);
    EXPECT_NEAR(c.length(), 3, 1e-5);
    EXPECT_NEAR(c.at_length_fraction(0).x, 0, 1e-12);
    EXPECT_NEAR(c.at_length_fraction(0.5).x, 1.5, 1e-3);
    EXPECT_NEAR(c.at_length_fraction(0.2).x, 0.6, 1e-3);
    EXPECT_NEAR(c.at_length_fraction(1).x, 3, 1e-5);
}

TEST(Curve, EndpointAndBezierTypesOfFourPointsAreTheBezierCurve)
{
    Vec3 p0{0, 0, 0}, p1{0, 3, 0}, p2{3, 3, 0}, p3{3, 0, 1};
    Vec3 middle = (p0 + p1 * 3 + p2 * 3 + p3) * (1.0 / 8);
    SpaceCurve endpoint = make(Kind::bspline_endpoint, {p0, p1, p2, p3});
    SpaceCurve bezier = make(Kind::bezier, {p0, p1, p2, p3});
    for (const SpaceCurve* c : {&endpoint, &bezier}) {
        expect_near(c->at_parameter(0), p0, 1e-12);
        expect_near(c->at_parameter(0.5), middle, 1e-5);
        expect_near(c->at_parameter(1), p3, 1e-5);
    }
}

TEST(Curve, BezierSegmentsShareTheirEndPoints)
{
    // Seven points: two cubic segments, the second starting at P3.
    std::vector<Vec3> p = {{0, 0, 0}, {1, 1, 0}, {2, 1, 0}, {3, 0, 0}, {4, -1, 0}, {5, -1, 0}, {6, 0, 0}};
    SpaceCurve c = make(Kind::bezier, p);
    expect_near(c.at_parameter(0.5), p[3], 1e-5);
    // A quarter of the way: the first segment's middle.
    expect_near(c.at_parameter(0.25), (p[0] + p[1] * 3 + p[2] * 3 + p[3]) * (1.0 / 8), 1e-5);
}

TEST(Curve, PhantomPointsMakeTheSplineReachItsEnds)
{
    // 2 P0 - P1 before P0: (2 P0 - P1 + 4 P0 + P1) / 6 = P0.
    Vec3 p0{1, 1, 0}, p1{2, 3, 0}, p2{4, 3, 0}, p3{5, 1, 0};
    SpaceCurve c = make(Kind::bspline_phantom, {p0, p1, p2, p3});
    EXPECT_EQ(c.expanded_points().size(), 6u);
    expect_near(c.at_parameter(0), p0, 1e-12);
    expect_near(c.at_parameter(1), p3, 1e-5);
}

TEST(Curve, ClosedBsplineReturnsToItsStart)
{
    // A square's corners: closed, the curve starts and ends at (P0 + 4 P1 + P2) / 6.
    Vec3 p0{1, 1, 0}, p1{-1, 1, 0}, p2{-1, -1, 0}, p3{1, -1, 0};
    SpaceCurve c = make(Kind::bspline_closed, {p0, p1, p2, p3}, 1000);
    EXPECT_EQ(c.expanded_points().size(), 7u);
    Vec3 start = (p0 + p1 * 4 + p2) * (1.0 / 6);
    expect_near(c.at_parameter(0), start, 1e-12);
    expect_near(c.at_parameter(1), start, 1e-5);
    expect_near(c.at_length_fraction(1), start, 1e-5);
    // By symmetry the quarter of the length is the next corner's point.
    expect_near(c.at_length_fraction(0.25), (p1 + p2 * 4 + p3) * (1.0 / 6), 1e-3);
}

TEST(Curve, TooFewPointsGiveZero)
{
    SpaceCurve c = make(Kind::bspline, {{1, 1, 1}, {2, 2, 2}, {3, 3, 3}});
    EXPECT_EQ(c.length(), 0);
    expect_near(c.at_length_fraction(0.5), {0, 0, 0}, 0);
    SpaceCurve empty;
    EXPECT_EQ(empty.length(), 0);
    expect_near(empty.at_length_fraction(0.3), {0, 0, 0}, 0);
}

TEST(CurveFile, ReadsTheEditorFormatWithMultiplicities)
{
    SpaceCurve c = parse_curve_text(curve_text("bspline", "0 0 0 3\n1 0 0 1\n2 0 0 1\n3 0 0 3\n", 4), "c.con");
    EXPECT_EQ(c.kind(), Kind::bspline);
    ASSERT_EQ(c.expanded_points().size(), 8u);
    EXPECT_EQ(c.expanded_points()[2].x, 0);
    EXPECT_EQ(c.expanded_points()[3].x, 1);
    EXPECT_NEAR(c.length(), 3, 1e-5);
    EXPECT_NEAR(c.at_length_fraction(1).x, 3, 1e-5);
}

TEST(CurveFile, TypesAndDimensions)
{
    EXPECT_EQ(parse_curve_text(curve_text("bezier", "0 0 0 1\n1 0 0 1\n2 0 0 1\n3 0 0 1\n", 4), "c").kind(),
              Kind::bezier);
    EXPECT_EQ(parse_curve_text(curve_text("bspline-endpoint", "0 0 0 1\n1 0 0 1\n2 0 0 1\n3 0 0 1\n", 4), "c").kind(),
              Kind::bspline_endpoint);
    EXPECT_EQ(parse_curve_text(curve_text("whatever", "0 0 0 1\n1 0 0 1\n2 0 0 1\n3 0 0 1\n", 4), "c").kind(),
              Kind::bspline);  // cpfg: unknown types are plain B-splines
    // Dimension 3: no multiplicity column; dimension 2: z = 0.
    SpaceCurve d3 = parse_curve_text("points: 4\ndimension: 3\n0 0 1\n1 0 1\n2 0 1\n3 0 1\n", "c");
    EXPECT_EQ(d3.expanded_points().size(), 4u);
    EXPECT_NEAR(d3.at_parameter(0).z, 1, 1e-12);
    SpaceCurve d2 = parse_curve_text("points: 4\n0 5\n1 5\n2 5\n3 5\n", "c");
    EXPECT_NEAR(d2.at_parameter(0.5).y, 5, 1e-12);
    EXPECT_EQ(d2.at_parameter(0.5).z, 0);
}

TEST(CurveFile, NestedCurvesAreReadAndNotUsed)
{
    // The second point carries a nested curve of two points; the third top-level point
    // follows it.
    std::string text = "points: 4\ndimension: 4\n0 0 0 1\n1 0 0 1\npoints: 2\ndimension: 3\n9 9 9\n8 8 8\n"
                       "2 0 0 1\n3 0 0 1\n";
    SpaceCurve c = parse_curve_text(text, "c");
    ASSERT_EQ(c.expanded_points().size(), 4u);
    EXPECT_EQ(c.expanded_points()[2].x, 2);
    EXPECT_EQ(c.expanded_points()[3].x, 3);
}

TEST(CurveFile, MalformedFilesAreErrorsWithTheirLine)
{
    try {
        parse_curve_text(curve_text("bspline", "0 0 0 1\n1 0 0\n", 2), "bad.con");
        FAIL() << "expected an Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bad.con:12"), std::string::npos) << e.what();
    }
    EXPECT_THROW(parse_curve_text("points: 1\n0 0\n1 1\n", "c"), Error);        // too many points
    EXPECT_THROW(parse_curve_text("version: 1.4\n", "c"), Error);                // no points
    EXPECT_THROW(parse_curve_text("points: 2\ndimension: 7\n", "c"), Error);     // bad dimension
    EXPECT_THROW(parse_curve_text("points: 2\n0 0 0 -1\n", "c"), Error);         // dimension 2 here
    EXPECT_THROW(parse_curve_text("points: 2\ndimension: 4\n0 0 0 -1\n", "c"), Error);  // multiplicity
    EXPECT_THROW(parse_curve_text("points: 2\n0 x\n", "c"), Error);
    // Fewer points than declared: a warning, the rest at the origin (cpfg).
    SpaceCurve c = parse_curve_text("points: 5\n1 1\n2 2\n3 3\n4 4\n", "c");
    EXPECT_EQ(c.expanded_points().size(), 5u);
    EXPECT_EQ(c.expanded_points()[4].x, 0);
}

TEST(CurveFile, ContourFilesAreReadAsSplines)
{
    // A Cambium extension: a `cver` contour is its B-spline (closed ones closed).
    SpaceCurve c = parse_curve_text("cver 1 1\nname: sq\npoints: 4 4\ntype: closed\n"
                                    "1 1 0 1\n-1 1 0 1\n-1 -1 0 1\n1 -1 0 1\n", "sq.con");
    EXPECT_EQ(c.kind(), Kind::bspline_closed);
    expect_near(c.at_parameter(0), {-2.0 / 3, 2.0 / 3, 0}, 1e-12);
    SpaceCurve plain = parse_curve_text("4 2 open\n0 0\n1 0\n2 0\n3 0\n", "l.con");
    EXPECT_NEAR(plain.length(), 1, 1e-5);
}

TEST(CurveSet, ViewCommandsGiveIdsFromOneAndSamples)
{
    std::filesystem::path dir = temp_dir("curve_test");
    std::ofstream(dir / "line.crv") << curve_text("bspline", "0 0 0 1\n1 0 0 1\n2 0 0 1\n3 0 0 1\n4 0 0 1\n", 5);
    std::ofstream(dir / "up.crv") << curve_text("bspline", "0 0 0 1\n0 1 0 1\n0 2 0 1\n0 3 0 1\n", 4);
    ViewFile view = parse_view_file("curve: line.crv\n"
                                    "curve: missing.crv\n"  // a warning; id 2 stays taken
                                    "curve: up.crv 3\n",
                                    "v.v");
    CurveSet set = CurveSet::from_view_commands(view.curves, dir);
    ASSERT_EQ(set.size(), 3u);
    EXPECT_NEAR(set.evaluate('x', 1, 0.5), 2, 1e-5);
    EXPECT_NEAR(set.evaluate('l', 1, 0), 2, 1e-5);
    EXPECT_EQ(set.evaluate('x', 2, 0.5), 0);
    EXPECT_EQ(set.evaluate('l', 2, 0), 0);
    EXPECT_NEAR(set.evaluate('y', 3, 0.5), 1.5, 1e-5);
    EXPECT_EQ(set.evaluate('z', 3, 0.5), 0);
    EXPECT_EQ(set.evaluate('x', 4, 0.5), 0);  // no such curve: a warning and 0
    EXPECT_EQ(set.evaluate('x', 0, 0.5), 0);
}

TEST(CurveSet, SamplesSetTheLengthTable)
{
    // A quarter circle-like arc: the tabulated length grows with the samples (a finer
    // polyline is longer), as cpfg's curveGAL does.
    std::filesystem::path dir = temp_dir("curve_test");
    std::ofstream(dir / "arc.crv") << curve_text("bspline", "0 0 0 3\n0 1 0 1\n1 1 0 3\n", 3);
    CurveSet coarse = CurveSet::from_view_commands(parse_view_file("curve: arc.crv 3\n", "v.v").curves, dir);
    CurveSet fine = CurveSet::from_view_commands(parse_view_file("curve: arc.crv 1000\n", "v.v").curves, dir);
    // Three samples: the chords from (0,0) to the middle point and on to (1,1).
    const SpaceCurve& c = fine.curve(1);
    Vec3 middle = c.at_parameter(0.5);
    double chords = std::hypot(middle.x, middle.y) + std::hypot(1 - middle.x, 1 - middle.y);
    EXPECT_NEAR(coarse.evaluate('l', 1, 0), chords, 1e-5);
    EXPECT_GT(fine.evaluate('l', 1, 0), coarse.evaluate('l', 1, 0));
}

TEST(CurveCorpus, RidleyProfileEndsAtItsTripledEndPoints)
{
    std::filesystem::path file = corpus() / "cpfg/10-manuals/11-CPFG/Ridley/profile.con";
    if (!std::filesystem::exists(file))
        GTEST_SKIP() << "corpus not found";
    SpaceCurve c = read_curve_file(file);
    EXPECT_EQ(c.kind(), Kind::bspline);
    EXPECT_EQ(c.expanded_points().size(), 8u);  // multiplicities 3 1 1 3
    // Tripled end points: the curve starts and ends at them (values from the file).
    expect_near(c.at_length_fraction(0), {0.269398, -0.447751, 0}, 1e-9);
    expect_near(c.at_length_fraction(1), {-0.001478, 0.202475, 0}, 1e-5);
    // The length lies between the end points' distance and the control polygon's.
    double chord = std::hypot(0.269398 + 0.001478, -0.447751 - 0.202475);
    double polygon = std::hypot(0.274471 - 0.269398, -0.109864 + 0.447751) +
                     std::hypot(0.165305 - 0.274471, 0.175183 + 0.109864) +
                     std::hypot(-0.001478 - 0.165305, 0.202475 - 0.175183);
    EXPECT_GT(c.length(), chord);
    EXPECT_LT(c.length(), polygon);
}

TEST(CurveCorpus, RidleyStringMatchesCpfg)
{
    // Ridley walks its curve by curveX/curveY(1, s/L) in steps of 0.001 of L = curveGAL(1)
    // and prints the points: cpfg's string holds every value to 6 digits.
    std::filesystem::path model = corpus() / "cpfg/10-manuals/11-CPFG/Ridley";
    std::filesystem::path oracle = corpus() / "oracle/10-manuals/11-CPFG/Ridley/string.str";
    if (!std::filesystem::exists(model / "spiral.v") || !std::filesystem::exists(oracle))
        GTEST_SKIP() << "corpus not found";
    ViewFile view = read_view_file(model / "spiral.v");
    auto functions = std::make_shared<const FunctionSet>(FunctionSet::from_view_file(view));
    auto curves = std::make_shared<const CurveSet>(CurveSet::from_view_file(view));
    lsys::LoadOptions load;
    load.function = [functions](int id, double x) { return functions->evaluate(id, x); };
    load.curve = [curves](char which, int id, double t) { return curves->evaluate(which, id, t); };
    lsys::LSystem lsystem = lsys::LSystem::load(model / "spiral.l", load);
    std::string ours = lsys::to_text(lsystem.derive(), lsystem.symbols());
    std::ifstream in(oracle);
    std::string reference((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::erase(reference, '\n');
    std::erase(reference, '\r');
    ASSERT_EQ(ours.size(), reference.size());
    EXPECT_TRUE(ours == reference);
}
