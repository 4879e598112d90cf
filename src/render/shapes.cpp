// SPDX-License-Identifier: Apache-2.0
// The ShapeKind table: each kind of primitive's Embree geometry, texture coordinates and
// spawn offsets (render/shapes.h).
#include "render/shapes.h"

#include <cstring>
#include <numbers>
#include <string>

#include "base/diagnostics.h"
#include "geom/scene_limits.h"
#include "render/tube_angle.h"

namespace cambium::render {
namespace {

constexpr float pi = std::numbers::pi_v<float>;

/// The derivatives of the Hermite basis at u.
std::array<float, 4> hermite_derivative(float u)
{
    float u2 = u * u;
    return {6 * u2 - 6 * u, 3 * u2 - 4 * u + 1, -6 * u2 + 6 * u, 3 * u2 - 2 * u};
}

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

// ---- Emitters: primitives as area lights ---------------------------------------------

bool triangle_emitter(const GeometrySource& part, std::uint32_t prim, Emitter& e)
{
    const geom::TriangleMesh& mesh = part.geometry->mesh;
    const auto& tri = mesh.triangles[prim];
    if (tri[0] >= mesh.positions.size() || tri[1] >= mesh.positions.size() ||
        tri[2] >= mesh.positions.size())
        return false;  // the Embree scene rejects such a mesh with a message
    Vec3f p0 = vec(mesh.positions[tri[0]]), p1 = vec(mesh.positions[tri[1]]),
          p2 = vec(mesh.positions[tri[2]]);
    // The front, as a hit decides it: where the vertex normals point, else the winding.
    Vec3f nsum;
    if (mesh.normals.size() == mesh.positions.size())
        nsum = vec(mesh.normals[tri[0]]) + vec(mesh.normals[tri[1]]) + vec(mesh.normals[tri[2]]);
    float side = dot(cross(p1 - p0, p2 - p0), nsum) < 0 ? -1.0f : 1.0f;
    e.form = Emitter::Form::triangle;
    e.a = p0;
    e.b = p1;
    e.c = p2;
    Vec3f face = cross(e.b - e.a, e.c - e.a);
    e.area = 0.5f * length(face);
    if (!(e.area > 0))
        return false;
    e.side = side;
    e.normal = normalize(face) * side;
    return true;
}

bool disc_emitter(const GeometrySource& part, std::uint32_t prim, Emitter& e)
{
    const geom::Discs& discs = part.geometry->discs;
    if (prim >= discs.normals.size())
        return false;
    e.form = Emitter::Form::disc;
    e.a = vec(discs.centres[prim]);
    e.radius = discs.centres[prim][3];
    e.normal = normalize(vec(discs.normals[prim]));
    e.area = pi * e.radius * e.radius;
    return e.area > 0 && length(e.normal) != 0;
}

/// A line segment of constant radius emits from its lateral surface; a cone (tapered
/// line) is not sampled, nor are the caps and joints.
bool line_emitter(const GeometrySource& part, std::uint32_t prim, Emitter& e)
{
    const geom::LinearCurves& segs = part.geometry->lines;
    std::uint32_t k = segs.segments[prim];
    if (std::size_t(k) + 1 >= segs.keys.size())
        return false;
    float r0 = segs.keys[k][3], r1 = segs.keys[k + 1][3];
    if (!(r0 > 0) || std::fabs(r0 - r1) > 1e-3f * std::max(r0, r1))
        return false;
    e.form = Emitter::Form::cylinder;
    e.a = vec(segs.keys[k]);
    e.b = vec(segs.keys[k + 1]);
    e.radius = 0.5f * (r0 + r1);
    e.area = 2 * pi * e.radius * length(e.b - e.a);
    if (!(e.area > 0))
        return false;
    e.normal = normalize(e.b - e.a);  // the axis
    return true;
}

bool sphere_emitter(const GeometrySource& part, std::uint32_t prim, Emitter& e)
{
    const geom::Spheres& spheres = part.geometry->spheres;
    e.form = Emitter::Form::sphere;
    e.a = vec(spheres.centres[prim]);
    e.radius = spheres.centres[prim][3];
    e.area = 4 * pi * e.radius * e.radius;
    return e.area > 0;
}

/// The lines as lights read the geometry's own keys (their radii in world units, since
/// pixel-width lines are never lights).
GeometrySource emitting_lines(const geom::Geometry& g) { return lines_source(g, nullptr, false); }

}  // namespace

// ---- The table ----------------------------------------------------------------------

// Spawn offsets, measured (accel_test): with the leaving primitive skipped, round shapes
// need no offset even at curve joints; a small one guards against float error at large
// coordinates. Flat shapes skip nothing: their offset is ~80 float ulps of the hit's
// largest coordinate or the primitive's (see EmbreeScene::intersect), which clears the
// error of Embree's hit distance at any angle (physics_test: a plane lit at grazing angles).
constexpr std::array<ShapeKind, 7> shape_kinds{{
    /* line */ {build_lines, line_coords, line_frame, 1e-3f, 1e-6f, 0, true, emitting_lines,
                line_emitter, true},
    /* curve */ {build_curves, curve_coords, curve_frame, 1e-3f, 1e-6f, 0, true, nullptr, nullptr,
                 false},
    /* sphere */ {build_spheres, sphere_coords, frame_of<sphere_coords, sphere_tangents>, 1e-4f,
                  1e-6f, 0, true, spheres_source, sphere_emitter, true},
    /* disc */ {build_discs, no_coords, frame_of<no_coords, no_tangents>, 0, 1e-5f, 1e-7f, false,
                discs_source, disc_emitter, true},
    /* triangle */ {build_triangles, triangle_coords, frame_of<triangle_coords, triangle_tangents>,
                    0, 1e-5f, 1e-7f, false, triangles_source, triangle_emitter, false},
    /* cap */ {build_caps, cap_coords, frame_of<cap_coords, no_tangents>, 1e-3f, 1e-5f, 1e-7f,
               false, nullptr, nullptr, false},
    /* joint */ {build_joints, joint_coords, frame_of<joint_coords, no_tangents>, 1e-3f, 1e-6f, 0,
                 true, nullptr, nullptr, false},
}};

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

}  // namespace cambium::render
