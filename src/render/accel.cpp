// SPDX-License-Identifier: Apache-2.0
// EmbreeScene: the Scene's primitives in Embree (the only user of <embree3/rtcore.h>).
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

using Key = std::array<float, 4>;

Vec3f vec(const geom::Float3& a) { return {a[0], a[1], a[2]}; }
Vec3f vec(const geom::Float4& a) { return {a[0], a[1], a[2]}; }

/// v normalised (zero stays zero) by one division, not three: the hit's normals.
Vec3f unit(const Vec3f& v)
{
    float l = length(v);
    return l > 0 ? v * (1 / l) : v;
}

/// The largest magnitude among p's coordinates. std::max, not std::fmax: for numbers they
/// agree, and fmax's NaN rule keeps the compiler from inlining it (a libm call per use).
float largest_coordinate(const Vec3f& p)
{
    return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
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

/// The Hermite basis at u: weights of p0, t0, p1, t1.
std::array<float, 4> hermite(float u)
{
    float u2 = u * u, u3 = u2 * u;
    return {2 * u3 - 3 * u2 + 1, u3 - 2 * u2 + u, -2 * u3 + 3 * u2, u3 - u2};
}

/// The derivatives of the Hermite basis at u.
std::array<float, 4> hermite_derivative(float u)
{
    float u2 = u * u;
    return {6 * u2 - 6 * u, 3 * u2 - 4 * u + 1, -6 * u2 + 6 * u, 3 * u2 - 2 * u};
}

template <class T>
T at_or(const std::vector<T>& v, std::size_t i, T fallback)
{
    return i < v.size() ? v[i] : fallback;
}

struct HitResolver;

/// A primitive's own material entries for both sides (`back` = `front` where the part has
/// no back materials), before inherit_material is resolved.
struct MaterialEntries {
    std::uint16_t front = 0, back = 0;
};

/// What a hit on a triangle of a large mesh reads of it, in one cache line (56 of its 64
/// bytes): the true normal turned to the front and the extent, as triangle_surface()
/// makes them from the vertices, the three vertex normals and the material entries. Read
/// through the triangle's vertex indices instead, each hit waited for two cache misses,
/// one after the other (the indices, then the vertices), beside those of the entries.
struct alignas(64) TriangleRecord {
    Vec3f face;
    float extent = 0;
    std::array<Vec3f, 3> normals;
    MaterialEntries materials;
};
static_assert(sizeof(TriangleRecord) == 64);

/// One Embree geometry's source primitives and where their attributes live.
struct GeometrySource {
    Shape shape = Shape::line;
    const geom::Geometry* geometry = nullptr;
    const Key* line_keys = nullptr;  ///< lines, caps, joints: keys with world-unit radii
    bool unlit = false;
    const HitResolver* owner = nullptr;
    const LineEnds* ends = nullptr;  ///< caps and joints: the segments they belong to
    /// Per-primitive attributes, indexed by attribute_index(): front and back (flat
    /// shapes only) materials, textures (none: never textured).
    const std::vector<std::uint16_t>* material = nullptr;
    const std::vector<std::uint16_t>* back_material = nullptr;
    const std::vector<std::int16_t>* texture = nullptr;
    /// Some primitive names a texture in `texture` (else only an instance's can apply).
    bool own_textures = false;
    /// Caps and joints: the line segment each belongs to (their attributes are its).
    const std::vector<std::uint32_t>* segment = nullptr;
    /// The filters its Embree geometry runs on each candidate hit (none: no filter at all):
    /// the primitive a ray leaves, the pixels a pixel-width line covers, alpha cut-outs.
    bool skips_self = false, pixel_line = false, cut_out = false;
    /// Every primitive's material entries are `uniform` (found at build time), so a hit
    /// reads none: Lilac's 247 k petal triangles have one material, whose two entries
    /// per triangle were two more cache misses a hit (beside the vertices').
    std::optional<MaterialEntries> uniform{};
    /// Triangles of a large mesh of the scene's own: one record each (wants_records(),
    /// make_records()), else null.
    const TriangleRecord* records = nullptr;

    std::uint32_t attribute_index(std::uint32_t prim) const
    {
        return segment ? (*segment)[prim] : prim;
    }
};

/// What a primitive says about its hit in object space.
struct LocalSurface {
    Vec3f geometric;     ///< true normal (front side for discs and triangles)
    /// Triangles: the vertex normals interpolated (front side), or zero: the geometric
    /// one. Other shapes have none (zero), and surface_hit() reads it for triangles only.
    Vec3f shading;
    float radius = 0;
    bool two_sided = false;
    /// Flat shapes: their largest coordinate (object space), a measure of the float error
    /// of a hit on them.
    float extent = 0;
};

using TextureCoords = std::array<float, 2>;
using TextureTangents = std::array<Vec3f, 2>;
struct TextureFrame {
    TextureCoords st;
    TextureTangents tangents;
};

/// Everything accel does that depends on the kind of primitive: one entry per Shape in
/// `shape_kinds`, so a new kind of primitive is added in one place (and a case in
/// local_surface(), which every hit calls).
struct ShapeKind {
    /// Embree's geometry of the part's primitives (throws cambium::Error on a bad index).
    RTCGeometry (*build)(RTCDevice device, const GeometrySource& part);
    /// Texture coordinates (s, t) of a hit.
    TextureCoords (*texture_coords)(const GeometrySource& part, std::uint32_t prim, float u,
                                    float v, const Vec3f& ng);
    /// A textured hit's (s, t) and its tangents: texture_coords, and dP/ds and dP/dt in
    /// object space (their derivatives; zero where a coordinate does not change). One call,
    /// so that what both need (a curve's axis) is found once.
    TextureFrame (*texture_frame)(const GeometrySource& part, std::uint32_t prim, float u,
                                  float v, const Vec3f& ng, float radius);
    /// Spawned rays start this far off the surface: per unit of radius, per unit of the
    /// hit's largest coordinate, and absolute (see EmbreeScene::intersect).
    float offset_per_radius, offset_per_scale, offset_absolute;
    /// Whether a ray leaving the shape must skip it: Embree's round curves and spheres
    /// have no self-intersection protection (FACTS.md: half the rays leaving a curve would
    /// hit it again), so their geometries filter the primitive a ray leaves. Flat shapes
    /// rely on their offset alone and run no filter for it.
    bool self_hits;
};

// ---- Shared by the shapes ------------------------------------------------------------

void check_segments(const std::vector<std::uint32_t>& segments, std::size_t keys,
                    const char* what)
{
    for (std::uint32_t first : segments)
        if (first + 1 >= keys)
            throw Error(std::string("scene: ") + what + " segment starts at key " +
                        std::to_string(first) + " of " + std::to_string(keys));
}

template <class T>
void check_size(const std::vector<T>& v, std::size_t n, const char* what)
{
    if (v.size() != n)
        throw Error(std::string("scene: ") + std::to_string(v.size()) + " " + what + " for " +
                    std::to_string(n));
}

/// Copies `data` into a new Embree-owned buffer (Embree pads it for its SSE loads, which
/// shared float3 and uint3 buffers would need by hand).
template <class T>
void copy_buffer(RTCGeometry g, RTCBufferType type, RTCFormat format, const std::vector<T>& data)
{
    void* dst = rtcSetNewGeometryBuffer(g, type, 0, format, sizeof(T), data.size());
    if (dst)
        std::memcpy(dst, data.data(), sizeof(T) * data.size());
}

void share_keys(RTCGeometry g, RTCBufferType type, const Key* keys, std::size_t n)
{
    rtcSetSharedGeometryBuffer(g, type, 0, RTC_FORMAT_FLOAT4, keys, 0, sizeof(Key), n);
}

void share_segments(RTCGeometry g, const std::vector<std::uint32_t>& segments)
{
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, segments.data(), 0,
                               sizeof(std::uint32_t), segments.size());
}

