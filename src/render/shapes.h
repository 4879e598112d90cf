// SPDX-License-Identifier: Apache-2.0
// Everything render does that depends on the kind of primitive: the ShapeKind table (how
// Embree builds a shape, its texture coordinates, its spawn offsets, its self-hit filter,
// its emission as an area light) and the per-hit surface functions, inlined into accel's
// hit code. A new kind of primitive is one row here and one case in local_surface().
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/line_geometry.h"
#include "render/vecf.h"

namespace cambium::render {

using Key = std::array<float, 4>;

inline Vec3f vec(const geom::Float3& a) { return {a[0], a[1], a[2]}; }
inline Vec3f vec(const geom::Float4& a) { return {a[0], a[1], a[2]}; }

/// The largest magnitude among p's coordinates. std::max, not std::fmax: for numbers they
/// agree, and fmax's NaN rule keeps the compiler from inlining it (a libm call per use).
inline float largest_coordinate(const Vec3f& p)
{
    return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
}

/// The Hermite basis at u: weights of p0, t0, p1, t1.
inline std::array<float, 4> hermite(float u)
{
    float u2 = u * u, u3 = u2 * u;
    return {2 * u3 - 3 * u2 + 1, u3 - 2 * u2 + u, -2 * u3 + 3 * u2, u3 - u2};
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

/// An emissive primitive as next-event estimation samples it, in its geometry's space.
struct Emitter {
    enum class Form : std::uint8_t { triangle, disc, sphere, cylinder };
    Form form = Form::triangle;
    Vec3f a, b, c;     ///< triangle corners; a = centre (disc, sphere) or start and b = end (cylinder)
    Vec3f normal;      ///< unit front normal (triangle, disc); cylinder: axis
    float radius = 0;  ///< disc, sphere, cylinder
    float area = 0;
    float side = 1;    ///< triangle: -1 where the front is against the winding
};

/// Everything render does that depends on the kind of primitive (accel's Embree geometry
/// and hits, the area lights' emitters): one entry per Shape in `shape_kinds`, so a new
/// kind of primitive is added in one place (and a case in local_surface(), which every
/// hit calls).
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
    /// Area lights (AreaLights): the part holding a geometry's primitives of the shape,
    /// for `emitter` (null with it: the shape's emission is found by BSDF sampling alone).
    GeometrySource (*emitting_part)(const geom::Geometry& g);
    /// Primitive `prim` as a light in its geometry's space; false where it cannot be
    /// sampled (a bad index, no area, a tapered line).
    bool (*emitter)(const GeometrySource& part, std::uint32_t prim, Emitter& out);
    /// Instanced, listed only under similarity transforms: Embree draws the shape as an
    /// ellipsoid or ellipse otherwise, which the lights do not sample.
    bool similarity_only;
};

/// The shapes area lights list, in the order they are listed (which sampling sees).
inline constexpr std::array<Shape, 4> emitting_shapes{Shape::triangle, Shape::disc, Shape::line,
                                                      Shape::sphere};

[[gnu::always_inline]] inline LocalSurface line_surface(const GeometrySource& part,
                                                        std::uint32_t prim, float u, float,
                                                        const Vec3f& ng)
{
    const geom::LinearCurves& l = part.geometry->lines;
    const Key& k0 = part.line_keys[l.segments[prim]];
    const Key& k1 = part.line_keys[l.segments[prim] + 1];
    return {ng, Vec3f(), k0[3] + (k1[3] - k0[3]) * u, false};
}

/// The largest coordinate of a disc (centre and radius).
inline float disc_extent(const Key& c) { return largest_coordinate(vec(c)) + c[3]; }

[[gnu::always_inline]] inline LocalSurface cap_surface(const GeometrySource& part,
                                                       std::uint32_t prim, float, float,
                                                       const Vec3f&)
{
    // the solid cylinder's end: its normal points out, like the tube's
    const Key& cap = part.ends->caps[prim];
    return {vec(part.ends->cap_normals[prim]), Vec3f(), cap[3], false, disc_extent(cap)};
}

[[gnu::always_inline]] inline LocalSurface joint_surface(const GeometrySource& part,
                                                         std::uint32_t prim, float, float,
                                                         const Vec3f& ng)
{
    return {ng, Vec3f(), part.ends->joints[prim][3], false};
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

[[gnu::always_inline]] inline LocalSurface sphere_surface(const GeometrySource& part,
                                                          std::uint32_t prim, float, float,
                                                          const Vec3f& ng)
{
    return {ng, Vec3f(), part.geometry->spheres.centres[prim][3], false};
}

[[gnu::always_inline]] inline LocalSurface disc_surface(const GeometrySource& part,
                                                        std::uint32_t prim, float, float,
                                                        const Vec3f&)
{
    return {vec(part.geometry->discs.normals[prim]), Vec3f(), 0, true,
            disc_extent(part.geometry->discs.centres[prim])};
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

/// One row per Shape, in its order (shapes.cpp).
extern const std::array<ShapeKind, 7> shape_kinds;

inline const ShapeKind& kind(Shape s) { return shape_kinds[static_cast<std::size_t>(s)]; }

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
GeometrySource lines_source(const geom::Geometry& g, const Key* keys, bool unlit);
GeometrySource line_end_source(Shape shape, const geom::Geometry& g, const Key* keys,
                               const LineEnds& ends);
GeometrySource curves_source(const geom::Geometry& g);
GeometrySource spheres_source(const geom::Geometry& g);
GeometrySource discs_source(const geom::Geometry& g);
GeometrySource triangles_source(const geom::Geometry& g);

/// How many primitives the part's Embree geometry holds.
std::size_t primitive_count(const GeometrySource& part);

}  // namespace cambium::render
