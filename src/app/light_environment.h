// SPDX-License-Identifier: Apache-2.0
// The light environment for open L-systems (docs/environment.md), in the place of vlab's
// QuasiMC: at each environmental pass the plant is interpreted, the specification's
// lights are traced through it (and through the other plants of a field sharing it) with
// the light report's tracer, and each ?E is answered with the light of the organ that
// follows it, in one process.
#pragma once

#include <functional>
#include <memory>
#include <optional>

#include "env/environment.h"
#include "env/light_spec.h"
#include "geom/scene.h"
#include "render/light_report.h"

namespace cambium::app {

/// A pass's plant as a Scene whose primitives name their modules in the derived string.
using PassScene = std::function<geom::Scene(const env::PassPlant&)>;

/// The light environment: answers a ?E whose first parameter is at least 0 (QuasiMC's
/// "return a value") with `spec.answer` for the organ after it, in the light report's
/// units; leaves the others as they are. A `Q(n)` after a ?E sets the rays of this and
/// later passes (QuasiMC's Q module). Pass k traces with seed k, so runs repeat at any
/// thread count (`threads`, 0: TBB's default). Shared by a scene file's field, it traces
/// every plant together where it stands, each plant's last geometry shading the others.
/// `ground`: the --ground under them (light_report_ground), reflecting as in the report.
std::unique_ptr<env::Environment> make_light_environment(env::LightSpec spec, PassScene scene_of, int threads,
                                                         std::optional<render::LightReportSettings::Ground> ground);

}  // namespace cambium::app
