// SPDX-License-Identifier: Apache-2.0
// TextureSet (OIIO TextureSystem): orientation, sRGB decoding, modulate/decal, formats,
// missing files, and alpha cut-outs in EmbreeScene.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "render/accel.h"
#include "render/color.h"
#include "render/texture.h"
#include "geom_scenes.h"
#include "render/integrator.h"
#include "render/light.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using namespace testing;
namespace fs = std::filesystem;

constexpr float inf = std::numeric_limits<float>::infinity();

/// A fresh folder under the system temp dir for this test.
fs::path temp_dir()
{
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path d = fs::temp_directory_path() /
                 (std::string("cambium_texture_") + info->name() + "_" +
                  std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

/// Writes an 8-bit image of w x h pixels, `channels` per pixel, top row first.
void write_image(const fs::path& file, int w, int h, int channels,
                 const std::vector<std::uint8_t>& pixels)
{
    auto out = OIIO::ImageOutput::create(file.string());
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::UINT8);
    ASSERT_TRUE(out->open(file.string(), spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    out->close();
}

/// 2x2 RGBA: top row red (opaque), green (alpha 0); bottom row blue (opaque), 50% grey
/// (alpha 1).
std::vector<std::uint8_t> quadrants()
{
    return {255, 0, 0, 255, 0, 255, 0, 0, 0, 0, 255, 255, 128, 128, 128, 255};
}

geom::TextureDef nearest(const fs::path& file)
{
    geom::TextureDef d;
    d.file = file;
    d.linear_filter = false;
    d.mipmap = false;
    return d;
}

// OpenGL's t runs up: t near 1 is the image's top row; 8-bit values decode as sRGB.
TEST(Texture, OrientationAndDecoding)
{
    fs::path dir = temp_dir();
    write_image(dir / "q.png", 2, 2, 4, quadrants());
    TextureSet set({nearest(dir / "q.png")});
    ASSERT_EQ(set.size(), 1u);
    EXPECT_TRUE(set.has_alpha(0));
    Texel top_left = set.lookup(0, 0.25f, 0.75f);
    EXPECT_NEAR(top_left.colour.x, 1, 1e-4f);
    EXPECT_NEAR(top_left.colour.y, 0, 1e-4f);
    EXPECT_NEAR(top_left.alpha, 1, 1e-4f);
    // Colours are not multiplied by alpha (cpfg's GL textures are unassociated).
    Texel top_right = set.lookup(0, 0.75f, 0.75f);
    EXPECT_NEAR(top_right.colour.y, 1, 1e-4f);
    EXPECT_NEAR(top_right.alpha, 0, 1e-4f);
    EXPECT_NEAR(set.lookup(0, 0.25f, 0.25f).colour.z, 1, 1e-4f);
    EXPECT_NEAR(set.lookup(0, 0.75f, 0.25f).colour.x, srgb_to_linear(128 / 255.0f), 1e-3f);
    // Coordinates wrap (GL_REPEAT): (1.25, -0.25) is (0.25, 0.75), the red texel.
    EXPECT_NEAR(set.lookup(0, 1.25f, -0.25f).colour.x, 1, 1e-4f);
    EXPECT_NEAR(set.lookup(0, 1.25f, -0.25f).colour.z, 0, 1e-4f);
    fs::remove_all(dir);
}

TEST(Texture, ModulateAndDecal)
{
    fs::path dir = temp_dir();
    write_image(dir / "q.png", 2, 2, 4, quadrants());
    geom::TextureDef modulate = nearest(dir / "q.png"), decal = modulate;
    decal.decal = true;
    TextureSet set({modulate, decal});
    auto apply = [&](int index, float s, float t) {
        TextureSet::Rgbx seen;
        set.apply(index, Vec3f(0.5f), s, t, TextureFootprint{}, seen);
        return seen.rgb();
    };
    Vec3f grey = apply(0, 0.75f, 0.25f);
    float g = srgb_to_linear(128 / 255.0f);
    EXPECT_NEAR(grey.x, 0.5f * g, 1e-4f);
    Vec3f replaced = apply(1, 0.75f, 0.25f);
    EXPECT_NEAR(replaced.x, g, 1e-4f);
    EXPECT_EQ(apply(geom::no_texture, 0, 0), Vec3f(0.5f));
    fs::remove_all(dir);
}

// cpfg's usual format: SGI .rgb, relative to the view file's folder.
TEST(Texture, ReadsSgiRelativeToBase)
{
    fs::path dir = temp_dir();
    write_image(dir / "leaf.rgb", 2, 2, 3, {10, 20, 30, 40, 50, 60, 70, 80, 90, 200, 210, 220});
    geom::TextureDef d = nearest("leaf.rgb");
    TextureSet set({d}, dir);
    EXPECT_FALSE(set.has_alpha(0));
    EXPECT_NEAR(set.lookup(0, 0.75f, 0.25f).colour.x, srgb_to_linear(200 / 255.0f), 1e-3f);
    EXPECT_NEAR(set.lookup(0, 0.25f, 0.75f).colour.z, srgb_to_linear(30 / 255.0f), 1e-3f);
    fs::remove_all(dir);
}

TEST(Texture, MissingFileIsSkippedAndLooksUpWhite)
{
    geom::TextureDef d;
    d.file = "/nonexistent/cambium/bark.rgb";
    TextureSet set({d});
    EXPECT_EQ(set.size(), 1u);  // the index keeps its place for @Tx
    EXPECT_FALSE(set.valid(0));
    Texel t = set.lookup(0, 0.5f, 0.5f);
    EXPECT_EQ(t.colour.x, 1.0f);
    EXPECT_EQ(t.alpha, 1.0f);
}

TEST(Texture, UnreadableFileIsSkipped)
{
    fs::path dir = temp_dir();
    {
        std::ofstream(dir / "bad.png") << "not an image";
    }
    geom::TextureDef d;
    d.file = dir / "bad.png";
    TextureSet set({d});
    EXPECT_FALSE(set.valid(0));
    EXPECT_FALSE(set.has_alpha(0));
    fs::remove_all(dir);
}

// The silhouette of a textured quad is the texture's alpha mask, also through an instance.
TEST(Texture, AlphaCutOutSilhouetteIsTheMask)
{
    fs::path dir = temp_dir();
    // 8x8 mask: opaque where (col + 2 row) % 3 == 0, top row first.
    const int n = 8;
    std::vector<std::uint8_t> pixels;
    auto opaque = [](int col, int row) { return (col + 2 * row) % 3 == 0; };
    for (int row = 0; row < n; ++row)
        for (int col = 0; col < n; ++col)
            for (std::uint8_t c : {200, 100, 50, opaque(col, row) ? 255 : 0})
                pixels.push_back(static_cast<std::uint8_t>(c));
    write_image(dir / "mask.png", n, n, 4, pixels);
    TextureSet set({nearest(dir / "mask.png")});

    geom::Scene s;
    add_quad(s.geometry, 0, 0, 8, 8, 0, 1, 1, 0);  // uv (0,0)..(1,1) over x, y 0..8
    geom::Prototype p;
    add_quad(p.geometry, 0, 0, 8, 8, 0, geom::inherit_material, geom::inherit_material);
    s.prototypes.push_back(p);
    geom::Instance inst;
    inst.transform = transform({1, 0, 0, 0, 1, 0, 0, 0, 1}, {20, 0, 0});
    inst.texture = 0;
    s.instances.push_back(inst);
    EmbreeScene accel(s, top_camera(0, 0, 10, 10, 10), &set);
    int mismatches = 0;
    for (int row = 0; row < n; ++row)
        for (int col = 0; col < n; ++col) {
            // Texel (col, row) lies at x = col + 0.5, y = 8 - (row + 0.5) (t runs up).
            float x = col + 0.5f, y = n - (row + 0.5f);
            for (float dx : {0.0f, 20.0f}) {
                bool hit = accel.intersect({x + dx, y, 5}, {0, 0, -1}, 0, inf).has_value();
                bool blocked = accel.occluded({x + dx, y, 5}, {0, 0, -1}, 0, inf);
                mismatches += (hit != opaque(col, row)) + (blocked != opaque(col, row));
            }
        }
    EXPECT_EQ(mismatches, 0);
    // Without the texture set nothing is cut out.
    EmbreeScene plain(s, top_camera(0, 0, 10, 10, 10));
    EXPECT_TRUE(plain.intersect({1.5f, 7.5f, 5}, {0, 0, -1}, 0, inf));
    EXPECT_FALSE(opaque(1, 0));
    fs::remove_all(dir);
}

// An RGBA image whose alpha is at least 128/255 everywhere cuts nothing out, so its
// surfaces get no alpha test (no filter at all on a flat quad); one texel below 128 is
// enough to bring the test back, and it cuts out that texel only.
TEST(Texture, OpaqueAlphaNeedsNoCutOutTest)
{
    fs::path dir = temp_dir();
    const int n = 4;
    auto image = [&](const char* name, std::uint8_t lowest) {
        std::vector<std::uint8_t> pixels;
        for (int i = 0; i < n * n; ++i)
            for (std::uint8_t c : {200, 100, 50, i == 5 ? lowest : 255})
                pixels.push_back(c);
        write_image(dir / name, n, n, 4, pixels);
        return nearest(dir / name);
    };
    TextureSet set({image("opaque.png", 128), image("hole.png", 127)});
    EXPECT_TRUE(set.has_alpha(0));
    EXPECT_FALSE(set.cuts_out(0));
    EXPECT_TRUE(set.cuts_out(1));
    EXPECT_FALSE(set.cuts_out(7));  // not a texture
    for (std::int16_t texture : {0, 1}) {
        geom::Scene s;
        add_quad(s.geometry, 0, 0, 4, 4, 0, 1, 1, texture);  // uv (0,0)..(1,1), x, y 0..4
        EmbreeScene accel(s, top_camera(0, 0, 10, 10, 10), &set);
        EXPECT_EQ(accel.filtered_shapes().empty(), texture == 0);
        int holes = 0;
        for (int row = 0; row < n; ++row)
            for (int col = 0; col < n; ++col) {
                float x = col + 0.5f, y = n - (row + 0.5f);  // texel (col, row)
                bool hit = accel.intersect({x, y, 5}, {0, 0, -1}, 0, inf).has_value();
                holes += !hit;
                EXPECT_EQ(hit, texture == 0 || row * n + col != 5) << col << ", " << row;
            }
        EXPECT_EQ(holes, texture == 0 ? 0 : 1);
    }
    fs::remove_all(dir);
}

// Rendered: a white quad under a white light shows the texture's decoded colours, and
// the background where it is cut out.
TEST(Texture, TexturedQuadRendersTheTexture)
{
    fs::path dir = temp_dir();
    write_image(dir / "q.png", 2, 2, 4, quadrants());
    TextureSet set({nearest(dir / "q.png")});
    geom::Scene s;
    s.materials[1].diffuse = {1, 1, 1};
    add_quad(s.geometry, 0, 0, 8, 8, 0, 1, 1, 0);
    geom::Light light;
    light.kind = geom::Light::Kind::directional;
    light.direction = {0, 0, 1};
    s.lights.push_back(light);
    auto at = [&](float x, float y) {
        Camera c = top_camera(x, y, 0.2, 20, 20);
        EmbreeScene accel(s, c, &set);
        PathContext ctx;
        ctx.accel = &accel;
        ctx.textures = &set;
        ctx.materials = make_materials(s.materials);
        ctx.lights = make_lights(s.lights);
        ctx.background = Vec3f(0.25f);
        ctx.max_depth = 1;
        prepare_path_context(ctx);
        return trace_block(ctx, c, 9, 9, 11, 11, 1).radiance;
    };
    Vec3f red = at(2, 6), blue = at(2, 2), grey = at(6, 2), cut = at(6, 6);
    EXPECT_NEAR(red.x, 1, 1e-4f);
    EXPECT_NEAR(red.y, 0, 1e-4f);
    EXPECT_NEAR(blue.z, 1, 1e-4f);
    EXPECT_NEAR(grey.y, srgb_to_linear(128 / 255.0f), 1e-3f);
    EXPECT_EQ(cut, Vec3f(0.25f));
    fs::remove_all(dir);
}

/// Writes a float checkerboard (0 and 1, linear) of `checks` x `checks` squares of
/// `size` texels each.
void write_checker(const fs::path& file, int checks, int size)
{
    int n = checks * size;
    std::vector<float> pixels(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            pixels[std::size_t(y) * n + x] = ((x / size + y / size) % 2) ? 1.0f : 0.0f;
    auto out = OIIO::ImageOutput::create(file.string());
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(n, n, 1, OIIO::TypeDesc::FLOAT);
    ASSERT_TRUE(out->open(file.string(), spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    out->close();
}

/// A white square [-h, h]^2 at z = 0 facing +z whose uv run 0..repeat, textured with 0.
void add_tiled_plane(geom::Geometry& g, float h, float repeat)
{
    geom::Float3 n{0, 0, 1};
    add_triangle(g, {{{-h, -h, 0}, {h, -h, 0}, {h, h, 0}}}, {n, n, n},
                 {{{0, 0}, {repeat, 0}, {repeat, repeat}}}, 1, 1, 0);
    add_triangle(g, {{{-h, -h, 0}, {h, h, 0}, {-h, h, 0}}}, {n, n, n},
                 {{{0, 0}, {repeat, repeat}, {0, repeat}}}, 1, 1, 0);
}

/// Per-pixel radiance (green) of a camera over the plane at 1 spp, with and without the
/// camera's ray cone.
std::vector<float> checker_pixels(const geom::Scene& s, const TextureSet& set, const Camera& c,
                                  bool filtered)
{
    EmbreeScene accel(s, c, &set);
    PathContext ctx;
    ctx.accel = &accel;
    ctx.textures = &set;
    ctx.materials = make_materials(s.materials);
    ctx.lights = make_lights(s.lights);
    ctx.max_depth = 1;
    prepare_path_context(ctx);
    if (filtered)
        ctx.camera_cone = {float(c.pixel_size()), 0};
    std::vector<float> out;
    for (int y = 0; y < c.height(); ++y)
        for (int x = 0; x < c.width(); ++x) {
            Sampler sm(std::uint32_t(x), std::uint32_t(y), 0, 5);
            double jx = sm.next(), jy = sm.next();
            CameraRay ray = c.generate_ray(x + jx, y + jy);
            out.push_back(trace_path(ctx, Vec3f(ray.org), Vec3f(ray.dir), sm).radiance.y);
        }
    return out;
}

std::pair<double, double> mean_variance(const std::vector<float>& v)
{
    double m = 0, var = 0;
    for (float x : v)
        m += x;
    m /= double(v.size());
    for (float x : v)
        var += (x - m) * (x - m);
    return {m, var / double(v.size() - 1)};
}

// A checkerboard seen from so far that each pixel covers ~100 checks: with the camera's
// footprint the mipmap gives every pixel about the mean (0.5 under a white light of
// irradiance pi on albedo 1), while point lookups land on black or white at random.
TEST(Texture, DistantCheckerFiltersToTheMean)
{
    fs::path dir = temp_dir();
    write_checker(dir / "checker.exr", 8, 4);
    geom::TextureDef def;
    def.file = dir / "checker.exr";
    TextureSet set({def});
    ASSERT_TRUE(set.valid(0));
    geom::Scene s;
    s.materials[1].diffuse = {1, 1, 1};
    s.lights.push_back(directional({0, 0, 1}));
    add_tiled_plane(s.geometry, 100, 400);  // 400 tiles of 8 checks over 200 units
    Camera c = top_camera(0, 0, 160, 16, 16);  // 10 units = 160 checks across a pixel
    auto [mean, variance] = mean_variance(checker_pixels(s, set, c, true));
    EXPECT_NEAR(mean, 0.5, 0.03);
    EXPECT_LT(variance, 1e-3);
    auto [raw_mean, raw_variance] = mean_variance(checker_pixels(s, set, c, false));
    EXPECT_GT(raw_variance, 0.1);  // the aliasing the footprint removes
    std::printf("[texture] distant checker: filtered mean %.4f var %.2g; unfiltered mean "
                "%.4f var %.2g\n", mean, variance, raw_mean, raw_variance);

    // render() gives camera rays their cone too (a perspective view from high above).
    s.textures = {def};
    RenderSettings settings = small(16, 16, 1);
    settings.aovs = false;
    Camera eye = Camera::perspective({0, 0, 200}, {0, 0, 0}, {0, 1, 0}, 40, 16, 16);
    Image img = render(s, eye, settings);
    std::vector<float> green;
    for (std::size_t i = 1; i < img.rgba.size(); i += 4)
        green.push_back(img.rgba[i]);
    auto [seen_mean, seen_variance] = mean_variance(green);
    EXPECT_NEAR(seen_mean, 0.5, 0.03);
    EXPECT_LT(seen_variance, 1e-3);

    // Seen up close (a pixel a fifth of a check), pixels stay black or white.
    Camera near = top_camera(0.0625, 0.0625, 0.2, 16, 16);
    auto [near_mean, near_variance] = mean_variance(checker_pixels(s, set, near, true));
    EXPECT_GT(near_variance, 0.1);
    EXPECT_NEAR(near_mean, 0.5, 0.15);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace cambium::render

namespace cambium::render {
namespace {

/// PNG's chunk checksum (CRC-32 of ISO 3309), which libpng verifies for IHDR.
std::uint32_t png_crc(const std::string& bytes)
{
    std::uint32_t crc = 0xffffffffu;
    for (unsigned char b : bytes) {
        crc ^= b;
        for (int k = 0; k < 8; ++k)
            crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
    }
    return crc ^ 0xffffffffu;
}

std::string big_endian(std::uint32_t v)
{
    return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
            static_cast<char>(v)};
}

std::string png_chunk(const std::string& type, const std::string& data)
{
    return big_endian(static_cast<std::uint32_t>(data.size())) + type + data +
           big_endian(png_crc(type + data));
}

/// A PNG of a few dozen bytes whose header declares `width` x `height` RGBA pixels; its
/// image data is empty, so only the header can be read.
void write_png_header(const fs::path& file, std::uint32_t width, std::uint32_t height)
{
    std::string ihdr = big_endian(width) + big_endian(height) + std::string("\x08\x06\0\0\0", 5);
    std::ofstream(file, std::ios::binary)
        << std::string("\x89PNG\r\n\x1a\n", 8) << png_chunk("IHDR", ihdr) << png_chunk("IDAT", "")
        << png_chunk("IEND", "");
}

geom::TextureDef texture_file(const fs::path& file)
{
    geom::TextureDef def;
    def.file = file;
    return def;
}

TEST(TextureLimits, HugeDeclaredDimensionsAreRefusedFromTheHeader)
{
    // 30000 x 30000 RGBA would decode to 3.4 GiB (4.5 with MIP levels)
    fs::path dir = temp_dir();
    fs::path file = dir / "huge.png";
    write_png_header(file, 30000, 30000);
    try {
        TextureSet set({texture_file(file)});
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  file.string() + ": error: texture is 30000 x 30000 pixels; textures may have "
                                  "at most 16384 pixels on a side (and one layer)");
    }
    fs::remove_all(dir);
}

TEST(TextureLimits, DecodedSizePastTheBudgetIsRefused)
{
    // 4000 x 4000 RGBA bytes: 61 MiB, 81.4 MiB with MIP levels, past a 64 MiB budget
    fs::path dir = temp_dir();
    fs::path file = dir / "large.png";
    write_png_header(file, 4000, 4000);
    try {
        TextureSet set({texture_file(file)}, {}, std::uint64_t{64} << 20);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  file.string() + ": error: texture needs 81.4 MiB decoded, more than the "
                                  "memory budget of 64.0 MiB (--max-memory)");
    }
    // a real small image within the budget still loads
    write_image(dir / "small.png", 2, 2, 4, quadrants());
    TextureSet small({texture_file(dir / "small.png")}, {}, std::uint64_t{64} << 20);
    EXPECT_TRUE(small.valid(0));
    fs::remove_all(dir);
}

}  // namespace
}  // namespace cambium::render
