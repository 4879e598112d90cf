// SPDX-License-Identifier: Apache-2.0
// Organ masks (docs/masks.md): MurmurHash3, Cryptomatte ids, coverages against alpha,
// mattes against renders of one organ alone, the EXR's channels and manifest.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "base/limits.h"
#include "render/camera.h"
#include "render/image_io.h"
#include "render/organ_masks.h"
#include "render/render.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

namespace fs = std::filesystem;

// Published MurmurHash3_x86_32 vectors, checked against an independent implementation
// (Python, from the algorithm's description) before being written here.
TEST(Murmur3, PublishedVectors)
{
    EXPECT_EQ(murmur3_32("", 0), 0u);
    EXPECT_EQ(murmur3_32("", 1), 0x514e28b7u);
    EXPECT_EQ(murmur3_32("hello", 0), 0x248bfa47u);
    EXPECT_EQ(murmur3_32("The quick brown fox jumps over the lazy dog", 0), 0x2e4ff723u);
    EXPECT_EQ(murmur3_32("abcd", 0x9747b28cu), 0xf0478627u);
    EXPECT_EQ(murmur3_32("abc", 0), 0xb3dd93fau);  // a 3-byte tail
    EXPECT_EQ(hash_text(0x0f85aedfu), "0f85aedf");
}

// Every hash becomes a normal float (never NaN, infinite, zero or denormal); hashes
// whose exponent is neither all zeros nor all ones keep their bits.
TEST(CryptomatteId, NeverNanInfiniteOrDenormal)
{
    std::vector<std::uint32_t> hashes{0u, 1u, 0x007fffffu, 0x80000000u, 0x807fffffu,
                                      0x7f800000u, 0x7fc00000u, 0x7fffffffu, 0xff800000u,
                                      0xffffffffu, 0x00800000u, 0x3f800000u};
    std::mt19937 random(7);
    for (int i = 0; i < 200000; ++i)
        hashes.push_back(static_cast<std::uint32_t>(random()));
    for (std::uint32_t h : hashes) {
        const float id = cryptomatte_id(h);
        ASSERT_TRUE(std::isnormal(id)) << std::hex << h;
        const std::uint32_t exponent = (h >> 23) & 0xffu;
        const std::uint32_t bits = std::bit_cast<std::uint32_t>(id);
        if (exponent != 0 && exponent != 0xffu)
            ASSERT_EQ(bits, h) << std::hex << h;
        else
            ASSERT_EQ(bits, h ^ (1u << 23)) << std::hex << h;
    }
}

constexpr int width = 48, height = 36;

/// Two cylinders, each its own organ: A ("L 7", age 3, order 1) across in front, B
/// ("I 12") upright behind it, partly hidden by A.
geom::Scene two_organs(bool with_a = true, bool with_b = true)
{
    geom::Scene s = testing::empty_scene({-3, -3, -3}, {3, 3, 3});
    if (with_a) {
        testing::add_segment(s, {-2.5, 0.3, 1}, {1.5, 0.3, 1}, 0.5f);
        s.geometry.lines.module.push_back(7);
    }
    if (with_b) {
        testing::add_segment(s, {0.6, -2.5, -1}, {0.6, 2.5, -1}, 0.6f);
        s.geometry.lines.module.push_back(12);
    }
    s.geometry.modules.names = {"L", "I"};
    s.geometry.modules.records = {{7, 0, 3}, {12, 1, geom::unknown_age}};
    s.geometry.modules.orders = {1, 0};
    s.lights.push_back(testing::directional({0.3, 1, 1}));
    return s;
}

