// SPDX-License-Identifier: Apache-2.0
// EmbreeScene: the Scene's primitives in Embree (with render/shapes, the only user of
// <embree3/rtcore.h>): the scenes built, hits resolved, rays traced.
#include "render/accel.h"

#include <embree3/rtcore.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <map>
#include <mutex>
#include <new>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "base/diagnostics.h"
#include "geom/scene_limits.h"
#include "render/line_geometry.h"
#include "render/pixel_lines.h"
#include "render/ray_counter.h"
#include "render/ray_tilt.h"
#include "render/shapes.h"
#include "render/texture.h"
#include "render/tube_angle.h"

namespace cambium::render {

namespace {

constexpr float pi = std::numbers::pi_v<float>;

const char* error_name(RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    }
    return "error";
}

/// Embree's messages: remembered (the build throws the first one) and warned about.
struct ErrorSink {
    std::mutex mutex;
    std::string first;

    static void callback(void* user, RTCError code, const char* text)
    {
        auto* sink = static_cast<ErrorSink*>(user);
        std::string message = std::string("Embree: ") + error_name(code) +
                              (text && *text ? std::string(": ") + text : std::string());
        {
            std::lock_guard lock(sink->mutex);
            if (sink->first.empty())
                sink->first = message;
        }
        warn(message);
    }
};

/// v normalised (zero stays zero) by one division, not three: the hit's normals.
Vec3f unit(const Vec3f& v)
{
    float l = length(v);
    return l > 0 ? v * (1 / l) : v;
}

/// An intersection context that carries the primitive to ignore (Embree 3 passes the
/// context to filter functions, so it may be extended C-style). Every ray this file traces
/// has one: the self-hit filter of curves and spheres reads it.
struct SkipContext {
    RTCIntersectContext context;
    PrimId skip;
};

SkipContext make_context(PrimId skip, bool coherent)
{
    SkipContext c;
    rtcInitIntersectContext(&c.context);
    c.context.flags =
        coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    c.skip = skip;
    return c;
}

/// Rejects candidate hits on the primitive the ray leaves (round shapes only: see ShapeKind).
void skip_self(const RTCFilterFunctionNArguments* args)
{
    const auto* ctx = reinterpret_cast<const SkipContext*>(args->context);
    if (ctx->skip.geom == PrimId::none)
        return;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0)
            continue;
        if (RTCHitN_geomID(args->hit, args->N, i) == ctx->skip.geom &&
            RTCHitN_primID(args->hit, args->N, i) == ctx->skip.prim &&
            RTCHitN_instID(args->hit, args->N, i, 0) == ctx->skip.inst)
            args->valid[i] = 0;
    }
}

/// A 3x3 matrix by columns.
struct Mat3 {
    Vec3f c0{1, 0, 0}, c1{0, 1, 0}, c2{0, 0, 1};
    Vec3f operator*(const Vec3f& v) const { return c0 * v.x + c1 * v.y + c2 * v.z; }
};

/// What a hit on an instance reads of its Instance besides the transform: the prototype and
/// the materials and texture that replace inherit_material and no_texture. Instances that
/// agree share one (Embree user data of their instance geometry), so an instance costs
/// Cambium nothing beside what Embree keeps of it.
struct InstanceStyle {
    std::uint32_t prototype = 0;
    std::uint16_t material = 0;
    std::uint16_t back_material = 0;
    std::int16_t texture = geom::no_texture;

    auto key() const { return std::tuple(prototype, material, back_material, texture); }
};

/// An instance's placement, made at hit time from the transform Embree holds: its linear
/// part and the inverse transpose for normals. The factors radii and offsets scale by are
/// made only for the hits that need them (most instanced hits are on flat prototypes):
/// a cube root on every instanced hit was a visible share of hit processing.
struct Placement {
    InstanceStyle style;  ///< the instance's own (equal to the shared one Embree holds)
    std::uint32_t index = PrimId::none;  ///< in Scene::instances
    Mat3 linear, normals;
    float det = 1;  ///< of the linear part

    /// The factor radii scale by: the cube root of the volume scale.
    float radius_scale() const { return std::cbrt(std::fabs(det)); }
    /// The most the linear part stretches a coordinate (inf-norm).
    float largest_scale() const
    {
        const Vec3f &a = linear.c0, &b = linear.c1, &c = linear.c2;
        return std::max({std::fabs(a.x) + std::fabs(b.x) + std::fabs(c.x),
                         std::fabs(a.y) + std::fabs(b.y) + std::fabs(c.y),
                         std::fabs(a.z) + std::fabs(b.z) + std::fabs(c.z)});
    }
};

/// `m`: the 3x4 column-major transform (as geom::Instance::transform).
Placement make_placement(const float* m, const InstanceStyle& style, std::uint32_t index)
{
    Placement p;
    p.style = style;
    p.index = index;
    p.linear = {{m[0], m[1], m[2]}, {m[3], m[4], m[5]}, {m[6], m[7], m[8]}};
    const Vec3f &a = p.linear.c0, &b = p.linear.c1, &c = p.linear.c2;
    p.det = dot(a, cross(b, c));
    float inv = p.det != 0 ? 1 / p.det : 0;
    // (A^-1)^T has the columns (b x c, c x a, a x b) / det.
    p.normals = {cross(b, c) * inv, cross(c, a) * inv, cross(a, b) * inv};
    return p;
}

/// The bytes the C heap has handed out and not taken back, in every arena (0 without glibc).
std::size_t heap_in_use()
{
#if defined(__GLIBC__)
    struct mallinfo2 info = mallinfo2();
    return info.uordblks + info.hblkhd;
#else
    return 0;
#endif
}

}  // namespace

/// What hits are resolved with: parts by geometry id, instances' placements, textures
/// (also read by the alpha filter during traversal).
struct HitResolver {
    const TextureSet* textures = nullptr;
    std::unique_ptr<const Camera> camera;  ///< pixel-width lines are drawn for its pixels
    std::vector<const GeometrySource*> top_parts;  ///< by top-level geometry id
    std::vector<std::vector<const GeometrySource*>> proto_parts;  ///< by prototype, geometry id
    RTCScene top = nullptr;  ///< the top-level scene: instances' transforms and styles
    /// Instances are attached under consecutive geometry ids from first_instance_id, in
    /// Scene::instances order (instance i at first_instance_id + i - first_instance_index;
    /// unplaced ones leave their id unused). Line-end scenes' instances come before.
    std::uint32_t first_instance_id = PrimId::none;
    std::uint32_t first_instance_index = 0;
    std::span<const geom::Instance> instances;  ///< the scene's (it outlives this)
    std::deque<InstanceStyle> styles;  ///< one per distinct style (stable addresses)
    /// The caps and the joints of the scene's own shaded lines live in two scenes of their
    /// own, each placed once, untransformed, by a top-level instance (none: no such scene).
    /// Embree's leaves hold primitives of one geometry only: caps and joints beside every
    /// segment in one BVH left most leaves with one primitive, and cost 187 B per segment
    /// instead of about 70 (tree10m, build/benchmarks/render). Up to EmbreeScene::line_ends_beside_up_to
    /// segments they stay beside the lines, which saves every ray two traversals.
    struct PlacedEnds {
        std::uint32_t instance = PrimId::none;
        std::vector<const GeometrySource*> parts;  ///< by geometry id in its scene
    };
    std::array<PlacedEnds, 2> line_end_scenes;  ///< caps, joints

