// SPDX-License-Identifier: Apache-2.0
// EmbreeScene: the Scene's primitives in Embree (the only user of <embree3/rtcore.h>).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "geom/scene.h"
#include "render/camera.h"
#include "render/vecf.h"

namespace cambium::render {

/// A primitive: Embree geometry id and primitive id.
struct PrimId {
    static constexpr std::uint32_t none = 0xffffffffu;
    std::uint32_t geom = none;
    std::uint32_t prim = none;
};

/// A ray's first hit, ready for shading.
struct SurfaceHit {
    float t = 0;
    Vec3f position;
    Vec3f normal;              ///< unit shading normal, facing the incoming ray
    std::uint32_t geom_id = 0;
    std::uint32_t prim_id = 0;
    std::uint16_t material = 0;  ///< index into Scene::materials
    float radius = 0;          ///< curve radius at the hit (world units)
    /// Distance to move a spawned ray's origin along `normal`: Embree's round curves have
    /// no self-intersection protection (FACTS.md), so this scales with the radius.
    float spawn_offset = 0;
    /// Drawn in its flat colour, not shaded: cpfg's `line style: pixel` lines are
    /// unlit GL lines, and this keeps their look (docs/deviations.md).
    bool unlit = false;

    PrimId prim() const { return {geom_id, prim_id}; }
};

/// The acceleration structure of one frame. Shares the Scene's index and flag buffers
/// (and its keys when radii are already in world units): the Scene must outlive it.
/// Thread-safe for concurrent intersect()/occluded() after construction.
class EmbreeScene {
public:
    /// Builds the scene; `camera` converts pixel-width line radii to world units.
    /// Throws cambium::Error if Embree fails; Embree warnings go to cambium::warn.
    EmbreeScene(const geom::Scene& scene, const Camera& camera);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    /// First hit along org + t dir, t in [tnear, tfar], ignoring the primitive `skip`
    /// (the convex curve segment a spawned ray leaves cannot truly be hit again; Embree
    /// would report spurious hits on it). `coherent` for camera rays.
    std::optional<SurfaceHit> intersect(const Vec3f& org, const Vec3f& dir, float tnear,
                                        float tfar, PrimId skip = {},
                                        bool coherent = false) const;
    /// Whether anything but `skip` blocks org + t dir for t in [tnear, tfar].
    bool occluded(const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
                  PrimId skip = {}) const;

    /// Number of curve segments given to Embree.
    std::size_t segment_count() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace cambium::render
