// SPDX-License-Identifier: Apache-2.0
// A background scene in a `line style: pixel` view: the plant's lines are pixel-width, the
// background's cylinders keep their world radius.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "app/pipeline.h"

using namespace cambium;
namespace fs = std::filesystem;

TEST(BackgroundPixelLines, BackgroundCylinderKeepsItsWorldRadius)
{
    fs::path dir = fs::temp_directory_path() / "cambium_background_pixel";
    fs::create_directories(dir);
    std::ofstream(dir / "plant.l") << "lsystem: 1\nderivation length: 0\naxiom: F(1)\nendlsystem\n";
    std::ofstream(dir / "bg.dat") << "translate 10 0 0\ncylinder 3 4\n";
    std::ofstream(dir / "plant.v") << "line style: pixel\nbackground scene: bg.dat\n";
    app::Options options;
    options.lsystem = dir / "plant.l";
    options.view = dir / "plant.v";
    app::Model model = app::load_model(options);
    geom::Scene scene = app::interpret(model, app::derive(model, options), options);
    ASSERT_TRUE(scene.line_radius_in_pixels);
    EXPECT_EQ(scene.geometry.lines.segment_count(), 1u);  // the plant's F alone
    ASSERT_FALSE(scene.geometry.mesh.positions.empty());
    double widest = 0;
    for (const geom::Float3& p : scene.geometry.mesh.positions)
        widest = std::max(widest, std::hypot(p[0] - 10.0, p[2]));
    EXPECT_NEAR(widest, 3.0, 1e-5);  // world units, not 3 pixels
}