    bool placed_instance(std::uint32_t inst_id) const
    {
        return inst_id != PrimId::none && first_instance_id != PrimId::none &&
               inst_id >= first_instance_id;
    }
    /// The style of the instance with this top-level geometry id (nullptr: not an instance
    /// of a prototype). Read during traversal by the filters, so no transform is made.
    const InstanceStyle* style(std::uint32_t inst_id) const
    {
        if (!placed_instance(inst_id))
            return nullptr;
        return static_cast<const InstanceStyle*>(
            rtcGetGeometryUserData(rtcGetGeometry(top, inst_id)));
    }
    /// The placement of that instance, from the scene's own instance: the transform
    /// Embree was given and the style, in one record. (Asking Embree for its copy of them
    /// took three API calls per instanced hit, each entering the shared device, and two
    /// cache misses.)
    std::optional<Placement> placement(std::uint32_t inst_id) const
    {
        if (!placed_instance(inst_id))
            return std::nullopt;
        const std::uint32_t index = inst_id - first_instance_id + first_instance_index;
        const geom::Instance& inst = *instance(inst_id);
        return make_placement(inst.transform.data(),
                              {inst.prototype, inst.material, inst.back_material, inst.texture},
                              index);
    }
    /// The scene's record of a placed instance (placed_instance(inst_id)).
    const geom::Instance* instance(std::uint32_t inst_id) const
    {
        return &instances[inst_id - first_instance_id + first_instance_index];
    }
    const GeometrySource* part(std::uint32_t inst_id, std::uint32_t geom_id) const
    {
        if (inst_id != PrimId::none)
            for (const PlacedEnds& e : line_end_scenes)
                if (inst_id == e.instance)
                    return e.parts[geom_id];
        if (const InstanceStyle* st = style(inst_id))
            return proto_parts[st->prototype][geom_id];
        return top_parts[geom_id];
    }
    /// The same, given the hit's placement (no second look-up of the instance).
    const GeometrySource* part(std::uint32_t inst_id, std::uint32_t geom_id,
                               const std::optional<Placement>& placement) const
    {
        if (placement)
            return proto_parts[placement->style.prototype][geom_id];
        if (inst_id != PrimId::none)
            for (const PlacedEnds& e : line_end_scenes)
                if (inst_id == e.instance)
                    return e.parts[geom_id];
        return top_parts[geom_id];
    }
    int texture_of(const GeometrySource& part, std::uint32_t prim, const InstanceStyle* p) const;
};

struct EmbreeScene::Impl : HitResolver {
    ErrorSink errors;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<RTCScene> prototype_scenes;
    std::vector<RTCScene> line_end_rtc_scenes;  ///< the scene's own caps and joints (HitResolver)
    std::deque<GeometrySource> parts;  ///< stable addresses (Embree user data)
    /// The records of large meshes' triangles (GeometrySource::records), one vector each.
    std::deque<std::vector<TriangleRecord>> triangle_records;
    std::deque<LineEnds> line_ends;  ///< caps and joints of shaded lines (stable addresses)
    std::vector<Key> world_keys;  ///< line keys with pixel radii converted (else empty)
    /// Pixel-width lines of prototypes, placed by every instance in world space with
    /// their radii converted (a radius in pixels depends on each copy's depth).
    geom::Geometry placed_lines;
    std::size_t segments = 0;
    std::vector<Shape> filtered_geometries;  ///< the shape of each geometry with a filter
    bool tilt_rays = false;  ///< some Hermite curves are built: rays are traced off_axis()

    Vec3f traced(const Vec3f& dir) const { return tilt_rays ? off_axis(dir) : dir; }
    /// The hit Embree reported for the ray org + t dir, ready for shading.
    SurfaceHit surface_hit(const RTCRayHit& rh, const Vec3f& org, const Vec3f& dir) const
    {
        return hit_of<SurfaceHit>(rh, org, dir);
    }
    /// The hit as a SurfaceHit, or as a LightHit: the same values, without the shading
    /// normal and texture, which are not made.
    template <class Hit>
    Hit hit_of(const RTCRayHit& rh, const Vec3f& org, const Vec3f& dir) const;
    /// The same made in `out`, in place: written once, not copied (a copy read right after
    /// the hit's stores stalled on store forwarding).
    void surface_hit(const RTCRayHit& rh, const Vec3f& org, const Vec3f& dir,
                     std::optional<SurfaceHit>& out) const
    {
        // emplace() initialises the hit from this conversion's result: the hit is built
        // where it is stored (guaranteed elision), as placement new does below.
        struct Made {
            const Impl& m;
            const RTCRayHit& rh;
            const Vec3f &org, &dir;
            operator SurfaceHit() const { return m.surface_hit(rh, org, dir); }
        };
        out.emplace(Made{*this, rh, org, dir});
    }
    /// Traces one ray with rtcIntersect1 (counted; a ray Embree cannot take is skipped):
    /// whether it hit something, reported in rh.
    bool trace(RTCRayHit& rh, const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
               PrimId skip, bool coherent) const;
    /// Traces rh[0 .. traced - 1] as one stream of coherent rays and makes the hit of
    /// rh[k] in hits[slot(k)] (reset where it met nothing), for the ray that ray_at(slot(k))
    /// gives (EmbreeScene::intersect_coherent). Returns the hits' bits (bit slot(k)).
    template <typename Slot, typename RayAt>
    std::uint32_t trace_stream(std::span<RTCRayHit> rh, std::size_t traced, Slot slot, RayAt ray_at,
                      std::span<std::optional<SurfaceHit>> hits) const;
    mutable std::atomic<std::uint64_t> skipped_rays{0};
    RayCounter rays;
    double build_seconds = 0;
    std::size_t embree_shared_bytes = 0;  ///< shared_bytes() of every part built
    std::size_t embree_unmonitored_bytes = 0;  ///< embree_unmonitored_bytes()
    /// Embree's own allocations, from its memory monitor (called from any thread).
    std::atomic<std::int64_t> embree_bytes{0}, embree_peak_bytes{0};

    static bool monitor_memory(void* self, ssize_t bytes, bool /*post*/)
    {
        // Refused allocations are undone with a negative call, so the sum stays true.
        Impl& m = *static_cast<Impl*>(self);
        std::int64_t now = m.embree_bytes.fetch_add(bytes, std::memory_order_relaxed) + bytes;
        std::int64_t peak = m.embree_peak_bytes.load(std::memory_order_relaxed);
        while (now > peak && !m.embree_peak_bytes.compare_exchange_weak(peak, now))
            ;
        return true;
    }

    ~Impl()
    {
        if (scene)
            rtcReleaseScene(scene);
        for (RTCScene s : prototype_scenes)
            if (s)
                rtcReleaseScene(s);
        for (RTCScene s : line_end_rtc_scenes)
            rtcReleaseScene(s);
        if (device)
            rtcReleaseDevice(device);
    }

    void check(const char* what)
    {
        std::lock_guard lock(errors.mutex);
        if (!errors.first.empty())
            throw Error(std::string(what) + ": " + errors.first);
    }

