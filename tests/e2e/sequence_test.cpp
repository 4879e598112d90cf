// SPDX-License-Identifier: Apache-2.0
// Sequences through the app layer: what is loaded once, and in-between frames.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "app/sequence.h"
#include "lsys/inbetween.h"
#include "render/render.h"
#include "render/texture.h"

using namespace cambium;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name)
{
    fs::path dir = fs::temp_directory_path() /
                   ("cambium_seq_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

/// A plant whose stem elongates and thickens: F(x) --> F(x+1), !(w) --> !(w*2).
fs::path growing_plant(const fs::path& dir)
{
    std::ofstream(dir / "g.l") << "lsystem: 1\nderivation length: 3\naxiom: !(0.1) F(1) A\n"
                                  "F(x) --> F(x+1)\n!(w) --> !(w*1.5)\nA --> [+F(1)]A\n"
                                  "endlsystem\n";
    std::ofstream(dir / "g.v") << "line style: cylinder\ntexture: F: bark.png\n";
    render::Image texture{2, 2, std::vector<float>(16, 0.5f)};
    render::write_image(texture, dir / "bark.png", {});
    return dir;
}

app::Options options_for(const fs::path& dir, const std::vector<std::string>& extra)
{
    std::vector<std::string> words = {"-a", "-q", "-w", "16", "12", "--spp", "1"};
    words.insert(words.end(), extra.begin(), extra.end());
    words.push_back((dir / "g.l").string());
    words.push_back((dir / "g.v").string());
    std::optional<app::Options> options = app::parse_command_line(words);
    EXPECT_TRUE(options.has_value());
    return *options;
}

app::SequenceOutputs outputs_for(const app::Options& options, const fs::path& pattern)
{
    app::SequenceOutputs out;
    out.images = {pattern};
    out.settings.width = options.width;
    out.settings.height = options.height;
    out.settings.samples_per_pixel = options.samples_per_pixel;
    app::apply_staging(out.settings, options);
    out.write_strings = [](const app::Model&, const lsys::ModuleString&, int) {};
    out.say = [](const std::string&) {};
    return out;
}

TEST(Sequence, TexturesAreOpenedOncePerAnimation)
{
    fs::path dir = growing_plant(scratch("textures"));
    for (bool ground : {false, true}) {
        std::vector<std::string> extra;
        if (ground)
            extra = {"--ground", (dir / "bark.png").string()};
        app::Options options = options_for(dir, extra);
        std::uint64_t before = render::TextureSet::constructed_count();
        ASSERT_EQ(app::run_sequence(options, outputs_for(options, dir / "f%d.png")), 0);
        EXPECT_EQ(render::TextureSet::constructed_count() - before, 1u) << "ground " << ground;
        for (const char* file : {"f1.png", "f2.png", "f3.png"})
            EXPECT_TRUE(fs::exists(dir / file)) << file;
    }
}

TEST(Sequence, InbetweenBoundsLieBetweenTheSteps)
{
    fs::path dir = growing_plant(scratch("bounds"));
    app::Options options = options_for(dir, {"--inbetween", "3"});
    app::Model model = app::load_model(options);
    std::vector<geom::Bounds3> steps;
    std::vector<std::vector<geom::Bounds3>> between;
    lsys::ModuleString before;
    std::vector<lsys::Growth> grows(model.lsystem.symbols().size());
    for (const char* name : {"F", "!"})
        grows[std::size_t(model.lsystem.symbols().find(name))] = {true, 1};
    app::derive_frames_with_lineage(
        model, app::animation_frames(model, options), true,
        [&](const geom::AnimationFrame&, const lsys::ModuleString& string,
            const std::vector<std::uint32_t>& lineage) {
        if (!steps.empty()) {
            between.emplace_back();
            for (int k = 1; k <= 3; ++k) {
                lsys::ModuleString s = lsys::inbetween(before, string, lineage, k / 4.0f, grows);
                between.back().push_back(app::interpret(model, s, options).bounds);
            }
        }
        steps.push_back(app::interpret(model, string, options).bounds);
        before = string;
    });
    ASSERT_EQ(steps.size(), 3u);
    ASSERT_EQ(between.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        double low = steps[i].hi.y, high = steps[i + 1].hi.y;
        ASSERT_LT(low, high);  // the stem grows
        double previous = low;
        for (const geom::Bounds3& b : between[i]) {
            EXPECT_GT(b.hi.y, previous) << "step " << i;  // and grows steadily
            EXPECT_LT(b.hi.y, high) << "step " << i;
            previous = b.hi.y;
        }
    }
}

}  // namespace
