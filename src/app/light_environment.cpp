// SPDX-License-Identifier: Apache-2.0
#include "app/light_environment.h"

#include <cmath>
#include <unordered_map>

#include "base/diagnostics.h"
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

class LightEnvironment final : public env::Environment {
public:
    LightEnvironment(env::LightSpec spec, PassScene scene_of, int threads)
        : m_spec(std::move(spec)), m_scene_of(std::move(scene_of)), m_threads(threads)
    {
    }

    void observe(const env::PassPlant& plant) override { m_scene = m_scene_of(plant); }

    std::vector<env::Reply> pass(const std::vector<env::Query>& queries, int step) override
    {
        if (!m_scene)
            throw Error("QuasiMC: the light environment computes on one plant's own geometry, which this "
                        "pass did not give it (a scene file's field does not share it)");
        for (const env::Query& q : queries)
            take_settings(q);
        render::LightReportSettings settings;
        settings.rays = m_spec.rays;
        settings.seed = static_cast<std::uint64_t>(step);
        settings.threads = m_threads;
        settings.max_bounces = m_spec.max_depth;
        settings.view_lights = false;
        for (const env::ParallelLight& l : m_spec.lights)
            settings.lights.push_back(parallel_light(l));
        if (m_spec.optics) {
            const auto& o = *m_spec.optics;
            settings.optics = std::array<render::SurfaceOptics, 2>{
                render::SurfaceOptics{o[0].reflectance, o[0].transmittance},
                render::SurfaceOptics{o[1].reflectance, o[1].transmittance}};
        }
        const render::LightReport report = render::trace_light(*m_scene, settings);
        m_scene.reset();
        std::unordered_map<std::uint64_t, render::OrganLight> organs;
        for (const render::OrganLight& o : report.organs) {
            render::OrganLight& sum = organs[o.module];  // instances of one module add up
            sum.area += o.area;
            sum.absorbed += o.absorbed;
            sum.incident_front += o.incident_front;
            sum.incident_back += o.incident_back;
        }
        std::vector<env::Reply> replies;
        for (const env::Query& q : queries) {
            if (q.module.params.empty() || !(q.module.params[0] >= 0) || is_setting(q))
                continue;
            const auto it = organs.find(q.organ);
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
    std::optional<geom::Scene> m_scene;
    bool m_warned_sky = false;
};

}  // namespace

std::unique_ptr<env::Environment> make_light_environment(env::LightSpec spec, PassScene scene_of, int threads)
{
    return std::make_unique<LightEnvironment>(std::move(spec), std::move(scene_of), threads);
}

}  // namespace cambium::app