    RTCScene new_scene()
    {
        RTCScene s = rtcNewScene(device);
        // transmittance() counts what it passes through in a context filter.
        rtcSetSceneFlags(s, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
        rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
        return s;
    }

    /// Where add_geometry() puts the caps and joints of shaded lines: their scenes and
    /// geometry ids (null: beside the lines).
    struct LineEndsTarget {
        RTCScene caps, joints;  // (no member initializers: {} as a default argument zeroes them)
        std::vector<const GeometrySource*>*cap_ids, *joint_ids;
    };
    /// Adds every non-empty part of g to s; ids[geomID] = its GeometrySource.
    void add_geometry(RTCScene s, const geom::Geometry& g, std::vector<const GeometrySource*>& ids,
                      const Key* line_keys, bool unlit, bool alpha, bool lines = true,
                      LineEndsTarget ends = {});
    /// Places `ends` (the scene's own caps or joints) in the top-level scene, if not empty.
    void place_line_ends(RTCScene ends, PlacedEnds& e);
    /// Builds the part's Embree geometry (its ShapeKind) and attaches it to s; `alpha`:
    /// hits are cut out where its texture's alpha is below one half.
    void attach(RTCScene s, GeometrySource part, std::vector<const GeometrySource*>& ids,
                bool alpha);
};

namespace {

/// Rejects hits where the primitive's texture is cut out (alpha < 0.5).
void alpha_filter(const RTCFilterFunctionNArguments* args)
{
    const auto* part = static_cast<const GeometrySource*>(args->geometryUserPtr);
    const HitResolver& owner = *part->owner;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0)
            continue;
        std::uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
        const InstanceStyle* p = owner.style(RTCHitN_instID(args->hit, args->N, i, 0));
        int texture = owner.texture_of(*part, prim, p);
        if (!owner.textures->cuts_out(texture))
            continue;
        Vec3f ng(RTCHitN_Ng_x(args->hit, args->N, i), RTCHitN_Ng_y(args->hit, args->N, i),
                 RTCHitN_Ng_z(args->hit, args->N, i));
        auto st = kind(part->shape).texture_coords(*part, prim, RTCHitN_u(args->hit, args->N, i),
                                                   RTCHitN_v(args->hit, args->N, i), ng);
        if (owner.textures->lookup(texture, st[0], st[1]).alpha < 0.5f)
            args->valid[i] = 0;
    }
}

template <class T>
bool any_texture(const std::vector<T>& textures)
{
    for (auto t : textures)
        if (t != geom::no_texture)
            return true;
    return false;
}

/// Whether any of the textures cuts its surface out: only then do hits need the alpha
/// test (an opaque RGBA image, as all of GeneralizedCylinder's, would pay a texture lookup
/// per candidate hit for nothing).
template <class T>
bool any_cut_out(const TextureSet* set, const std::vector<T>& textures)
{
    if (set)
        for (auto t : textures)
            if (set->cuts_out(t))
                return true;
    return false;
}

/// A hit's materials: the side hit, then the instance's for inherit_material; a generalized
/// cylinder's colour blend toward its end material.
struct HitMaterials {
    std::uint16_t material = 0, end_material = 0;
    float blend = 0;
};

/// Read apart from materials_at(), before the hit's surface: on a large mesh they miss the
/// cache, and read first their misses overlap those of the vertices. (Read after, where
/// the side hit picks the entry, the back one waited for the vertices: the side is known
/// from them only.)
MaterialEntries material_entries(const GeometrySource& part, std::uint32_t prim)
{
    if (part.uniform)
        return *part.uniform;
    if (part.records)
        return part.records[prim].materials;
    std::uint32_t index = part.attribute_index(prim);
    std::uint16_t front = at_or(*part.material, index, std::uint16_t{0});
    return {front, part.back_material ? at_or(*part.back_material, index, front) : front};
}

/// The material entries every primitive of the part has, if they are all the same (none:
/// they differ, or the part is empty). Found by asking material_entries() of each, so a
/// hit that takes them from here gets what it would have read.
std::optional<MaterialEntries> uniform_materials(const GeometrySource& part)
{
    const std::size_t n = primitive_count(part);
    if (n == 0)
        return std::nullopt;
    const MaterialEntries first = material_entries(part, 0);
    for (std::size_t prim = 1; prim < n; ++prim) {
        MaterialEntries e = material_entries(part, static_cast<std::uint32_t>(prim));
        if (e.front != first.front || e.back != first.back)
            return std::nullopt;
    }
    return first;
}

HitMaterials materials_at(const GeometrySource& part, std::uint32_t prim, MaterialEntries own,
                          bool back, const InstanceStyle* style, float u)
{
    auto resolve = [&](std::uint16_t mat) -> std::uint16_t {
        if (mat != geom::inherit_material)
            return mat;
        return style ? (back ? style->back_material : style->material) : 0;
    };
    HitMaterials m;
    m.material = resolve(back ? own.back : own.front);
    const geom::HermiteCurves& c = part.geometry->curves;
    if (part.shape == Shape::curve && prim < c.end_material.size()) {
        std::uint16_t end = resolve(c.end_material[prim]);
        if (end != m.material) {
            m.end_material = end;
            m.blend = std::clamp(u, 0.0f, 1.0f);
        }
    }
    return m;
}

/// Most surfaces a transmittance ray passes through before it counts as blocked.
constexpr int max_pass_throughs = 64;

/// The context of a transmittance ray: what it has passed through so far. Embree may
/// report one hit more than once (with spatial splits, from each BVH leaf holding the
/// primitive), so each counted hit is remembered.
struct OpacityContext {
    SkipContext skip;  ///< first: the geometry filters read the context as a SkipContext
    const HitResolver* resolver = nullptr;
    std::span<const float> opacity;
    float through = 1;
    struct Counted {
        std::uint32_t geom, prim, inst;
        float t;
    };
    int count = 0;
    std::array<Counted, max_pass_throughs> counted;

    float opacity_of(std::uint16_t m) const { return m < opacity.size() ? opacity[m] : 1.0f; }
    bool seen(const Counted& c) const
    {
        for (int k = 0; k < count; ++k) {
            const Counted& o = counted[std::size_t(k)];
            if (o.geom == c.geom && o.prim == c.prim && o.inst == c.inst &&
                std::fabs(o.t - c.t) <= 1e-6f * std::fmax(o.t, c.t))
                return true;
        }
        return false;
    }
};

