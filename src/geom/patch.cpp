// SPDX-License-Identifier: Apache-2.0
// Bicubic patches: evaluation with cpfg's basis matrices, tessellation, @PS/@PC/@PD.
#include "geom/patch.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace cambium::geom {

namespace {

using Matrix4 = std::array<std::array<double, 4>, 4>;

// The basis matrices M of x(s,t) = S·M·P·Mᵀ·Tᵀ, as cpfg's patches.c defines them.
constexpr Matrix4 bezier_matrix{{{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 3, 0, 0}, {1, 0, 0, 0}}};
constexpr Matrix4 bspline_matrix{{{-1.0 / 6, 3.0 / 6, -3.0 / 6, 1.0 / 6},
                                  {3.0 / 6, -6.0 / 6, 3.0 / 6, 0},
                                  {-3.0 / 6, 0, 3.0 / 6, 0},
                                  {1.0 / 6, 4.0 / 6, 1.0 / 6, 0}}};
constexpr Matrix4 cardinal_matrix{
    {{-0.5, 1.5, -1.5, 0.5}, {1.0, -2.5, 2.0, -0.5}, {-0.5, 0.0, 0.5, 0.0}, {0.0, 1.0, 0.0, 0.0}}};

const Matrix4& basis_matrix(PatchBasis basis)
{
    switch (basis) {
    case PatchBasis::bspline: return bspline_matrix;
    case PatchBasis::cardinal: return cardinal_matrix;
    case PatchBasis::bezier: break;
    }
    return bezier_matrix;
}

// Weights w_i = Σ_k S_k M[k][i] for the power vector S (or its derivative).
std::array<double, 4> weights(const Matrix4& m, const std::array<double, 4>& power)
{
    std::array<double, 4> w{};
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 4; ++k)
            w[i] += power[k] * m[k][i];
    return w;
}

std::array<double, 4> powers(double u) { return {u * u * u, u * u, u, 1}; }
std::array<double, 4> power_derivatives(double u) { return {3 * u * u, 2 * u, 1, 0}; }

Vec3 combine(const PatchControl& control, const std::array<double, 4>& ws,
             const std::array<double, 4>& wt)
{
    Vec3 sum;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            sum += control[static_cast<std::size_t>(4 * i + j)] * (ws[i] * wt[j]);
    return sum;
}

int clamp_steps(int steps) { return std::clamp(steps, 1, max_patch_steps); }

// cpfg's vertex normal: ∂x/∂t × ∂x/∂s, (0,1,0) when degenerate.
Vec3 vertex_normal(const Vec3& dt, const Vec3& ds)
{
    Vec3 n = cross(dt, ds);
    double l = length(n);
    return l == 0 ? Vec3{0, 1, 0} : n / l;
}

// cpfg softens each corner normal with its two grid neighbours (calculate_surface),
// in this order, each using the values already updated.
void blend_corner_normals(PatchGrid& g)
{
    const int S = g.s_steps, T = g.t_steps;
    auto blend = [&](int s, int t, int s1, int t1, int s2, int t2) {
        Vec3& n = g.normals[g.index(s, t)];
        n = normalize(n * 0.5 + g.normals[g.index(s1, t1)] + g.normals[g.index(s2, t2)]);
    };
    blend(0, 0, 0, 1, 1, 0);
    blend(S, 0, S, 1, S - 1, 0);
    blend(S, T, S, T - 1, S - 1, T);
    blend(0, T, 0, T - 1, 1, T);
}

Float3 to_float3(const Vec3& v)
{
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

}  // namespace

Vec3 patch_point(PatchBasis basis, const PatchControl& control, double s, double t)
{
    const Matrix4& m = basis_matrix(basis);
    return combine(control, weights(m, powers(s)), weights(m, powers(t)));
}

Vec3 patch_ds(PatchBasis basis, const PatchControl& control, double s, double t)
{
    const Matrix4& m = basis_matrix(basis);
    return combine(control, weights(m, power_derivatives(s)), weights(m, powers(t)));
}

Vec3 patch_dt(PatchBasis basis, const PatchControl& control, double s, double t)
{
    const Matrix4& m = basis_matrix(basis);
    return combine(control, weights(m, powers(s)), weights(m, power_derivatives(t)));
}

