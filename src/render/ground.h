// SPDX-License-Identifier: Apache-2.0
// The ground plane of staged renders (--ground, --shadow-catcher): an infinite horizontal
// plane under the plant, intersected analytically beside the Embree scene.
#pragma once

#include <cstdint>
#include <optional>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/vecf.h"

namespace cambium::render {

/// The Embree geometry id that marks hits on the ground (no Embree geometry has it).
inline constexpr std::uint32_t ground_geom_id = 0xfffffffeu;

/// The lowest point of the scene's geometry along +y (cpfg's view up, the turtle's
/// initial heading): the least of cpfg's bounds, triangle vertices, the bottoms of
/// spheres and discs, instanced prototypes, and the curves' axis points without their
/// radius (a stem standing on its flat end rests on the ground). 0 when empty.
double lowest_point(const geom::Scene& scene);

/// The plane y = height, perpendicular to the view's up vector, extending to infinity
/// (it meets the horizon in perspective views and fills a parallel view that looks
/// down on it). Seen from either side; its normal faces the ray.
struct GroundPlane {
    float height = 0;
    std::uint16_t material = 0;            ///< index into the path context's materials
    std::int16_t texture = geom::no_texture;  ///< tiled: (s, t) = (x, z) / tile
    float tile = 1;                        ///< world units per texture repeat
    /// Shadow catcher: camera rays that meet the ground record how much light the plant
    /// takes from it (PathResult::catcher) instead of its radiance, and no other ray
    /// sees it.
    bool shadow_catcher = false;

    /// The distance along org + t dir (t in (0, tfar)) at which the ray meets the plane.
    std::optional<float> distance(const Vec3f& org, const Vec3f& dir, float tfar) const;
    /// The hit at distance t, ready for shading.
    SurfaceHit hit(const Vec3f& org, const Vec3f& dir, float t) const;
};

}  // namespace cambium::render
