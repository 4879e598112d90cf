// SPDX-License-Identifier: Apache-2.0
#include "app/light_environment.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include "app/scene_file.h"
#include "base/diagnostics.h"
#include "geom/background_scene.h"
#include "render/light_report.h"

namespace cambium::app {
namespace {

render::RenderLight parallel_light(const env::ParallelLight& l)
{
    render::RenderLight r;
    r.kind = render::RenderLight::Kind::directional;
    r.toward_light = render::Vec3f(-float(l.travel[0]), -float(l.travel[1]), -float(l.travel[2]));
    r.colour = render::Vec3f(float(l.irradiance));
    return r;
}

/// What the organ's light is answered as.
double answer_of(const render::OrganLight& o, env::LightAnswer answer)
{
    const double area = o.area > 0 ? o.area : 0;
    switch (answer) {
    case env::LightAnswer::absorbed_flux:
        return o.absorbed;
    case env::LightAnswer::absorbed_irradiance:
        return area > 0 ? o.absorbed / area : 0;
    case env::LightAnswer::front_irradiance:
        return area > 0 ? o.incident_front / area : 0;
    case env::LightAnswer::back_irradiance:
        return area > 0 ? o.incident_back / area : 0;
    }
    return 0;
}

/// Whether two plants' materials are the same table (plants of one model share one).
bool same_materials(const std::vector<geom::Material>& a, const std::vector<geom::Material>& b)
{
    auto same = [](const geom::Material& x, const geom::Material& y) {
        return x.ambient == y.ambient && x.diffuse == y.diffuse && x.emission == y.emission &&
               x.specular == y.specular && x.shininess == y.shininess && x.transparency == y.transparency &&
               x.translucency == y.translucency && x.index_lighting == y.index_lighting &&
               x.colour_index == y.colour_index && x.colour_table == y.colour_table;
    };
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), same);
}

/// One plant's last pass: its interpretation and where it stands.
struct PlantPass {
    geom::Scene scene;
    Transform placement{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
};

/// Every plant placed in one scene, as a scene file's field is (app/scene_assembly): each
/// plant's own geometry a prototype placed by an instance of its number, its organs'
/// instances moved with it, so each primitive's organ is (plant, module).
geom::Scene field_of(const std::map<std::size_t, PlantPass>& plants)
{
    geom::Scene out;
    out.materials.clear();
    std::vector<std::pair<std::size_t, std::size_t>> tables;  // (first material, plant) per table
    for (const auto& [number, plant] : plants) {
        const geom::Scene& s = plant.scene;
        std::size_t first = out.materials.size();
        const auto same = std::find_if(tables.begin(), tables.end(), [&](const auto& t) {
            return same_materials(plants.at(t.second).scene.materials, s.materials);
        });
        if (same != tables.end()) {
            first = same->first;
        } else {
            if (first + s.materials.size() > geom::inherit_material)
                throw Error("QuasiMC: the plants sharing the light environment have more than " +
                            std::to_string(geom::inherit_material) + " materials between them");
            out.materials.insert(out.materials.end(), s.materials.begin(), s.materials.end());
            tables.emplace_back(first, number);
        }
        const auto offset = static_cast<std::uint16_t>(first);
        const auto plant_number = static_cast<std::uint32_t>(number);
        auto shifted = [&](geom::Geometry g) {
            geom::offset_materials(g, offset);
            return g;
        };
        geom::Instance own;
        own.prototype = static_cast<std::uint32_t>(out.prototypes.size());
        own.transform = plant.placement;
        own.plant = plant_number;
        out.prototypes.push_back({"plant " + std::to_string(number), shifted(s.geometry)});
        out.instances.push_back(own);  // first: OrganModules finds the plant's table by it
        const auto prototypes = static_cast<std::uint32_t>(out.prototypes.size());
        for (const geom::Prototype& p : s.prototypes)
            out.prototypes.push_back({p.name, shifted(p.geometry)});
        for (geom::Instance organ : s.instances) {
            organ.prototype += prototypes;
            if (organ.material != geom::inherit_material)
                organ.material = static_cast<std::uint16_t>(organ.material + offset);
            if (organ.back_material != geom::inherit_material)
                organ.back_material = static_cast<std::uint16_t>(organ.back_material + offset);
            organ.transform = compose(plant.placement, organ.transform);
            organ.plant = plant_number;
            out.instances.push_back(organ);
        }
    }
    return out;
}

class LightEnvironment final : public env::Environment {
public:
    LightEnvironment(env::LightSpec spec, PassScene scene_of, int threads,
                     std::optional<render::LightReportSettings::Ground> ground)
        : m_spec(std::move(spec)), m_scene_of(std::move(scene_of)), m_threads(threads), m_ground(std::move(ground))
    {
    }

