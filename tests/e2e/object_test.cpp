// SPDX-License-Identifier: Apache-2.0
// End-to-end: an L-system whose flowers are -o> objects (instanced) renders the same
// picture as the same L-system with --> (expanded inline), through the app pipeline.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "app/pipeline.h"
#include "render/render.h"

using namespace cambium;
namespace fs = std::filesystem;

namespace {

double mean_difference(const render::Image& a, const render::Image& b)
{
    double difference = 0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i)
        difference += std::fabs(a.rgba[i] - b.rgba[i]);
    return difference / static_cast<double>(a.rgba.size());
}

/// A stem with three flowers; `arrow` is the flower production's delimiter.
std::string plant(const std::string& arrow)
{
    return "lsystem: 1\nderivation length: 3\naxiom: A\n"
           "A --> F(2)[+(40)K]/(137)A\n"
           "homomorphism\n"
           "K " + arrow + " F(1)[;(2)@O(0.8)][&(30)F(0.5)]\n"
           "endlsystem\n";
}

struct Built {
    geom::Scene scene;
    render::Image image;
};

Built build(const std::string& arrow, const std::string& line_style = "cylinder")
{
    // a folder of this process's own: ctest runs this file's tests in parallel processes
    fs::path dir = fs::temp_directory_path() /
                   ("cambium_objects_" + std::to_string(getpid()) + (arrow == "-o>" ? "o_" : "i_") +
                    line_style);
    fs::create_directories(dir);
    std::ofstream(dir / "plant.l") << plant(arrow);
    // `initial line width:` without a unit sets cpfg's polygon style: the style after it
    std::ofstream(dir / "plant.v") << "angle factor: 8\ninitial line width: "
                                   << (line_style == "pixel" ? "3" : "0.2")
                                   << "\nline style: " << line_style
                                   << "\nlight: V: 0 0 1\nscale factor: 0.9\n";
    app::Options options;
    options.lsystem = dir / "plant.l";
    options.view = dir / "plant.v";
    app::Model model = app::load_model(options);
    Built b{app::interpret(model, app::derive(model, options), options), {}};
    render::RenderSettings settings;
    settings.width = 64;
    settings.height = 64;
    settings.samples_per_pixel = 16;
    settings.max_depth = 2;
    b.image = render::render(b.scene, settings);
    fs::remove_all(dir);
    return b;
}

}  // namespace

TEST(Objects, InstancedObjectsRenderLikeInlineOnes)
{
    Built instanced = build("-o>");
    Built inline_ = build("-->");
    // independent expectation: one flower shape, three occurrences
    EXPECT_EQ(instanced.scene.prototypes.size(), 1u);
    EXPECT_EQ(instanced.scene.instances.size(), 3u);
    EXPECT_TRUE(inline_.scene.instances.empty());
    EXPECT_EQ(instanced.scene.geometry.spheres.centres.size(), 0u);
    EXPECT_EQ(inline_.scene.geometry.spheres.centres.size(), 3u);

    ASSERT_EQ(instanced.image.rgba.size(), inline_.image.rgba.size());
    double coverage = 0;
    for (std::size_t i = 3; i < inline_.image.rgba.size(); i += 4)
        coverage += inline_.image.rgba[i];
    EXPECT_GT(coverage, 20.0);  // the plant is in the picture
    // the same picture up to float rounding of the placement
    EXPECT_LT(mean_difference(instanced.image, inline_.image), 1e-4);
}

TEST(Objects, PixelWideLinesInsideObjectsKeepTheirWidth)
{
    // lines N pixels wide are sized per placed copy, at its own depth
    Built instanced = build("-o>", "pixel");
    Built inline_ = build("-->", "pixel");
    EXPECT_TRUE(inline_.scene.line_radius_in_pixels);
    EXPECT_EQ(instanced.scene.instances.size(), 3u);
    ASSERT_EQ(instanced.image.rgba.size(), inline_.image.rgba.size());
    EXPECT_LT(mean_difference(instanced.image, inline_.image), 1e-4);
}
