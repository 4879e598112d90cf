// SPDX-License-Identifier: Apache-2.0
// Geometry the renderer derives from the Scene's lines before building Embree: the discs
// and spheres that close shaded cylinders (cpfg's flat ends and round bends), and
// prototypes' pixel-width lines placed in world space (their width depends on depth).
#pragma once

#include <cstdint>
#include <vector>

#include "geom/scene.h"
#include "render/camera.h"

namespace cambium::render {

/// Cylinders (F, G) as cpfg draws them: truncated cones with flat ends. Embree's round
/// linear curves sweep a sphere, which turns a short wide segment (a lamp's base, a
/// trunk's foot) into a ball; its cone curves are the exact frustums but leave the ends
/// open and a wedge at each bend. So shaded lines are cone curves, each free end gets a
/// disc and each bent joint a sphere of the joint's radius (the round joint cpfg's
/// smooth tubes show).
struct LineEnds {
    std::vector<geom::Float4> caps;                   ///< disc centre and radius per free end
    std::vector<geom::Float3> cap_normals;   ///< out of the cylinder
    std::vector<std::uint32_t> cap_segment;  ///< the segment each cap closes
    std::vector<std::uint8_t> cap_at_end;    ///< 1: at the segment's second key
    std::vector<geom::Float4> joints;                 ///< sphere centre and radius per bent joint
    std::vector<std::uint32_t> joint_segment;  ///< the segment a joint ends
};

/// The caps and joints of the shaded lines `l` whose keys (radii in world units) are `keys`.
LineEnds line_ends(const geom::LinearCurves& l, const geom::Float4* keys);

/// The pixel-width lines of every instance's prototype in world space: keys transformed,
/// radii converted at each key's depth, materials and textures resolved. Throws
/// cambium::Error past 2^27 keys or on a segment whose key is out of range.
geom::LinearCurves place_pixel_lines(const geom::Scene& scene, const Camera& camera);

/// The keys of `lines` with radii converted from pixels to world units at each key's depth.
std::vector<geom::Float4> keys_in_world_units(const geom::LinearCurves& lines,
                                              const Camera& camera);

}  // namespace cambium::render
