// SPDX-License-Identifier: Apache-2.0
// write_image: formats, exact background bytes, no partial files on failure.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "base/diagnostics.h"
#include "render/color.h"
#include "render/image_io.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

namespace fs = std::filesystem;

/// A fresh empty folder under the system temp folder, removed afterwards.
class TempDir {
public:
    TempDir()
    {
        m_path = fs::temp_directory_path() /
                 ("cambium_film_test_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(m_path);
        fs::create_directories(m_path);
    }
    ~TempDir()
    {
        std::error_code ec;
        fs::permissions(m_path, fs::perms::owner_all, ec);
        fs::remove_all(m_path, ec);
    }
    const fs::path& path() const { return m_path; }

private:
    fs::path m_path;
};

Image gradient(int w, int h)
{
    Image img{w, h, std::vector<float>(std::size_t(w) * h * 4)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            img.at(x, y, 0) = float(x) / w;
            img.at(x, y, 1) = float(y) / h;
            img.at(x, y, 2) = 0.25f;
            img.at(x, y, 3) = x < w / 2 ? 1.0f : 0.0f;
        }
    return img;
}

std::vector<float> read_back(const fs::path& file, OIIO::ImageSpec& spec,
                             OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT)
{
    auto in = OIIO::ImageInput::open(file.string());
    EXPECT_TRUE(in) << OIIO::geterror();
    if (!in)
        return {};
    spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    return px;
}

// The background of cpfg's window (e.g. Horneophyton's 161,161,161 or 08-leaf-pos's
// 179,229,164) must come back as the same bytes after decode, render, encode, PNG.
TEST(WriteImage, BackgroundRoundTripsToExactPngBytes)
{
    TempDir dir;
    geom::Scene s = testing::empty_scene({-1, -1, 0}, {1, 1, 0});
    for (int trial = 0; trial < 3; ++trial) {
        const unsigned char bytes[3][3] = {{161, 161, 161}, {179, 229, 164}, {0, 36, 6}};
        s.background = {bytes[trial][0] / 255.0f, bytes[trial][1] / 255.0f,
                        bytes[trial][2] / 255.0f};
        RenderSettings set;
        set.width = 20;
        set.height = 10;
        set.samples_per_pixel = 3;
        Image img = render(s, set);
        fs::path file = dir.path() / "bg.png";
        write_image(img, file);
        auto in = OIIO::ImageInput::open(file.string());
        ASSERT_TRUE(in);
        ASSERT_EQ(in->spec().nchannels, 3);
        std::vector<unsigned char> px(20 * 10 * 3);
        ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
        for (std::size_t i = 0; i < px.size(); ++i)
            ASSERT_EQ(px[i], bytes[trial][i % 3]) << "byte " << i;
    }
}

TEST(WriteImage, PngIsSrgbEncoded)
{
    TempDir dir;
    Image img{1, 1, {0.318547f, 0.5f, 1.5f, 1.0f}};  // 0.318547 linear = 0.6 display
    write_image(img, dir.path() / "one.png");
    OIIO::ImageSpec spec;
    auto px = read_back(dir.path() / "one.png", spec);
    ASSERT_EQ(px.size(), 3u);
    EXPECT_NEAR(px[0] * 255, 153, 0.01);  // 0.6 * 255
    EXPECT_NEAR(px[1] * 255, 188, 0.01);  // sRGB(0.5) = 0.7354
    EXPECT_NEAR(px[2] * 255, 255, 0.01);  // clamped
}

TEST(WriteImage, ExrKeepsLinearRgbaAndCoverage)
{
    TempDir dir;
    Image img = gradient(16, 8);
    img.at(3, 2, 0) = 4.0f;  // over 1: EXR keeps it
    write_image(img, dir.path() / "g.exr");
    OIIO::ImageSpec spec;
    auto px = read_back(dir.path() / "g.exr", spec);
    ASSERT_EQ(spec.nchannels, 4);
    ASSERT_EQ(spec.width, 16);
    for (std::size_t i = 0; i < px.size(); ++i)
        EXPECT_NEAR(px[i], img.rgba[i], 1e-3f * std::max(1.0f, img.rgba[i]));
}

TEST(WriteImage, TiffAndJpegAreReadable)
{
    TempDir dir;
    Image img = gradient(16, 8);
    for (const char* name : {"g.tif", "g.jpg"}) {
        write_image(img, dir.path() / name);
        OIIO::ImageSpec spec;
        auto px = read_back(dir.path() / name, spec);
        EXPECT_EQ(spec.width, 16) << name;
        EXPECT_EQ(spec.height, 8) << name;
    }
}

// cpfg's -rgb and -tga snapshots: SGI and Targa files hold the same 8-bit sRGB pixels
// as the PNG, and keep a transparent render's alpha.
TEST(WriteImage, SgiAndTargaHoldThePngsPixels)
{
    TempDir dir;
    Image img = gradient(16, 8);
    write_image(img, dir.path() / "g.png");
    OIIO::ImageSpec png_spec;
    const auto png = read_back(dir.path() / "g.png", png_spec);
    for (const char* name : {"g.rgb", "g.SGI", "g.tga"}) {
        write_image(img, dir.path() / name);
        OIIO::ImageSpec spec;
        const auto px = read_back(dir.path() / name, spec);
        EXPECT_EQ(spec.width, 16) << name;
        EXPECT_EQ(spec.nchannels, png_spec.nchannels) << name;
        EXPECT_EQ(px, png) << name;
    }
    img.transparent = true;
    write_image(img, dir.path() / "t.tga");
    OIIO::ImageSpec spec;
    read_back(dir.path() / "t.tga", spec);
    EXPECT_EQ(spec.nchannels, 4);
}

// The target is an existing folder: OIIO writes the temporary file, the rename fails.
// The temporary file must be gone and the error must name the target.
TEST(WriteImage, FailedRenameLeavesNoTemporaryFileAndNamesTarget)
{
    TempDir dir;
    fs::path file = dir.path() / "taken.png";
    fs::create_directories(file / "inside");
    try {
        write_image(gradient(4, 4), file);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
    std::size_t entries = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path()))
        ++entries;
    EXPECT_EQ(entries, 1u);  // only the folder that was in the way
}

