// SPDX-License-Identifier: Apache-2.0
// The ground plane of staged renders.
#include "render/ground.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geom/primitives.h"

namespace cambium::render {
namespace {

/// The lowest y of a geometry after `place` (a point transform).
template <class Place>
double geometry_lowest(const geom::Geometry& g, const Place& place, double scale)
{
    double low = std::numeric_limits<double>::infinity();
    auto at = [&](float x, float y, float z) { return place(geom::Vec3{x, y, z}).y; };
    for (const geom::Float4& k : g.lines.keys)
        low = std::min(low, at(k[0], k[1], k[2]));
    for (const geom::Float4& k : g.curves.points)
        low = std::min(low, at(k[0], k[1], k[2]));
    for (const geom::Float4& c : g.spheres.centres)
        low = std::min(low, at(c[0], c[1], c[2]) - c[3] * scale);
    for (std::size_t i = 0; i < g.discs.size(); ++i) {
        const geom::Float4& c = g.discs.centres[i];
        low = std::min(low, at(c[0], c[1], c[2]) - c[3] * scale);
    }
    for (const geom::Float3& p : g.mesh.positions)
        low = std::min(low, at(p[0], p[1], p[2]));
    return low;
}

}  // namespace

double lowest_point(const geom::Scene& scene)
{
    double low = scene.bounds.empty() ? std::numeric_limits<double>::infinity()
                                      : scene.bounds.lo.y;
    low = std::min(low, geometry_lowest(scene.geometry, [](const geom::Vec3& p) { return p; }, 1));
    for (const geom::Instance& inst : scene.instances) {
        if (inst.prototype >= scene.prototypes.size())
            continue;
        const auto& m = inst.transform;
        auto place = [&](const geom::Vec3& p) { return geom::Affine3x4(m).apply(p); };
        // Radii scale with the transform's largest axis (an upper bound: the ground
        // may sit slightly lower than a squashed sphere's bottom, never above it).
        double scale = std::max({std::hypot(m[0], m[1], m[2]), std::hypot(m[3], m[4], m[5]),
                                 std::hypot(m[6], m[7], m[8])});
        low = std::min(low, geometry_lowest(scene.prototypes[inst.prototype].geometry, place,
                                            scale));
    }
    return std::isfinite(low) ? low : 0.0;
}

std::optional<float> GroundPlane::distance(const Vec3f& org, const Vec3f& dir, float tfar) const
{
    if (dir.y == 0)
        return std::nullopt;
    float t = (height - org.y) / dir.y;
    if (!(t > 0) || !(t < tfar) || !std::isfinite(t))
        return std::nullopt;
    return t;
}

SurfaceHit GroundPlane::hit(const Vec3f& org, const Vec3f& dir, float t) const
{
    SurfaceHit h;
    h.t = t;
    h.position = org + dir * t;
    h.position.y = height;  // exactly on the plane, whatever the rounding
    h.normal = h.geometric_normal = Vec3f(0, dir.y < 0 ? 1.0f : -1.0f, 0);
    h.geom_id = ground_geom_id;
    h.prim_id = 0;
    h.material = h.end_material = material;
    h.texture = texture;
    h.shape = Shape::triangle;
    h.back = dir.y > 0;
    h.u = h.position.x / tile;
    h.v = h.position.z / tile;
    h.dpds = {tile, 0, 0};
    h.dpdt = {0, 0, tile};
    // Spawned rays leave the plane itself out (the ground is skipped by its id), so the
    // offset only keeps them clear of geometry resting on it.
    h.spawn_offset = 1e-5f * std::max(1.0f, std::fabs(h.position.x) + std::fabs(h.position.z) +
                                                std::fabs(height));
    return h;
}

}  // namespace cambium::render
