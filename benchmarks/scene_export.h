// SPDX-License-Identifier: Apache-2.0
// The interpreted Scene as plain JSON, for rebuilding the same plant in another renderer
// (benchmarks/cycles/import_scene.py builds it in Blender to compare noise with Cycles).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <ostream>

#include "geom/scene.h"

namespace cambium::bench {

/// Writes `scene` as Cambium renders it at width x height: the camera make_camera()
/// frames, the view file's lights and the materials decoded to the path tracer's linear
/// quantities (render::make_lights, render::make_materials with cpfg's ambient), the
/// geometry and prototypes with their instances as stored, texture files made absolute
/// against `model_folder`, and the background and ambient environment radiance.
/// Layout: benchmarks/cycles/README.md.
/// What a staged still adds (convergence --stage): whether the view file's lights are
/// kept (without them, no light and no OpenGL ambient term is written), the ground plane
/// (its height and decoded diffuse colour), the lat-long map lighting the scene, and
/// whether camera rays that miss see the map rather than the view's background.
struct StageExport {
    bool view_lights = true;
    std::optional<double> ground_height;
    std::array<float, 3> ground_diffuse{};
    std::filesystem::path environment_map;  ///< empty: none
    float environment_scale = 1, environment_rotation_deg = 0;
    bool backdrop_environment = false;
};

void write_scene_json(const geom::Scene& scene, int width, int height,
                      const std::filesystem::path& model_folder, std::ostream& out,
                      const std::optional<StageExport>& stage = std::nullopt);

}  // namespace cambium::bench
