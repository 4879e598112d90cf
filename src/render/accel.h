// SPDX-License-Identifier: Apache-2.0
// EmbreeScene: the Scene's primitives in Embree (with render/shapes, the only Embree users).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "geom/primitives.h"
#include "geom/scene.h"
#include "render/camera.h"
#include "render/vecf.h"

namespace cambium::render {

class TextureSet;

/// A primitive: instance (none for the scene's own geometry), Embree geometry id in its
/// scene, primitive id.
struct PrimId {
    static constexpr std::uint32_t none = 0xffffffffu;
    std::uint32_t geom = none;
    std::uint32_t prim = none;
    std::uint32_t inst = none;
};

/// The kind of primitive hit: closed ones (curves, spheres) enclose a volume, flat ones
/// (discs, triangles) have two sides with their own materials.
/// `cap`: the flat end of a cylinder (F, G) where no segment continues it; `joint`: the
/// sphere that rounds a bend between two.
enum class Shape : std::uint8_t { line, curve, sphere, disc, triangle, cap, joint };

/// A ray's first hit, ready for shading. Everything is in world space.
struct SurfaceHit {
    float t = 0;
    Vec3f position;
    Vec3f normal;              ///< unit shading normal, facing the incoming ray
    Vec3f geometric_normal;    ///< unit true surface normal, facing the incoming ray
    std::uint32_t geom_id = 0;
    std::uint32_t prim_id = 0;
    std::uint32_t inst_id = PrimId::none;  ///< the instance's Embree geometry id
    std::uint32_t instance = PrimId::none;  ///< in Scene::instances (none: own geometry)
    /// The primitive's index in its Geometry's array of its kind (primitive_kind(shape)):
    /// the scene's own, or the instance's prototype's; a cap's or joint's is its segment's.
    /// Pixel-width lines of prototypes are placed in world space: theirs is none.
    std::uint32_t primitive = PrimId::none;
    std::uint16_t material = 0;  ///< index into Scene::materials (side and instance resolved)
    /// A generalized cylinder's colour blends along its axis: the surface is
    /// (1 - material_blend) `material` + material_blend `end_material` (resolved the same
    /// way). material_blend = 0 (the usual case): `material` alone.
    std::uint16_t end_material = 0;
    float material_blend = 0;
    std::int16_t texture = geom::no_texture;  ///< index into Scene::textures
    float u = 0, v = 0;        ///< texture coordinates (OpenGL's s, t)
    /// World-space change of position per unit of s and of t at the hit (textured hits
    /// only; zero where a coordinate is constant): turns ray footprints into texture ones.
    Vec3f dpds, dpdt;
    Shape shape = Shape::line;
    bool back = false;         ///< the ray hit the back side of a disc or triangle
    bool inside = false;       ///< the ray hit a closed primitive from within
    float radius = 0;          ///< curve or sphere radius at the hit (world units)
    /// Distance to move a spawned ray's origin along `geometric_normal`: for round shapes
    /// (which rays leaving them also skip: Embree's curves have no self-intersection
    /// protection, FACTS.md) it scales with the radius; flat ones are skipped by nothing,
    /// so theirs covers the float error of the hit (accel.cpp, ShapeKind).
    float spawn_offset = 0;
    /// Drawn in its flat colour, not shaded: cpfg's `line style: pixel` lines are
    /// unlit GL lines, and this keeps their look (docs/deviations.md).
    bool unlit = false;

    PrimId prim() const { return {geom_id, prim_id, inst_id}; }
    /// Whether the primitive encloses a volume (a ray leaving inward meets it again).
    bool closed() const { return shape != Shape::disc && shape != Shape::triangle; }
    /// Whether a ray leaving toward wi goes into the primitive's volume (never, if flat).
    bool enters(const Vec3f& wi) const
    {
        return closed() && ((dot(geometric_normal, wi) < 0) != inside);
    }
};

/// What the light report reads of a hit (EmbreeScene::intersect_light): SurfaceHit's
/// fields of these names, with the same values, and nothing of the shading normal or the
/// texture, which it does not read (benchmarks/light_report: making them was a tenth of
/// its time).
struct LightHit {
    float t = 0;
    Vec3f position;
    Vec3f geometric_normal;    ///< unit true surface normal, facing the incoming ray
    std::uint32_t geom_id = 0;
    std::uint32_t prim_id = 0;
    std::uint32_t inst_id = PrimId::none;
    std::uint32_t instance = PrimId::none;
    std::uint32_t primitive = PrimId::none;
    std::uint16_t material = 0;
    std::uint16_t end_material = 0;
    float material_blend = 0;
    float spawn_offset = 0;
    Shape shape = Shape::line;
    bool back = false;
    bool unlit = false;

