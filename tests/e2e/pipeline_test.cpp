// SPDX-License-Identifier: Apache-2.0
// End-to-end: L-system text -> derivation -> turtle -> path tracer -> image, checked
// against facts computed here independently (cpfg's framing, symmetry, lighting).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <OpenImageIO/imageio.h>

#include "geom/interpreter.h"
#include "geom/palette.h"
#include "lsys/lsystem.h"
#include "render/render.h"

using namespace cambium;

namespace {

struct Rendered {
    render::Image image;
    geom::Scene scene;
};

Rendered render_model(const std::string& lsystem, const std::string& view, int w, int h, int spp,
                      geom::Rgb background = {0, 0, 0})
{
    lsys::LSystem l = lsys::LSystem::from_source(lsystem, "e2e.l");
    lsys::ModuleString s = l.derive();
    geom::Scene scene = geom::interpret(s, l.symbols(), geom::parse_view_file(view, "e2e.v"));
    for (auto& m : scene.materials)
        m.diffuse = {0.8f, 0.8f, 0.8f};
    scene.background = background;
    render::RenderSettings settings;
    settings.width = w;
    settings.height = h;
    settings.samples_per_pixel = spp;
    settings.max_depth = 3;
    return {render::render(scene, settings), scene};
}

float channel(const render::Image& im, int x, int y, int c)
{
    return im.rgba[(static_cast<std::size_t>(y) * im.width + x) * 4 + c];
}

struct Box {
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
};

/// Pixels whose coverage (alpha) is at least one half.
Box silhouette(const render::Image& im)
{
    Box b;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            if (channel(im, x, y, 3) >= 0.5f) {
                b.x0 = std::min(b.x0, x);
                b.x1 = std::max(b.x1, x);
                b.y0 = std::min(b.y0, y);
                b.y1 = std::max(b.y1, y);
            }
    return b;
}

}  // namespace

// An L: up 10, right 6, width 0.5. cpfg's parallel auto-fit (control.c, verified on
// the corpus oracle images) maps the box's centre to the image centre with
// k = W / (2 * max(sx, sy * W / H) / scale) pixels per unit. Here: box x 0..6,
// y 0..10, W x H = 96 x 72, scale 0.8 -> span 8.333, k = 5.76 px per unit.
TEST(Pipeline, SilhouetteLiesWhereCpfgsCameraPutsIt)
{
    Rendered r = render_model("lsystem: 1\nderivation length: 0\naxiom: F(10)-(90)F(6)\nendlsystem\n",
                              "angle factor: 4\nline style: cylinder\ninitial line width: 0.5\n"
                              "scale factor: 0.8\nlight: V: 0 0 1\n",
                              96, 72, 16);
    const double k = 96.0 / (2 * (5.0 / 0.75) / 0.8);
    const double r_px = 0.25 * k;
    auto px = [&](double x) { return 48 + (x - 3) * k; };
    auto py = [&](double y) { return 36 - (y - 5) * k; };
    Box b = silhouette(r.image);
    // Pixel i covers [i, i+1): a pixel is in when at least half of it is covered.
    // The free ends are cut square as cpfg's cylinders are; the corner is round.
    EXPECT_NEAR(b.x0, px(0) - r_px, 1.0);
    EXPECT_NEAR(b.x1 + 1, px(6), 1.0);
    EXPECT_NEAR(b.y0, py(10) - r_px, 1.0);
    EXPECT_NEAR(b.y1 + 1, py(0), 1.0);
}