void set_flags(RTCGeometry g, const std::vector<std::uint8_t>& flags, std::size_t segments)
{
    // Neighbour flags close the joints of a polyline without caps or bulges.
    if (flags.size() == segments)
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR, flags.data(), 0,
                                   sizeof(std::uint8_t), flags.size());
    else if (!flags.empty())
        warn("scene: " + std::to_string(flags.size()) + " curve flags for " +
             std::to_string(segments) + " segments; flags ignored");
}

/// Around a tube, s runs once round the circumference; along it, t as its keys say.
/// (The cross product's direction does not depend on ng's length: one root, one division.)
TextureTangents tube_tangents(const Vec3f& axis, const Vec3f& ng, float radius, float dv)
{
    const Vec3f around = cross(axis, ng);
    const float length = std::sqrt(dot(around, around));
    return {length > 0 ? around * (2 * pi * radius / length) : around,
            dv != 0 ? axis * (1 / dv) : Vec3f()};
}

TextureTangents no_tangents(const GeometrySource&, std::uint32_t, float, const Vec3f&, float)
{
    return {Vec3f(), Vec3f()};
}

TextureCoords no_coords(const GeometrySource&, std::uint32_t, float, float, const Vec3f&)
{
    return {0, 0};
}

/// A shape's texture frame from its separate coordinates and tangents (shapes whose two
/// share no work).
template <auto coords, auto tangents>
TextureFrame frame_of(const GeometrySource& part, std::uint32_t prim, float u, float v,
                      const Vec3f& ng, float radius)
{
    return {coords(part, prim, u, v, ng), tangents(part, prim, u, ng, radius)};
}

