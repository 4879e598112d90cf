// SPDX-License-Identifier: Apache-2.0
// Single-precision 3-vectors for the hot path (rays, normals, linear RGB radiance).
#pragma once

#include <algorithm>
#include <cmath>

#include "geom/vec.h"

namespace cambium::render {

/// A float 3-vector; used for points, directions and linear RGB alike.
struct Vec3f {
    float x = 0, y = 0, z = 0;

    constexpr Vec3f() = default;
    constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}
    explicit Vec3f(const geom::Vec3& v)
        : x(static_cast<float>(v.x)), y(static_cast<float>(v.y)), z(static_cast<float>(v.z))
    {
    }

    constexpr Vec3f operator+(const Vec3f& b) const { return {x + b.x, y + b.y, z + b.z}; }
    constexpr Vec3f operator-(const Vec3f& b) const { return {x - b.x, y - b.y, z - b.z}; }
    constexpr Vec3f operator-() const { return {-x, -y, -z}; }
    constexpr Vec3f operator*(const Vec3f& b) const { return {x * b.x, y * b.y, z * b.z}; }
    constexpr Vec3f operator*(float s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3f operator/(float s) const { return {x / s, y / s, z / s}; }
    Vec3f& operator+=(const Vec3f& b) { x += b.x; y += b.y; z += b.z; return *this; }
    Vec3f& operator*=(const Vec3f& b) { x *= b.x; y *= b.y; z *= b.z; return *this; }
    Vec3f& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
    constexpr bool operator==(const Vec3f&) const = default;
};

constexpr Vec3f operator*(float s, const Vec3f& v) { return v * s; }
constexpr float dot(const Vec3f& a, const Vec3f& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3f cross(const Vec3f& a, const Vec3f& b)
{
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const Vec3f& v) { return std::sqrt(dot(v, v)); }
/// Relative luminance of linear Rec. 709 RGB (the weights of ITU-R BT.709).
inline float luminance(const Vec3f& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
inline Vec3f normalize(const Vec3f& v)
{
    float l = length(v);
    return l > 0 ? v / l : v;
}
constexpr float max_component(const Vec3f& v) { return std::max(v.x, std::max(v.y, v.z)); }
constexpr bool is_black(const Vec3f& v) { return v.x == 0 && v.y == 0 && v.z == 0; }

/// Builds an orthonormal basis (t, b) around the unit vector n (Duff et al. 2017).
inline void make_basis(const Vec3f& n, Vec3f& t, Vec3f& b)
{
    float sign = std::copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float c = n.x * n.y * a;
    t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

}  // namespace cambium::render
