// SPDX-License-Identifier: Apache-2.0
// What every user of a Geometry's primitives shares, whatever their kind: how many there
// are, and how an instance's transform places a point of its prototype.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geom/scene.h"
#include "geom/vec.h"

namespace cambium::geom {

/// The arrays of a Geometry, one per kind of primitive.
enum class PrimitiveKind : std::uint8_t { lines, curves, spheres, discs, mesh };

/// Provenance: the module entries of a Geometry's primitives of one kind.
inline const std::vector<std::uint32_t>& modules_of(const Geometry& g, PrimitiveKind k)
{
    switch (k) {
    case PrimitiveKind::lines: return g.lines.module;
    case PrimitiveKind::curves: return g.curves.module;
    case PrimitiveKind::spheres: return g.spheres.module;
    case PrimitiveKind::discs: return g.discs.module;
    default: return g.mesh.module;
    }
}

inline constexpr std::array<PrimitiveKind, 5> primitive_kinds{
    PrimitiveKind::lines, PrimitiveKind::curves, PrimitiveKind::spheres, PrimitiveKind::discs,
    PrimitiveKind::mesh};

/// The primitives `g` draws of one kind.
inline std::size_t primitive_count(const Geometry& g, PrimitiveKind k)
{
    switch (k) {
    case PrimitiveKind::lines: return g.lines.segment_count();
    case PrimitiveKind::curves: return g.curves.segment_count();
    case PrimitiveKind::spheres: return g.spheres.size();
    case PrimitiveKind::discs: return g.discs.size();
    default: return g.mesh.size();
    }
}

/// The primitives `g` draws, every kind together.
inline std::size_t primitive_count(const Geometry& g)
{
    std::size_t n = 0;
    for (PrimitiveKind k : primitive_kinds)
        n += primitive_count(g, k);
    return n;
}

/// An instance's placement x' = A x + t: Instance::transform read as its 3x4 column-major
/// matrix (columns: the images of the x, y, z axes, then the translation).
class Affine3x4 {
public:
    explicit Affine3x4(const std::array<float, 12>& m) : m(m) {}

    /// In float, as Embree places a prototype's points.
    Float3 apply(const Float3& p) const
    {
        return {m[0] * p[0] + m[3] * p[1] + m[6] * p[2] + m[9],
                m[1] * p[0] + m[4] * p[1] + m[7] * p[2] + m[10],
                m[2] * p[0] + m[5] * p[1] + m[8] * p[2] + m[11]};
    }
    /// In double.
    Vec3 apply(const Vec3& p) const { return linear(p) + Vec3{m[9], m[10], m[11]}; }
    /// A direction: the linear part alone, in float.
    Float3 linear(const Float3& v) const
    {
        return {m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
                m[2] * v[0] + m[5] * v[1] + m[8] * v[2]};
    }
    /// A direction, in double.
    Vec3 linear(const Vec3& v) const
    {
        return {m[0] * v.x + m[3] * v.y + m[6] * v.z, m[1] * v.x + m[4] * v.y + m[7] * v.z,
                m[2] * v.x + m[5] * v.y + m[8] * v.z};
    }
    /// The linear part's determinant, in double (its sign says whether it mirrors).
    double determinant() const
    {
        return double(m[0]) * (double(m[4]) * m[8] - double(m[7]) * m[5]) -
               double(m[3]) * (double(m[1]) * m[8] - double(m[7]) * m[2]) +
               double(m[6]) * (double(m[1]) * m[5] - double(m[4]) * m[2]);
    }

private:
    const std::array<float, 12>& m;
};

}  // namespace cambium::geom
