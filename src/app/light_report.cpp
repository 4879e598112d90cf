// SPDX-License-Identifier: Apache-2.0
#include "app/light_report.h"

#include "app/sequence.h"
#include "base/diagnostics.h"

namespace cambium::app {

render::LightReport write_light_report(const geom::Scene& scene, const Options& options)
{
    render::LightReportSettings settings;
    settings.rays = options.light_rays;
    settings.threads = options.threads;
    settings.view_lights = !options.no_view_lights;
    settings.environment = make_environment(options);
    settings.infinite_canopy = options.infinite_canopy;
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
