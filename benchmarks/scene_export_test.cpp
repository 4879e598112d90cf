// SPDX-License-Identifier: Apache-2.0
// The scene export's staging (convergence --stage --export-scene): what another renderer
// is told to light a staged still with.
#include <cmath>
#include <filesystem>
#include <sstream>
#include <unistd.h>

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

/// The exported sky is the map plus the sun lamp: together they give back the sky's
/// radiance in every direction, and the map alone holds no sun.
TEST(SceneExport, SkyIsItsDomeMapPlusTheSunLamp)
{
    namespace render = cambium::render;
    render::SkyParameters p;
    p.sun_direction = {0.3f, 0.6f, -0.5f};
    const render::environment_kind::Sky sky(p);
    const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                       ("cambium-sky-" + std::to_string(getpid()) + ".exr");
    const auto sun = cambium::bench::write_sky_dome_map(sky, 512, file);
    const render::Environment map = render::make_map_environment(file);
    std::filesystem::remove(file);
    ASSERT_TRUE(sun.has_value());
    const render::Vec3f toward = normalize(p.sun_direction);
    EXPECT_NEAR(sun->toward_sun[0], toward.x, 1e-6);
    const float sun_cos = 1 - sun->solid_angle / (2 * 3.14159265f);

    // Away from the sun's aureole the dome varies slowly: the map's texel (a 4 x 4 mean,
    // stored as half floats) is within 3% of the sky there.
    int checked = 0;
    for (int k = 0; k < 200; ++k) {
        float c = 0.98f - 1.96f * float(k) / 199, phi = 2.39996f * float(k);
        float s = std::sqrt(1 - c * c);
        render::Vec3f d{s * std::cos(phi), c, s * std::sin(phi)};
        if (dot(d, toward) > 0.9f || std::abs(c) < 0.05f)
            continue;
        const render::Vec3f want = sky.radiance(d), got = map.radiance(d);
        EXPECT_NEAR(got.y, want.y, 0.03f * want.y + 1e-6f) << "direction " << k;
        ++checked;
    }
    EXPECT_GT(checked, 150);

    // At the sun: the map has only the dome there, the lamp the rest.
    const render::Vec3f at_sun = sky.radiance(toward), dome = map.radiance(toward);
    render::Vec3f lamp{sun->radiance[0], sun->radiance[1], sun->radiance[2]};
    EXPECT_LT(dome.y, 1e-3f * at_sun.y);
    EXPECT_NEAR(dome.y + lamp.y, at_sun.y, 2e-3f * at_sun.y);
    EXPECT_GT(sun_cos, std::cos(0.3f * 3.14159265f / 180));
}

}  // namespace
