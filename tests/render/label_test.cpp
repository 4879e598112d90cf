// SPDX-License-Identifier: Apache-2.0
// `@L` labels drawn onto the image: at the projected anchor, in the label's colour,
// hidden by what is in front of the anchor, and a clear error without any font.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "base/diagnostics.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/labels.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using testing::empty_scene;
using testing::small;

constexpr std::uint16_t red = 2, grey = 1;

/// A label "MMM" in red at the origin, seen from +z (parallel), on black.
geom::Scene labelled_scene()
{
    geom::Scene s = empty_scene({-1, -1, -1}, {1, 1, 1});
    s.materials[red].diffuse = {1, 0, 0};
    s.materials[grey].diffuse = {0.5f, 0.5f, 0.5f};
    s.labels.push_back({"MMM", {0, 0, 0}, red});
    s.label_font.pixel_size = 16;
    return s;
}

/// A square of two triangles covering x, y in [-2, 2] at height z, facing +z.
void add_square(geom::Scene& s, float z)
{
    auto base = static_cast<std::uint32_t>(s.geometry.mesh.positions.size());
    for (auto [x, y] : {std::pair{-2.0f, -2.0f}, {2.0f, -2.0f}, {2.0f, 2.0f}, {-2.0f, 2.0f}}) {
        s.geometry.mesh.positions.push_back({x, y, z});
        s.geometry.mesh.normals.push_back({0, 0, 1});
    }
    s.geometry.mesh.triangles.push_back({base, base + 1, base + 2});
    s.geometry.mesh.triangles.push_back({base, base + 2, base + 3});
    s.geometry.mesh.material.insert(s.geometry.mesh.material.end(), 2, grey);
    s.geometry.mesh.back_material.insert(s.geometry.mesh.back_material.end(), 2, grey);
}

struct RedPixels {
    int near_anchor = 0, elsewhere = 0;
};

/// Red pixels in the box a 16-pixel "MMM" starting at the anchor takes, and elsewhere.
RedPixels red_pixels(const geom::Scene& s)
{
    RenderSettings settings = small(96, 96, 1);
    Image image = render(s, settings);
    PixelPoint p = make_camera(s.view, s.bounds, 96, 96).project({0, 0, 0});
    RedPixels n;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            bool is_red = image.at(x, y, 0) > 0.5f && image.at(x, y, 1) < 0.05f && image.at(x, y, 2) < 0.05f;
            bool in_box = x >= p.x - 1 && x <= p.x + 45 && y >= p.y - 16 && y <= p.y + 2;
            (in_box ? n.near_anchor : n.elsewhere) += is_red ? 1 : 0;
        }
    return n;
}

TEST(Labels, TextAppearsAtTheProjectedAnchorInItsColour)
{
    RedPixels n = red_pixels(labelled_scene());
    EXPECT_GT(n.near_anchor, 40);  // three 16-pixel Ms have far more than 40 full pixels
    EXPECT_EQ(n.elsewhere, 0);
}

TEST(Labels, SurfaceInFrontHidesTheLabelOneBehindDoesNot)
{
    geom::Scene front = labelled_scene();
    add_square(front, 0.5f);  // between the camera (+z) and the anchor
    EXPECT_EQ(red_pixels(front).near_anchor, 0);
    geom::Scene behind = labelled_scene();
    add_square(behind, -0.5f);
    EXPECT_GT(red_pixels(behind).near_anchor, 40);
}

TEST(Labels, AnchorOffTheImageDrawsNothing)
{
    geom::Scene s = labelled_scene();
    s.labels[0].position = {50, 0, 0};
    RedPixels n = red_pixels(s);
    EXPECT_EQ(n.near_anchor + n.elsewhere, 0);
}

/// A rectangle of two triangles covering x in [x0, x1], y in [-2, 2] at height z, facing +z.
void add_rectangle(geom::Scene& s, float x0, float x1, float z)
{
    auto base = static_cast<std::uint32_t>(s.geometry.mesh.positions.size());
    for (auto [x, y] : {std::pair{x0, -2.0f}, {x1, -2.0f}, {x1, 2.0f}, {x0, 2.0f}}) {
        s.geometry.mesh.positions.push_back({x, y, z});
        s.geometry.mesh.normals.push_back({0, 0, 1});
    }
    s.geometry.mesh.triangles.push_back({base, base + 1, base + 2});
    s.geometry.mesh.triangles.push_back({base, base + 2, base + 3});
    s.geometry.mesh.material.insert(s.geometry.mesh.material.end(), 2, grey);
    s.geometry.mesh.back_material.insert(s.geometry.mesh.back_material.end(), 2, grey);
}

