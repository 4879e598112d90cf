// SPDX-License-Identifier: Apache-2.0
// Tests of colormap and material file reading and of the colour table's blocks.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "base/diagnostics.h"
#include "geom/palette.h"

using namespace cambium;
using namespace cambium::geom;

namespace {
std::filesystem::path write_bytes(const std::string& name, const std::vector<unsigned char>& bytes)
{
    auto path = std::filesystem::temp_directory_path() / ("cambium_palette_" + name);
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                static_cast<std::streamsize>(bytes.size()));
    return path;
}
}  // namespace

TEST(Palette, ColormapEntriesAreDiffuseAndEntryZeroIsBackground)
{
    std::vector<unsigned char> bytes(768, 0);
    bytes[0] = 10; bytes[1] = 20; bytes[2] = 30;          // entry 0
    bytes[3 * 7] = 255; bytes[3 * 7 + 1] = 51;             // entry 7
    Palette palette;
    palette.load_colormap(1, write_bytes("a.map", bytes));
    auto entries = palette.entries(1);
    EXPECT_FLOAT_EQ(entries[7].diffuse.r, 1.0f);
    EXPECT_FLOAT_EQ(entries[7].diffuse.g, 0.2f);
    // cpfg draws colour indices without OpenGL lighting: no ambient term
    EXPECT_FLOAT_EQ(entries[7].ambient.r, 0.0f);
    EXPECT_FLOAT_EQ(palette.background(1).g, 20 / 255.0f);
}

TEST(Palette, ColormapOfWrongSizeIsAnErrorNamingTheFile)
{
    auto path = write_bytes("short.map", std::vector<unsigned char>(700, 1));
    try {
        read_colormap(path);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("short.map"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("768"), std::string::npos);
    }
}

TEST(Palette, MaterialRecordsByIdAndBackgroundFromEmission)
{
    // id, transparency, ambient, diffuse, emission, specular, shininess
    std::vector<unsigned char> bytes = {0, 0, 0, 0, 0, 0, 0, 0, 5, 6, 7, 0, 0, 0, 0,
                                        3, 51, 1, 2, 3, 255, 0, 102, 0, 0, 0, 9, 9, 9, 64};
    Palette palette;
    palette.load_materials(1, write_bytes("a.mat", bytes));
    auto m = palette.entries(1);
    EXPECT_FLOAT_EQ(m[3].diffuse.r, 1.0f);
    EXPECT_FLOAT_EQ(m[3].diffuse.b, 0.4f);
    EXPECT_FLOAT_EQ(m[3].transparency, 0.2f);
    EXPECT_FLOAT_EQ(m[3].shininess, 64.0f);
    EXPECT_FLOAT_EQ(m[2].diffuse.r, 1.0f);  // undefined ids get cpfg's white default
    EXPECT_FLOAT_EQ(m[2].ambient.r, 0.0f);
    EXPECT_FLOAT_EQ(palette.background(1).b, 7 / 255.0f);
}

TEST(Palette, AnEmptyBlockIsCpfgsGreyAndMixingModesIsAnError)
{
    Palette palette;
    palette.load_colormap(1, write_bytes("b.map", std::vector<unsigned char>(768, 0)));
    EXPECT_FLOAT_EQ(palette.entries(2)[5].diffuse.g, 200 / 255.0f);
    EXPECT_THROW(palette.entries(16), Error);
    EXPECT_THROW(palette.load_materials(1, write_bytes("c.mat", std::vector<unsigned char>(15, 0))),
                 Error);
}