/// The context filter of transmittance rays: multiplies in the transparency of each
/// surface met and lets the ray go on, reading only the hit's material (no normals,
/// texture coordinates or shading); an opaque surface is kept as the blocking hit.
void opacity_filter(const RTCFilterFunctionNArguments* args)
{
    auto* ctx = reinterpret_cast<OpacityContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0)
            continue;
        OpacityContext::Counted c{RTCHitN_geomID(args->hit, args->N, i),
                                  RTCHitN_primID(args->hit, args->N, i),
                                  RTCHitN_instID(args->hit, args->N, i, 0),
                                  RTCRayN_tfar(args->ray, args->N, i)};
        if (ctx->seen(c)) {
            args->valid[i] = 0;
            continue;
        }
        const InstanceStyle* p = ctx->resolver->style(c.inst);
        const GeometrySource& part = *ctx->resolver->part(c.inst, c.geom);
        float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
        // The ray and Ng are both in the hit primitive's own space here.
        Vec3f ng(RTCHitN_Ng_x(args->hit, args->N, i), RTCHitN_Ng_y(args->hit, args->N, i),
                 RTCHitN_Ng_z(args->hit, args->N, i));
        Vec3f dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                  RTCRayN_dir_z(args->ray, args->N, i));
        LocalSurface local = local_surface(part, c.prim, u, v, ng);
        bool back = local.two_sided && dot(local.geometric, dir) > 0;
        HitMaterials m = materials_at(part, c.prim, material_entries(part, c.prim), back, p, u);
        float opacity = ctx->opacity_of(m.material);
        if (m.blend > 0)
            opacity += (ctx->opacity_of(m.end_material) - opacity) * m.blend;
        if (opacity >= 1 || ctx->count == max_pass_throughs)
            continue;  // blocks the ray
        ctx->through *= 1 - opacity;
        ctx->counted[std::size_t(ctx->count++)] = c;
        args->valid[i] = 0;
    }
}

}  // namespace

int HitResolver::texture_of(const GeometrySource& part, std::uint32_t prim,
                            const InstanceStyle* p) const
{
    if (!part.texture)
        return geom::no_texture;
    // Untextured parts (most) read no per-primitive entry: a cache miss on large ones.
    std::int16_t t = part.own_textures
                         ? at_or(*part.texture, part.attribute_index(prim), geom::no_texture)
                         : geom::no_texture;
    // A prototype's untextured primitives take their instance's texture.
    if (t == geom::no_texture && p)
        t = p->texture;
    return t;
}

namespace {

/// Keeps a hit on a pixel-width line only in the pixels OpenGL draws (pixel_lines.h).
void pixel_line_filter(const RTCFilterFunctionNArguments* args)
{
    const auto* part = static_cast<const GeometrySource*>(args->geometryUserPtr);
    const geom::LinearCurves& lines = part->geometry->lines;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0)
            continue;
        std::uint32_t first = lines.segments[RTCHitN_primID(args->hit, args->N, i)];
        const Key& a = part->line_keys[first];
        const Key& b = part->line_keys[first + 1];
        float t = RTCRayN_tfar(args->ray, args->N, i);  // the candidate hit's distance
        geom::Vec3 hit{RTCRayN_org_x(args->ray, args->N, i) + t * RTCRayN_dir_x(args->ray, args->N, i),
                       RTCRayN_org_y(args->ray, args->N, i) + t * RTCRayN_dir_y(args->ray, args->N, i),
                       RTCRayN_org_z(args->ray, args->N, i) + t * RTCRayN_dir_z(args->ray, args->N, i)};
        if (!pixel_line_draws(*part->owner->camera, {a[0], a[1], a[2]}, {b[0], b[1], b[2]}, a[3], hit))
            args->valid[i] = 0;
    }
}

/// The filters a geometry needs, in order (attached only to geometries that need one).
void geometry_filter(const RTCFilterFunctionNArguments* args)
{
    const auto* part = static_cast<const GeometrySource*>(args->geometryUserPtr);
    if (part->skips_self)
        skip_self(args);
    if (part->pixel_line)
        pixel_line_filter(args);
    if (part->cut_out)
        alpha_filter(args);
}

/// The context filter of single rays in a scene with triangle records: asks for the record
/// of each candidate hit on a mesh that has them, so that its cache miss runs while Embree
/// traverses on (a hit's conversion, which starts when Embree returns, waited for it).
/// Accepts every hit. Set by trace() only: a context filter is paid only by the rays whose
/// hits are converted (as the meshes' geometry filter, it made every traversal of the
/// scene 2-3% dearer, raw Embree's replay too); camera streams meet the same few
/// triangles, already in cache.
void prefetch_records(const RTCFilterFunctionNArguments* args)
{
    const auto* part = static_cast<const GeometrySource*>(args->geometryUserPtr);
    if (!part->records)
        return;
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i] != 0)
            __builtin_prefetch(&part->records[RTCHitN_primID(args->hit, args->N, i)]);
}

/// The bytes of `v` if Embree reads it in place (padded for its loads), else 0.
template <class T>
std::size_t padded_bytes(const std::vector<T>& v)
{
    return geom::padded_for_embree(v) ? v.size() * sizeof(T) : 0;
}

/// The bytes of the part's buffers that Embree reads in place (rtcSetSharedGeometryBuffer):
/// part of what Embree needs for it, though Cambium holds them.
std::size_t bytes_shared_with_embree(const GeometrySource& part)
{
    const geom::Geometry& g = *part.geometry;
    auto flags = [](const auto& v, std::size_t n) { return v.size() == n ? n : 0; };
    switch (part.shape) {
    case Shape::line:
        return g.lines.keys.size() * sizeof(Key) + g.lines.segments.size() * sizeof(std::uint32_t) +
               (part.unlit ? flags(g.lines.flags, g.lines.segments.size()) : 0);
    case Shape::curve:
        return (g.curves.points.size() + g.curves.tangents.size()) * sizeof(Key) +
               g.curves.segments.size() * sizeof(std::uint32_t) +
               flags(g.curves.flags, g.curves.segments.size());
    case Shape::sphere: return g.spheres.centres.size() * sizeof(Key);
    case Shape::disc: return g.discs.centres.size() * sizeof(Key);  // normals: copied
    case Shape::triangle:  // read in place when padded (build_triangles), else copied
        return padded_bytes(g.mesh.positions) + padded_bytes(g.mesh.triangles);
    case Shape::cap:
        return part.ends->caps.size() * sizeof(Key) + padded_bytes(part.ends->cap_normals);
    case Shape::joint: return part.ends->joints.size() * sizeof(Key);
    }
    return 0;
}

/// Whether the part's triangles get records: a mesh of the scene's own geometry (a plant,
/// with its small instances drawn in place) whose indices and vertices outgrow a core's
/// cache (2 MiB: 64 Ki triangles hold about that much), so that hits on it miss, up to the
/// number of triangles geom::flatten_small_instances places at most. Records cost 64 B a
/// triangle, about what Embree's BVH of them costs (32 MiB at most): prototypes do without
/// them, since scenes of many plants have many large ones (a field of lilac variants) and
/// the memory they save by instancing must stay saved (docs/architecture.md).
bool wants_records(const GeometrySource& part)
{
    constexpr std::size_t records_from = std::size_t{1} << 16, records_up_to = std::size_t{1} << 19;
    const std::size_t n = part.shape == Shape::triangle ? part.geometry->mesh.size() : 0;
    return n >= records_from && n <= records_up_to;
}

/// One record per triangle of the part, made by the functions a hit without them calls,
/// so that a hit reading them gets the same numbers.
std::vector<TriangleRecord> make_records(const GeometrySource& part)
{
    const geom::TriangleMesh& m = part.geometry->mesh;
    std::vector<TriangleRecord> records(m.size());
    for (std::uint32_t i = 0; i < records.size(); ++i) {
        const auto& tri = m.triangles[i];
        const LocalSurface l = triangle_surface(part, i, 0, 0, Vec3f());
        records[i].face = l.geometric;
        records[i].extent = l.extent;
        records[i].normals = {vec(m.normals[tri[0]]), vec(m.normals[tri[1]]), vec(m.normals[tri[2]])};
        records[i].materials = material_entries(part, i);
    }
    return records;
}

}  // namespace

