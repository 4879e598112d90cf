// SPDX-License-Identifier: Apache-2.0
// cpfg's colormap-mode lighting (manual 5.2.5): the colour index moves with the cosine to
// the light, and the path tracer shows the moved entry's hue.
#include <gtest/gtest.h>

#include "render/color.h"
#include "render/material.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using geom::IndexLighting;

/// A colormap: every entry black except those given.
std::vector<geom::Material> colormap(std::initializer_list<std::pair<int, geom::Rgb>> entries)
{
    std::vector<geom::Material> table(geom::colour_indices);
    for (geom::Material& m : table)
        m.diffuse = {0, 0, 0};
    for (auto [index, colour] : entries)
        table[static_cast<std::size_t>(index)].diffuse = colour;
    return table;
}

void light_by(std::vector<geom::Material>& table, int index, IndexLighting rule)
{
    table[static_cast<std::size_t>(index)].index_lighting = rule;
    table[static_cast<std::size_t>(index)].colour_index = static_cast<std::uint8_t>(index);
}

float hue_ratio(const Vec3f& c) { return c.x / (c.x + c.y + c.z); }

TEST(IndexLighting, CosineMovesTheIndexByTruncatedDiffuseReflectionTimesCosine)
{
    // Entry 100 white; 99 red, 101 blue: diffuse reflection 1 reaches them at cos = -1, 1.
    auto table = colormap({{99, {1, 0, 0}}, {100, {1, 1, 1}}, {101, {0, 0, 1}}});
    light_by(table, 100, IndexLighting::cosine);
    geom::ColourIndexLight light;
    light.diffuse_reflection = 1;
    std::vector<IndexRamp> ramps = make_index_ramps(table, light);
    ASSERT_EQ(ramps.size(), table.size());
    EXPECT_EQ(ramps[0].rule, IndexLighting::none);
    const IndexRamp& ramp = ramps[100];
    // C truncates toward zero: 0.99 stays at the own entry, white.
    Vec3f own = index_lit_albedo(ramp, light, 0.99f);
    EXPECT_NEAR(own.x, 1, 1e-5);
    EXPECT_NEAR(own.z, 1, 1e-5);
    Vec3f lit = index_lit_albedo(ramp, light, 1.0f);
    EXPECT_EQ(lit.x, 0);
    EXPECT_EQ(lit.y, 0);
    EXPECT_NEAR(lit.z, 1, 1e-6);  // blue, as bright as it can be below white's luminance
    Vec3f dark = index_lit_albedo(ramp, light, -1.0f);
    EXPECT_NEAR(dark.x, 1, 1e-6);
    EXPECT_EQ(dark.z, 0);
    EXPECT_NEAR(hue_ratio(index_lit_albedo(ramp, light, -0.99f)), 1.0f / 3, 1e-5);
}

TEST(IndexLighting, SurfaceRulePicksTheBlockEntryByAmbientPlusDiffuseCosine)
{
    // Manual 5.2.5: index = 64 hue + (index mod 64)(ambient + diffuse |cos|). Index 255
    // with ambient .15 and diffuse .5 shows entries 201 (edge-on) .. 232 (facing).
    std::vector<std::pair<int, geom::Rgb>> entries;
    for (int k = 192; k < 256; ++k)
        entries.push_back({k, {0.2f, 0.2f, 0.2f}});
    auto table = colormap({});
    for (auto [k, c] : entries)
        table[static_cast<std::size_t>(k)].diffuse = c;
    table[201].diffuse = {0.5f, 0, 0};  // red
    table[232].diffuse = {0, 0.5f, 0};  // green
    table[255].diffuse = {0.2f, 0.2f, 0.2f};
    light_by(table, 255, IndexLighting::surface);
    geom::ColourIndexLight light;
    light.surface_ambient = 0.15f;
    light.surface_diffuse = 0.5f;
    std::vector<IndexRamp> ramps = make_index_ramps(table, light);
    const IndexRamp& ramp = ramps[255];
    Vec3f edge_on = index_lit_albedo(ramp, light, 0);
    EXPECT_GT(edge_on.x, 0);
    EXPECT_EQ(edge_on.y, 0);
    Vec3f facing = index_lit_albedo(ramp, light, -1);  // |cos|: either side
    EXPECT_EQ(facing.x, 0);
    EXPECT_GT(facing.y, 0);
    // The hue moves; the luminance stays the own entry's (the path tracer shades it).
    // (in display values, where ramps are made: green 0.5 has luminance 0.7152 x 0.5)
    EXPECT_NEAR(facing.y, srgb_to_linear(0.2f / 0.7152f), 1e-5);
}

TEST(IndexLighting, PlainShadeRampsKeepTheOwnColour)
{
    // A ramp of one hue in several brightnesses: the albedo is the own entry's at every
    // cosine, so such models render as without index lighting.
    auto table = colormap({});
    for (int k = 90; k <= 110; ++k) {
        float v = 0.3f + 0.03f * static_cast<float>(k - 90);
        table[static_cast<std::size_t>(k)].diffuse = {v, 0.5f * v, 0.25f * v};
    }
    light_by(table, 100, IndexLighting::cosine);
    geom::ColourIndexLight light;
    std::vector<IndexRamp> ramps = make_index_ramps(table, light);
    const IndexRamp& ramp = ramps[100];
    Vec3f own = decode_display(table[100].diffuse);
    for (float c : {-1.0f, -0.5f, 0.0f, 0.37f, 1.0f}) {
        Vec3f a = index_lit_albedo(ramp, light, c);
        EXPECT_NEAR(a.x, own.x, 2e-3 * own.x) << c;
        EXPECT_NEAR(a.y, own.y, 2e-3 * own.x) << c;
        EXPECT_NEAR(a.z, own.z, 2e-3 * own.x) << c;
    }
}

/// A cylinder across the view, lit from the camera's side, in colormap entry 100 (white)
/// whose neighbours 101..110 are red.
geom::Scene white_cylinder_with_red_neighbours(bool index_lit)
{
    geom::Scene s = testing::empty_scene({-1, -1, -1}, {1, 1, 1});
    testing::add_segment(s, {-1, 0, 0}, {1, 0, 0}, 0.5f, 100);
    s.materials = colormap({{100, {1, 1, 1}}});
    for (int k = 101; k <= 110; ++k)
        s.materials[static_cast<std::size_t>(k)].diffuse = {0.8f, 0, 0};
    s.lights = {testing::directional({0, 0, 1})};
    if (index_lit) {
        light_by(s.materials, 100, IndexLighting::cosine);
        s.colour_index_light = geom::ColourIndexLight{{0, 0, 1}, 10, 0.15f, 0.75f};
    }
    return s;
}

TEST(IndexLighting, RenderShowsTheMovedEntrysHue)
{
    RenderSettings settings = testing::small(9, 9, 4);
    Image plain = render(white_cylinder_with_red_neighbours(false), settings);
    Image lit = render(white_cylinder_with_red_neighbours(true), settings);
    // The middle faces the light (cos 1): cpfg shows entry 110, red.
    EXPECT_GT(plain.at(4, 4, 1), 0.5f * plain.at(4, 4, 0));  // white without it
    EXPECT_GT(lit.at(4, 4, 0), 0.2f);
    EXPECT_LT(lit.at(4, 4, 1), 0.01f * lit.at(4, 4, 0));
}

}  // namespace
}  // namespace cambium::render