Camera camera() { return Camera::perspective({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 40, width, height); }

RenderSettings mask_settings(PixelFilter filter = PixelFilter::gaussian)
{
    RenderSettings set = testing::small(width, height, 16);
    set.filter = filter;
    set.organ_mask_depth = default_organ_mask_depth;
    return set;
}

/// Pixel i's coverage of the organ whose id is `id` in layer l (0: CryptoOrgan).
float matte(const Image& img, std::size_t i, float id, std::size_t l = 0)
{
    const OrganLayers& m = img.organ_masks;
    const float* r = &m.cryptomatte[l].ranks[i * std::size_t(2 * m.depth)];
    float sum = 0;
    for (int k = 0; k < m.depth; ++k)
        if (std::bit_cast<std::uint32_t>(r[2 * k]) == std::bit_cast<std::uint32_t>(id))
            sum += r[2 * k + 1];
    return sum;
}

float id_of(const std::string& name) { return cryptomatte_id(murmur3_32(name)); }

// Per pixel the coverages of both layers sum to its alpha, ranked largest first, with a
// filter wider than the pixel (samples fall in neighbouring pixels' footprints).
TEST(OrganMasks, CoveragesSumToAlpha)
{
    for (PixelFilter filter : {PixelFilter::box, PixelFilter::gaussian}) {
        const Image img = render(two_organs(), camera(), mask_settings(filter));
        ASSERT_EQ(img.organ_masks.depth, 6);
        ASSERT_EQ(img.organ_masks.cryptomatte.size(), 2u);
        int covered = 0, shared = 0;
        for (std::size_t i = 0; i < std::size_t(width * height); ++i) {
            const float alpha = img.rgba[i * 4 + 3];
            covered += alpha > 0;
            for (const CryptomatteLayer& layer : img.organ_masks.cryptomatte) {
                const float* r = &layer.ranks[i * 12];
                float sum = 0;
                for (int k = 0; k < 6; ++k) {
                    sum += r[2 * k + 1];
                    if (k > 0) {
                        ASSERT_LE(r[2 * k + 1], r[2 * k - 1]) << "ranks out of order at " << i;
                    }
                    if (r[2 * k + 1] == 0) {
                        ASSERT_EQ(r[2 * k], 0.0f) << "an id without coverage at " << i;
                    }
                }
                ASSERT_NEAR(sum, alpha, 1e-3) << layer.name << " pixel " << i;
                shared += layer.name == "CryptoOrgan" && r[3] > 0;
            }
        }
        EXPECT_GT(covered, width * height / 10);
        EXPECT_GT(shared, 10) << "some pixels should show both organs";
    }
}

// The front organ's matte is its alpha in a render of it alone: the camera samples are a
// pure function of (pixel, sample, seed), so a sample meets A in both renders or in
// neither (A is in front); only float rounding of count / samples may differ (1e-6).
// The hidden organ's matte is at most its own alpha, and less where A covers it.
TEST(OrganMasks, MatteEqualsTheOrganRenderedAlone)
{
    const Image both = render(two_organs(), camera(), mask_settings());
    const Image a = render(two_organs(true, false), camera(), mask_settings());
    const Image b = render(two_organs(false, true), camera(), mask_settings());
    double hidden = 0, a_area = 0;
    for (std::size_t i = 0; i < std::size_t(width * height); ++i) {
        ASSERT_NEAR(matte(both, i, id_of("L 7")), a.rgba[i * 4 + 3], 1e-6) << "pixel " << i;
        ASSERT_LE(matte(both, i, id_of("I 12")), b.rgba[i * 4 + 3] + 1e-6) << "pixel " << i;
        hidden += b.rgba[i * 4 + 3] - matte(both, i, id_of("I 12"));
        a_area += a.rgba[i * 4 + 3];
        // the symbol layer's matte of L is the organ's (one organ per symbol here)
        ASSERT_NEAR(matte(both, i, id_of("L"), 1), a.rgba[i * 4 + 3], 1e-6);
    }
    EXPECT_GT(a_area, 50);
    EXPECT_GT(hidden, 5) << "A should hide part of B";
}

// The organ channels name the organ covering most of the pixel; -1 where none.
TEST(OrganMasks, OrganChannelsOfTheMostCoveringOrgan)
{
    const Image img = render(two_organs(), camera(), mask_settings(PixelFilter::box));
    const OrganLayers& m = img.organ_masks;
    int a = 0, b = 0, none = 0;
    for (std::size_t i = 0; i < std::size_t(width * height); ++i) {
        const float alpha = img.rgba[i * 4 + 3];
        if (alpha == 0) {
            ASSERT_EQ(m.index[i], -1.0f);
            ASSERT_EQ(m.plant[i], -1.0f);
            ++none;
        } else if (matte(img, i, id_of("L 7")) > 0.5f) {
            ASSERT_EQ(m.index[i], 7.0f);
            ASSERT_EQ(m.age[i], 3.0f);
            ASSERT_EQ(m.order[i], 1.0f);
            ASSERT_EQ(m.plant[i], 0.0f);
            ++a;
        } else if (matte(img, i, id_of("I 12")) > 0.5f) {
            ASSERT_EQ(m.index[i], 12.0f);
            ASSERT_EQ(m.age[i], -1.0f);  // unknown
            ASSERT_EQ(m.order[i], 0.0f);
            ++b;
        }
    }
    EXPECT_GT(a, 0);
    EXPECT_GT(b, 0);
    EXPECT_GT(none, 0);
}

/// A temporary folder for EXR files.
fs::path temp_folder()
{
    const fs::path dir = fs::temp_directory_path() / ("cambium_organ_masks_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}

// The EXR: float Cryptomatte channels, the header's attributes under the layer's key,
// a manifest that parses and names every id the pixels hold, and organ channels.
TEST(OrganMasks, ExrLayersAndManifest)
{
    const Image img = render(two_organs(), camera(), mask_settings());
    const fs::path file = temp_folder() / "masks.exr";
    write_image(img, file);
    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in);
    const OIIO::ImageSpec spec = in->spec();
    std::map<std::string, int> channel;
    for (int c = 0; c < spec.nchannels; ++c)
        channel[spec.channelnames[std::size_t(c)]] = c;
    std::vector<float> pixels(std::size_t(width * height * spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
    in->close();
    for (const std::string layer : {"CryptoOrgan", "CryptoSymbol"}) {
        const std::string key = "cryptomatte/" + hash_text(murmur3_32(layer)).substr(0, 7);
        EXPECT_EQ(spec.get_string_attribute(key + "/name"), layer);
        EXPECT_EQ(spec.get_string_attribute(key + "/hash"), "MurmurHash3_32");
        EXPECT_EQ(spec.get_string_attribute(key + "/conversion"), "uint32_to_float32");
        const nlohmann::json manifest = nlohmann::json::parse(spec.get_string_attribute(key + "/manifest"));
        ASSERT_TRUE(manifest.is_object());
        std::map<std::uint32_t, std::string> by_id;  // the float id's bits -> name
        for (const auto& [name, hash] : manifest.items()) {
            const std::uint32_t h = std::stoul(hash.get<std::string>(), nullptr, 16);
            EXPECT_EQ(h, murmur3_32(name)) << name;
            by_id[std::bit_cast<std::uint32_t>(cryptomatte_id(h))] = name;
        }
        if (layer == "CryptoOrgan") {
            EXPECT_TRUE(manifest.contains("L 7"));
            EXPECT_TRUE(manifest.contains("I 12"));
        } else {
            EXPECT_TRUE(manifest.contains("L"));
            EXPECT_TRUE(manifest.contains("I"));
        }
        for (int group = 0; group < 3; ++group)
            for (const char* c : {"R", "G", "B", "A"}) {
                const std::string name = layer + (group ? "0" + std::to_string(group) : "00") + "." + c;
                ASSERT_TRUE(channel.count(name)) << name;
                EXPECT_EQ(spec.channelformat(channel[name]), OIIO::TypeDesc::FLOAT) << name;
            }
        // every id with coverage in the file is in the manifest; the coverages sum to alpha
        for (std::size_t i = 0; i < std::size_t(width * height); ++i) {
            float sum = 0;
            const float* p = &pixels[i * std::size_t(spec.nchannels)];
            for (int group = 0; group < 3; ++group) {
                // channels by name: the file keeps them in its own (alphabetical) order
                const std::string g = layer + "0" + std::to_string(group) + ".";
                for (const auto& [id_channel, coverage_channel] : {std::pair{"R", "G"}, std::pair{"B", "A"}}) {
                    const float id = p[channel[g + id_channel]], coverage = p[channel[g + coverage_channel]];
                    if (coverage > 0) {
                        ASSERT_TRUE(by_id.count(std::bit_cast<std::uint32_t>(id))) << layer << " pixel " << i;
                    }
                    sum += coverage;
                }
            }
            ASSERT_NEAR(sum, p[channel["A"]], 1e-3);
        }
    }
    for (const char* name : {"organ.index", "organ.age", "organ.order", "organ.plant"}) {
        ASSERT_TRUE(channel.count(name)) << name;
        EXPECT_EQ(spec.channelformat(channel[name]), OIIO::TypeDesc::FLOAT);
    }
}

// Without organ masks the EXR has no mask channel and no cryptomatte attribute, and
// the masks change nothing else: the same RGBA with them as without.
TEST(OrganMasks, WithoutThemTheExrHasNoExtraChannels)
{
    RenderSettings plain = mask_settings();
    plain.organ_mask_depth = 0;
    const Image without = render(two_organs(), camera(), plain);
    const Image with = render(two_organs(), camera(), mask_settings());
    EXPECT_TRUE(without.organ_masks.empty());
    EXPECT_EQ(without.rgba, with.rgba);
    const fs::path file = temp_folder() / "plain.exr";
    write_image(without, file);
    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in);
    const std::vector<std::string> expected{"R", "G", "B", "A", "albedo.R", "albedo.G", "albedo.B",
                                            "normal.X", "normal.Y", "normal.Z", "Z"};
    std::vector<std::string> names = in->spec().channelnames;
    std::sort(names.begin(), names.end());
    std::vector<std::string> sorted = expected;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(names, sorted);
    for (const auto& attribute : in->spec().extra_attribs)
        EXPECT_EQ(attribute.name().string().find("cryptomatte"), std::string::npos);
}

// A scene file's plant: its organs are named "plant K MODEL/SYMBOL INDEX", with the
// placement in organ.plant.
TEST(OrganMasks, PlantPlacementsPrefixTheNames)
{
    geom::Scene s = testing::empty_scene({-3, -3, -3}, {3, 3, 3});
    geom::Prototype p;
    p.name = "tree";
    geom::Scene inner = two_organs(true, false);
    p.geometry = inner.geometry;
    s.prototypes.push_back(p);
    geom::Instance in;
    in.prototype = 0;
    in.transform = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    in.plant = 2;
    s.instances.push_back(in);
    const Image img = render(s, camera(), mask_settings());
    bool found = false;
    for (std::size_t i = 0; i < std::size_t(width * height); ++i)
        if (matte(img, i, id_of("plant 2 tree/L 7")) > 0.5f) {
            found = true;
            EXPECT_EQ(img.organ_masks.plant[i], 2.0f);
            EXPECT_EQ(img.organ_masks.index[i], 7.0f);
        }
    EXPECT_TRUE(found);
    bool named = false;
    for (const auto& [key, value] : img.organ_masks.attributes)
        named |= value.find("\"plant 2 tree/L 7\"") != std::string::npos;
    EXPECT_TRUE(named);
}

// The masks' memory counts against the budget, with a message naming the option.
TEST(OrganMasks, CountAgainstTheMemoryBudget)
{
    RenderSettings set = mask_settings();
    set.max_memory_bytes = std::uint64_t(width) * height * 100;  // below the ~300 B a pixel
    try {
        render(two_organs(), camera(), set);
        FAIL() << "expected the memory budget to refuse";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--max-memory"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("organ masks"), std::string::npos) << e.what();
    }
    set.max_memory_bytes = default_max_memory_bytes();
    set.organ_mask_depth = 3;
    EXPECT_THROW(render(two_organs(), camera(), set), Error);
}

}  // namespace
}  // namespace cambium::render