void EmbreeScene::Impl::attach(RTCScene s, GeometrySource part,
                               std::vector<const GeometrySource*>& ids, bool alpha)
{
    const ShapeKind& shape = kind(part.shape);
    RTCGeometry g = shape.build(device, part);
    embree_shared_bytes += bytes_shared_with_embree(part);
    part.owner = this;
    part.skips_self = shape.self_hits;
    part.pixel_line = part.shape == Shape::line && part.unlit;
    part.cut_out = textures && (alpha || part.pixel_line);
    part.own_textures = part.texture && any_texture(*part.texture);
    part.uniform = uniform_materials(part);
    if (s == scene && wants_records(part))
        part.records = triangle_records.emplace_back(make_records(part)).data();
    parts.push_back(part);
    rtcSetGeometryUserData(g, &parts.back());
    if (part.skips_self || part.pixel_line || part.cut_out) {
        rtcSetGeometryIntersectFilterFunction(g, &geometry_filter);
        rtcSetGeometryOccludedFilterFunction(g, &geometry_filter);
        filtered_geometries.push_back(part.shape);
    }
    rtcCommitGeometry(g);
    unsigned id = rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
    if (ids.size() <= id)
        ids.resize(id + 1, nullptr);
    ids[id] = &parts.back();
}

void EmbreeScene::Impl::add_geometry(RTCScene s, const geom::Geometry& geo,
                                     std::vector<const GeometrySource*>& ids, const Key* line_keys,
                                     bool unlit, bool alpha, bool lines, LineEndsTarget ends)
{

    const geom::LinearCurves& l = geo.lines;
    if (lines && !l.segments.empty()) {
        const Key* keys = line_keys ? line_keys : l.keys.data();
        bool cut = alpha || any_cut_out(textures, l.texture);
        attach(s, lines_source(geo, keys, unlit), ids, cut);
        if (!unlit) {
            const LineEnds& e = line_ends.emplace_back(render::line_ends(l, keys));
            if (!e.caps.empty())
                attach(ends.caps ? ends.caps : s, line_end_source(Shape::cap, geo, keys, e),
                       ends.cap_ids ? *ends.cap_ids : ids, cut);
            if (!e.joints.empty())
                attach(ends.joints ? ends.joints : s, line_end_source(Shape::joint, geo, keys, e),
                       ends.joint_ids ? *ends.joint_ids : ids, cut);
        }
    }
    if (!geo.curves.segments.empty()) {
        attach(s, curves_source(geo), ids, alpha || any_cut_out(textures, geo.curves.texture));
        tilt_rays = true;
    }
    // Spheres are textured but not cut out: cpfg's @O spheres are solid.
    if (geo.spheres.size() > 0)
        attach(s, spheres_source(geo), ids, false);
    if (geo.discs.size() > 0)
        attach(s, discs_source(geo), ids, false);
    if (geo.mesh.size() > 0)
        attach(s, triangles_source(geo), ids, alpha || any_cut_out(textures, geo.mesh.texture));
}

void EmbreeScene::Impl::place_line_ends(RTCScene ends, PlacedEnds& e)
{
    if (e.parts.empty()) {
        rtcReleaseScene(ends);
        return;
    }
    line_end_rtc_scenes.push_back(ends);
    rtcCommitScene(ends);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, ends);
    const std::array<float, 12> identity{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity.data());
    rtcCommitGeometry(g);
    e.instance = rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
}

EmbreeScene::EmbreeScene(const geom::Scene& scene, const Camera& camera,
                         const TextureSet* textures)
    : m_impl(std::make_unique<Impl>())
{
    auto start = std::chrono::steady_clock::now();
    Impl& m = *m_impl;
    m.textures = textures;
    m.camera = std::make_unique<const Camera>(camera);
    m.device = rtcNewDevice(nullptr);
    if (!m.device)
        throw Error(std::string("Embree: cannot create a device: ") +
                    error_name(rtcGetDeviceError(nullptr)));
    rtcSetDeviceErrorFunction(m.device, &ErrorSink::callback, &m.errors);
    rtcSetDeviceMemoryMonitorFunction(m.device, &Impl::monitor_memory, &m);
    m.scene = m.new_scene();

    const geom::Geometry& own = scene.geometry;
    // Embree's high quality (spatial splits) builds a large mesh slowly: 0.5 CPU s for
    // Lilac's 250 k triangles of petals drawn in place (geom/flatten.h), against 0.1 s
    // at medium quality, for rays as fast (docs/benchmarks.md).
    constexpr std::size_t high_quality_triangles_up_to = 65536;
    if (own.mesh.size() > high_quality_triangles_up_to)
        rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_MEDIUM);
    if (scene.line_radius_in_pixels && !own.lines.keys.empty())
        m.world_keys = keys_in_world_units(own.lines, camera);
    RTCScene caps = m.new_scene(), joints = m.new_scene();
    auto& [cap_scene, joint_scene] = m.line_end_scenes;
    // Up to a quarter million lines keep their caps and joints beside them in the
    // top-level BVH: each scene of their own is a second and third traversal for every ray
    // that crosses the plant (Lilac, 2 k segments: 14% of the render's CPU time;
    // WeepingBirch, 29 k: 15%), and the leaves they crowd cost about 130 B a segment more
    // (WeepingBirch: Embree 2.6 -> 6.4 MiB; 34 MB at the limit).
    const bool ends_beside = own.lines.segment_count() <= line_ends_beside_up_to;
    m.add_geometry(m.scene, own, m.top_parts,
                   m.world_keys.empty() ? nullptr : m.world_keys.data(),
                   scene.line_radius_in_pixels, false, true,
                   ends_beside ? Impl::LineEndsTarget{nullptr, nullptr, nullptr, nullptr}
                               : Impl::LineEndsTarget{caps, joints, &cap_scene.parts,
                                                      &joint_scene.parts});
    m.place_line_ends(caps, cap_scene);
    m.place_line_ends(joints, joint_scene);
    m.segments = own.lines.segment_count() + own.curves.segment_count();

    // Pixel-width lines inside prototypes: each placed copy in world space, drawn unlit
    // like the scene's own (cpfg's GL lines are as wide at any depth and scale).
    if (scene.line_radius_in_pixels) {
        m.placed_lines.lines = place_pixel_lines(scene, camera);
        m.add_geometry(m.scene, m.placed_lines, m.top_parts, nullptr, true, false);
        m.segments += m.placed_lines.lines.segment_count();
    }

    // Prototypes: one Embree scene each, built only if some instance places it.
    std::vector<bool> placed(scene.prototypes.size(), false), cut_out(placed);
    for (const geom::Instance& inst : scene.instances) {
        if (inst.prototype >= scene.prototypes.size())
            throw Error("scene: instance of prototype " + std::to_string(inst.prototype) +
                        " of " + std::to_string(scene.prototypes.size()));
        placed[inst.prototype] = true;
        if (textures && textures->cuts_out(inst.texture))
            cut_out[inst.prototype] = true;
    }
    m.prototype_scenes.assign(scene.prototypes.size(), nullptr);
    m.proto_parts.resize(scene.prototypes.size());
    for (std::size_t i = 0; i < scene.prototypes.size(); ++i) {
        const geom::Geometry& g = scene.prototypes[i].geometry;
        // With pixel-width lines placed above, a prototype of lines alone has nothing left.
        bool lines_only = g.curves.segment_count() == 0 && g.spheres.size() == 0 &&
                          g.discs.size() == 0 && g.mesh.size() == 0;
        if (!placed[i] || g.empty() || (scene.line_radius_in_pixels && lines_only))
            continue;
        m.prototype_scenes[i] = m.new_scene();
        m.add_geometry(m.prototype_scenes[i], g, m.proto_parts[i], nullptr, false, cut_out[i],
                       !scene.line_radius_in_pixels);
        rtcCommitScene(m.prototype_scenes[i]);
    }
    // Each instance keeps nothing here: Embree holds its transform, and its user data
    // points at the style it shares with the instances that agree with it.
    std::map<decltype(InstanceStyle{}.key()), const InstanceStyle*> style_of;
    m.top = m.scene;
    m.instances = scene.instances;
    const std::size_t heap_before = heap_in_use();
    for (std::uint32_t index = 0; index < scene.instances.size(); ++index) {
        const geom::Instance& inst = scene.instances[index];
        RTCScene proto = m.prototype_scenes[inst.prototype];
        if (!proto)
            continue;
        InstanceStyle style{inst.prototype, inst.material, inst.back_material, inst.texture};
        auto [found, added] = style_of.emplace(style.key(), nullptr);
        if (added)
            found->second = &m.styles.emplace_back(style);
        RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, proto);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, inst.transform.data());
        rtcSetGeometryUserData(g, const_cast<InstanceStyle*>(found->second));
        rtcCommitGeometry(g);
        if (m.first_instance_id == PrimId::none) {
            m.first_instance_id = rtcAttachGeometry(m.scene, g);
            m.first_instance_index = index;
        } else {
            rtcAttachGeometryByID(m.scene, g, m.first_instance_id + (index - m.first_instance_index));
        }
        rtcReleaseGeometry(g);
    }
    // Embree's memory monitor sees its buffers and BVHs, not its instance objects: they are
    // most of the heap this loop takes (the styles it adds are a few).
    m.embree_unmonitored_bytes = std::max(heap_in_use(), heap_before) - heap_before;
    rtcCommitScene(m.scene);
    m.check("building the Embree scene");
    m.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

