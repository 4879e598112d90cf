// SPDX-License-Identifier: Apache-2.0
// The turtle reads the derived string itself when the homomorphism would copy it
// unchanged (the copy cost a fifth of a 12 M-segment tree's time to first pixel); the
// Scene is the same either way.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/pipeline.h"
#include "model_folder.h"

using namespace cambium;
namespace fs = std::filesystem;

namespace {

app::Options write_model(const std::string& name, const std::string& lsystem)
{
    return cambium::testing::write_model("turtle_string_" + name, lsystem);
}

const std::string plain = "lsystem: 1\nderivation length: 3\naxiom: A\n"
                          "A --> F(1)[+(30)A]/(90)A\nendlsystem\n";
const std::string with_homomorphism = "lsystem: 1\nderivation length: 3\naxiom: A\n"
                                      "A --> F(1)[+(30)A]/(90)A\nhomomorphism\n"
                                      "A --> F(0.2)\nendlsystem\n";

TEST(TurtleString, DerivedStringIsReadDirectlyOnlyWithoutHomomorphism)
{
    app::Options options = write_model("plain", plain);
    app::Model model = app::load_model(options);
    EXPECT_TRUE(app::turtle_reads_derived_string(model, options));

    app::Options h = write_model("homomorphism", with_homomorphism);
    app::Model hm = app::load_model(h);
    EXPECT_FALSE(app::turtle_reads_derived_string(hm, h));
    // with the homomorphism already applied in the string (--homo), it is read as it is
    h.homomorphism_in_string = true;
    EXPECT_TRUE(app::turtle_reads_derived_string(hm, h));
}

TEST(TurtleString, ReadingTheDerivedStringGivesTheSameScene)
{
    app::Options options = write_model("same", plain);
    app::Model model = app::load_model(options);
    lsys::ModuleString derived = app::derive(model, options);
    geom::Scene direct = app::interpret(model, derived, options);
    geom::Scene copied = app::interpret_turtle_string(
        model, app::turtle_string(model, derived, options), options);
    ASSERT_EQ(direct.geometry.lines.segment_count(), 7u);  // 1 + 2 + 4 internodes
    EXPECT_EQ(direct.geometry.lines.keys, copied.geometry.lines.keys);
    EXPECT_EQ(direct.geometry.lines.segments, copied.geometry.lines.segments);
    EXPECT_EQ(direct.geometry.lines.flags, copied.geometry.lines.flags);

    // the homomorphism's F(0.2) per apex shows that the other path still applies it
    app::Options h = write_model("homomorphism_applied", with_homomorphism);
    app::Model hm = app::load_model(h);
    geom::Scene applied = app::interpret(hm, app::derive(hm, h), h);
    EXPECT_GT(applied.geometry.lines.segment_count(), direct.geometry.lines.segment_count());
}

// Untextured lines carry no texture v or texture index, and no growth slack.
TEST(TurtleString, UntexturedLinesKeepNoTextureBuffers)
{
    app::Options options = write_model("untextured", plain);
    app::Model model = app::load_model(options);
    geom::Scene scene = app::interpret(model, app::derive(model, options), options);
    const geom::LinearCurves& l = scene.geometry.lines;
    ASSERT_EQ(l.segment_count(), 7u);
    EXPECT_TRUE(l.v.empty());
    EXPECT_TRUE(l.texture.empty());
    EXPECT_EQ(l.keys.capacity(), l.keys.size());
    EXPECT_EQ(l.material.size(), 7u);

    // a textured segment keeps both (the texture file need not exist to be named)
    app::Options t = write_model("textured", "lsystem: 1\nderivation length: 1\naxiom: A\n"
                                             "A --> F(1)@Tx(1)F(1)\nendlsystem\n");
    std::ofstream(t.view, std::ios::app) << "texture: F: bark.png\n";
    app::Model tm = app::load_model(t);
    geom::Scene textured = app::interpret(tm, app::derive(tm, t), t);
    EXPECT_EQ(textured.geometry.lines.texture.size(), textured.geometry.lines.segment_count());
    EXPECT_EQ(textured.geometry.lines.v.size(), textured.geometry.lines.keys.size());
}

}  // namespace
