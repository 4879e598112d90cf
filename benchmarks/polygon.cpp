// SPDX-License-Identifier: Apache-2.0
// Polygon triangulation benchmark: large turtle polygons (`{ . }`), one JSON line each.
//
// Usage: polygon [vertices]   (default 300000)
// Outlines: a zigzag circle (every other vertex reflex), a star-shaped outline with
// random radii, a comb with long teeth, and a convex circle. Each line reports the time,
// the triangles made and how far their total area is from the outline's (relative).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "geom/polygon.h"

using cambium::geom::Vec3;

namespace {

std::vector<Vec3> zigzag_circle(std::size_t n)
{
    std::vector<Vec3> p;
    for (std::size_t i = 0; i < n; ++i) {
        double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
        double r = i % 2 ? 1.0 : 0.9;
        p.push_back({r * std::cos(a), r * std::sin(a), 0});
    }
    return p;
}

std::vector<Vec3> random_star(std::size_t n)
{
    std::vector<Vec3> p;
    std::uint32_t state = 12345;
    for (std::size_t i = 0; i < n; ++i) {
        state = state * 1664525u + 1013904223u;
        double r = 0.2 + (state >> 8) / double(1u << 24);
        double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
        p.push_back({r * std::cos(a), r * std::sin(a), 0});
    }
    return p;
}

/// Teeth of height 10 along the x axis, closed by a base below.
std::vector<Vec3> comb(std::size_t n)
{
    std::vector<Vec3> p;
    std::size_t teeth = (n - 2) / 4;
    for (std::size_t t = 0; t < teeth; ++t) {
        double x = 2.0 * static_cast<double>(t);
        p.push_back({x, 0, 0});
        p.push_back({x, 10, 0});
        p.push_back({x + 1, 10, 0});
        p.push_back({x + 1, 0, 0});
    }
    p.push_back({2.0 * static_cast<double>(teeth), -1, 0});
    p.push_back({0, -1, 0});
    // counter-clockwise: reverse the clockwise walk above
    return {p.rbegin(), p.rend()};
}

std::vector<Vec3> convex_circle(std::size_t n)
{
    std::vector<Vec3> p;
    for (std::size_t i = 0; i < n; ++i) {
        double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
        p.push_back({std::cos(a), std::sin(a), 0});
    }
    return p;
}

double shoelace(const std::vector<Vec3>& p)
{
    double a = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3& u = p[i];
        const Vec3& v = p[(i + 1) % p.size()];
        a += u.x * v.y - v.x * u.y;
    }
    return std::abs(0.5 * a);
}

}  // namespace

int main(int argc, char** argv)
{
    std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 300'000;
    struct Case {
        const char* name;
        std::function<std::vector<Vec3>(std::size_t)> make;
    };
    for (const Case& c : {Case{"zigzag_circle", zigzag_circle}, Case{"random_star", random_star},
                          Case{"comb", comb}, Case{"convex_circle", convex_circle}}) {
        std::vector<Vec3> outline = c.make(n);
        auto start = std::chrono::steady_clock::now();
        bool cut_short = false;
        auto triangles = cambium::geom::triangulate_polygon(outline, &cut_short);
        double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        double area = 0;
        for (const auto& t : triangles)
            area += 0.5 * std::abs(cross(outline[t[1]] - outline[t[0]], outline[t[2]] - outline[t[0]]).z);
        double expected = shoelace(outline);
        std::printf("{\"outline\": \"%s\", \"vertices\": %zu, \"triangles\": %zu, \"seconds\": %.4f, "
                    "\"cut_short\": %s, \"area_error\": %.3g}\n",
                    c.name, outline.size(), triangles.size(), seconds, cut_short ? "true" : "false",
                    std::abs(area - expected) / expected);
    }
    return 0;
}