EmbreeScene::~EmbreeScene() = default;

std::size_t EmbreeScene::segment_count() const { return m_impl->segments; }

std::uint64_t EmbreeScene::skipped_rays() const { return m_impl->skipped_rays.load(); }

double EmbreeScene::build_seconds() const { return m_impl->build_seconds; }

std::uint64_t EmbreeScene::rays_traced() const { return m_impl->rays.total(); }

std::uint64_t EmbreeScene::embree_bytes() const
{
    return static_cast<std::uint64_t>(std::max<std::int64_t>(0, m_impl->embree_bytes.load()));
}

std::uint64_t EmbreeScene::embree_peak_bytes() const
{
    return static_cast<std::uint64_t>(m_impl->embree_peak_bytes.load());
}

std::uint64_t EmbreeScene::shared_bytes() const { return m_impl->embree_shared_bytes; }

std::uint64_t EmbreeScene::embree_unmonitored_bytes() const
{
    return m_impl->embree_unmonitored_bytes;
}

namespace {

template <class T>
std::size_t capacity_bytes(const std::vector<T>& v)
{
    return v.capacity() * sizeof(T);
}

}  // namespace

std::uint64_t EmbreeScene::own_bytes() const
{
    const Impl& m = *m_impl;
    std::size_t bytes = capacity_bytes(m.world_keys) + m.styles.size() * sizeof(InstanceStyle) +
                        m.parts.size() * sizeof(GeometrySource);
    for (const std::vector<TriangleRecord>& r : m.triangle_records)
        bytes += capacity_bytes(r);
    for (const LineEnds& e : m.line_ends)
        bytes += capacity_bytes(e.caps) + capacity_bytes(e.cap_normals) +
                 capacity_bytes(e.cap_segment) + capacity_bytes(e.cap_at_end) +
                 capacity_bytes(e.joints) + capacity_bytes(e.joint_segment);
    const geom::LinearCurves& p = m.placed_lines.lines;
    bytes += capacity_bytes(p.keys) + capacity_bytes(p.v) + capacity_bytes(p.segments) +
             capacity_bytes(p.flags) + capacity_bytes(p.material) + capacity_bytes(p.texture);
    return bytes;
}

