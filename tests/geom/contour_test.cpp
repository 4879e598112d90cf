// SPDX-License-Identifier: Apache-2.0
// Tests of contour files (every version), galleries and arc-length resampling.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "geom/contour.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

// A square with corners (+-1, +-1), counter-clockwise, each corner tripled so that the
// B-spline runs along the edges (written in every format).
const char* square_plain =
    "12 2 closed\n"
    "1 1\n1 1\n1 1\n-1 1\n-1 1\n-1 1\n-1 -1\n-1 -1\n-1 -1\n1 -1\n1 -1\n1 -1\n";
const char* square_101 =
    "cver 1 1\nname: square\npoints: 4 12\ntype: closed\n"
    "1 1 0 3\n-1 1 0 3\n-1 -1 0 3\n1 -1 0 3\n";
const char* square_102 =
    "cver 1 2\nname: square\npoints: 4 12\ntype: cr\n"
    "1 1 0 3\n-1 1 0 3\n-1 -1 0 3\n1 -1 0 3\n";
const char* square_103 =
    "cver 1 3\nname: square\npoints: 4 12\ntype: cr\nsamples: 8\n"
    "markers: 1\n0 0\n"
    "1 1 0 3\n-1 1 0 3\n-1 -1 0 3\n1 -1 0 3\n";

}  // namespace

TEST(Contour, SquareResampledTo8LiesOnItAtEqualArcLength)
{
    Contour c = parse_contour(square_101, "square.con");
    ContourSamples s = resample(c, 8);
    ASSERT_EQ(s.vertices.size(), 8u);
    EXPECT_TRUE(s.closed);
    EXPECT_NEAR(s.length, 8.0, 1e-9);
    // The first vertex (corner (1,1)) is turned onto +x: the square becomes the diamond
    // |x| + |y| = sqrt 2, and 8 samples at arc length 1 are its corners and edge midpoints.
    const double r = std::sqrt(2.0), h = r / 2;
    const double expected[8][2] = {{r, 0}, {h, h}, {0, r}, {-h, h}, {-r, 0}, {-h, -h}, {0, -r}, {h, -h}};
    for (int i = 0; i < 8; ++i) {
        EXPECT_NEAR(s.vertices[i].x, expected[i][0], 2e-3) << i;
        EXPECT_NEAR(s.vertices[i].y, expected[i][1], 2e-3) << i;
        EXPECT_NEAR(std::abs(s.vertices[i].x) + std::abs(s.vertices[i].y), r, 1e-6) << i;
    }
    // Normals of a counter-clockwise contour point outward.
    for (int i = 0; i < 8; ++i)
        EXPECT_GT(s.normals[i].x * s.vertices[i].x + s.normals[i].y * s.vertices[i].y, 0) << i;
}

TEST(Contour, EveryVersionParsesToTheSameShape)
{
    Contour reference = parse_contour(square_plain, "plain.con");
    EXPECT_EQ(reference.version, 0);
    ASSERT_EQ(reference.points.size(), 12u);
    for (const char* text : {square_101, square_102, square_103}) {
        Contour c = parse_contour(text, "v.con");
        EXPECT_TRUE(c.closed);
        EXPECT_EQ(c.name, "square");
        ASSERT_EQ(c.points.size(), reference.points.size());
        for (std::size_t i = 0; i < c.points.size(); ++i) {
            EXPECT_EQ(c.points[i].x, reference.points[i].x);
            EXPECT_EQ(c.points[i].y, reference.points[i].y);
            EXPECT_EQ(c.points[i].z, 0.0);
        }
    }
    EXPECT_EQ(parse_contour(square_103, "v.con").samples, 8);
}

TEST(Contour, OpenContourKeepsItsOrientationAndHasBothEnds)
{
    // A segment from (-1, 0) to (1, 0), end points tripled (manual's open contour style).
    Contour c = parse_contour("6 2 open\n-1 0\n-1 0\n-1 0\n1 0\n1 0\n1 0\n", "open.con");
    EXPECT_FALSE(c.closed);
    ContourSamples s = resample(c, 4);
    ASSERT_EQ(s.vertices.size(), 5u);
    // cpfg's length table stops a tenth of a segment before the end: there x is
    // 1 - 0.1^3 / 3 (the last segment is x(u) = 1 - (1-u)^3 / 3).
    double end = 1 - 0.001 / 3;
    double step = (end + 1) / 4;
    for (int i = 0; i < 5; ++i) {
        EXPECT_NEAR(s.vertices[i].x, -1 + i * step, 2e-3) << i;
        EXPECT_NEAR(s.vertices[i].y, 0, 1e-12) << i;
    }
}

