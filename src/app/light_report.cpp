// SPDX-License-Identifier: Apache-2.0
#include "app/light_report.h"

#include "app/sequence.h"
#include "app/shot_options.h"
#include "base/diagnostics.h"

namespace cambium::app {

std::optional<render::LightReportSettings::Ground> light_report_ground(const Options& options)
{
    const std::optional<std::string>& value = options.shot.ground;
    if (!value)
        return std::nullopt;  // --shadow-catcher alone: no ray but the camera's sees it
    render::LightReportSettings::Ground ground;  // mid grey, as the renderer's default
    if (is_ground_texture(*value)) {
        warn("--light-report: the ground's texture " + *value + " is not read; the ground is traced mid grey");
    } else if (!value->empty()) {
        const auto rgb = background_colour(*value, "--ground");
        ground.colour = {rgb[0], rgb[1], rgb[2]};
    }
    return ground;
}

render::LightReport write_light_report(const geom::Scene& scene, const Options& options)
{
    render::LightReportSettings settings;
    settings.rays = options.light_rays;
    settings.threads = options.threads;
    settings.view_lights = !options.no_view_lights;
    settings.environment = make_environment(options);
    settings.infinite_canopy = options.infinite_canopy;
    settings.ground = light_report_ground(options);
    if (options.canopy_tile.size() == 4)
        settings.canopy_tile = {options.canopy_tile[0], options.canopy_tile[1], options.canopy_tile[2],
                                options.canopy_tile[3]};
    render::LightReport report = render::trace_light(scene, settings);
    for (const std::string& skipped : report.skipped_lights)
        warn("--light-report: " + skipped);
    render::write_light_report(report, *options.light_report);
    return report;
}

}  // namespace cambium::app