namespace {

/// Whether Embree takes the ray (its traversal asserts this): finite, starting within
/// geom::max_ray_start, so that instances' frames keep it in range too (scene_limits.h).
bool traceable(const Vec3f& org, const Vec3f& dir, float tnear, float tfar)
{
    constexpr auto reach = static_cast<float>(geom::max_ray_start);
    // |v| <= limit, not -limit <= v && v <= limit (the same, NaN included): the compiler
    // made a branch of each &&.
    auto within = [](float v, float limit) { return std::fabs(v) <= limit; };
    // & rather than &&: every test is cheap, and one branch predicts better than nine.
    return within(org.x, reach) & within(org.y, reach) & within(org.z, reach) &
           std::isfinite(dir.x) & std::isfinite(dir.y) & std::isfinite(dir.z) & (tnear >= 0) &
           !std::isnan(tfar);
}

/// The floats of a camera ray in order (org, dir, tfar), each with the largest magnitude
/// it may have for traceable() with tnear 0: origins within reach, directions finite, tfar
/// anything but NaN. (A NaN is within no bound.)
constexpr int camera_ray_floats = 7;
static_assert(sizeof(CameraRayF) == camera_ray_floats * sizeof(float));
constexpr std::array<float, camera_ray_floats> camera_ray_bounds{
    static_cast<float>(geom::max_ray_start), static_cast<float>(geom::max_ray_start),
    static_cast<float>(geom::max_ray_start), std::numeric_limits<float>::max(),
    std::numeric_limits<float>::max(),       std::numeric_limits<float>::max(),
    std::numeric_limits<float>::infinity()};

/// Whether traceable() holds for every one of `rays` (at most max_coherent_rays), with
/// tnear 0: the same test, made on their floats as one array against camera_ray_bounds,
/// which the compiler vectorises (per ray, traceable()'s nine tests were 40% of
/// intersect_coherent's own time on the plants' views).
bool every_ray_traceable(std::span<const CameraRayF> rays)
{
    constexpr std::size_t most = EmbreeScene::max_coherent_rays * camera_ray_floats;
    static constexpr auto bounds = [] {
        std::array<float, most> b{};
        for (std::size_t k = 0; k < most; ++k)
            b[k] = camera_ray_bounds[k % camera_ray_floats];
        return b;
    }();
    std::array<float, most> floats;
    const std::size_t n = std::min(rays.size() * camera_ray_floats, most);
    if (n > 0)  // (an empty span's data may be null, which memcpy must not be given)
        std::memcpy(floats.data(), rays.data(), n * sizeof(float));
    int within = 0;  // (a count, not a bool: so the loop vectorises)
    for (std::size_t k = 0; k < n; ++k)
        within += std::fabs(floats[k]) <= bounds[k];
    return within == static_cast<int>(n);
}

RTCRay make_ray(const Vec3f& org, const Vec3f& dir, float tnear, float tfar)
{
    RTCRay r;
    r.org_x = org.x;
    r.org_y = org.y;
    r.org_z = org.z;
    r.dir_x = dir.x;
    r.dir_y = dir.y;
    r.dir_z = dir.z;
    r.tnear = tnear;
    r.tfar = tfar;
    r.time = 0;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    return r;
}

/// rh made ready to trace: its ray make_ray(...), its hit none yet (as Embree asks).
void set_query(RTCRayHit& rh, const Vec3f& org, const Vec3f& dir, float tnear, float tfar)
{
    rh.ray = make_ray(org, dir, tnear, tfar);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

}  // namespace

std::optional<SurfaceHit> EmbreeScene::intersect(const Vec3f& org, const Vec3f& dir, float tnear,
                                                 float tfar, PrimId skip, bool coherent) const
{
    std::optional<SurfaceHit> hit;
    RTCRayHit rh;
    if (m_impl->trace(rh, org, dir, tnear, tfar, skip, coherent))
        m_impl->surface_hit(rh, org, dir, hit);
    return hit;
}

bool EmbreeScene::intersect(SurfaceHit& hit, const Vec3f& org, const Vec3f& dir, float tnear,
                            float tfar, PrimId skip, bool coherent) const
{
    RTCRayHit rh;
    if (!m_impl->trace(rh, org, dir, tnear, tfar, skip, coherent))
        return false;
    ::new (&hit) SurfaceHit(m_impl->surface_hit(rh, org, dir));  // made in place
    return true;
}

bool EmbreeScene::intersect_light(LightHit& hit, const Vec3f& org, const Vec3f& dir, float tnear,
                                  float tfar, PrimId skip) const
{
    RTCRayHit rh;
    if (!m_impl->trace(rh, org, dir, tnear, tfar, skip, false))
        return false;
    ::new (&hit) LightHit(m_impl->hit_of<LightHit>(rh, org, dir));
    return true;
}

std::uint32_t EmbreeScene::intersect_light(std::span<const LightRay> rays,
                                           std::span<LightHit> hits) const
{
    const Impl& m = *m_impl;
    std::array<RTCRayHit, max_coherent_rays> rh;
    std::array<std::uint32_t, max_coherent_rays> index;  // rh[k] is rays[index[k]]
    const std::size_t n = std::min({rays.size(), hits.size(), rh.size()});
    m.rays.add(n);
    std::size_t traced = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const LightRay& r = rays[i];
        if (!traceable(r.org, r.dir, 0, r.tfar)) {
            ++m.skipped_rays;
            continue;
        }
        set_query(rh[traced], r.org, m.traced(r.dir), 0, r.tfar);
        index[traced++] = static_cast<std::uint32_t>(i);
    }
    if (traced == 0)
        return 0;
    SkipContext context = make_context({}, true);
    if (!m.triangle_records.empty())
        context.context.filter = &prefetch_records;
    rtcIntersect1M(m.scene, &context.context, rh.data(), static_cast<unsigned>(traced),
                   sizeof(RTCRayHit));
    std::uint32_t hit_bits = 0;
    for (std::size_t k = 0; k < traced; ++k)
        if (rh[k].hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            const std::size_t i = index[k];
            ::new (&hits[i]) LightHit(m.hit_of<LightHit>(rh[k], rays[i].org, rays[i].dir));
            hit_bits |= std::uint32_t{1} << i;
        }
    return hit_bits;
}

bool EmbreeScene::Impl::trace(RTCRayHit& rh, const Vec3f& org, const Vec3f& dir, float tnear,
                              float tfar, PrimId skip, bool coherent) const
{
    rays.add();
    if (!traceable(org, dir, tnear, tfar)) {
        ++skipped_rays;
        return false;
    }
    SkipContext context = make_context(skip, coherent);
    if (!triangle_records.empty())
        context.context.filter = &prefetch_records;
    set_query(rh, org, traced(dir), tnear, tfar);
    rtcIntersect1(scene, &context.context, &rh);
    return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

template <typename Slot, typename RayAt>
std::uint32_t EmbreeScene::Impl::trace_stream(std::span<RTCRayHit> rh, std::size_t traced,
                                              Slot slot, RayAt ray_at,
                                              std::span<std::optional<SurfaceHit>> hits) const
{
    static_assert(max_coherent_rays <= 32);
    if (traced == 0)
        return 0;
    SkipContext context = make_context({}, true);
    // A stream of coherent rays: Embree gathers it into SIMD packets.
    rtcIntersect1M(scene, &context.context, rh.data(), static_cast<unsigned>(traced),
                   sizeof(RTCRayHit));
    // The instance records of the stream's instanced hits, asked for together: their
    // cache misses overlap instead of stalling each hit's conversion in turn.
    for (std::size_t k = 0; k < traced; ++k)
        if (placed_instance(rh[k].hit.instID[0]) && rh[k].hit.geomID != RTC_INVALID_GEOMETRY_ID)
            __builtin_prefetch(instance(rh[k].hit.instID[0]));
    std::uint32_t hit_bits = 0;
    for (std::size_t k = 0; k < traced; ++k) {
        const std::size_t i = slot(k);
        if (rh[k].hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            const CameraRayF r = ray_at(i);
            surface_hit(rh[k], r.org, r.dir, hits[i]);
            hit_bits |= std::uint32_t{1} << i;
        } else {
            hits[i].reset();
        }
    }
    return hit_bits;
}

std::uint32_t EmbreeScene::intersect_coherent(std::span<const CameraRayF> rays,
                                              std::span<std::optional<SurfaceHit>> hits,
                                              bool checked) const
{
    const Impl& m = *m_impl;
    std::array<RTCRayHit, max_coherent_rays> rh;
    std::size_t n = std::min({rays.size(), hits.size(), rh.size()});
    m.rays.add(n);
    // Camera rays are almost always all traceable: then rh[i] is rays[i], made in one pass
    // without an index.
    const bool all_traceable = checked || every_ray_traceable(rays.first(n));
    std::array<std::uint32_t, max_coherent_rays> index;  // rh[k] is rays[index[k]]
    std::size_t traced = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const CameraRayF& r = rays[i];
        if (!all_traceable && !traceable(r.org, r.dir, 0, r.tfar)) {
            ++m.skipped_rays;
            hits[i].reset();
            continue;
        }
        set_query(rh[traced], r.org, m.traced(r.dir), 0, r.tfar);
        index[traced++] = static_cast<std::uint32_t>(i);
    }
    return m.trace_stream(
        rh, traced, [&](std::size_t k) { return all_traceable ? k : std::size_t(index[k]); },
        [&](std::size_t i) -> const CameraRayF& { return rays[i]; }, hits);
}

