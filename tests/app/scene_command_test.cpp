// SPDX-License-Identifier: Apache-2.0
// `cambium scene.json` as a user runs it: an image from a good scene, with the command
// line overriding the file; for a bad one a message naming the file and JSON path, a
// non-zero exit and no image.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "shell_output.h"

namespace fs = std::filesystem;

namespace {

using Result = cambium::test::CommandResult;

Result run(const std::string& args, const fs::path& folder)
{
    return cambium::test::run_shell(std::string(CAMBIUM_EXE) + " " + args, folder);
}

fs::path scratch()
{
    fs::path dir = fs::temp_directory_path() / ("cambium_scene_cmd_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "m");
    std::ofstream(dir / "m/p.l") << "lsystem: 1\nderivation length: 2\naxiom: A\n"
                                    "A --> F(1)[+(40)F(0.5)]/(137)A\nendlsystem\n";
    std::ofstream(dir / "m/p.v") << "angle factor: 8\ninitial line width: 0.15\nline style: cylinder\n";
    return dir;
}

}  // namespace

TEST(SceneCommand, RendersAndTheCommandLineOverridesTheFile)
{
    fs::path dir = scratch();
    std::ofstream(dir / "field.json") << R"({
      "plants": [{"model": "m", "command": "cpfg p.l p.v",
                  "placements": [{"translate": [-1, 0, 0]}, {"translate": [1, 0, 0]}]}],
      "ground": {"size": [6, 6]},
      "camera": {"width": 300, "height": 200},
      "render": {"spp": 2}
    })";
    // -w overrides the camera's size; without -o the image is named after the scene
    Result r = run("-w 40 30 field.json", dir);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("2 plants (1 models, 1 derivations of 2 steps, 1 variants)"), std::string::npos) << r.output;
    auto in = OIIO::ImageInput::open((dir / "field.png").string());
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().width, 40);
    EXPECT_EQ(in->spec().height, 30);
    fs::remove_all(dir);
}

TEST(SceneCommand, ABadSceneNamesThePathAndWritesNothing)
{
    fs::path dir = scratch();
    std::ofstream(dir / "bad.json") << R"({"plants": [{"model": "m", "command": "cpfg p.l p.v",
        "placements": {"scatter": {"rectangle": [0, 0, 1, 1], "count": -3}}}]})";
    Result r = run("-o out.png bad.json", dir);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("bad.json: plants[0].placements.scatter.count: must be a positive integer"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
    // an error inside a model names the scene's plant and the model's file and line
    std::ofstream(dir / "m/p.l") << "lsystem: 1\naxiom: A(\nendlsystem\n";
    std::ofstream(dir / "model.json") << R"({"plants": [{"model": "m", "command": "cpfg p.l p.v",
        "placements": [{}]}]})";
    r = run("-o out.png model.json", dir);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("model.json: plants[0] (cpfg p.l p.v): "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("p.l:2:"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
    // a single file that is not a scene
    r = run("p.l", dir / "m");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("files: At least 2 required"), std::string::npos) << r.output;
    // options of several values stop before a scene file
    std::ofstream(dir / "m/p.l") << "lsystem: 1\nderivation length: 1\naxiom: F(1)\nendlsystem\n";
    std::ofstream(dir / "field.json") << R"({"plants": [{"model": "m", "command": "cpfg p.l p.v",
        "placements": [{}]}]})";
    r = run("--sun 0 1 0 -w 16 12 --spp 1 -o sun.png field.json", dir);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir / "sun.png"));
    fs::remove_all(dir);
}

// --light-report with a scene file: one report, each organ with its placement.
TEST(SceneCommand, LightReportOfAField)
{
    fs::path dir = scratch();
    std::ofstream(dir / "field.json") << R"({
      "plants": [{"model": "m", "command": "cpfg p.l p.v",
                  "placements": [{"translate": [-1, 0, 0]}, {"translate": [1, 0, 0]}]}]
    })";
    Result r = run("field.json --light-report light.csv --light-rays 20000", dir);
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir / "light.csv");
    std::string line;
    int plant0 = 0, plant1 = 0;
    while (std::getline(in, line)) {
        std::size_t a = line.find(','), b = line.find(',', a + 1), c = line.find(',', b + 1);
        if (a == std::string::npos || c == std::string::npos || line.rfind("module,", 0) == 0)
            continue;
        const std::string plant = line.substr(b + 1, c - b - 1);
        plant0 += plant == "0";
        plant1 += plant == "1";
    }
    EXPECT_GT(plant0, 0) << r.output;
    EXPECT_EQ(plant0, plant1);
    EXPECT_FALSE(fs::exists(dir / "field.png"));  // a report alone renders nothing
    fs::remove_all(dir);
}

// The command traces the --sky placed by --sun-at over an infinite canopy: the report
// names the sky and the tile, skips nothing, and what went down is below what came in; a
// bad --sun-at fails before the work, naming the option.
TEST(SceneCommand, LightReportUnderTheSkyOverACanopy)
{
    fs::path dir = scratch();
    Result r = run("m/p.l m/p.v --sky --sun-at 48.1 11.6 2024-06-21T12:00+02:00 --no-view-lights "
                   "--infinite-canopy --light-report light.json --light-rays 20000",
                   dir);
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir / "light.json");
    const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(json.find("\"sky and sun"), std::string::npos) << json.substr(0, 800);
    EXPECT_NE(json.find("infinite canopy: the tile"), std::string::npos);
    EXPECT_NE(json.find("\"skipped_lights\": []"), std::string::npos);
    EXPECT_EQ(json.find("directional toward"), std::string::npos);  // --no-view-lights
    Result bad = run("m/p.l m/p.v --sky --sun-at 91 0 2024-06-21T12:00Z --light-report b.json", dir);
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.output.find("--sun-at: latitude"), std::string::npos) << bad.output;
    EXPECT_FALSE(fs::exists(dir / "b.json"));
    fs::remove_all(dir);
}

// --ground reaches the report: its colour as albedo under the plant, the light it
// reflects traced; a texture is not read (mid grey, warned of).
TEST(SceneCommand, LightReportOverTheGround)
{
    fs::path dir = scratch();
    Result r = run("m/p.l m/p.v --ground 0.8,0.8,0.8 --sky --light-report light.json --light-rays 20000", dir);
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir / "light.json");
    const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(json.find("\"ground\": {\"height\": "), std::string::npos) << json.substr(0, 1200);
    EXPECT_NE(json.find("\"albedo\": 0.6038"), std::string::npos);
    EXPECT_NE(json.find("its unshadowed reflection"), std::string::npos);
    EXPECT_FALSE(fs::exists(dir / "p.png"));
    std::ofstream(dir / "soil.png") << "not read";
    r = run("m/p.l m/p.v --ground soil.png --light-report soil.json --light-rays 2000", dir);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("is not read; the ground is traced mid grey"), std::string::npos) << r.output;
    fs::remove_all(dir);
}
