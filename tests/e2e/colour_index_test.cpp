// SPDX-License-Identifier: Apache-2.0
// cpfg's colormap-mode lighting through the app pipeline: which models get it and the
// view-file settings it reads (manual 5.2.5; docs/materials.md "Colour-index lighting").
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/pipeline.h"
#include "base/diagnostics.h"

using namespace cambium;
namespace fs = std::filesystem;

namespace {

/// A one-segment plant with `view_lines` in its view file and a colormap whose entry i is
/// (i, i, i), interpreted as cpfg would with `-m` (or `-M` with a material file).
geom::Scene interpret_colormap_model(const std::string& name, const std::string& view_lines,
                                     bool material_file = false)
{
    fs::path dir = fs::temp_directory_path() / ("cambium_colour_index_" + name);
    fs::create_directories(dir);
    std::ofstream(dir / "plant.l") << "lsystem: 1\nderivation length: 1\naxiom: ;(7)F(1)\nendlsystem\n";
    std::ofstream(dir / "plant.v") << "line style: cylinder\n" << view_lines;
    {
        std::ofstream map(dir / "plant.map", std::ios::binary);
        for (int i = 0; i < 256; ++i)
            for (int c = 0; c < 3; ++c)
                map.put(static_cast<char>(i));
    }
    {
        std::ofstream mat(dir / "plant.mat", std::ios::binary);
        std::string record(15, '\0');
        mat.write(record.data(), static_cast<std::streamsize>(record.size()));
    }
    app::Options options;
    options.lsystem = dir / "plant.l";
    options.view = dir / "plant.v";
    options.colour_files.push_back(
        app::ColourFile{1, material_file, material_file ? dir / "plant.mat" : dir / "plant.map"});
    app::Model model = app::load_model(options);
    return app::interpret(model, app::derive(model, options), options);
}

TEST(ColourIndexLighting, ShadedColormapModelsReadTheViewsSettings)
{
    geom::Scene scene = interpret_colormap_model(
        "shaded", "render mode: shaded\nlight direction: 0,0,2\ndiffuse reflection: 25\n"
                  "surface ambient: 0.3\nsurface diffuse: 0.6\n");
    ASSERT_TRUE(scene.colour_index_light.has_value());
    const geom::ColourIndexLight& light = *scene.colour_index_light;
    EXPECT_DOUBLE_EQ(light.to_light.z, 1);  // normalised
    EXPECT_EQ(light.diffuse_reflection, 25);
    EXPECT_FLOAT_EQ(light.surface_ambient, 0.3f);
    EXPECT_FLOAT_EQ(light.surface_diffuse, 0.6f);
    // Entries 0..255 move by the cosine; their copies 256..511 (surfaces) by the surface
    // rule; 512..767 are the next colormap's (unloaded here: cpfg's grey), for patches.
    ASSERT_EQ(scene.materials.size(), 3 * geom::colour_indices);
    EXPECT_EQ(scene.materials[512 + 7].index_lighting, geom::IndexLighting::surface);
    EXPECT_EQ(scene.materials[512 + 7].colour_table, 512);
    EXPECT_EQ(scene.materials[512 + 7].diffuse, (geom::Rgb{200 / 255.0f, 200 / 255.0f, 200 / 255.0f}));
    EXPECT_EQ(scene.materials[7].index_lighting, geom::IndexLighting::cosine);
    EXPECT_EQ(scene.materials[7].colour_index, 7);
    EXPECT_EQ(scene.materials[256 + 7].index_lighting, geom::IndexLighting::surface);
    EXPECT_EQ(scene.materials[256 + 7].colour_index, 7);
    EXPECT_EQ(scene.materials[256 + 7].diffuse, scene.materials[7].diffuse);
    EXPECT_EQ(scene.geometry.lines.material.at(0), 7);
}

TEST(ColourIndexLighting, DefaultsAreCpfgs)
{
    geom::Scene scene = interpret_colormap_model("defaults", "shade mode: 3\n");
    ASSERT_TRUE(scene.colour_index_light.has_value());
    EXPECT_DOUBLE_EQ(scene.colour_index_light->to_light.x, 1);
    EXPECT_EQ(scene.colour_index_light->diffuse_reflection, 10);
    EXPECT_FLOAT_EQ(scene.colour_index_light->surface_ambient, 0.15f);
    EXPECT_FLOAT_EQ(scene.colour_index_light->surface_diffuse, 0.75f);
}

TEST(ColourIndexLighting, NotInFilledModeNorWithMaterials)
{
    geom::Scene filled = interpret_colormap_model("filled", "render mode: filled\n");
    EXPECT_FALSE(filled.colour_index_light.has_value());
    EXPECT_EQ(filled.materials.size(), geom::colour_indices);
    EXPECT_EQ(filled.materials[7].index_lighting, geom::IndexLighting::none);
    geom::Scene materials = interpret_colormap_model("materials", "render mode: shaded\n", true);
    EXPECT_FALSE(materials.colour_index_light.has_value());
    // cpfg's interpolated fill (`render mode: interpolated`, `shade mode: 2`) is unlit.
    EXPECT_FALSE(interpret_colormap_model("interpolated", "render mode: interpolated\n")
                     .colour_index_light.has_value());
    EXPECT_FALSE(interpret_colormap_model("shade2", "shade mode: 2\n").colour_index_light.has_value());
}

TEST(ColourIndexLighting, MalformedCoefficientIsAnErrorNamingTheLine)
{
    try {
        interpret_colormap_model("malformed", "render mode: shaded\ndiffuse reflection: lots\n");
        FAIL() << "no error";
    } catch (const Error& e) {
        std::string what = e.what();
        EXPECT_NE(what.find("plant.v:3"), std::string::npos) << what;
        EXPECT_NE(what.find("diffuse reflection"), std::string::npos) << what;
    }
}

// A model file sizes the colour ramps with `diffuse reflection:`: a huge value is bounded
// to the 256 indices (no multi-gigabyte ramp), and a non-finite one is an error.
TEST(ColourIndexLighting, HugeOrNonFiniteCoefficientsAreBounded)
{
    geom::Scene scene = interpret_colormap_model("huge", "render mode: shaded\ndiffuse reflection: 1e12\n");
    ASSERT_TRUE(scene.colour_index_light);
    EXPECT_EQ(scene.colour_index_light->diffuse_reflection, 255);
    for (const char* bad : {"diffuse reflection: nan", "surface ambient: inf"}) {
        try {
            interpret_colormap_model("nonfinite", std::string("render mode: shaded\n") + bad + "\n");
            ADD_FAILURE() << "no error for " << bad;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("plant.v:3"), std::string::npos) << e.what();
        }
    }
}
}  // namespace

