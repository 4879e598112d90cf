// SPDX-License-Identifier: Apache-2.0
// The unidirectional path tracer with next-event estimation toward the view file's lights.
#pragma once

#include <vector>

#include "render/accel.h"
#include "render/light.h"
#include "render/material.h"
#include "render/sampler.h"
#include "render/vecf.h"

namespace cambium::render {

/// Everything a path needs, read-only and shared by all threads.
struct PathContext {
    const EmbreeScene* accel = nullptr;
    std::vector<SurfaceMaterial> materials;
    std::vector<RenderLight> lights;
    Vec3f background;   ///< linear; seen by camera rays that miss
    Vec3f environment;  ///< linear; seen by secondary rays that escape
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
