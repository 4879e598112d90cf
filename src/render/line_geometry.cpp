// SPDX-License-Identifier: Apache-2.0
// Geometry the renderer derives from the Scene's lines before building Embree: the discs
// and spheres that close shaded cylinders (cpfg's flat ends and round bends), and
// prototypes' pixel-width lines placed in world space (their width depends on depth).
#include "render/line_geometry.h"

#include <cmath>
#include <string>

#include "base/diagnostics.h"
#include "geom/scene_limits.h"
#include "render/pixel_lines.h"
#include "render/vecf.h"

namespace cambium::render {

namespace {

/// Most line keys that placing pixel-width prototype lines may create.
constexpr std::size_t max_placed_keys = std::size_t{1} << 27;

template <class T>
T at_or(const std::vector<T>& v, std::size_t i, T fallback)
{
    return i < v.size() ? v[i] : fallback;
}

}  // namespace

geom::LinearCurves place_pixel_lines(const geom::Scene& scene, const Camera& camera)
{
    geom::LinearCurves out;
    std::size_t total = 0;
    for (const geom::Instance& inst : scene.instances)
        if (inst.prototype < scene.prototypes.size())
            total += scene.prototypes[inst.prototype].geometry.lines.keys.size();
    if (total > max_placed_keys)
        throw Error("scene: placing pixel-width lines of prototypes would make " +
                    std::to_string(total) + " keys (at most " +
                    std::to_string(max_placed_keys) + ")");
    for (const geom::Instance& inst : scene.instances) {
        if (inst.prototype >= scene.prototypes.size())
            continue;
        const geom::LinearCurves& l = scene.prototypes[inst.prototype].geometry.lines;
        if (l.segments.empty())
            continue;
        for (std::uint32_t k : l.segments)
            if (k + 1 >= l.keys.size())
                throw Error("scene: line segment starts at key " + std::to_string(k) + " of " +
                            std::to_string(l.keys.size()));
        const auto& m = inst.transform;
        auto first = static_cast<std::uint32_t>(out.keys.size());
        for (const geom::Float4& k : l.keys) {
            geom::Vec3 p{m[0] * k[0] + m[3] * k[1] + m[6] * k[2] + m[9],
                         m[1] * k[0] + m[4] * k[1] + m[7] * k[2] + m[10],
                         m[2] * k[0] + m[5] * k[1] + m[8] * k[2] + m[11]};
            out.keys.push_back({float(p.x), float(p.y), float(p.z),
                                static_cast<float>(pixel_line_world_radius(k[3], camera, p))});
        }
        for (std::size_t k = 0; k < l.keys.size(); ++k)
            out.v.push_back(l.v.size() == l.keys.size() ? l.v[k] : 0.0f);
        for (std::size_t i = 0; i < l.segments.size(); ++i) {
            out.segments.push_back(first + l.segments[i]);
            out.flags.push_back(l.flags.size() == l.segments.size() ? l.flags[i] : 0);
            std::uint16_t mat = at_or(l.material, i, std::uint16_t{0});
            out.material.push_back(mat == geom::inherit_material ? inst.material : mat);
            std::int16_t tex = at_or(l.texture, i, geom::no_texture);
            out.texture.push_back(tex == geom::no_texture ? inst.texture : tex);
        }
    }
    return out;
}

std::vector<geom::Float4> keys_in_world_units(const geom::LinearCurves& lines, const Camera& camera)
{
    std::vector<geom::Float4> keys(lines.keys);
    for (geom::Float4& k : keys)
        k[3] = static_cast<float>(pixel_line_world_radius(k[3], camera, {k[0], k[1], k[2]}));
    return keys;
}

LineEnds line_ends(const geom::LinearCurves& l, const geom::Float4* keys)
{
    constexpr std::uint8_t left = 1, right = 2;  // RTC_CURVE_FLAG_NEIGHBOR_LEFT / _RIGHT
    // Below this bend (about 0.8 degrees) the frustums meet without a visible wedge.
    constexpr float straight = 0.9999f;
    const std::size_t n = l.segments.size();
    auto flags_of = [&](std::size_t i) -> std::uint8_t {
        return l.flags.size() == n ? l.flags[i] : 0;
    };
    auto direction = [&](std::uint32_t k) {
        Vec3f d = Vec3f(keys[k + 1][0], keys[k + 1][1], keys[k + 1][2]) -
                  Vec3f(keys[k][0], keys[k][1], keys[k][2]);
        float length = std::sqrt(dot(d, d));
        return length > 0 ? d * (1 / length) : Vec3f();
    };
    LineEnds e;
    auto add_cap = [&](const geom::Float4& at, const Vec3f& out, std::size_t segment, bool end) {
        if (!(at[3] > 0) || dot(out, out) == 0)
            return;  // tapered to nothing, or no direction: no end to close
        e.caps.push_back(at);
        e.cap_normals.push_back({out.x, out.y, out.z});
        e.cap_segment.push_back(static_cast<std::uint32_t>(segment));
        e.cap_at_end.push_back(end ? 1 : 0);
    };
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t k = l.segments[i];
        const std::uint8_t f = flags_of(i);
        Vec3f dir = direction(k);
        if (!(f & left))
            add_cap(keys[k], -dir, i, false);
        if (!(f & right)) {
            add_cap(keys[k + 1], dir, i, true);
        } else if (k + 2 < l.keys.size() && keys[k + 1][3] > 0 &&
                   dot(dir, direction(k + 1)) < straight) {
            e.joints.push_back(keys[k + 1]);
            e.joint_segment.push_back(static_cast<std::uint32_t>(i));
        }
    }
    // Kept while the scene is drawn: without their growth slack (a third of tree10m's).
    e.caps.shrink_to_fit();
    geom::fit_buffer(e.cap_normals, geom::embree_padding_bytes);  // Embree reads it in place
    e.cap_segment.shrink_to_fit();
    e.cap_at_end.shrink_to_fit();
    e.joints.shrink_to_fit();
    e.joint_segment.shrink_to_fit();
    return e;
}

}  // namespace cambium::render