namespace {

/// A surface file of two unit-square patches: the first takes the turtle's colour, the
/// second has TOP COLOR 300 (past the first colormap) and BOTTOM COLOR 40.
std::string two_patch_surface()
{
    std::string s = "0 1 0 1 0 0\nCONTACT POINT X: 0 Y: 0 Z: 0\nEND POINT X: 0 Y: 1 Z: 0\n"
                    "HEADING X: 0 Y: 1 Z: 0\nUP X: 0 Y: 0 Z: 1\nSIZE: 1\n";
    for (const char* colours : {"TOP COLOR: 0 DIFFUSE: 0.00 BOTTOM COLOR: 0 DIFFUSE: 0.00",
                                "TOP COLOR: 300 DIFFUSE: 0.00 BOTTOM COLOR: 40 DIFFUSE: 0.00"}) {
        s += std::string("patch\n") + colours + "\nAL: ~ A: ~ AR: ~\nL: ~ R: ~\nBL: ~ B: ~ BR: ~\n";
        for (int i = 0; i < 4; ++i) {
            for (int j = 0; j < 4; ++j)
                s += std::to_string(j / 3.0) + " " + std::to_string(i / 3.0) + " 0  ";
            s += "\n";
        }
    }
    return s;
}

/// `;(7)~s` with that surface, lit by colour index with two colormaps (-m1: entry i is
/// (i, i, i); -m2: entry i is (255 - i, i, 0)), or by a material file.
geom::Scene interpret_patch_colour_model(const std::string& name, bool material_file)
{
    fs::path dir = fs::temp_directory_path() / ("cambium_patch_colours_" + name);
    fs::create_directories(dir);
    std::ofstream(dir / "plant.l") << "lsystem: 1\nderivation length: 1\naxiom: ;(7)~s\nendlsystem\n";
    std::ofstream(dir / "plant.v") << "render mode: shaded\nsurface: s patches.s 1\n";
    std::ofstream(dir / "patches.s") << two_patch_surface();
    for (int block : {1, 2}) {
        std::ofstream map(dir / ("plant" + std::to_string(block) + ".map"), std::ios::binary);
        for (int i = 0; i < 256; ++i) {
            map.put(static_cast<char>(block == 1 ? i : 255 - i));
            map.put(static_cast<char>(i));
            map.put(static_cast<char>(block == 1 ? i : 0));
        }
    }
    std::ofstream(dir / "plant.mat", std::ios::binary) << std::string(15, '\0');
    app::Options options;
    options.lsystem = dir / "plant.l";
    options.view = dir / "plant.v";
    if (material_file) {
        options.colour_files.push_back(app::ColourFile{1, true, dir / "plant.mat"});
    } else {
        options.colour_files.push_back(app::ColourFile{1, false, dir / "plant1.map"});
        options.colour_files.push_back(app::ColourFile{2, false, dir / "plant2.map"});
    }
    app::Model model = app::load_model(options);
    geom::Scene scene = app::interpret(model, app::derive(model, options), options);
    fs::remove_all(dir);
    return scene;
}

}  // namespace

