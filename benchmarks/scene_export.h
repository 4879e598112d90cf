// SPDX-License-Identifier: Apache-2.0
// The interpreted Scene as plain JSON, for rebuilding the same plant in another renderer
// (benchmarks/cycles/import_scene.py builds it in Blender to compare noise with Cycles).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <ostream>

#include "geom/scene.h"
#include "render/environment.h"

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
/// whether camera rays that miss see the map rather than the view's background. A --sky
/// is given as its dome and ground in a map (write_sky_dome_map) and its sun as a lamp.
struct StageExport {
    /// The sun disk: direction toward it, solid angle, linear radiance.
    struct Sun {
        std::array<float, 3> toward_sun{};
        float solid_angle = 0;
        std::array<float, 3> radiance{};
    };
    bool view_lights = true;
    std::optional<double> ground_height;
    std::array<float, 3> ground_diffuse{};
    std::filesystem::path environment_map;  ///< empty: none
    float environment_scale = 1, environment_rotation_deg = 0;
    std::optional<Sun> sun;  ///< the --sky's sun, when it is up
    bool backdrop_environment = false;
};

/// Writes the sky's dome (and the ground's radiance below the horizon) without its sun as
/// a lat-long EXR of width x width/2 texels in the --env convention (render/environment.h),
/// each texel the mean over 4 x 4 directions within it; returns the sun disk (nullopt
/// when it is down). Throws cambium::Error when the file cannot be written.
std::optional<StageExport::Sun> write_sky_dome_map(const render::environment_kind::Sky& sky,
                                                   int width, const std::filesystem::path& file);

void write_scene_json(const geom::Scene& scene, int width, int height,
                      const std::filesystem::path& model_folder, std::ostream& out,
                      const std::optional<StageExport>& stage = std::nullopt);

}  // namespace cambium::bench
