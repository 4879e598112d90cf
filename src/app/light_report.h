// SPDX-License-Identifier: Apache-2.0
// --light-report for a still (docs/light.md): the light each organ of an interpreted
// scene absorbs, traced with the options' rays and threads and written to the options'
// file; the command and the Python module both measure through it.
#pragma once

#include <optional>

#include "app/command_line.h"
#include "geom/scene.h"
#include "render/light_report.h"

namespace cambium::app {

/// The --ground as the light report traces it (none without --ground): its colour; a
/// texture is not read (mid grey).
std::optional<render::LightReportSettings::Ground> light_report_ground(const Options& options);

/// Traces `scene`'s lights onto its organs and writes the report to
/// `*options.light_report` (.json or .csv); lights the report cannot trace are warned of.
render::LightReport write_light_report(const geom::Scene& scene, const Options& options);

}  // namespace cambium::app
