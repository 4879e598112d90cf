// SPDX-License-Identifier: Apache-2.0
// The interpreted Scene as plain JSON, for rebuilding the same plant in another renderer
// (benchmarks/cycles/import_scene.py builds it in Blender to compare noise with Cycles).
#pragma once

#include <filesystem>
#include <ostream>

#include "geom/scene.h"

namespace cambium::bench {

/// Writes `scene` as Cambium renders it at width x height: the camera make_camera()
/// frames, the view file's lights and the materials decoded to the path tracer's linear
/// quantities (render::make_lights, render::make_materials with cpfg's ambient), the
/// geometry and prototypes with their instances as stored, texture files made absolute
/// against `model_folder`, and the background and ambient environment radiance.
/// Layout: benchmarks/cycles/README.md.
void write_scene_json(const geom::Scene& scene, int width, int height,
                      const std::filesystem::path& model_folder, std::ostream& out);

}  // namespace cambium::bench
