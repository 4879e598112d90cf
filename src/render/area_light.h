// SPDX-License-Identifier: Apache-2.0
// Emissive primitives as area lights: the list next-event estimation samples from.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/material.h"
#include "render/vecf.h"

namespace cambium::render {

/// A point on an area light seen from a shading point: unit direction and distance to
/// it, the radiance it sends back along -wi and the solid-angle density it was drawn with
/// (selection included).
struct AreaLightSample {
    Vec3f wi;
    float distance = 0;
    Vec3f radiance;
    float pdf = 0;
    /// How far short of the point a shadow ray stops, so that float error cannot let the
    /// light's own surface block it (scaled to the radius for tubes).
    float margin = 0;
};

/// Every emissive triangle, disc, sphere and cylindrical line segment of the scene, the
/// instanced ones included (placed in world space), as lights for next-event estimation
/// (docs: area_light.cpp). A light is chosen in proportion to its power (area times the
/// luminance of its sides); triangles, discs and cylinders are then sampled uniformly by
/// area, spheres uniformly in the cone they subtend. Hermite curves, tapered segments and
/// pixel-width lines are not in the list: their emission is found by BSDF sampling alone
/// (pdf() says 0 for them, so their hits keep full weight).
/// Thread-safe after construction.
class AreaLights {
public:
    /// The emissive primitives of `scene` under `materials` (make_materials of the
    /// scene's). At most `max_lights` are kept (a warning says when more are left to
    /// BSDF sampling).
    AreaLights(const geom::Scene& scene, const std::vector<SurfaceMaterial>& materials,
               std::size_t max_lights = std::size_t{1} << 24);

    bool empty() const { return m_lights.empty(); }
    std::size_t size() const { return m_lights.size(); }
    /// The summed area times luminance of the lights' sides: their emitted power over pi.
    double power() const { return m_power; }

    /// A point on a light for the shading point p, from three uniforms; nullopt if the
    /// point sends nothing toward p.
    std::optional<AreaLightSample> sample(const Vec3f& p, float u_select, float u1,
                                          float u2) const;

    /// The solid-angle density sample(p, ...) has for the point `hit` (found by a ray
    /// from p); 0 when the primitive hit is not in the list.
    float pdf(const Vec3f& p, const SurfaceHit& hit) const;

private:
    enum class Kind : std::uint8_t { triangle, disc, sphere, cylinder };
    struct Light {
        Kind kind = Kind::triangle;
        Vec3f a, b, c;          ///< triangle corners; a = centre (disc, sphere) or start
                                ///< and b = end (cylinder)
        Vec3f normal;           ///< unit front normal (triangle, disc); cylinder: axis
        float radius = 0;       ///< disc, sphere, cylinder
        float area = 0;
        Vec3f front, back;      ///< emitted radiance of each side (sphere: front only)
    };

    void add(const Light& light, std::uint64_t key);
    void add_geometry(const geom::Geometry& g, const geom::Instance* instance,
                      std::uint32_t instance_index, const std::vector<SurfaceMaterial>& materials,
                      bool lines);
    float select_probability(std::size_t i) const;
    float pdf_of(std::size_t i, const Vec3f& p, const Vec3f& x) const;
    static std::uint64_t key(Shape shape, std::uint32_t prim, std::uint32_t instance);

    std::vector<Light> m_lights;
    std::vector<double> m_cdf;  ///< m_lights.size() + 1 entries, last 1
    /// (key(), light), one run per placement sorted by key: pdf() finds its run through
    /// m_runs and searches it alone (a hash map cost more to build, with thousands of
    /// instanced emissive petals, and more to search).
    std::vector<std::pair<std::uint64_t, std::uint32_t>> m_index;
    /// The runs' bounds in m_index: run 0 the scene's own geometry, run i + 1 instance i's
    /// (empty unless something glows).
    std::vector<std::uint32_t> m_runs;
    std::size_t m_max = 0;
    double m_power = 0;
    bool m_full = false;
};

}  // namespace cambium::render
