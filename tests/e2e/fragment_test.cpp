// SPDX-License-Identifier: Apache-2.0
// Fragmentation (manual 5.1.9 `%(par)`): after a step the fragment has moved to the end of
// the string behind `%(par, turtle index)`, and it is drawn with the turtle saved where
// it was: the picture is the one its in-place string draws.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "model_folder.h"

using namespace cambium;
namespace fs = std::filesystem;

namespace {

app::Options write_model(const std::string& name, const std::string& lsystem)
{
    return cambium::testing::write_model("fragment_" + name, lsystem);
}

using Segment = std::array<long, 6>;

/// Each segment's end points in 1e-4 units, sorted: the drawing, whatever the order.
std::vector<Segment> segments(const geom::Scene& scene)
{
    const geom::LinearCurves& l = scene.geometry.lines;
    std::vector<Segment> out;
    for (std::uint32_t s : l.segments) {
        Segment seg{};
        for (int e = 0; e < 2; ++e)
            for (int c = 0; c < 3; ++c)
                seg[static_cast<std::size_t>(3 * e + c)] = std::lround(l.keys[s + e][c] * 1e4);
        out.push_back(seg);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// The fragment sits in a rotated, rolled, pitched branch, and a module after its branch
// moves the turtle on, so a fragment drawn with any other turtle lands elsewhere.
const std::string plant = "lsystem: 1\nderivation length: 2\n"
                          "axiom: F(1)[+(30)/(45)F(1)%(1)F(1)[-(45)F(2)]&(20)F(1)]-(20)F(1)\n"
                          "endlsystem\n";

TEST(Fragment, MovedFragmentIsDrawnWithItsSavedTurtle)
{
    app::Options options = write_model("moved", plant);
    app::Model model = app::load_model(options);

    options.steps = 0;
    lsys::ModuleString in_place = app::derive(model, options);
    geom::Scene before = app::interpret(model, in_place, options);

    options.steps = 1;
    lsys::ModuleString moved = app::derive(model, options);
    EXPECT_EQ(lsys::to_text(moved, model.lsystem.symbols()),
              "F(1)[+(30)/(45)F(1)]-(20)F(1)%(1,0)F(1)[-(45)F(2)]&(20)F(1)");
    geom::Scene after = app::interpret(model, moved, options);

    ASSERT_EQ(before.geometry.lines.segment_count(), 6u);
    EXPECT_EQ(segments(before), segments(after));
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(before.bounds.lo[c], after.bounds.lo[c], 1e-5);
        EXPECT_NEAR(before.bounds.hi[c], after.bounds.hi[c], 1e-5);
    }

    // a second step moves nothing more and draws the same
    options.steps = 2;
    lsys::ModuleString again = app::derive(model, options);
    EXPECT_EQ(lsys::to_text(again, model.lsystem.symbols()), lsys::to_text(moved, model.lsystem.symbols()));
    EXPECT_EQ(segments(before), segments(app::interpret(model, again, options)));
}

}  // namespace