// A folder that cannot be written (a regular file stands where the folder should be, which
// fails even for root): an error naming the file, nothing written.
TEST(WriteImage, UnwritableFolderFailsCleanly)
{
    TempDir dir;
    fs::path blocker = dir.path() / "not_a_folder";
    { std::ofstream(blocker) << "x"; }
    fs::path file = blocker / "out.exr";
    try {
        write_image(gradient(4, 4), file);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
    std::size_t entries = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path()))
        ++entries;
    EXPECT_EQ(entries, 1u);
}

TEST(WriteImage, MissingFolderAndUnknownFormatFailCleanly)
{
    TempDir dir;
    EXPECT_THROW(write_image(gradient(4, 4), dir.path() / "no" / "such.png"), Error);
    EXPECT_THROW(write_image(gradient(4, 4), dir.path() / "out.xyz"), Error);
    try {  // cpfg's Sun raster and Utah RLE: no library here writes them
        check_output_format(dir.path() / "out.ras");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(".png, .exr, .tif, .jpg, .rgb or .tga"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(write_image(gradient(4, 4), dir.path() / "out.mp4"), Error);  // a video, not an image
    EXPECT_THROW(write_image(Image{}, dir.path() / "out.png"), Error);
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

// A rename over an existing file replaces it whole; a failed write keeps the old one.
TEST(WriteImage, FailedWriteKeepsThePreviousFile)
{
    TempDir dir;
    fs::path file = dir.path() / "keep.exr";
    write_image(gradient(8, 8), file);
    auto before = fs::file_size(file);
    Image bad{8, 8, std::vector<float>(3)};  // malformed
    EXPECT_THROW(write_image(bad, file), Error);
    EXPECT_EQ(fs::file_size(file), before);
    std::size_t entries = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path()))
        ++entries;
    EXPECT_EQ(entries, 1u);
}

}  // namespace
}  // namespace cambium::render