TEST(Pipeline, BackgroundPixelsAreTheBackgroundColourInThePng)
{
    // Colour as a colormap holds it: bytes (10, 80, 200).
    geom::Rgb bg{10 / 255.0f, 80 / 255.0f, 200 / 255.0f};
    Rendered r = render_model("lsystem: 1\nderivation length: 0\naxiom: F(10)\nendlsystem\n",
                              "line style: cylinder\ninitial line width: 0.4\nscale factor: 0.5\n",
                              48, 48, 4, bg);
    auto file = std::filesystem::temp_directory_path() / "cambium_e2e_background.png";
    render::write_image(r.image, file);
    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in);
    std::vector<unsigned char> pixels(48 * 48 * in->spec().nchannels);
    ASSERT_TRUE(in->read_image(0, 0, 0, -1, OIIO::TypeDesc::UINT8, pixels.data()));
    int n = in->spec().nchannels;
    for (int corner : {0, 47, 48 * 47, 48 * 48 - 1}) {
        EXPECT_EQ(pixels[corner * n + 0], 10);
        EXPECT_EQ(pixels[corner * n + 1], 80);
        EXPECT_EQ(pixels[corner * n + 2], 200);
    }
}

// A trunk with two branches mirrored about it, lit from the viewer's side: the image
// must equal its left-right mirror within Monte Carlo noise.
TEST(Pipeline, MirrorSymmetricModelGivesMirrorSymmetricImage)
{
    Rendered r = render_model(
        "lsystem: 1\nderivation length: 3\naxiom: A(8)\n"
        "A(x) --> F(x)[+(40)A(x*0.6)][-(40)A(x*0.6)]\nendlsystem\n",
        "line style: cylinder\ninitial line width: 0.6\nlight: V: 0 0 1\n", 64, 64, 64);
    ASSERT_GT(r.scene.geometry.lines.segment_count(), 5u);
    const auto& im = r.image;
    double diff = 0, total = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            for (int c = 0; c < 4; ++c) {
                float a = channel(im, x, y, c), b = channel(im, im.width - 1 - x, y, c);
                diff += std::fabs(a - b);
                total += a;
            }
    EXPECT_GT(total, 0);
    EXPECT_LT(diff / total, 0.05) << "relative asymmetry";
}

// Lit from +x, a thick vertical trunk is bright on its right side, dark on its left,
// and never black where it faces the light.
TEST(Pipeline, LitPlantIsNotBlackAndFacesItsLight)
{
    Rendered r = render_model("lsystem: 1\nderivation length: 0\naxiom: F(10)\nendlsystem\n",
                              "line style: cylinder\ninitial line width: 4\nlight: V: 1 0 0\n",
                              64, 64, 32);
    const auto& im = r.image;
    Box b = silhouette(im);
    ASSERT_GT(b.x1 - b.x0, 6);
    int y = (b.y0 + b.y1) / 2;
    double left = 0, right = 0;
    for (int x = b.x0; x <= b.x1; ++x) {
        double lum = channel(im, x, y, 0) + channel(im, x, y, 1) + channel(im, x, y, 2);
        (x < (b.x0 + b.x1) / 2 ? left : right) += lum;
    }
    EXPECT_GT(right, 0.1);
    EXPECT_GT(right, 3 * left);
}

// cpfg draws `line style: pixel` lines unlit in their colour: the centre of a 5-pixel
// line shows exactly the material's colour, whatever the lights.
TEST(Pipeline, PixelLinesShowTheirFlatColour)
{
    lsys::LSystem l = lsys::LSystem::from_source(
        "lsystem: 1\nderivation length: 0\naxiom: -(90)F(10)\nendlsystem\n", "e2e.l");
    geom::Scene scene = geom::interpret(
        l.derive(), l.symbols(),
        geom::parse_view_file("initial line width: 5 pixels\ninitial color: 3\n"
                              "light: V: 0 1 0\nscale factor: 0.5\n", "e2e.v"));
    scene.materials[3].diffuse = {1.0f, 0.5f, 0.25f};
    render::RenderSettings settings;
    settings.width = 40;
    settings.height = 40;
    settings.samples_per_pixel = 8;
    render::Image im = render::render(scene, settings);
    // sRGB 0.5 decodes to 0.2140 linear, 0.25 to 0.0508.
    EXPECT_NEAR(channel(im, 20, 20, 0), 1.0, 1e-3);
    EXPECT_NEAR(channel(im, 20, 20, 1), 0.2140, 1e-3);
    EXPECT_NEAR(channel(im, 20, 20, 2), 0.0508, 1e-3);
}
