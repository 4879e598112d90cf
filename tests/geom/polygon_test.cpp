// SPDX-License-Identifier: Apache-2.0
// Tests of polygon triangulation: areas against the shoelace formula, no triangle outside.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "geom/polygon.h"

using namespace cambium::geom;

namespace {

using Outline = std::vector<Vec3>;

/// Shoelace area of a polygon given in the xy plane (signed: + for counter-clockwise).
double shoelace(const std::vector<std::array<double, 2>>& p)
{
    double a = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const auto& u = p[i];
        const auto& v = p[(i + 1) % p.size()];
        a += u[0] * v[1] - v[0] * u[1];
    }
    return 0.5 * a;
}

/// Even-odd point-in-polygon test in the xy plane.
bool inside(const std::vector<std::array<double, 2>>& p, double x, double y)
{
    bool in = false;
    for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
        if ((p[i][1] > y) != (p[j][1] > y) &&
            x < (p[j][0] - p[i][0]) * (y - p[i][1]) / (p[j][1] - p[i][1]) + p[i][0])
            in = !in;
    }
    return in;
}

Outline lift(const std::vector<std::array<double, 2>>& p)
{
    Outline o;
    for (const auto& q : p)
        o.push_back({q[0], q[1], 0});
    return o;
}

/// Checks a planar xy outline: areas add up, each triangle is counter-clockwise
/// (as the outline) and its centroid lies inside the polygon. `max_triangles`: at
/// most n - 2 (fewer when clipping meets collinear vertices).
void check_xy(const std::vector<std::array<double, 2>>& p, std::size_t max_triangles)
{
    Outline o = lift(p);
    auto tris = triangulate_polygon(o);
    EXPECT_LE(tris.size(), max_triangles);
    EXPECT_GE(tris.size(), 1u);
    double total = 0;
    for (const auto& t : tris) {
        const Vec3 &a = o[t[0]], &b = o[t[1]], &c = o[t[2]];
        double area = 0.5 * cross(b - a, c - a).z;
        EXPECT_GT(area, 1e-12) << "triangle " << t[0] << " " << t[1] << " " << t[2];
        total += area;
        Vec3 g = (a + b + c) / 3.0;
        EXPECT_TRUE(inside(p, g.x, g.y)) << "centroid " << g.x << "," << g.y << " outside";
    }
    EXPECT_NEAR(total, shoelace(p), 1e-9);
}

}  // namespace

