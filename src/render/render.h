// SPDX-License-Identifier: Apache-2.0
// The render layer's entry points: render a Scene to an Image, write it to a file.
#pragma once

#include <cstdint>

#include "geom/scene.h"
#include "render/camera.h"
#include "render/film.h"

namespace cambium::render {

/// How to render a frame.
struct RenderSettings {
    int width = 640, height = 480;  ///< cpfg's default window
    int samples_per_pixel = 64;
    /// Path segments at most: 1 = direct light only, 2 = one bounce, ...
    int max_depth = 6;
    /// Russian roulette starts after this many segments.
    int roulette_depth = 3;
    std::uint64_t seed = 0;
    int threads = 0;  ///< 0 = all cores
    /// Radiance (linear RGB) of the uniform environment that secondary rays see when they
    /// escape: the physically-based stand-in for cpfg's ambient term. Camera rays that
    /// miss see the background colour instead.
    geom::Rgb ambient{0.05f, 0.05f, 0.05f};
};

/// Renders the scene as cpfg frames it (make_camera) with a unidirectional path tracer.
/// The result depends on the scene, the settings and the seed, never on the thread count.
/// Throws cambium::Error on invalid settings or an Embree failure.
Image render(const geom::Scene& scene, const RenderSettings& settings);

/// Renders with an explicit camera (tests, turntables).
Image render(const geom::Scene& scene, const Camera& camera, const RenderSettings& settings);

}  // namespace cambium::render
