// SPDX-License-Identifier: Apache-2.0
// The unidirectional path tracer: next-event estimation toward the view file's lights and
// the environment (MIS against BSDF sampling), transmission, opacity, Russian roulette.
#pragma once

#include <vector>

#include "render/accel.h"
#include "render/environment.h"
#include "render/light.h"
#include "render/material.h"
#include "render/sampler.h"
#include "render/texture.h"
#include "render/vecf.h"

namespace cambium::render {

/// Everything a path needs, read-only and shared by all threads.
struct PathContext {
    const EmbreeScene* accel = nullptr;
    std::vector<SurfaceMaterial> materials;
    std::vector<RenderLight> lights;
    const TextureSet* textures = nullptr;  ///< textures of hits (none: untextured)
    Vec3f background;  ///< linear; seen by camera rays that miss
    /// Seen by secondary rays that escape and sampled for next-event estimation (MIS
    /// against BSDF sampling); not owned. Null: the uniform radiance `ambient`.
    const Environment* environment = nullptr;
    Vec3f ambient;     ///< linear; used only when environment is null
    /// Camera rays that miss see `environment` (a sky or an HDR map the user chose)
    /// instead of cpfg's background colour.
    bool environment_visible = false;
    int max_depth = 6;
    int roulette_depth = 3;
};

/// The radiance of one path and whether its camera ray hit geometry.
struct PathResult {
    Vec3f radiance;
    bool hit = false;
};

/// Traces the camera ray (org, dir) with the sampler's dimensions. Allocates nothing.
PathResult trace_path(const PathContext& ctx, const Vec3f& org, const Vec3f& dir,
                      Sampler& sampler);

}  // namespace cambium::render