    PrimId prim() const { return {geom_id, prim_id, inst_id}; }
    bool closed() const { return shape != Shape::disc && shape != Shape::triangle; }
};

/// A ray of a stream for EmbreeScene::intersect_light: org + t dir, t in [0, tfar].
struct LightRay {
    Vec3f org, dir;
    float tfar = 0;
};

/// The Geometry array a shape's primitives are in.
using geom::PrimitiveKind;
inline PrimitiveKind primitive_kind(Shape s)
{
    switch (s) {
    case Shape::curve: return PrimitiveKind::curves;
    case Shape::sphere: return PrimitiveKind::spheres;
    case Shape::disc: return PrimitiveKind::discs;
    case Shape::triangle: return PrimitiveKind::mesh;
    default: return PrimitiveKind::lines;  // line, cap, joint
    }
}

/// The acceleration structure of one frame: every Geometry part natively in Embree
/// (round linear and Hermite curves, sphere points, oriented discs, triangles), each
/// prototype in its own Embree scene placed by one instance per Scene::Instance.
/// Shares the Scene's buffers: the Scene (and `textures`) must outlive it.
/// Thread-safe for concurrent intersect()/occluded() after construction.
class EmbreeScene {
public:
    /// A scene whose own shaded lines have at most this many segments builds their caps
    /// and joints beside them in one BVH (faster: one traversal, not three); more keep
    /// them in two scenes of their own (less memory: docs/architecture.md).
    static constexpr std::size_t line_ends_beside_up_to = 262144;