    void observe(const env::PassPlant& plant) override
    {
        PlantPass pass{m_scene_of(plant)};  // in the plant's own thread: plants interpret at once
        if (plant.placement)
            pass.placement = *plant.placement;
        std::lock_guard lock(m_mutex);
        m_plants[plant.plant] = std::move(pass);
    }

    std::vector<env::Reply> pass(const std::vector<env::Query>& queries, int step) override
    {
        for (const env::Query& q : queries)
            take_settings(q);
        render::LightReportSettings settings;
        settings.rays = m_spec.rays;
        settings.seed = static_cast<std::uint64_t>(step);
        settings.threads = m_threads;
        settings.max_bounces = m_spec.max_depth;
        settings.view_lights = false;
        settings.ground = m_ground;
        for (const env::ParallelLight& l : m_spec.lights)
            settings.lights.push_back(parallel_light(l));
        if (m_spec.optics) {
            const auto& o = *m_spec.optics;
            settings.optics = std::array<render::SurfaceOptics, 2>{
                render::SurfaceOptics{o[0].reflectance, o[0].transmittance},
                render::SurfaceOptics{o[1].reflectance, o[1].transmittance}};
        }
        // plants that have stopped deriving keep their last geometry: they still shade
        const render::LightReport report = render::trace_light(field_of(m_plants), settings);
        std::map<std::pair<std::uint64_t, std::uint64_t>, render::OrganLight> organs;
        for (const render::OrganLight& o : report.organs) {
            render::OrganLight& sum = organs[{o.plant, o.module}];  // instances of one module add up
            sum.area += o.area;
            sum.absorbed += o.absorbed;
            sum.incident_front += o.incident_front;
            sum.incident_back += o.incident_back;
        }
        std::vector<env::Reply> replies;
        for (const env::Query& q : queries) {
            if (q.module.params.empty() || !(q.module.params[0] >= 0) || is_setting(q))
                continue;
            const auto it = organs.find({q.plant, q.organ});
            const double value = it == organs.end() ? 0 : answer_of(it->second, m_spec.answer);
            replies.push_back(env::Reply{q.address, {static_cast<float>(value)}});
        }
        return replies;
    }

private:
    static bool is_setting(const env::Query& q)
    {
        return q.following && (q.following->symbol == "Q" || q.following->symbol == "J");
    }

    /// QuasiMC's setting modules after a ?E: Q(rays, ...) changes the rays; J (the sky
    /// model's day) is not followed.
    void take_settings(const env::Query& q)
    {
        if (!q.following)
            return;
        if (q.following->symbol == "Q" && !q.following->params.empty()) {
            const double n = q.following->params[0];
            if (!(n >= 1 && n <= static_cast<double>(env::max_light_rays)))
                throw Error("QuasiMC: Q(" + std::to_string(n) + "): the rays of a pass lie in 1 .. " +
                            std::to_string(env::max_light_rays));
            m_spec.rays = static_cast<std::uint64_t>(n);
        } else if (q.following->symbol == "J" && !m_warned_sky) {
            warn("QuasiMC: J (the sky model's day and weather) is not followed by Cambium's light environment");
            m_warned_sky = true;
        }
    }

    env::LightSpec m_spec;
    PassScene m_scene_of;
    int m_threads = 0;
    std::optional<render::LightReportSettings::Ground> m_ground;
    std::mutex m_mutex;
    std::map<std::size_t, PlantPass> m_plants;
    bool m_warned_sky = false;
};

}  // namespace

std::unique_ptr<env::Environment> make_light_environment(env::LightSpec spec, PassScene scene_of, int threads,
                                                         std::optional<render::LightReportSettings::Ground> ground)
{
    return std::make_unique<LightEnvironment>(std::move(spec), std::move(scene_of), threads, std::move(ground));
}

}  // namespace cambium::app