// ---- Lines (F, G): cone curves, or round ones for pixel-width lines ------------------

RTCGeometry build_lines(RTCDevice device, const GeometrySource& part)
{
    const geom::LinearCurves& l = part.geometry->lines;
    check_segments(l.segments, l.keys.size(), "line");
    // cpfg's pixel lines are GL lines: Embree's round (swept-sphere) curves suit them;
    // shaded cylinders are exact frustums closed by caps and joints (LineEnds).
    RTCGeometry g = rtcNewGeometry(device, part.unlit ? RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE
                                                      : RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE);
    share_keys(g, RTC_BUFFER_TYPE_VERTEX, part.line_keys, l.keys.size());
    share_segments(g, l.segments);
    if (part.unlit)
        set_flags(g, l.flags, l.segments.size());
    return g;
}

[[gnu::always_inline]] inline LocalSurface line_surface(const GeometrySource& part,
                                                        std::uint32_t prim, float u, float,
                                                        const Vec3f& ng)
{
    const geom::LinearCurves& l = part.geometry->lines;
    const Key& k0 = part.line_keys[l.segments[prim]];
    const Key& k1 = part.line_keys[l.segments[prim] + 1];
    return {ng, Vec3f(), k0[3] + (k1[3] - k0[3]) * u, false};
}

/// Texture t at key k of the lines (0 without per-key t).
float line_t(const geom::LinearCurves& l, std::uint32_t k)
{
    return l.v.size() == l.keys.size() ? l.v[k] : 0.0f;
}

TextureCoords line_coords(const GeometrySource& part, std::uint32_t prim, float u, float,
                          const Vec3f& ng)
{
    const geom::LinearCurves& l = part.geometry->lines;
    std::uint32_t k = l.segments[prim];
    float t = line_t(l, k) + (line_t(l, k + 1) - line_t(l, k)) * u;
    return {angle_around(vec(part.line_keys[k + 1]) - vec(part.line_keys[k]), ng), t};
}

/// line_coords and the tube's tangents, from one axis.
TextureFrame line_frame(const GeometrySource& part, std::uint32_t prim, float u, float,
                        const Vec3f& ng, float radius)
{
    const geom::LinearCurves& l = part.geometry->lines;
    std::uint32_t k = l.segments[prim];
    const float t0 = line_t(l, k), dt = line_t(l, k + 1) - t0;
    const Vec3f axis = vec(part.line_keys[k + 1]) - vec(part.line_keys[k]);
    return {{angle_around(axis, ng), t0 + dt * u}, tube_tangents(axis, ng, radius, dt)};
}

// ---- Caps and joints: the flat free ends and round bends of shaded lines ------------

/// The largest coordinate of a disc (centre and radius).
float disc_extent(const Key& c) { return largest_coordinate(vec(c)) + c[3]; }

