// SPDX-License-Identifier: Apache-2.0
// Where shaded cylinders (F, G) end and bend: the flat discs and joint spheres the
// renderer closes them with (render/line_geometry.h) and the mesh exports tessellate
// (geom/tessellate.h), found by one rule so that both close the same ends.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "geom/scene.h"

namespace cambium::geom {

/// Below this cosine of a bend (about 0.8 degrees) a chain's frustums meet without a
/// visible wedge, so its joint gets no sphere.
inline constexpr float straight_joint = 0.9999f;

/// The unit direction of the line from key k to key k + 1, or zero where they coincide.
inline Float3 line_direction(const Float4* keys, std::uint32_t k)
{
    const Float3 d{keys[k + 1][0] - keys[k][0], keys[k + 1][1] - keys[k][1],
                   keys[k + 1][2] - keys[k][2]};
    const float length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(length > 0))
        return {0, 0, 0};
    const float inverse = 1 / length;
    return {d[0] * inverse, d[1] * inverse, d[2] * inverse};
}

inline float dot(const Float3& a, const Float3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Segment i of `l` (keys `keys`, radii in world units) in order: cap(key, outward unit
/// normal, at its second key?) for each free end that has a radius and a direction, and
/// joint(key) where its next segment continues it bent by more than straight_joint.
template <class Cap, class Joint>
void visit_line_ends(const LinearCurves& l, const Float4* keys, std::size_t i, Cap&& cap,
                     Joint&& joint)
{
    const std::uint32_t k = l.segments[i];
    const std::uint8_t f = l.flags.size() == l.segments.size() ? l.flags[i] : 0;
    const Float3 dir = line_direction(keys, k);
    auto add_cap = [&](const Float4& at, const Float3& out, bool end) {
        if (at[3] > 0 && dot(out, out) != 0)  // else tapered to nothing or no direction
            cap(at, out, end);
    };
    if (!(f & LinearCurves::neighbour_left))
        add_cap(keys[k], Float3{-dir[0], -dir[1], -dir[2]}, false);
    if (!(f & LinearCurves::neighbour_right))
        add_cap(keys[k + 1], dir, true);
    else if (k + 2 < l.keys.size() && keys[k + 1][3] > 0 &&
             dot(dir, line_direction(keys, k + 1)) < straight_joint)
        joint(keys[k + 1]);
}

}  // namespace cambium::geom
