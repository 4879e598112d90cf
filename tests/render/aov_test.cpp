// SPDX-License-Identifier: Apache-2.0
// Film output: EXR layers (albedo, normal, depth), transparent PNG, exposure.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <unistd.h>

#include "render/color.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

namespace fs = std::filesystem;

fs::path temp_folder()
{
    fs::path p = fs::temp_directory_path() /
                 ("cambium_aov_test_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(p);
    return p;
}

// A perspective camera at z = 20 looking at a segment of radius 2 along x through the
// origin: the centre pixel's ray hits the top of the cylinder at distance 18.
TEST(Aov, ExrHasLayersAndTheCameraDistance)
{
    geom::Scene s = testing::empty_scene({-5, -5, -5}, {5, 5, 5});
    testing::add_segment(s, {-20, 0, 0}, {20, 0, 0}, 2.0f);
    s.materials[1].diffuse = {0.6f, 0.4f, 0.2f};
    Camera camera = Camera::perspective({0, 0, 20}, {0, 0, 0}, {0, 1, 0}, 30, 32, 32);
    RenderSettings set;
    set.width = set.height = 32;
    set.samples_per_pixel = 4;
    set.max_depth = 1;
    set.threads = 2;
    Image img = render(s, camera, set);
    ASSERT_EQ(img.depth.size(), 32u * 32u);
    fs::path dir = temp_folder();
    fs::path file = dir / "layers.exr";
    write_image(img, file);

    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<std::string> expected{"R", "G", "B", "A", "albedo.R", "albedo.G", "albedo.B",
                                      "normal.X", "normal.Y", "normal.Z", "Z"};
    ASSERT_EQ(spec.nchannels, int(expected.size()));
    // OpenEXR stores channels sorted by name; compare as sets.
    std::vector<std::string> names(spec.channelnames.begin(), spec.channelnames.end());
    std::sort(names.begin(), names.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(names, expected);
    std::vector<float> px(std::size_t(32) * 32 * spec.nchannels);
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    auto channel = [&](const std::string& name, int x, int y) {
        int c = spec.channelindex(name);
        EXPECT_GE(c, 0) << name;
        return px[(std::size_t(y) * 32 + x) * spec.nchannels + c];
    };
    // Pixel (16, 16) spans 0..0.335 units right and down of the axis at the focus plane:
    // its rays meet the cylinder at y <= 0.17 * 18/20, so z >= 1.993, distance <= 18.01.
    EXPECT_NEAR(channel("Z", 16, 16), 18.0f, 0.02f);
    EXPECT_TRUE(std::isinf(channel("Z", 16, 0)));  // above the cylinder: nothing
    EXPECT_NEAR(channel("normal.Z", 16, 16), 1.0f, 0.01f);
    EXPECT_NEAR(channel("albedo.R", 16, 16), srgb_to_linear(0.6f), 2e-3f);
    EXPECT_NEAR(channel("albedo.B", 16, 16), srgb_to_linear(0.2f), 2e-3f);
    EXPECT_EQ(channel("A", 16, 16), 1.0f);
    EXPECT_EQ(channel("albedo.R", 16, 0), 0.0f);
    in->close();
    fs::remove_all(dir);
}

TEST(Aov, TransparentPngHasStraightAlpha)
{
    fs::path dir = temp_folder();
    // Half-covered pixel of linear colour 0.318547 (display 0.6) over nothing.
    Image img{2, 1, {0.318547f * 0.5f, 0, 0, 0.5f, 0, 0, 0, 0}};
    img.transparent = true;
    write_image(img, dir / "t.png");
    // Read the file's bytes as they are (OIIO would premultiply them by default).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open((dir / "t.png").string(), &config);
    ASSERT_TRUE(in);
    ASSERT_EQ(in->spec().nchannels, 4);
    unsigned char px[8];
    ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, px));
    EXPECT_EQ(px[0], 153);  // straight colour: 0.6 * 255
    EXPECT_EQ(px[3], 128);  // 0.5 * 255 rounded
    EXPECT_EQ(px[7], 0);
    in->close();
    // Opaque images stay RGB.
    img.transparent = false;
    write_image(img, dir / "o.png");
    EXPECT_EQ(OIIO::ImageInput::open((dir / "o.png").string())->spec().nchannels, 3);
    fs::remove_all(dir);
}

TEST(Aov, ExposureScalesDisplayFormatsOnly)
{
    fs::path dir = temp_folder();
    Image img{1, 1, {0.318547f / 4, 0.5f, 0.25f, 1.0f}};
    WriteOptions plus_two;
    plus_two.exposure = 2;  // x4
    write_image(img, dir / "e.png", plus_two);
    write_image(img, dir / "e.exr", plus_two);
    float png[3], exr[4];
    auto in = OIIO::ImageInput::open((dir / "e.png").string());
    ASSERT_TRUE(in);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, png));
    EXPECT_NEAR(png[0] * 255, 153, 0.01);
    EXPECT_NEAR(png[1] * 255, 255, 0.01);  // 2.0 clamps
    in = OIIO::ImageInput::open((dir / "e.exr").string());
    ASSERT_TRUE(in);
    ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, exr));
    EXPECT_NEAR(exr[1], 0.5f, 1e-3f);  // EXR stays scene-referred
    fs::remove_all(dir);
}

}  // namespace
}  // namespace cambium::render