RTCGeometry build_caps(RTCDevice device, const GeometrySource& part)
{
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    share_keys(g, RTC_BUFFER_TYPE_VERTEX, part.ends->caps.data(), part.ends->caps.size());
    const std::vector<geom::Float3>& normals = part.ends->cap_normals;
    if (geom::padded_for_embree(normals))  // line_ends() leaves the room
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, normals.data(), 0,
                                   sizeof(geom::Float3), normals.size());
    else
        copy_buffer(g, RTC_BUFFER_TYPE_NORMAL, RTC_FORMAT_FLOAT3, normals);
    return g;
}

[[gnu::always_inline]] inline LocalSurface cap_surface(const GeometrySource& part,
                                                       std::uint32_t prim, float, float,
                                                       const Vec3f&)
{
    // the solid cylinder's end: its normal points out, like the tube's
    const Key& cap = part.ends->caps[prim];
    return {vec(part.ends->cap_normals[prim]), Vec3f(), cap[3], false, disc_extent(cap)};
}

/// The rim's t; s is the centre of the unrolled tube (one texel across the end).
TextureCoords cap_coords(const GeometrySource& part, std::uint32_t prim, float, float,
                         const Vec3f&)
{
    const geom::LinearCurves& l = part.geometry->lines;
    return {0.5f, line_t(l, l.segments[part.ends->cap_segment[prim]] +
                               part.ends->cap_at_end[prim])};
}

RTCGeometry build_joints(RTCDevice device, const GeometrySource& part)
{
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    share_keys(g, RTC_BUFFER_TYPE_VERTEX, part.ends->joints.data(), part.ends->joints.size());
    return g;
}

[[gnu::always_inline]] inline LocalSurface joint_surface(const GeometrySource& part,
                                                         std::uint32_t prim, float, float,
                                                         const Vec3f& ng)
{
    return {ng, Vec3f(), part.ends->joints[prim][3], false};
}

TextureCoords joint_coords(const GeometrySource& part, std::uint32_t prim, float, float,
                           const Vec3f&)
{
    const geom::LinearCurves& l = part.geometry->lines;
    return {0.5f, line_t(l, l.segments[part.ends->joint_segment[prim]] + 1)};
}

// ---- Curves: generalized cylinders as round Hermite segments ------------------------

RTCGeometry build_curves(RTCDevice device, const GeometrySource& part)
{
    const geom::HermiteCurves& c = part.geometry->curves;
    check_segments(c.segments, c.points.size(), "curve");
    check_size(c.tangents, c.points.size(), "curve tangents");
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_HERMITE_CURVE);
    share_keys(g, RTC_BUFFER_TYPE_VERTEX, c.points.data(), c.points.size());
    share_keys(g, RTC_BUFFER_TYPE_TANGENT, c.tangents.data(), c.tangents.size());
    share_segments(g, c.segments);
    set_flags(g, c.flags, c.segments.size());
    return g;
}

/// The direction of a Hermite segment's axis (its derivative) at u.
Vec3f hermite_axis(const geom::HermiteCurves& c, std::uint32_t k, float u)
{
    auto d = hermite_derivative(u);
    return vec(c.points[k]) * d[0] + vec(c.tangents[k]) * d[1] + vec(c.points[k + 1]) * d[2] +
           vec(c.tangents[k + 1]) * d[3];
}

[[gnu::always_inline]] inline LocalSurface curve_surface(const GeometrySource& part,
                                                         std::uint32_t prim, float u, float,
                                                         const Vec3f& ng)
{
    const geom::HermiteCurves& c = part.geometry->curves;
    std::uint32_t k = c.segments[prim];
    auto h = hermite(u);
    float radius = c.points[k][3] * h[0] + c.tangents[k][3] * h[1] + c.points[k + 1][3] * h[2] +
                   c.tangents[k + 1][3] * h[3];
    return {ng, Vec3f(), radius, false};
}

float curve_dv(const geom::HermiteCurves& c, std::uint32_t k)
{
    return c.v.size() == c.points.size() ? c.v[k + 1] - c.v[k] : 0.0f;
}

TextureCoords curve_coords(const GeometrySource& part, std::uint32_t prim, float u, float,
                           const Vec3f& ng)
{
    const geom::HermiteCurves& c = part.geometry->curves;
    std::uint32_t k = c.segments[prim];
    float t = c.v.size() == c.points.size() ? c.v[k] + curve_dv(c, k) * u : 0.0f;
    return {angle_around(hermite_axis(c, k, u), ng), t};
}