PatchGrid sample_patch(PatchBasis basis, const PatchControl& control, int s_steps, int t_steps)
{
    PatchGrid g;
    g.s_steps = clamp_steps(s_steps);
    g.t_steps = clamp_steps(t_steps);
    const std::size_t count = static_cast<std::size_t>(g.s_steps + 1) * (g.t_steps + 1);
    g.positions.resize(count);
    g.normals.resize(count);
    for (int i = 0; i <= g.s_steps; ++i) {
        double s = static_cast<double>(i) / g.s_steps;
        for (int j = 0; j <= g.t_steps; ++j) {
            double t = static_cast<double>(j) / g.t_steps;
            g.positions[g.index(i, j)] = patch_point(basis, control, s, t);
            g.normals[g.index(i, j)] =
                vertex_normal(patch_dt(basis, control, s, t), patch_ds(basis, control, s, t));
        }
    }
    blend_corner_normals(g);
    return g;
}

void append_patch_grid(const PatchGrid& g, std::uint16_t material, std::uint16_t back_material,
                       std::int16_t texture, TriangleMesh& out)
{
    const auto base = static_cast<std::uint32_t>(out.positions.size());
    for (int i = 0; i <= g.s_steps; ++i) {
        for (int j = 0; j <= g.t_steps; ++j) {
            out.positions.push_back(to_float3(g.positions[g.index(i, j)]));
            out.normals.push_back(to_float3(g.normals[g.index(i, j)]));
            out.uvs.push_back({static_cast<float>(static_cast<double>(i) / g.s_steps),
                               static_cast<float>(static_cast<double>(j) / g.t_steps)});
        }
    }
    auto vertex = [&](int i, int j) { return base + static_cast<std::uint32_t>(g.index(i, j)); };
    // Going +t then +s turns counter-clockwise around n = ∂t × ∂s.
    for (int i = 0; i < g.s_steps; ++i) {
        for (int j = 0; j < g.t_steps; ++j) {
            out.triangles.push_back({vertex(i, j), vertex(i, j + 1), vertex(i + 1, j)});
            out.triangles.push_back({vertex(i, j + 1), vertex(i + 1, j + 1), vertex(i + 1, j)});
            for (int k = 0; k < 2; ++k) {
                out.material.push_back(material);
                out.back_material.push_back(back_material);
                out.texture.push_back(texture);
            }
        }
    }
}

void tessellate_patch(PatchBasis basis, const PatchControl& control, int s_steps, int t_steps,
                      std::uint16_t material, std::uint16_t back_material, std::int16_t texture,
                      TriangleMesh& out)
{
    append_patch_grid(sample_patch(basis, control, s_steps, t_steps), material, back_material,
                      texture, out);
}

LsystemPatches::Patch& LsystemPatches::find_or_create(double id)
{
    auto it = m_patches.find(id);
    if (it != m_patches.end())
        return it->second;
    if (m_patches.size() >= max_patches)
        throw Error("too many L-system defined patches (@PS/@PC): the limit is " +
                    std::to_string(max_patches));
    return m_patches[id];
}

void LsystemPatches::start(double id, int basis)
{
    Patch& p = find_or_create(id);
    p = Patch{};
    if (basis >= 1 && basis <= 3)
        p.basis = static_cast<PatchBasis>(basis);
}

void LsystemPatches::set_control_point(double id, int row, int column, const Vec3& position,
                                       const FileLoc& loc)
{
    if (row < 0 || row > 3 || column < 0 || column > 3) {
        warn(loc, "@PC: row and column must be 0..3; control point ignored");
        return;
    }
    Patch& p = find_or_create(id);
    auto k = static_cast<std::size_t>(4 * row + column);
    if (p.assigned[k])
        warn(loc, "@PC: control point " + std::to_string(row) + "," + std::to_string(column) +
                      " of patch " + std::to_string(id) + " reassigned");
    p.assigned[k] = true;
    p.control[k] = position;
}

bool LsystemPatches::draw(double id, int s_steps, int t_steps, std::uint16_t material,
                          std::uint16_t back_material, std::int16_t texture, TriangleMesh& out,
                          const FileLoc& loc) const
{
    auto it = m_patches.find(id);
    if (it == m_patches.end()) {
        warn(loc, "@PD: patch " + std::to_string(id) + " has no control points; not drawn");
        return false;
    }
    const Patch& p = it->second;
    if (!std::all_of(p.assigned.begin(), p.assigned.end(), [](bool a) { return a; })) {
        warn(loc, "@PD: patch " + std::to_string(id) + " has unassigned control points; not drawn");
        return false;
    }
    int s = s_steps > 0 ? s_steps : default_patch_steps;
    int t = t_steps > 0 ? t_steps : default_patch_steps;
    tessellate_patch(p.basis, p.control, s, t, material, back_material, texture, out);
    return true;
}

}  // namespace cambium::geom
