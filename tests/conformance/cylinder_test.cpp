// SPDX-License-Identifier: Apache-2.0
// Segment end points against cpfg's rayshade export: every `cylinder` / `cone` of the
// oracle's scene.ray is one of our line segments. This pins down where segments go,
// tropisms included (the pre-3.0 `tropism direction:` with `_`, manual 5.2.7).
#include <gtest/gtest.h>

#include <zlib.h>

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "corpus_model.h"

namespace cambium::test {
namespace {

namespace fs = std::filesystem;

using Point = std::array<double, 3>;
struct Segment {
    Point start, end;
};

/// The text of scene.ray or scene.ray.gz (zlib reads both).
std::string read_ray_file(const fs::path& oracle, const std::string& prefix)
{
    for (const char* name : {"scene.ray", "scene.ray.gz"}) {
        fs::path file = oracle / (prefix + name);
        if (!fs::exists(file))
            continue;
        gzFile in = gzopen(file.c_str(), "rb");
        std::string text;
        char buffer[1 << 16];
        int n = 0;
        while (in && (n = gzread(in, buffer, sizeof buffer)) > 0)
            text.append(buffer, static_cast<std::size_t>(n));
        if (in)
            gzclose(in);
        return text;
    }
    return {};
}

/// `cylinder surf r x y z x y z` and `cone surf r x y z r x y z`.
std::vector<Segment> ray_segments(const std::string& text)
{
    std::vector<Segment> segments;
    std::istringstream in(text);
    std::string word, surface;
    double radius = 0;
    while (in >> word) {
        Segment s;
        if (word == "cylinder") {
            in >> surface >> radius >> s.start[0] >> s.start[1] >> s.start[2] >> s.end[0] >> s.end[1] >>
                s.end[2];
        } else if (word == "cone") {
            in >> surface >> radius >> s.start[0] >> s.start[1] >> s.start[2] >> radius >> s.end[0] >>
                s.end[1] >> s.end[2];
        } else {
            continue;
        }
        segments.push_back(s);
    }
    return segments;
}

std::vector<Segment> our_segments(const geom::Scene& scene)
{
    const geom::LinearCurves& lines = scene.geometry.lines;
    std::vector<Segment> segments;
    for (std::uint32_t first : lines.segments) {
        const auto& a = lines.keys[first];
        const auto& b = lines.keys[first + 1];
        segments.push_back({{a[0], a[1], a[2]}, {b[0], b[1], b[2]}});
    }
    return segments;
}

double distance(const Point& a, const Point& b)
{
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

struct Agreement {
    std::size_t cpfg = 0, found = 0;
    double worst = 0;  ///< the largest end-point distance of the closest segment
};

/// For each cpfg segment, the closest of ours (the larger of its two end-point distances).
Agreement compare(const std::vector<Segment>& cpfg, const std::vector<Segment>& ours, double tolerance)
{
    Agreement a;
    a.cpfg = cpfg.size();
    for (const Segment& c : cpfg) {
        double best = INFINITY;
        for (const Segment& o : ours)
            best = std::min(best, std::max(distance(c.start, o.start), distance(c.end, o.end)));
        a.worst = std::max(a.worst, best);
        if (best <= tolerance)
            ++a.found;
    }
    return a;
}

/// Runs `command` (cpfg's, in the model's folder) and compares with `prefix`scene.ray.
void expect_cpfg_segments(const std::string& id, const std::string& command, const std::string& prefix = "")
{
    auto corpus = corpus_dir();
    if (!corpus)
        GTEST_SKIP() << "corpus not found";
    CorpusModel model{id, *corpus / "cpfg" / id, *corpus / "oracle" / id, {}, false};
    std::istringstream words(command);
    for (std::string w; words >> w;)
        model.command.push_back(w);
    std::string ray = read_ray_file(model.oracle, prefix);
    if (ray.empty())
        GTEST_SKIP() << "no scene.ray for " << id;
    app::Options options = model_options(model);
    set_warnings_enabled(false);
    app::Model loaded = app::load_model(options);
    geom::Scene scene = app::interpret(loaded, app::derive(loaded, options), options);
    set_warnings_enabled(true);
    std::vector<Segment> cpfg = ray_segments(ray);
    ASSERT_FALSE(cpfg.empty());
    geom::Vec3 size = scene.bounds.extent();
    double tolerance = 1e-4 * std::max({size.x, size.y, size.z});  // scene.ray prints 6 digits
    Agreement a = compare(cpfg, our_segments(scene), tolerance);
    EXPECT_EQ(a.found, a.cpfg) << id << " " << prefix << ": " << a.found << " of " << a.cpfg
                               << " cpfg segments are ours; the worst is " << a.worst << " away (tolerance "
                               << tolerance << ")";
}

// Sedge: `_(0-.1)` bends the stalks away from `tropism direction:` (they hang), `_(0)`
// stops it; the female spike bends under `initial elasticity: 0.02` alone.
TEST(CylinderConformance, SedgeHangsAsCpfgDrawsIt)
{
    expect_cpfg_segments("10-manuals/11-CPFG/Sedge", "-m1 sedge.map -m2 sedge.map2 sedge.l sedge.v sedge.a");
}
TEST(CylinderConformance, SedgeFemaleSpike)
{
    expect_cpfg_segments("10-manuals/11-CPFG/Sedge", "-m2 sedge.map2 female.l female.v female.a", "female.");
}
TEST(CylinderConformance, SedgeLeafArches)
{
    expect_cpfg_segments("10-manuals/11-CPFG/Sedge", "-m2 sedge.map2 leaf.l leaf.v leaf.a", "leaf.");
}
// Lychnis: `_(0.05)` in the axiom with no `initial elasticity:`.
TEST(CylinderConformance, LychnisBendsAsCpfgDrawsIt)
{
    expect_cpfg_segments("10-manuals/10-GettingStarted/01-Lychnis", "-M material.mat plant.l plant.v plant.a");
}

}  // namespace
}  // namespace cambium::test