/// curve_coords and the tube's tangents, from one evaluation of the axis.
TextureFrame curve_frame(const GeometrySource& part, std::uint32_t prim, float u, float,
                         const Vec3f& ng, float radius)
{
    const geom::HermiteCurves& c = part.geometry->curves;
    std::uint32_t k = c.segments[prim];
    const bool keyed = c.v.size() == c.points.size();
    const float dv = keyed ? c.v[k + 1] - c.v[k] : 0.0f;
    const Vec3f axis = hermite_axis(c, k, u);
    return {{angle_around(axis, ng), keyed ? c.v[k] + dv * u : 0.0f},
            tube_tangents(axis, ng, radius, dv)};
}

// ---- Spheres (@O) -------------------------------------------------------------------

RTCGeometry build_spheres(RTCDevice device, const GeometrySource& part)
{
    const geom::Spheres& sp = part.geometry->spheres;
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    share_keys(g, RTC_BUFFER_TYPE_VERTEX, sp.centres.data(), sp.centres.size());
    return g;
}

[[gnu::always_inline]] inline LocalSurface sphere_surface(const GeometrySource& part,
                                                          std::uint32_t prim, float, float,
                                                          const Vec3f& ng)
{
    return {ng, Vec3f(), part.geometry->spheres.centres[prim][3], false};
}

/// s = longitude / 2 pi about z, t = latitude / pi + 1/2.
TextureCoords sphere_coords(const GeometrySource&, std::uint32_t, float, float, const Vec3f& ng)
{
    Vec3f n = normalize(ng);
    return {std::atan2(n.y, n.x) / (2 * pi) + 0.5f,
            std::asin(std::fmax(-1.0f, std::fmin(1.0f, n.z))) / pi + 0.5f};
}

TextureTangents sphere_tangents(const GeometrySource&, std::uint32_t, float, const Vec3f& ng,
                                float radius)
{
    Vec3f n = normalize(ng);
    float rxy = std::sqrt(n.x * n.x + n.y * n.y);
    if (rxy <= 0)
        return {Vec3f(), Vec3f()};
    Vec3f east(-n.y / rxy, n.x / rxy, 0), north(-n.z * n.x / rxy, -n.z * n.y / rxy, rxy);
    return {east * (2 * pi * radius * rxy), north * (pi * radius)};
}

// ---- Discs (@o, @c) -----------------------------------------------------------------

RTCGeometry build_discs(RTCDevice device, const GeometrySource& part)
{
    const geom::Discs& d = part.geometry->discs;
    check_size(d.normals, d.centres.size(), "disc normals");
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    share_keys(g, RTC_BUFFER_TYPE_VERTEX, d.centres.data(), d.centres.size());
    copy_buffer(g, RTC_BUFFER_TYPE_NORMAL, RTC_FORMAT_FLOAT3, d.normals);
    return g;
}

[[gnu::always_inline]] inline LocalSurface disc_surface(const GeometrySource& part,
                                                        std::uint32_t prim, float, float,
                                                        const Vec3f&)
{
    return {vec(part.geometry->discs.normals[prim]), Vec3f(), 0, true,
            disc_extent(part.geometry->discs.centres[prim])};
}

// ---- Triangles (polygons, surfaces, meshes) -----------------------------------------

RTCGeometry build_triangles(RTCDevice device, const GeometrySource& part)
{
    const geom::TriangleMesh& m = part.geometry->mesh;
    check_size(m.normals, m.positions.size(), "mesh normals");
    for (const auto& tri : m.triangles)
        for (std::uint32_t i : tri)
            if (i >= m.positions.size())
                throw Error("scene: triangle vertex " + std::to_string(i) + " of " +
                            std::to_string(m.positions.size()));
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Read in place where the Scene left room for Embree's 16-byte loads past the last
    // element (geom::fit_mesh_buffers), else copied.
    if (geom::padded_for_embree(m.positions))
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                   m.positions.data(), 0, sizeof(geom::Float3), m.positions.size());
    else
        copy_buffer(g, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, m.positions);
    if (geom::padded_for_embree(m.triangles))
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m.triangles.data(),
                                   0, sizeof(m.triangles[0]), m.triangles.size());
    else
        copy_buffer(g, RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3, m.triangles);
    return g;
}

