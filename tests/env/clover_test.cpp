// SPDX-License-Identifier: Apache-2.0
// The built-in clover (light under leaf discs on a grid) on hand-made cases whose
// answers follow from what vlab's program computes (docs/environment.md).
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdio>
#include <fstream>

#include "env_fixture.h"

namespace cambium::env {
namespace {

using testing::first_params;
using testing::model_with;
using testing::query_at;

/// A model folder with `spec` as enviro.spec, a light.rgb file and an image reader that
/// returns `image` for it.
Context clover_model(const std::string& test, const std::string& spec, const RgbImage& image)
{
    Context context = model_with("clover_" + test, "enviro.spec", spec);
    std::ofstream(context.folder / "light.rgb") << "image";
    context.read_image = [image](const std::filesystem::path& file) {
        if (file.filename() != "light.rgb")
            throw Error(FileLoc{file.string()}, "no such image");
        return image;
    };
    return context;
}

std::unique_ptr<Environment> clover(const std::string& test, const std::string& spec,
                                    const RgbImage& image = {})
{
    return make_builtin("clover", {"enviro.spec"}, clover_model(test, spec, image));
}

/// An image of `width` x `height` pixels, rows top to bottom, each (red, green, 0).
RgbImage image_of(int width, int height, const std::vector<std::array<std::uint8_t, 2>>& red_green)
{
    RgbImage image{width, height, {}};
    for (const auto& p : red_green)
        image.rgb.insert(image.rgb.end(), {p[0], p[1], 0});
    return image;
}

// the light of a cell whose image green is `green` under `leaves` leaves
float lit(int green, float t, int leaves)
{
    float power = 1;
    for (int i = 0; i < leaves; ++i)
        power *= t;
    return static_cast<float>(static_cast<float>(green) / 255.0 * power);
}

// a 4x4 grid of unit cells from (0, 0), over a 2x2 image: top row green 200 and 220
// (red 64), bottom row green 100 and 120 (red 32)
const std::string four = "grid size: 4x4\ngrid position: 0 0\ngrid range: 4x4view.pnl\ninput image: light.rgb\n"
                         "transmittance: 0.5\n";
const RgbImage two_by_two = image_of(2, 2, {{64, 200}, {64, 220}, {32, 100}, {32, 120}});

TEST(Clover, TheImageSpansTheGridFromItsBottomRow)
{
    // grid cells 0..2 take pixel 0 and cell 3 pixel 1 (3 · 1/3 truncated); grid row 0 is
    // the image's bottom row, as the program reads SGI rows
    auto env = clover("image", four, two_by_two);
    auto replies = env->pass({query_at(1, {0.5f, 0.5f, 0}, {1}), query_at(2, {3.5f, 0.5f, 0}, {1}),
                              query_at(3, {2.5f, 2.5f, 0}, {0, 0}), query_at(4, {3.5f, 3.5f, 0}, {0, 7})},
                             0);
    auto answers = first_params(replies);
    EXPECT_EQ(answers.at(1), lit(100, 0.5f, 0));
    EXPECT_EQ(answers.at(2), lit(120, 0.5f, 0));
    EXPECT_EQ(answers.at(3), lit(100, 0.5f, 0));
    EXPECT_EQ(answers.at(4), lit(220, 0.5f, 0));
    for (const Reply& r : replies) {
        EXPECT_EQ(r.params.size(), r.address >= 3 ? 2u : 1u);  // the ratio only when asked
        if (r.address == 4) {
            EXPECT_EQ(*r.params[1], 0.5f);  // red 64 / 128
        }
    }
}

TEST(Clover, TheCorpusModelsQueryReadsThePixelTheProgramRead)
{
    // 13-clover: a 1024 grid over a 256 image, from (-50, -50) over 100; the query at
    // (20, 25) is cell (716, 768), pixel (178, 191) counted from the bottom: in that
    // model's light.rgb, green 159 there (cpfg answered 0.623529) and 47 at row 191 from
    // the top
    RgbImage image{256, 256, std::vector<std::uint8_t>(256 * 256 * 3, 0)};
    image.rgb[((255 - 191) * 256 + 178) * 3 + 1] = 159;
    image.rgb[(191 * 256 + 178) * 3 + 1] = 47;
    auto env = clover("corpus", "grid position: -50 -50\ngrid range: 100x100view.pnl\ngrid size: 1024x1024\n"
                                "input image: light.rgb\nverbose: off\ntransmittance: 0.01\n",
                      image);
    const float answer = first_params(env->pass({query_at(3, {20, 25, 0}, {0})}, 0)).at(3);
    char text[32];
    std::snprintf(text, sizeof text, "%g", answer);
    EXPECT_STREQ(text, "0.623529");
}

TEST(Clover, PixelsAreTakenByTruncation)
{
    // 3 pixels over 5 cells: cell x takes pixel floor(x / 2); rounding would give cell 1
    // pixel 1
    auto env = clover("truncation",
                      "grid size: 5x5\ngrid position: 0 0\ngrid range: 5x5\ninput image: light.rgb\n",
                      image_of(3, 1, {{0, 10}, {0, 20}, {0, 30}}));
    auto answers = first_params(env->pass({query_at(1, {1.5f, 0.5f, 0}, {1}), query_at(2, {3.5f, 4.5f, 0}, {1}),
                                           query_at(3, {4.5f, 2.5f, 0}, {1})},
                                          0));
    EXPECT_EQ(answers.at(1), lit(10, 1, 0));
    EXPECT_EQ(answers.at(2), lit(20, 1, 0));
    EXPECT_EQ(answers.at(3), lit(30, 1, 0));
}

TEST(Clover, EachLeafOverACellMultipliesItsLightByTheTransmittance)
{
    // the question comes first in the string but is answered after the pass's leaves
    auto env = clover("leaves", four, two_by_two);
    auto answers = first_params(env->pass({query_at(1, {0.5f, 0.5f, 0}, {1}), query_at(2, {0.5f, 0.5f, 0}, {1, 0.01f}),
                                           query_at(3, {0.4f, 0.6f, 0}, {1, 0.01f})},
                                          0));
    EXPECT_EQ(answers.at(1), lit(100, 0.5f, 2));
    EXPECT_EQ(answers.size(), 1u);  // laying a leaf gets no answer
}

TEST(Clover, LeavesStayUntilRemoved)
{
    auto env = clover("persist", four, two_by_two);
    env->pass({query_at(1, {0.5f, 0.5f, 0}, {1, 0.01f})}, 0);
    EXPECT_EQ(first_params(env->pass({query_at(2, {0.5f, 0.5f, 0}, {1})}, 1)).at(2), lit(100, 0.5f, 1));
    EXPECT_EQ(first_params(env->pass({query_at(3, {0.5f, 0.5f, 0}, {2, 0.01f}),
                                      query_at(4, {0.5f, 0.5f, 0}, {1})},
                                     2))
                  .at(4),
              lit(100, 0.5f, 0));
    // with "remove old leaves" every pass starts bare
    auto bare = clover("remove_old", four + "remove old leaves: on\n", two_by_two);
    bare->pass({query_at(1, {0.5f, 0.5f, 0}, {1, 0.01f})}, 0);
    EXPECT_EQ(first_params(bare->pass({query_at(2, {0.5f, 0.5f, 0}, {1})}, 1)).at(2), lit(100, 0.5f, 0));
}

TEST(Clover, ACountNeverGoesBelowZero)
{
    // the removal on a bare cell changes nothing, so the leaf after it counts
    auto env = clover("clamp", four, two_by_two);
    auto answers = first_params(env->pass({query_at(1, {0.5f, 0.5f, 0}, {5, 0.01f}),
                                           query_at(2, {0.5f, 0.5f, 0}, {1, 0.01f}),
                                           query_at(3, {0.5f, 0.5f, 0}, {1})},
                                          0));
    EXPECT_EQ(answers.at(3), lit(100, 0.5f, 1));
}

TEST(Clover, OutsideTheGridIsDark)
{
    auto env = clover("outside", four, two_by_two);
    auto replies = env->pass({query_at(1, {-0.5f, 0.5f, 0}, {0, 1}), query_at(2, {0.5f, 4.5f, 0}, {1})}, 0);
    ASSERT_EQ(replies.size(), 2u);
    EXPECT_EQ(*replies[0].params[0], 0.0f);
    EXPECT_EQ(*replies[0].params[1], 0.0f);
    EXPECT_EQ(*replies[1].params[0], 0.0f);
}

TEST(Clover, ADiscCoversAnEllipseOverTheHalfOpenRangeOfCells)
{
    // area 4: radius 1.13, 2 cells a half-axis; offsets -2..1 on each axis where
    // x²/4 + y²/4 <= 1, around the centre's cell (2, 2); no image: full light
    auto env = clover("ellipse", "grid size: 8x8\ngrid position: 0 0\ngrid range: 8x8\ntransmittance: 0.5\n");
    std::vector<Query> queries{query_at(0, {2.5f, 2.5f, 0}, {1, 4})};
    const std::vector<std::pair<std::array<int, 2>, bool>> cells{
        {{0, 2}, true}, {{4, 2}, false}, {{2, 0}, true}, {{2, 4}, false}, {{1, 1}, true},
        {{3, 3}, true}, {{0, 0}, false}, {{3, 0}, false}, {{2, 2}, true}};
    for (std::size_t i = 0; i < cells.size(); ++i)
        queries.push_back(query_at(i + 1, {cells[i].first[0] + 0.5f, cells[i].first[1] + 0.5f, 0}, {1}));
    auto answers = first_params(env->pass(queries, 0));
    for (std::size_t i = 0; i < cells.size(); ++i)
        EXPECT_EQ(answers.at(i + 1), cells[i].second ? 0.5f : 1.0f)
            << "cell " << cells[i].first[0] << "," << cells[i].first[1];
}

TEST(Clover, TinyAreasAreNoLeaves)
{
    auto env = clover("tiny", four, two_by_two);
    auto answers = first_params(env->pass({query_at(1, {0.5f, 0.5f, 0}, {1, 5e-8f}),
                                           query_at(2, {3.5f, 0.5f, 0}, {1, 2e-7f}),
                                           query_at(3, {0.5f, 0.5f, 0}, {1}), query_at(4, {3.5f, 0.5f, 0}, {1})},
                                          0));
    EXPECT_EQ(answers.at(3), lit(100, 0.5f, 0));
    EXPECT_EQ(answers.at(4), lit(120, 0.5f, 1));
}

TEST(Clover, ZeroTransmittanceBecomesOneTenThousandth)
{
    auto env = clover("zero", "grid size: 4x4\ngrid position: 0 0\ngrid range: 4x4\ntransmittance: 0\n");
    auto answers = first_params(env->pass({query_at(1, {0.5f, 0.5f, 0}, {1, 0.01f}),
                                           query_at(2, {0.5f, 0.5f, 0}, {1})},
                                          0));
    EXPECT_EQ(answers.at(2), lit(255, 0.0001f, 1));
}

TEST(Clover, WithZNotUpTheGroundIsXAndZ)
{
    auto env = clover("z_not_up", four + "z is up: no\n", two_by_two);
    auto answers = first_params(env->pass({query_at(1, {3.5f, 99, 3.5f}, {1}), query_at(2, {3.5f, 3.5f, 0.5f}, {1})}, 0));
    EXPECT_EQ(answers.at(1), lit(220, 0.5f, 0));
    EXPECT_EQ(answers.at(2), lit(120, 0.5f, 0));
}

TEST(Clover, OversizedGridsAndMissingImagesAreErrors)
{
    EXPECT_THROW(clover("huge", "grid size: 5000x5000\n"), Error);
    EXPECT_THROW(clover("no_cells", "grid size: 0x8\n"), Error);
    EXPECT_THROW(clover("no_image", "input image: other.rgb\n"), Error);
    Context context = model_with("clover_no_reader", "enviro.spec", "input image: light.rgb\n");
    EXPECT_THROW(make_builtin("clover", {"enviro.spec"}, context), Error);
}

// A FIFO would block the image reader forever and a device never ends: refused before
// the reader is called, naming the spec line.
TEST(Clover, AnImageThatIsNoRegularFileIsRefusedAtItsLine)
{
    Context fifo = clover_model("fifo", "grid size: 4x4\ninput image: pipe.rgb\n", two_by_two);
    ASSERT_EQ(::mkfifo((fifo.folder / "pipe.rgb").c_str(), 0600), 0);
    bool read = false;
    fifo.read_image = [&read](const std::filesystem::path&) {
        read = true;
        return two_by_two;
    };
    try {
        make_builtin("clover", {"enviro.spec"}, fifo);
        ADD_FAILURE() << "a FIFO image was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.loc().file, (fifo.folder / "enviro.spec").string());
        EXPECT_EQ(e.loc().line, 2);
        EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(read);

    Context device = clover_model("device", "input image: /dev/zero\n", two_by_two);
    device.allow_file_access = true;
    device.read_image = fifo.read_image;
    EXPECT_THROW(make_builtin("clover", {"enviro.spec"}, device), Error);
    EXPECT_FALSE(read);
}

}  // namespace
}  // namespace cambium::env