    /// Builds the scene; `camera` converts pixel-width line radii to world units. With
    /// `textures`, hits on textured meshes and curves where the texture's alpha < 0.5 are
    /// ignored (cut-outs). Throws cambium::Error if Embree fails or an index is out of range.
    EmbreeScene(const geom::Scene& scene, const Camera& camera,
                const TextureSet* textures = nullptr);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    /// First hit along org + t dir, t in [tnear, tfar], ignoring the primitive `skip`
    /// if it is round (a curve, sphere or joint: the convex primitive a spawned ray leaves
    /// cannot truly be hit again; Embree would report spurious hits on it). Flat
    /// primitives are never skipped: rays leave them from `SurfaceHit::spawn_offset`.
    /// `coherent` for camera rays.
    std::optional<SurfaceHit> intersect(const Vec3f& org, const Vec3f& dir, float tnear,
                                        float tfar, PrimId skip = {},
                                        bool coherent = false) const;
    /// The same, the hit made in `hit` (storage for one, alive or not: its old value is
    /// overwritten) if there is one; returns whether there is. For the path tracer: with
    /// GCC 12's library every empty std::optional of a hit is zeroed whole when it is made
    /// (a string store of 120 bytes, about 8 ns), and the hit is written once, in place.
    bool intersect(SurfaceHit& hit, const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
                   PrimId skip = {}, bool coherent = false) const;
    /// At most this many rays per intersect_coherent() call.
    static constexpr std::size_t max_coherent_rays = 16;
    /// intersect(r.org, r.dir, 0, r.tfar, {}, true) for each of `rays` (at most
    /// max_coherent_rays) into `hits`, the rays traced together as one stream, which
    /// Embree gathers into SIMD packets: cheaper per ray for camera rays close together
    /// (a pixel's samples). The same hits as intersect() gives. `checked`: the caller
    /// vouches that every ray is one intersect() would trace (finite, starting within
    /// geom::max_ray_start), as Camera::generate_rays_f's are once Camera::check_range
    /// passed, and the check per ray is left out. Returns a bit per ray, set where it hit
    /// (bit k: hits[k] has a value), so that a caller need not read every hit.
    std::uint32_t intersect_coherent(std::span<const CameraRayF> rays,
                                     std::span<std::optional<SurfaceHit>> hits,
                                     bool checked = false) const;
    /// The same for the first n of `rays` (rays.ray(k) for k < n; n at most
    /// ParallelRays::capacity), read by component: the stream is filled from their arrays,
    /// with one direction for all.
    std::uint32_t intersect_coherent(const ParallelRays& rays, std::size_t n,
                                     std::span<std::optional<SurfaceHit>> hits,
                                     bool checked = false) const;
    /// intersect(org, dir, tnear, tfar, skip) made as a LightHit in `hit`; returns whether
    /// there is one.
    bool intersect_light(LightHit& hit, const Vec3f& org, const Vec3f& dir, float tnear,
                         float tfar, PrimId skip = {}) const;
    /// The same for each of `rays` (at most max_coherent_rays, skipping nothing) into
    /// `hits`, traced together as one stream of coherent rays (a light's neighbouring
    /// rays). The same hits, their distance (and what is made from it) as Embree's packet
    /// kernels round it: within a few float ulps of the single ray's (accel_test). Returns
    /// a bit per ray, set where it hit.
    std::uint32_t intersect_light(std::span<const LightRay> rays, std::span<LightHit> hits) const;
    /// Whether anything but `skip` blocks org + t dir for t in [tnear, tfar].
    bool occluded(const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
                  PrimId skip = {}) const;
    /// The fraction of light passing along org + t dir for t in [tnear, tfar] (skipping
    /// `skip` as intersect() does): the product of (1 - opacity) over every surface met,
    /// each wall of a closed primitive counted, with `opacity` by material index (1 past
    /// its end); 0 if an opaque surface blocks it or after 64 surfaces. Reads only each
    /// hit's material, in one traversal.
    float transmittance(const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
                        PrimId skip, std::span<const float> opacity) const;

    /// The shape of each Embree geometry that runs a filter function on candidate hits
    /// (self-hits of round shapes, pixel-line coverage, alpha cut-outs), in build order.
    std::vector<Shape> filtered_shapes() const;

    /// Rays that intersect() and occluded() skipped (a miss, not occluded) because
    /// Embree would abort on them: not finite, or starting beyond geom::max_ray_start.
    std::uint64_t skipped_rays() const;

    /// Number of curve segments (linear and Hermite) of the scene's own geometry.
    std::size_t segment_count() const;

    /// What building and using the scene cost (--stats): the constructor's wall time
    /// (geometry upload and every rtcCommitScene), rays traced so far by intersect() and
    /// occluded(), and the bytes Embree allocated itself (its memory monitor: BVHs and
    /// internal copies, not the Scene's buffers it shares), now and at most.
    double build_seconds() const;
    std::uint64_t rays_traced() const;
    std::uint64_t embree_bytes() const;
    std::uint64_t embree_peak_bytes() const;
    /// Embree's heap that its memory monitor does not report: its instance geometries (each
    /// an object, its transform and a slot in its scene's table, about 300 B), measured as
    /// the heap's growth while they are made (glibc's mallinfo2; 0 where it is missing or,
    /// under AddressSanitizer, empty).
    std::uint64_t embree_unmonitored_bytes() const;
    /// The bytes of the buffers Embree reads in place instead of copying (keys, segment
    /// indices, centres: the Scene's, or this object's own): part of what Embree needs.
    std::uint64_t shared_bytes() const;
    /// The bytes this object holds itself beside Embree and the Scene: caps and joints,
    /// converted and placed pixel-width lines, the styles instances share (nothing per
    /// instance: its placement is made at hit time from the transform Embree holds), the
    /// records of the triangles of a large mesh of the scene's own (64 B each, for 64 Ki to
    /// 512 Ki triangles; none for prototypes).
    std::uint64_t own_bytes() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace cambium::render
