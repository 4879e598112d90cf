// SPDX-License-Identifier: Apache-2.0
// Emissive primitives as area lights: the list next-event estimation samples from.
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/material.h"
#include "render/vecf.h"

namespace cambium::render {

struct GeometrySource;

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
/// instanced ones included, as lights for next-event estimation (docs: area_light.cpp).
/// Lights are kept once per distinct piece of geometry (the scene's own, each prototype
/// under the materials its instances give it) in its own space, so their memory follows
/// the distinct emissive geometry, not the placed copies: a sample chooses a placement
/// (the scene itself or an instance) in proportion to its power, then a light of it in
/// proportion to its power, and places that light with the instance's transform. Under
/// similarity transforms this is exactly the choice of a light by its power among all
/// placed lights. Triangles, discs and cylinders are then sampled uniformly by
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

    bool empty() const { return m_placements.empty(); }
    /// Lights kept: each distinct emissive primitive once, however often it is placed.
    std::size_t size() const { return m_stored; }
    /// Lights as placed: each instance's copies counted.
    std::size_t placed_size() const { return m_placed; }
    /// The summed area times luminance of the lights' sides: their emitted power over pi.
    double power() const { return m_power; }
    /// The largest luminance any listed light emits from either side.
    float max_luminance() const { return m_max_luminance; }

    /// A point on a light for the shading point p, from three uniforms; nullopt if the
    /// point sends nothing toward p.
    std::optional<AreaLightSample> sample(const Vec3f& p, float u_select, float u1,
                                          float u2) const;

    /// The solid-angle density sample(p, ...) has for the point `hit` (found by a ray
    /// from p); 0 when the primitive hit is not in the list.
    float pdf(const Vec3f& p, const SurfaceHit& hit) const;

private:
    /// As Emitter::Form (render/shapes.h), whose values it takes.
    enum class Kind : std::uint8_t { triangle, disc, sphere, cylinder };
    struct Light {
        Kind kind = Kind::triangle;
        Vec3f a, b, c;          ///< triangle corners; a = centre (disc, sphere) or start
                                ///< and b = end (cylinder)
        Vec3f normal;           ///< unit front normal (triangle, disc); cylinder: axis
        float radius = 0;       ///< disc, sphere, cylinder
        float area = 0;
        float side = 1;         ///< triangle: -1 where the front is against the winding
        Vec3f front, back;      ///< emitted radiance of each side (sphere: front only)
    };
    /// The lights of one piece of geometry in its own space, chosen by power.
    struct Group {
        std::vector<Light> lights;
        std::vector<double> cdf;  ///< lights.size() + 1 entries, last 1
        double power = 0;         ///< in the group's own units
        std::unordered_map<std::uint64_t, std::uint32_t> index;  ///< key() -> light
    };
    /// An instance's affine map x' = A x + t, the cofactor matrix for normals and whether
    /// it is a similarity (uniform scale times a rotation or reflection).
    struct Affine {
        Vec3f c0{1, 0, 0}, c1{0, 1, 0}, c2{0, 0, 1}, t;
        float det = 1, scale = 1;
        bool similarity = true;
        explicit Affine(const geom::Instance* instance = nullptr);
        Vec3f point(const Vec3f& p) const { return c0 * p.x + c1 * p.y + c2 * p.z + t; }
        Vec3f normal(const Vec3f& n) const;
    };
    /// A group where it is drawn: the scene's own geometry, or an instance.
    struct Placement {
        std::uint32_t group = 0;
        std::uint32_t instance = 0;  ///< PrimId::none: the scene's own
        Affine transform;
    };

    Group make_group(const geom::Geometry& g, std::uint16_t front_inherited,
                     std::uint16_t back_inherited, bool round_shapes,
                     const std::vector<SurfaceMaterial>& materials, bool lines);
    /// Adds the emissive primitives of one shape's part (render/shapes.h) to `group`.
    void add_emitters(Group& group, Shape shape, const GeometrySource& part,
                      std::uint16_t front_inherited, std::uint16_t back_inherited,
                      const std::vector<SurfaceMaterial>& materials);
    void add(Group& group, const Light& light, std::uint64_t key);
    void place(std::uint32_t group, std::uint32_t instance, const Affine& transform);
    /// The light in world space (its area, normal and radius follow the transform).
    static Light placed(const Light& light, const Placement& where);
    std::optional<AreaLightSample> sample_light(const Light& l, float select, const Vec3f& p,
                                                float u1, float u2) const;
    static float pdf_of(const Light& l, const Vec3f& p, const Vec3f& x);
    static std::uint64_t key(Shape shape, std::uint32_t prim);

    std::vector<Group> m_groups;
    std::vector<Placement> m_placements;
    std::vector<double> m_cdf;  ///< over m_placements by power: size() + 1 entries, last 1
    std::unordered_map<std::uint32_t, std::uint32_t> m_placement_of;  ///< instance -> placement
    std::size_t m_max = 0, m_stored = 0, m_placed = 0;
    double m_power = 0;
    float m_max_luminance = 0;
    bool m_full = false;
};

}  // namespace cambium::render