TEST(Contour, EndpointInterpolationClampsOpenContours)
{
    Contour c = parse_contour("cver 1 2\nname: e\npoints: 4 4\ntype: oe\n0 0 0 1\n1 1 0 1\n2 1 0 1\n3 0 0 1\n", "e.con");
    EXPECT_TRUE(c.endpoint_interpolation);
    Vec3 start = c.evaluate(0), finish = c.evaluate(c.segment_count());
    EXPECT_NEAR(start.x, 0, 1e-12);
    EXPECT_NEAR(start.y, 0, 1e-12);
    EXPECT_NEAR(finish.x, 3, 1e-12);
    EXPECT_NEAR(finish.y, 0, 1e-12);
}

TEST(Contour, ThreeDimensionalPointsKeepZ)
{
    Contour c = parse_contour("4 3 closed\n1 0 0.5\n0 1 0\n-1 0 0\n0 -1 0\n", "z.con");
    ASSERT_EQ(c.points.size(), 4u);
    EXPECT_EQ(c.points[0].z, 0.5);
    // The uniform B-spline at t = 0 is (P0 + 4 P1 + P2) / 6.
    Vec3 p = c.evaluate(0);
    EXPECT_NEAR(p.x, 0, 1e-12);
    EXPECT_NEAR(p.y, 4.0 / 6, 1e-12);
    EXPECT_NEAR(p.z, 0.5 / 6, 1e-12);
}

TEST(Contour, MalformedFilesAreErrorsWithLines)
{
    try {
        parse_contour("cver 1 1\nname: x\npoints: 2 2\ntype: closed\n1 1 0 1\n1 x 0 1\n", "bad.con");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().line, 6);
    }
    EXPECT_THROW(parse_contour("cver 2 0\n", "bad.con"), Error);
    // 100 * 42949673 + 97 wraps around to 101 in 32 bits: refused, not read as 1.1.
    try {
        parse_contour("cver 42949673 97\nname: x\npoints: 4 4\ntype: closed\n0 0 0 1\n"
                      "1 0 0 1\n1 1 0 1\n0 1 0 1\n",
                      "big.con");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().line, 1);
        EXPECT_EQ(e.loc().column, 6);
        EXPECT_NE(std::string(e.what()).find("unknown contour format 42949673.97"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(parse_contour("3 2 open\n0 0\n1 0\n2 0\n", "bad.con"), Error);  // 4 needed
    EXPECT_THROW(parse_contour("4 5 closed\n", "bad.con"), Error);
    EXPECT_THROW(parse_contour("999999999 2 closed\n", "bad.con"), Error);
    EXPECT_THROW(parse_contour("", "empty.con"), Error);
}

TEST(Contour, GalleryItemsInOrder)
{
    std::string text = std::string("contourgalleryver 1 1\nitems: 2\n") + square_101 +
                       "cver 1 1\nname: tri\npoints: 3 3\ntype: closed\n0 1 0 1\n-1 -1 0 1\n1 -1 0 1\n";
    std::vector<Contour> g = parse_contour_gallery(text, "g.cset");
    ASSERT_EQ(g.size(), 2u);
    EXPECT_EQ(g[0].name, "square");
    EXPECT_EQ(g[1].name, "tri");
    EXPECT_EQ(g[1].points.size(), 3u);
}

TEST(Contour, CircleSamplesStartOnX)
{
    ContourSamples s = circle_samples(4);
    ASSERT_EQ(s.vertices.size(), 4u);
    EXPECT_NEAR(s.vertices[0].x, 1, 1e-12);
    EXPECT_NEAR(s.vertices[1].y, 1, 1e-12);
}

TEST(Contour, CorpusContourFilesParse)
{
    const char* env = std::getenv("CAMBIUM_CORPUS");
    std::filesystem::path corpus = env ? env : CAMBIUM_CORPUS_DEFAULT;
    if (!std::filesystem::exists(corpus / "cpfg"))
        GTEST_SKIP() << "corpus not found";
    int parsed = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(corpus / "cpfg")) {
        if (entry.path().extension() != ".con")
            continue;
        std::ifstream in(entry.path());
        std::string first;
        std::getline(in, first);
        if (first.rfind("version:", 0) == 0)
            continue;  // a function file named .con (Ridley's profile)
        Contour c = read_contour(entry.path());
        EXPECT_GE(c.points.size(), 4u) << entry.path();
        ContourSamples s = resample(c, 8);
        EXPECT_EQ(s.vertices.size(), c.closed ? 8u : 9u) << entry.path();
        ++parsed;
    }
    EXPECT_GT(parsed, 0);
}