TEST(Labels, EachPixelIsHiddenByWhatIsInFrontOfItsOwnLabel)
{
    // A rectangle at z = 0.5 covers the right part of two labels' pixels: the red label
    // behind it (z = 0) loses exactly those pixels, the green one in front (z = 0.8), drawn
    // after it over the same columns, keeps all of them.
    constexpr std::uint16_t green = 3;
    geom::Scene s = labelled_scene();
    s.materials[green].diffuse = {0, 1, 0};
    s.labels.push_back({"MMM", {0, -0.5, 0.8}, green});
    add_rectangle(s, 0.25f, 2, 0.5f);
    Image image = render(s, small(96, 96, 1));
    Camera camera = make_camera(s.view, s.bounds, 96, 96);
    const int edge = static_cast<int>(camera.project({0.25, 0, 0}).x);
    const int red_row = static_cast<int>(camera.project({0, 0, 0}).y);
    const int green_row = static_cast<int>(camera.project({0, -0.5, 0.8}).y);
    ASSERT_GT(green_row, red_row + 20);  // the labels' rows do not overlap
    int red_left = 0, red_right = 0, green_left = 0, green_right = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            bool red = image.at(x, y, 0) > 0.5f && image.at(x, y, 1) < 0.05f;
            bool green_pixel = image.at(x, y, 1) > 0.5f && image.at(x, y, 0) < 0.05f;
            if (red && y <= red_row + 2)
                (x < edge ? red_left : red_right) += 1;
            if (green_pixel && y > red_row + 2)
                (x < edge ? green_left : green_right) += 1;
        }
    EXPECT_GT(red_left, 5);
    EXPECT_EQ(red_right, 0);  // behind the rectangle
    EXPECT_GT(green_left, 5);
    EXPECT_GT(green_right, 20);  // in front of it, over pixels the red label's test traced
}

TEST(Labels, GlyphPixelsAndMemoryPastTheirLimitsAreErrorsBeforeDrawing)
{
    geom::Scene s = labelled_scene();
    Camera camera = make_camera(s.view, s.bounds, 96, 96);
    EmbreeScene accel(s, camera);
    Image image{96, 96, std::vector<float>(96 * 96 * 4, 0.0f)};
    auto message = [&](const LabelLimits& limits) {
        try {
            draw_labels(image, s, camera, accel, std::nullopt, limits);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    LabelLimits pixels;
    pixels.max_glyph_pixels = 100;  // three 16-pixel Ms cover more
    EXPECT_NE(message(pixels).find("labels: the @L labels (1) cover more than 100 glyph pixels "
                                   "in all, the most labels may draw"),
              std::string::npos)
        << message(pixels);
    LabelLimits memory;
    memory.max_memory_bytes = 16 << 10;  // the depths of 96 x 96 pixels alone take 36 KiB
    EXPECT_NE(message(memory).find("labels: the glyphs of the label font (courier, 16 pixels) "
                                   "and the hidden-pixel depths need 36."),
              std::string::npos)
        << message(memory);
    EXPECT_NE(message(memory).find("more than the memory budget of 16.0 KiB (--max-memory)"),
              std::string::npos);
    for (float v : image.rgba)
        ASSERT_EQ(v, 0.0f);  // nothing was drawn
    EXPECT_EQ(message(LabelLimits{}), "");
    int drawn = 0;
    for (std::size_t i = 3; i < image.rgba.size(); i += 4)
        drawn += image.rgba[i] > 0.5f ? 1 : 0;
    EXPECT_GT(drawn, 40);
}

TEST(Labels, NoFontAtAllIsAnErrorSayingWhatToInstall)
{
    auto dir = std::filesystem::temp_directory_path() / "cambium_label_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "empty.conf") << "<?xml version=\"1.0\"?>\n<fontconfig></fontconfig>\n";
    const char* saved = std::getenv("FONTCONFIG_FILE");
    std::string saved_value = saved ? saved : "";
    setenv("FONTCONFIG_FILE", (dir / "empty.conf").c_str(), 1);
    std::string message;
    try {
        render(labelled_scene(), small(32, 32, 1));
    } catch (const Error& e) {
        message = e.what();
    }
    if (saved)
        setenv("FONTCONFIG_FILE", saved_value.c_str(), 1);
    else
        unsetenv("FONTCONFIG_FILE");
    EXPECT_NE(message.find("no font found for 'courier'"), std::string::npos) << message;
    EXPECT_NE(message.find("fonts-dejavu-core"), std::string::npos) << message;
}

}  // namespace
}  // namespace cambium::render
