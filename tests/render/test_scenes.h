// SPDX-License-Identifier: Apache-2.0
// Small hand-built Scenes shared by the render tests.
#pragma once

#include <array>

#include "geom/scene.h"
#include "render/render.h"

namespace cambium::render::testing {

/// Appends one round linear segment a-b of radius r with material m.
inline void add_segment(geom::Scene& s, const geom::Vec3& a, const geom::Vec3& b, float r,
                        std::uint16_t m = 1)
{
    auto first = static_cast<std::uint32_t>(s.geometry.lines.keys.size());
    s.geometry.lines.keys.push_back({float(a.x), float(a.y), float(a.z), r});
    s.geometry.lines.keys.push_back({float(b.x), float(b.y), float(b.z), r});
    s.geometry.lines.segments.push_back(first);
    s.geometry.lines.flags.push_back(0);
    s.geometry.lines.material.push_back(m);
}

/// A scene with no lights, a black background and the given fit box.
inline geom::Scene empty_scene(const geom::Vec3& lo, const geom::Vec3& hi)
{
    geom::Scene s;
    s.bounds.extend(lo);
    s.bounds.extend(hi);
    return s;
}

/// Settings for a small test render: no ambient (neither the environment nor cpfg's
/// OpenGL ambient term), 2 threads, direct light by default.
inline RenderSettings small(int w, int h, int spp, int depth = 1)
{
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.samples_per_pixel = spp;
    s.max_depth = depth;
    s.threads = 2;
    s.ambient = {0, 0, 0};
    s.opengl_ambient = false;
    return s;
}

/// A white directional light toward `toward_light`.
inline geom::Light directional(const geom::Vec3& toward_light)
{
    geom::Light l;
    l.kind = geom::Light::Kind::directional;
    l.direction = toward_light;
    return l;
}

}  // namespace cambium::render::testing
