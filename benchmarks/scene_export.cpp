// SPDX-License-Identifier: Apache-2.0
#include "scene_export.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "render/camera.h"
#include "render/color.h"
#include "render/image_io.h"
#include "render/light.h"
#include "render/material.h"
#include "render/render.h"

namespace cambium::bench {

namespace {

using nlohmann::json;
namespace geom = cambium::geom;
namespace render = cambium::render;

json vec(const geom::Vec3& v) { return json::array({v.x, v.y, v.z}); }
json vec(const render::Vec3f& v) { return json::array({v.x, v.y, v.z}); }

/// Arrays of fixed-size arrays flattened into one list of numbers (numpy reshapes them).
template <typename T, std::size_t N>
json flat(const std::vector<std::array<T, N>>& items)
{
    json out = json::array();
    for (const auto& item : items)
        for (const T& x : item)
            out.push_back(x);
    return out;
}

json geometry_json(const geom::Geometry& g)
{
    json out;
    out["lines"] = {{"keys", flat(g.lines.keys)},       {"segments", g.lines.segments},
                    {"material", g.lines.material},     {"texture", g.lines.texture},
                    {"v", g.lines.v}};
    out["curves"] = {{"points", flat(g.curves.points)}, {"tangents", flat(g.curves.tangents)},
                     {"segments", g.curves.segments},   {"material", g.curves.material},
                     {"end_material", g.curves.end_material},
                     {"texture", g.curves.texture},     {"v", g.curves.v}};
    out["spheres"] = {{"centres", flat(g.spheres.centres)}, {"material", g.spheres.material}};
    out["discs"] = {{"centres", flat(g.discs.centres)}, {"normals", flat(g.discs.normals)},
                    {"material", g.discs.material},     {"back_material", g.discs.back_material}};
    out["mesh"] = {{"positions", flat(g.mesh.positions)}, {"normals", flat(g.mesh.normals)},
                   {"uvs", flat(g.mesh.uvs)},             {"triangles", flat(g.mesh.triangles)},
                   {"material", g.mesh.material},         {"back_material", g.mesh.back_material},
                   {"texture", g.mesh.texture}};
    return out;
}

json camera_json(const render::Camera& c, const geom::Bounds3& bounds)
{
    json out = {{"projection", c.projection() == render::Camera::Projection::parallel
                                   ? "parallel"
                                   : "perspective"},
                {"origin", vec(c.origin())},
                {"forward", vec(c.forward())},
                {"up", vec(c.up())},
                {"right", vec(c.right())},
                {"pixel_size", c.pixel_size()},
                {"clip_near", std::isfinite(c.clip_near()) ? json(c.clip_near()) : json()},
                {"clip_far", std::isfinite(c.clip_far()) ? json(c.clip_far()) : json()}};
    if (c.projection() == render::Camera::Projection::perspective)
        // The vertical field of view: the image's height at unit distance from the eye.
        out["fov_y_rad"] =
            2 * std::atan(0.5 * c.height() * c.pixel_size_at(c.origin() + c.forward()));
    // A parallel camera's rays start behind everything: from the bounds' far side.
    geom::Vec3 extent = bounds.hi - bounds.lo;
    out["scene_radius"] = 0.5 * std::sqrt(extent.x * extent.x + extent.y * extent.y +
                                          extent.z * extent.z);
    out["scene_centre"] = vec((bounds.lo + bounds.hi) * 0.5);
    return out;
}

json lights_json(const std::vector<geom::Light>& lights)
{
    json out = json::array();
    for (const render::RenderLight& l : render::make_lights(lights)) {
        const char* kind = l.kind == render::RenderLight::Kind::directional ? "directional"
                           : l.kind == render::RenderLight::Kind::point   ? "point"
                                                                          : "spot";
        out.push_back({{"kind", kind},
                       {"position", vec(l.position)},
                       {"toward_light", vec(l.toward_light)},
                       {"spot_axis", vec(l.spot_axis)},
                       {"spot_exponent", l.spot_exponent},
                       {"spot_cos_cutoff", l.spot_cos_cutoff},
                       {"attenuation", {l.att_constant, l.att_linear, l.att_quadratic}},
                       {"colour", vec(l.colour)}});
    }
    return out;
}

json materials_json(const geom::Scene& scene, bool view_lights)
{
    json out = json::array();
    // Without the view's lights the renderer drops their OpenGL ambient term too.
    for (const render::SurfaceMaterial& m : render::make_materials(
             scene.materials,
             view_lights ? render::opengl_ambient_light(scene.lights) : geom::Rgb{0, 0, 0}))
        out.push_back({{"diffuse", vec(m.diffuse)},
                       {"translucency", m.translucency},
                       {"specular", vec(m.specular)},
                       {"exponent", m.exponent},
                       {"emission", vec(m.emission)},
                       {"opacity", m.opacity},
                       {"ambient_glow", vec(m.ambient_glow)}});
    return out;
}

}  // namespace

std::optional<StageExport::Sun> write_sky_dome_map(const render::environment_kind::Sky& sky,
                                                   int width, const std::filesystem::path& file)
{
    constexpr int sub = 4;
    constexpr float pi = 3.14159265358979f;
    render::Image map;
    map.width = width;
    map.height = width / 2;
    map.rgba.resize(std::size_t(map.width) * std::size_t(map.height) * 4);
    for (int j = 0; j < map.height; ++j)
        for (int i = 0; i < map.width; ++i) {
            render::Vec3f sum;
            for (int a = 0; a < sub; ++a)
                for (int b = 0; b < sub; ++b) {
                    // Uniform in the texel's polar angle, as the map's lookup is by angle.
                    float t = pi * (float(j) + (float(a) + 0.5f) / sub) / float(map.height);
                    float u = (float(i) + (float(b) + 0.5f) / sub) / float(map.width);
                    sum += sky.without_sun(render::environment_kind::LatLongTable::direction(
                        u, std::cos(t)));
                }
            sum = sum * (1.0f / (sub * sub));
            float* texel = &map.at(i, j, 0);
            texel[0] = sum.x;
            texel[1] = sum.y;
            texel[2] = sum.z;
            texel[3] = 1;
        }
    render::write_image(map, file);
    const render::environment_kind::Sky::SunDisk sun = sky.sun_disk();
    if (!(sun.solid_angle > 0) || !(sun.radiance.x > 0 || sun.radiance.y > 0 || sun.radiance.z > 0))
        return std::nullopt;
    return StageExport::Sun{{sun.direction.x, sun.direction.y, sun.direction.z},
                            sun.solid_angle,
                            {sun.radiance.x, sun.radiance.y, sun.radiance.z}};
}

void write_scene_json(const geom::Scene& scene, int width, int height,
                      const std::filesystem::path& model_folder, std::ostream& out,
                      const std::optional<StageExport>& stage)
{
    const bool view_lights = !stage || stage->view_lights;
    render::RenderSettings defaults;  // the ambient environment render() uses
    json j;
    j["format"] = "cambium-scene-1";
    j["width"] = width;
    j["height"] = height;
    j["shading"] = scene.shading == geom::Shading::shaded ? "shaded"
                   : scene.shading == geom::Shading::flat ? "flat"
                                                          : "unlit";  // filled, wireframe
    j["line_radius_in_pixels"] = scene.line_radius_in_pixels;
    j["camera"] = camera_json(render::make_camera(scene.view, scene.bounds, width, height),
                              scene.bounds);
    j["lights"] = view_lights ? lights_json(scene.lights) : json::array();
    j["materials"] = materials_json(scene, view_lights);
    if (stage) {
        json st;
        st["view_lights"] = stage->view_lights;
        st["ground"] = stage->ground_height
                           ? json{{"height", *stage->ground_height},
                                  {"diffuse", stage->ground_diffuse}}
                           : json();
        st["environment"] = stage->environment_map.empty()
                                ? json()
                                : json{{"map", stage->environment_map.string()},
                                       {"scale", stage->environment_scale},
                                       {"rotation_deg", stage->environment_rotation_deg}};
        if (stage->sun)
            st["sun"] = {{"toward_sun", stage->sun->toward_sun},
                         {"solid_angle", stage->sun->solid_angle},
                         {"radiance", stage->sun->radiance}};
        st["backdrop"] = stage->backdrop_environment ? "environment" : "view";
        j["stage"] = st;
    }
    j["background"] = vec(render::decode_display(scene.background));
    j["ambient_radiance"] = {defaults.ambient.r, defaults.ambient.g, defaults.ambient.b};
    j["max_depth"] = defaults.max_depth;
    json textures = json::array();
    for (const geom::TextureDef& t : scene.textures)
        textures.push_back({{"file", (t.file.is_absolute() ? t.file : model_folder / t.file)
                                         .lexically_normal()
                                         .string()},
                            {"decal", t.decal},
                            {"linear_filter", t.linear_filter}});
    j["textures"] = textures;
    j["geometry"] = geometry_json(scene.geometry);
    json prototypes = json::array();
    for (const geom::Prototype& p : scene.prototypes)
        prototypes.push_back({{"name", p.name}, {"geometry", geometry_json(p.geometry)}});
    j["prototypes"] = prototypes;
    json instances = json::array();
    for (const geom::Instance& i : scene.instances)
        instances.push_back({{"prototype", i.prototype},
                             {"transform", i.transform},
                             {"material", i.material},
                             {"back_material", i.back_material},
                             {"texture", i.texture}});
    j["instances"] = instances;
    out << j.dump() << '\n';
}

}  // namespace cambium::bench