TEST(Polygon, SquareGivesTwoTriangles) { check_xy({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 2); }

TEST(Polygon, ConcaveLShape)
{
    // area 3: a 2x2 square without its top-right unit square
    check_xy({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, 4);
}

TEST(Polygon, ConcaveArrowAndComb)
{
    check_xy({{0, 0}, {2, 1}, {4, 0}, {2, 4}}, 2);  // arrow head, reflex vertex at (2,1): area 8 - 2
    check_xy({{0, 0}, {5, 0}, {5, 3}, {4, 3}, {4, 1}, {3, 1}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}},
             10);  // comb with three teeth: 5*1 + 3 teeth of 2 = 11
}

TEST(Polygon, CollinearAndRepeatedVerticesAreHandled)
{
    // the unit square with midpoints on two edges and a repeated corner: area 1,
    // no zero-area triangle
    check_xy({{0, 0}, {0.5, 0}, {1, 0}, {1, 0}, {1, 0.5}, {1, 1}, {0, 1}}, 4);
    // a square with a zero-width spike going out and back along one edge's line
    check_xy({{0, 0}, {1, 0}, {2, 0}, {1, 0}, {1, 1}, {0, 1}}, 4);
}

TEST(Polygon, DegenerateOutlinesGiveNothing)
{
    EXPECT_TRUE(triangulate_polygon(Outline{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}).empty());
    EXPECT_TRUE(triangulate_polygon(Outline{{0, 0, 0}, {1, 0, 0}}).empty());
    EXPECT_TRUE(triangulate_polygon(Outline{}).empty());
}

TEST(Polygon, ClockwiseOutlineKeepsItsWinding)
{
    Outline o = lift({{0, 0}, {0, 1}, {1, 1}, {1, 0}});
    Vec3 n = polygon_normal(o);
    EXPECT_NEAR(n.z, -1, 1e-12);
    for (const auto& t : triangulate_polygon(o))
        EXPECT_LT(cross(o[t[1]] - o[t[0]], o[t[2]] - o[t[0]]).z, 0);
}

TEST(Polygon, TiltedPlanarLShapeKeepsItsArea)
{
    // the L shape of area 3 mapped into the plane spanned by (1,0,1)/sqrt2 and (0,1,0)
    std::vector<std::array<double, 2>> p{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
    Outline o;
    double k = 1 / std::sqrt(2.0);
    for (const auto& q : p)
        o.push_back({q[0] * k + 3, q[1], q[0] * k - 1});
    auto tris = triangulate_polygon(o);
    ASSERT_EQ(tris.size(), 4u);
    double total = 0;
    for (const auto& t : tris)
        total += 0.5 * length(cross(o[t[1]] - o[t[0]], o[t[2]] - o[t[0]]));
    EXPECT_NEAR(total, 3, 1e-9);
    Vec3 n = polygon_normal(o);
    EXPECT_NEAR(n.x, -k, 1e-12);
    EXPECT_NEAR(n.z, k, 1e-12);
}

TEST(Polygon, StarShapedOutlines)
{
    // star-shaped around the origin (so simple), radii from a fixed LCG: many reflex vertices
    std::uint32_t state = 12345;
    for (int trial = 0; trial < 20; ++trial) {
        std::size_t n = 5 + static_cast<std::size_t>(trial) * 7;
        std::vector<std::array<double, 2>> p;
        for (std::size_t i = 0; i < n; ++i) {
            state = state * 1664525u + 1013904223u;
            double r = 0.2 + (state >> 8) / double(1u << 24);
            double a = 2 * 3.141592653589793 * static_cast<double>(i) / static_cast<double>(n);
            p.push_back({r * std::cos(a), r * std::sin(a)});
        }
        check_xy(p, n - 2);
    }
}

TEST(Polygon, ManyVerticesFinishQuickly)
{
    std::vector<std::array<double, 2>> p;
    for (int i = 0; i < 2000; ++i) {
        double a = 2 * 3.141592653589793 * i / 2000.0;
        double r = i % 2 ? 1.0 : 0.9;  // a fine zigzag circle
        p.push_back({r * std::cos(a), r * std::sin(a)});
    }
    Outline o = lift(p);
    auto tris = triangulate_polygon(o);
    double total = 0;
    for (const auto& t : tris)
        total += 0.5 * cross(o[t[1]] - o[t[0]], o[t[2]] - o[t[0]]).z;
    EXPECT_NEAR(total, shoelace(p), 1e-9);
}

TEST(Polygon, OutlineTouchingItselfAtAVertex)
{
    // two squares joined at the corner (1,1), walked as one outline through it twice
    check_xy({{0, 0}, {1, 0}, {1, 1}, {2, 1}, {2, 2}, {1, 2}, {1, 1}, {0, 1}}, 6);
}

TEST(Polygon, LargeZigzagIsExactAndNotCutShort)
{
    // 20 000 vertices (the old clipper took seconds here; 300 000 are in
    // benchmarks/polygon.cpp): every triangle inside, the areas add up
    std::vector<std::array<double, 2>> p;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        double a = 2 * 3.141592653589793 * i / n;
        double r = i % 2 ? 1.0 : 0.9;
        p.push_back({r * std::cos(a), r * std::sin(a)});
    }
    Outline o = lift(p);
    bool cut_short = true;
    auto tris = triangulate_polygon(o, &cut_short);
    EXPECT_FALSE(cut_short);
    EXPECT_EQ(tris.size(), static_cast<std::size_t>(n - 2));
    double total = 0;
    for (const auto& t : tris) {
        double area = 0.5 * cross(o[t[1]] - o[t[0]], o[t[2]] - o[t[0]]).z;
        EXPECT_GT(area, 0);
        total += area;
    }
    EXPECT_NEAR(total, shoelace(p), 1e-9);
}

TEST(Polygon, LongCombWithDeepTeeth)
{
    // 500 teeth 10 high: every ear of the base is spoiled by tooth vertices nearby
    std::vector<std::array<double, 2>> p;
    for (int t = 499; t >= 0; --t) {
        double x = 2.0 * t;
        p.push_back({x + 1, 0});
        p.push_back({x + 1, 10});
        p.push_back({x, 10});
        p.push_back({x, 0});
    }
    p.insert(p.begin(), {{0, -1}, {1000, -1}});
    // counter-clockwise from (0,-1): base, then the teeth from the right
    check_xy(p, p.size() - 2);
}

// A star whose every step turns 137.508° (a golden-angle phyllotaxis outline) crosses
// itself everywhere: the walk finds no ear for a full round before each cut, quadratic
// quick misses that the budget must count. 4096 vertices take about 2 million steps.
TEST(Polygon, SelfIntersectingStarWalkCountsAgainstTheBudget)
{
    Outline star;
    double x = 0, y = 0, angle = 0;
    for (int i = 0; i < 4096; ++i) {
        star.push_back({x, y, 0});
        angle += 137.508 * 3.141592653589793 / 180;
        x += std::cos(angle);
        y += std::sin(angle);
    }
    bool cut_short = false;
    auto tris = triangulate_polygon(star, &cut_short, 1'000'000);
    EXPECT_TRUE(cut_short);
    EXPECT_EQ(tris.size(), star.size() - 2);  // the rest is still cut, in order
    tris = triangulate_polygon(star, &cut_short);
    EXPECT_FALSE(cut_short);
    EXPECT_EQ(tris.size(), star.size() - 2);
}