std::uint32_t EmbreeScene::intersect_coherent(const ParallelRays& rays, std::size_t n,
                                              std::span<std::optional<SurfaceHit>> hits,
                                              bool checked) const
{
    n = std::min({n, hits.size(), ParallelRays::capacity});
    if (!checked) {  // (rare: rays that may be out of reach) each ray is checked as a CameraRayF
        std::array<CameraRayF, ParallelRays::capacity> each;
        for (std::size_t k = 0; k < n; ++k)
            each[k] = rays.ray(k);
        return intersect_coherent(std::span(each.data(), n), hits, false);
    }
    const Impl& m = *m_impl;
    std::array<RTCRayHit, max_coherent_rays> rh;
    static_assert(ParallelRays::capacity <= max_coherent_rays);
    m.rays.add(n);
    const Vec3f dir = m.traced(rays.dir);  // (tilted once for all)
    for (std::size_t k = 0; k < n; ++k)  // rh[k] is rays.ray(k), without an index
        set_query(rh[k], {rays.org_x[k], rays.org_y[k], rays.org_z[k]}, dir, 0, rays.tfar[k]);
    return m.trace_stream(
        rh, n, [](std::size_t k) { return k; }, [&](std::size_t i) { return rays.ray(i); }, hits);
}

template <class Hit>
Hit EmbreeScene::Impl::hit_of(const RTCRayHit& rh, const Vec3f& org, const Vec3f& dir) const
{
    constexpr bool full = std::is_same_v<Hit, SurfaceHit>;
    const float t = rh.ray.tfar;
    // Where Embree found it: along the direction it traced (make_ray stored traced(dir),
    // which Embree leaves as it was: read back, not tilted a second time).
    const Vec3f position = org + Vec3f(rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z) * t;
    const std::uint32_t prim = rh.hit.primID, inst_id = rh.hit.instID[0];
    const std::optional<Placement> placement = this->placement(inst_id);
    const InstanceStyle* style = placement ? &placement->style : nullptr;
    const GeometrySource& part = *this->part(inst_id, rh.hit.geomID, placement);

    // Embree reports an instanced hit's normal in the prototype's frame.
    Vec3f ng(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    const MaterialEntries own_materials = material_entries(part, prim);
    const ShapeKind& shape = kind(part.shape);
    LocalSurface local = local_surface(part, prim, rh.hit.u, rh.hit.v, ng);
    Vec3f geometric = local.geometric;
    float radius = local.radius;
    if (placement) {
        geometric = placement->normals * geometric;
        if (radius != 0)
            radius *= placement->radius_scale();
    }
    // Only triangles interpolate a shading normal; the other shapes shade by their true one.
    // It is made unit before the side hit is known, beside the true normal, so that their
    // square roots and divisions overlap (turned to the side after: negation is exact).
    const bool smooth = full && part.shape == Shape::triangle;
    Vec3f shading;
    if constexpr (full)
        if (smooth)
            shading = unit(placement ? placement->normals * local.shading : local.shading);
    geometric = unit(geometric);
    const bool facing_away = dot(geometric, dir) > 0;
    const bool back = local.two_sided && facing_away;
    if (facing_away)
        geometric = -geometric;
    Vec3f normal = geometric;
    if constexpr (full)
        if (smooth) {
            if (back)
                shading = -shading;
            // A shading normal turned away from the ray (or absent) gives way to the true
            // one.
            if (dot(shading, dir) < 0)
                normal = shading;
        }

    HitMaterials materials = materials_at(part, prim, own_materials, back, style, rh.hit.u);
    const int texture = full ? texture_of(part, prim, style) : geom::no_texture;
    TextureCoords st{0, 0};
    TextureTangents tangents{};
    if (full && texture != geom::no_texture) {
        const TextureFrame frame =
            shape.texture_frame(part, prim, rh.hit.u, rh.hit.v, ng, local.radius);
        st = frame.st;
        tangents = frame.tangents;
        if (placement)
            tangents = {placement->linear * tangents[0], placement->linear * tangents[1]};
    }

    float scale = largest_coordinate(position);
    if (!shape.self_hits) {
        // Nothing skips a flat primitive: its offset must clear the float error of the hit,
        // which grows with the primitive's coordinates and (through the hit distance's
        // error) with the ray's length.
        float extent = local.extent * (placement ? placement->largest_scale() : 1);
        scale = std::max(scale, extent) + 0.2f * t;
    }
    const float spawn_offset =
        shape.offset_per_radius * radius + shape.offset_per_scale * scale + shape.offset_absolute;
    const std::uint32_t primitive =
        part.geometry == &placed_lines ? PrimId::none : part.attribute_index(prim);
    if constexpr (!full)
        return LightHit{
            .t = t,
            .position = position,
            .geometric_normal = geometric,
            .geom_id = rh.hit.geomID,
            .prim_id = prim,
            .inst_id = inst_id,
            .instance = placement ? placement->index : PrimId::none,
            .primitive = primitive,
            .material = materials.material,
            .end_material = materials.end_material,
            .material_blend = materials.blend,
            .spawn_offset = spawn_offset,
            .shape = part.shape,
            .back = back,
            .unlit = part.unlit,
        };
    else
    // Every field named, so the hit is written once, in the caller's storage (a
    // default-made hit was zeroed first by a string store, about 8 ns, then overwritten).
    return SurfaceHit{
        .t = t,
        .position = position,
        .normal = normal,
        .geometric_normal = geometric,
        .geom_id = rh.hit.geomID,
        .prim_id = prim,
        .inst_id = inst_id,
        .instance = placement ? placement->index : PrimId::none,
        .primitive = primitive,
        .material = materials.material,
        .end_material = materials.end_material,
        .material_blend = materials.blend,
        .texture = static_cast<std::int16_t>(texture),
        .u = st[0],
        .v = st[1],
        .dpds = tangents[0],
        .dpdt = tangents[1],
        .shape = part.shape,
        .back = back,
        // Curves' and spheres' true normals point out of them.
        .inside = !local.two_sided && facing_away,
        .radius = radius,
        .spawn_offset = spawn_offset,
        .unlit = part.unlit,
    };
}

float EmbreeScene::transmittance(const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
                                 PrimId skip, std::span<const float> opacity) const
{
    if (!traceable(org, dir, tnear, tfar)) {
        ++m_impl->skipped_rays;
        return 1;
    }
    OpacityContext context;
    context.skip = make_context(skip, false);
    context.skip.context.filter = &opacity_filter;
    context.resolver = m_impl.get();
    context.opacity = opacity;
    RTCRay r = make_ray(org, m_impl->traced(dir), tnear, tfar);
    rtcOccluded1(m_impl->scene, &context.skip.context, &r);
    if (r.tfar < 0 && std::isinf(r.tfar))
        return 0;
    return context.through;
}

std::vector<Shape> EmbreeScene::filtered_shapes() const { return m_impl->filtered_geometries; }

bool EmbreeScene::occluded(const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
                           PrimId skip) const
{
    m_impl->rays.add();
    if (!traceable(org, dir, tnear, tfar)) {
        ++m_impl->skipped_rays;
        return false;
    }
    SkipContext context = make_context(skip, false);
    RTCRay r = make_ray(org, m_impl->traced(dir), tnear, tfar);
    rtcOccluded1(m_impl->scene, &context.context, &r);
    // Embree marks an occluded ray by setting tfar to -inf.
    return r.tfar < 0 && std::isinf(r.tfar);
}

}  // namespace cambium::render