TEST(ColourIndexLighting, PatchColoursReplaceTheTurtlesAndReachTheNextColormap)
{
    // The small surface is drawn in place (geom/flatten.h): its triangles carry the
    // materials the instance showed.
    geom::Scene scene = interpret_patch_colour_model("colormap", false);
    EXPECT_TRUE(scene.instances.empty());
    const geom::TriangleMesh& mesh = scene.geometry.mesh;
    ASSERT_FALSE(mesh.triangles.empty());
    ASSERT_EQ(mesh.material.size(), mesh.triangles.size());
    ASSERT_EQ(mesh.back_material.size(), mesh.triangles.size());
    const std::size_t half = mesh.triangles.size() / 2;  // the two patches' triangles
    // The first patch takes the turtle's colour 7, surface-lit (256 + 7), on both sides.
    EXPECT_EQ(mesh.material.front(), 256 + 7);
    EXPECT_EQ(mesh.back_material.front(), 256 + 7);
    EXPECT_EQ(mesh.material[half - 1], 256 + 7);
    // The second: TOP 300 is entry 44 of the next colormap, BOTTOM 40 entry 40 of this one.
    EXPECT_EQ(mesh.material[half], 512 + 44);
    EXPECT_EQ(mesh.back_material[half], 256 + 40);
    EXPECT_EQ(mesh.material.back(), 512 + 44);
    const geom::Material& top = scene.materials.at(512 + 44);
    EXPECT_EQ(top.diffuse, (geom::Rgb{(255 - 44) / 255.0f, 44 / 255.0f, 0}));
    EXPECT_EQ(top.index_lighting, geom::IndexLighting::surface);
    EXPECT_EQ(top.colour_index, 44);
    EXPECT_EQ(top.colour_table, 512);
    EXPECT_EQ(scene.materials.at(256 + 40).diffuse, (geom::Rgb{40 / 255.0f, 40 / 255.0f, 40 / 255.0f}));
}

TEST(ColourIndexLighting, MaterialFilesIgnorePatchColours)
{
    geom::Scene scene = interpret_patch_colour_model("materials", true);
    const geom::TriangleMesh& mesh = scene.geometry.mesh;
    ASSERT_FALSE(mesh.triangles.empty());
    for (std::uint16_t m : mesh.material)
        EXPECT_EQ(m, 7);  // the turtle's material, no offset
    for (std::uint16_t m : mesh.back_material)
        EXPECT_EQ(m, 7);
}