[[gnu::always_inline]] inline LocalSurface triangle_surface(const GeometrySource& part,
                                                            std::uint32_t prim, float u, float v,
                                                            const Vec3f&)
{
    if (part.records) {
        const TriangleRecord& r = part.records[prim];
        return {r.face, r.normals[0] * (1 - u - v) + r.normals[1] * u + r.normals[2] * v, 0,
                true, r.extent};
    }
    const geom::TriangleMesh& m = part.geometry->mesh;
    const auto& tri = m.triangles[prim];
    Vec3f p0 = vec(m.positions[tri[0]]), p1 = vec(m.positions[tri[1]]),
          p2 = vec(m.positions[tri[2]]);
    Vec3f face = cross(p1 - p0, p2 - p0);
    Vec3f n0 = vec(m.normals[tri[0]]), n1 = vec(m.normals[tri[1]]), n2 = vec(m.normals[tri[2]]);
    // The front is where the vertex normals point; a flat face's winding if they vanish.
    if (dot(face, n0 + n1 + n2) < 0)
        face = -face;
    float extent =
        std::max({largest_coordinate(p0), largest_coordinate(p1), largest_coordinate(p2)});
    return {face, n0 * (1 - u - v) + n1 * u + n2 * v, 0, true, extent};
}

TextureCoords triangle_coords(const GeometrySource& part, std::uint32_t prim, float u, float v,
                              const Vec3f&)
{
    const geom::TriangleMesh& m = part.geometry->mesh;
    const auto& tri = m.triangles[prim];
    const auto& uv = m.uvs;
    if (uv.size() != m.positions.size())
        return {0, 0};
    float w = 1 - u - v;
    return {uv[tri[0]][0] * w + uv[tri[1]][0] * u + uv[tri[2]][0] * v,
            uv[tri[0]][1] * w + uv[tri[1]][1] * u + uv[tri[2]][1] * v};
}

TextureTangents triangle_tangents(const GeometrySource& part, std::uint32_t prim, float,
                                  const Vec3f&, float)
{
    const geom::TriangleMesh& m = part.geometry->mesh;
    const auto& tri = m.triangles[prim];
    if (m.uvs.size() != m.positions.size())
        return {Vec3f(), Vec3f()};
    Vec3f e1 = vec(m.positions[tri[1]]) - vec(m.positions[tri[0]]);
    Vec3f e2 = vec(m.positions[tri[2]]) - vec(m.positions[tri[0]]);
    const geom::Float2 &uv0 = m.uvs[tri[0]], &uv1 = m.uvs[tri[1]], &uv2 = m.uvs[tri[2]];
    float s1 = uv1[0] - uv0[0], t1 = uv1[1] - uv0[1];
    float s2 = uv2[0] - uv0[0], t2 = uv2[1] - uv0[1];
    float det = s1 * t2 - s2 * t1;
    if (!(std::fabs(det) > 1e-20f))
        return {Vec3f(), Vec3f()};
    float inv = 1 / det;
    return {(e1 * t2 - e2 * t1) * inv, (e2 * s1 - e1 * s2) * inv};
}

// ---- The table ----------------------------------------------------------------------

// Spawn offsets, measured (accel_test): with the leaving primitive skipped, round shapes
// need no offset even at curve joints; a small one guards against float error at large
// coordinates. Flat shapes skip nothing: their offset is ~80 float ulps of the hit's
// largest coordinate or the primitive's (see EmbreeScene::intersect), which clears the
// error of Embree's hit distance at any angle (physics_test: a plane lit at grazing angles).
constexpr std::array<ShapeKind, 7> shape_kinds{{
    /* line */ {build_lines, line_coords, line_frame, 1e-3f, 1e-6f, 0, true},
    /* curve */ {build_curves, curve_coords, curve_frame, 1e-3f, 1e-6f, 0, true},
    /* sphere */ {build_spheres, sphere_coords, frame_of<sphere_coords, sphere_tangents>, 1e-4f,
                  1e-6f, 0, true},
    /* disc */ {build_discs, no_coords, frame_of<no_coords, no_tangents>, 0, 1e-5f, 1e-7f, false},
    /* triangle */ {build_triangles, triangle_coords, frame_of<triangle_coords, triangle_tangents>,
                    0, 1e-5f, 1e-7f, false},
    /* cap */ {build_caps, cap_coords, frame_of<cap_coords, no_tangents>, 1e-3f, 1e-5f, 1e-7f,
               false},
    /* joint */ {build_joints, joint_coords, frame_of<joint_coords, no_tangents>, 1e-3f, 1e-6f, 0,
                 true},
}};

