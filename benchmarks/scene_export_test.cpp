// SPDX-License-Identifier: Apache-2.0
// The scene export's staging (convergence --stage --export-scene): what another renderer
// is told to light a staged still with.
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene_export.h"

namespace {

using nlohmann::json;

/// One triangle of a material with an ambient term, lit by one directional light.
cambium::geom::Scene lit_triangle()
{
    cambium::geom::Scene scene;
    cambium::geom::Material m;
    m.ambient = {0.5f, 0.5f, 0.5f};
    scene.materials.push_back(m);
    auto& mesh = scene.geometry.mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    mesh.uvs = {{0, 0}, {1, 0}, {0, 1}};
    mesh.triangles = {{0, 1, 2}};
    mesh.material = {0};
    mesh.back_material = {0};
    mesh.texture = {cambium::geom::no_texture};
    scene.bounds = {{0, 0, 0}, {1, 1, 0}};
    cambium::geom::Light sun;
    sun.kind = cambium::geom::Light::Kind::directional;
    scene.lights.push_back(sun);
    return scene;
}

json exported(const std::optional<cambium::bench::StageExport>& stage)
{
    std::ostringstream out;
    cambium::bench::write_scene_json(lit_triangle(), 32, 24, ".", out, stage);
    return json::parse(out.str());
}

double sum(const json& rgb)
{
    return rgb[0].get<double>() + rgb[1].get<double>() + rgb[2].get<double>();
}

TEST(SceneExport, UnstagedHasNoStageAndKeepsTheLights)
{
    json j = exported(std::nullopt);
    EXPECT_FALSE(j.contains("stage"));
    EXPECT_EQ(j["lights"].size(), 1u);
    EXPECT_GT(sum(j["materials"][0]["ambient_glow"]), 0);
}

TEST(SceneExport, DroppedViewLightsTakeTheirAmbientTermAlong)
{
    cambium::bench::StageExport stage;
    stage.view_lights = false;
    stage.ground_height = -0.5;
    stage.ground_diffuse = {0.2f, 0.2f, 0.2f};
    stage.environment_map = "/maps/sky.exr";
    stage.environment_scale = 2;
    stage.backdrop_environment = true;
    json j = exported(stage);
    EXPECT_TRUE(j["lights"].empty());
    EXPECT_EQ(sum(j["materials"][0]["ambient_glow"]), 0);  // as render() drops it
    ASSERT_TRUE(j.contains("stage"));
    EXPECT_FALSE(j["stage"]["view_lights"].get<bool>());
    EXPECT_EQ(j["stage"]["ground"]["height"].get<double>(), -0.5);
    EXPECT_FLOAT_EQ(j["stage"]["ground"]["diffuse"][1].get<float>(), 0.2f);
    EXPECT_EQ(j["stage"]["environment"]["map"], "/maps/sky.exr");
    EXPECT_EQ(j["stage"]["environment"]["scale"].get<double>(), 2);
    EXPECT_EQ(j["stage"]["backdrop"], "environment");
}

TEST(SceneExport, KeptViewLightsAndNoGroundOrMap)
{
    cambium::bench::StageExport stage;
    json j = exported(stage);
    EXPECT_EQ(j["lights"].size(), 1u);
    EXPECT_GT(sum(j["materials"][0]["ambient_glow"]), 0);
    EXPECT_TRUE(j["stage"]["ground"].is_null());
    EXPECT_TRUE(j["stage"]["environment"].is_null());
    EXPECT_EQ(j["stage"]["backdrop"], "view");
}

}  // namespace