const ShapeKind& kind(Shape s) { return shape_kinds[static_cast<std::size_t>(s)]; }

/// The hit's surface in object space from Embree's (u, v) and normal ng, by the part's
/// shape. A switch, not a ShapeKind entry: called for every hit, the shapes' functions
/// are inlined here, and their result is not returned through memory (reading it back
/// stalled on store forwarding); inlined, as are the shapes' functions (always_inline:
/// the compiler kept them calls).
[[gnu::always_inline]] inline LocalSurface local_surface(const GeometrySource& part,
                                                         std::uint32_t prim, float u, float v,
                                                         const Vec3f& ng)
{
    switch (part.shape) {
        case Shape::line: return line_surface(part, prim, u, v, ng);
        case Shape::curve: return curve_surface(part, prim, u, v, ng);
        case Shape::sphere: return sphere_surface(part, prim, u, v, ng);
        case Shape::disc: return disc_surface(part, prim, u, v, ng);
        case Shape::triangle: return triangle_surface(part, prim, u, v, ng);
        case Shape::cap: return cap_surface(part, prim, u, v, ng);
        case Shape::joint: return joint_surface(part, prim, u, v, ng);
    }
    return {ng, Vec3f(), 0, false};
}

/// The sources of a Geometry's primitives of each kind, attributes pointed at.
GeometrySource lines_source(const geom::Geometry& g, const Key* keys, bool unlit)
{
    const geom::LinearCurves& l = g.lines;
    return {Shape::line, &g, keys, unlit, nullptr, nullptr, &l.material, nullptr, &l.texture};
}

GeometrySource line_end_source(Shape shape, const geom::Geometry& g, const Key* keys,
                               const LineEnds& ends)
{
    GeometrySource s = lines_source(g, keys, false);
    s.shape = shape;
    s.ends = &ends;
    s.segment = shape == Shape::cap ? &ends.cap_segment : &ends.joint_segment;
    return s;
}

GeometrySource curves_source(const geom::Geometry& g)
{
    return {Shape::curve, &g, nullptr, false, nullptr, nullptr, &g.curves.material, nullptr,
            &g.curves.texture};
}

GeometrySource spheres_source(const geom::Geometry& g)
{
    return {Shape::sphere, &g, nullptr, false, nullptr, nullptr, &g.spheres.material, nullptr,
            &g.spheres.texture};
}

GeometrySource discs_source(const geom::Geometry& g)
{
    // Discs are never textured, not even by their instance.
    return {Shape::disc, &g, nullptr, false, nullptr, nullptr, &g.discs.material,
            &g.discs.back_material, nullptr};
}

GeometrySource triangles_source(const geom::Geometry& g)
{
    return {Shape::triangle, &g, nullptr, false, nullptr, nullptr, &g.mesh.material,
            &g.mesh.back_material, &g.mesh.texture};
}

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

}  // namespace

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

}  // namespace

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

/// How many primitives the part's Embree geometry holds.
std::size_t primitive_count(const GeometrySource& part)
{
    const geom::Geometry& g = *part.geometry;
    if (part.segment)  // caps and joints: one per entry
        return part.segment->size();
    switch (part.shape) {
    case Shape::line: return g.lines.segment_count();
    case Shape::curve: return g.curves.segment_count();
    case Shape::sphere: return g.spheres.size();
    case Shape::disc: return g.discs.size();
    case Shape::triangle: return g.mesh.size();
    case Shape::cap:
    case Shape::joint: break;  // (always with a segment)
    }
    return 0;
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

namespace {

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

}  // namespace

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
