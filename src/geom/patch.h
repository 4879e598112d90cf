// SPDX-License-Identifier: Apache-2.0
// Bicubic patches (Bézier, B-spline, cardinal): evaluation, tessellation, and the
// L-system defined patches of `@PS`, `@PC`, `@PD` (CPFG manual 5.1.9).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "base/diagnostics.h"
#include "geom/scene.h"
#include "geom/vec.h"

namespace cambium::geom {

/// The basis matrices of cpfg's patches, numbered as `@PS(i, basis)` numbers them.
enum class PatchBasis { bezier = 1, bspline = 2, cardinal = 3 };

/// Control points of one patch, row-major: control[4 * row + column]. The parameter s
/// runs along the rows (row 0 at s = 0, row 3 at s = 1), t along the columns.
using PatchControl = std::array<Vec3, 16>;

/// Finest subdivision cpfg allows along s or t (its S_COUNT / T_COUNT); coarser than 1
/// is raised to 1.
inline constexpr int max_patch_steps = 10;
/// cpfg's subdivision when none is given (S_COUNT / 2).
inline constexpr int default_patch_steps = 5;

/// The point x(s,t) = S·M·P·Mᵀ·Tᵀ of the patch, S = (s³, s², s, 1), T = (t³, t², t, 1).
Vec3 patch_point(PatchBasis basis, const PatchControl& control, double s, double t);

/// The partial derivatives ∂x/∂s and ∂x/∂t at (s, t).
Vec3 patch_ds(PatchBasis basis, const PatchControl& control, double s, double t);
Vec3 patch_dt(PatchBasis basis, const PatchControl& control, double s, double t);

/// A patch sampled on a (s_steps + 1) x (t_steps + 1) grid of vertices with cpfg's
/// vertex normals: n = ∂x/∂t × ∂x/∂s normalised ((0,1,0) where it vanishes), and at
/// the four corners cpfg's blend 0.5·n(corner) + n(neighbour along s) + n(neighbour
/// along t), normalised (cpfg does this so degenerate corners shade sensibly).
struct PatchGrid {
    int s_steps = 0;
    int t_steps = 0;
    std::vector<Vec3> positions;  ///< index s * (t_steps + 1) + t
    std::vector<Vec3> normals;    ///< same indexing, unit length

    std::size_t index(int s, int t) const
    {
        return static_cast<std::size_t>(s) * static_cast<std::size_t>(t_steps + 1) +
               static_cast<std::size_t>(t);
    }
};

/// Samples the patch at s = i / s_steps, t = j / t_steps. Steps are clamped to
/// [1, max_patch_steps].
PatchGrid sample_patch(PatchBasis basis, const PatchControl& control, int s_steps, int t_steps);

/// Appends the grid as 2 · s_steps · t_steps triangles to `out`: vertex normals from the
/// grid, uv = (s, t) in [0,1] (cpfg's "texture per patch"), every triangle wound
/// counter-clockwise seen from the side its normals point to (the front).
void append_patch_grid(const PatchGrid& grid, std::uint16_t material, std::uint16_t back_material,
                       std::int16_t texture, TriangleMesh& out);

/// sample_patch + append_patch_grid: 16 control points of `basis` into triangles.
void tessellate_patch(PatchBasis basis, const PatchControl& control, int s_steps, int t_steps,
                      std::uint16_t material, std::uint16_t back_material, std::int16_t texture,
                      TriangleMesh& out);

/// The L-system defined patches, keyed by the first parameter of @PS/@PC/@PD, as cpfg
/// keeps them (patches persist through the whole interpretation; a new @PS resets one).
/// The interpreter owns one per interpretation pass and calls:
///   `@PS(i)` / `@PS(i, basis)`  -> start(i, basis_parameter or 0)
///   `@PC(i, r, c)`              -> set_control_point(i, r, c, turtle.position, loc)
///   `@PD(i)` / `@PD(i, s, t)`   -> draw(i, s, t (0 when absent), turtle colour, back colour,
///                                       texture, scene.geometry.mesh, loc)
/// Control points are the turtle's world positions, so the triangles go straight into
/// the scene's mesh (no instance) with the turtle's materials.
class LsystemPatches {
public:
    /// `@PS(i, basis)`: all 16 points of patch `id` back to the origin and unassigned;
    /// basis 1, 2, 3 = Bézier, B-spline, cardinal; anything else (or 0) = Bézier.
    void start(double id, int basis);

    /// `@PC(i, r, c)`: control point (row, column) of patch `id` is `position`; creates
    /// the patch (Bézier) if no @PS named it. Rows and columns outside 0..3: a warning
    /// and nothing happens. Reassigning a point warns, as cpfg does.
    void set_control_point(double id, int row, int column, const Vec3& position, const FileLoc& loc);

    /// `@PD(i, s, t)`: appends the patch to `out` with s x t steps (0 = cpfg's default 5;
    /// clamped to 1..10). Returns false, with a warning, when the patch does not exist or
    /// some of its 16 points were never assigned (cpfg draws nothing then).
    bool draw(double id, int s_steps, int t_steps, std::uint16_t material,
              std::uint16_t back_material, std::int16_t texture, TriangleMesh& out,
              const FileLoc& loc) const;

    /// At most this many distinct patch ids (memory bound); more is an Error.
    static constexpr std::size_t max_patches = 1u << 16;

private:
    struct Patch {
        PatchBasis basis = PatchBasis::bezier;
        PatchControl control{};
        std::array<bool, 16> assigned{};
    };
    Patch& find_or_create(double id);
    std::map<double, Patch> m_patches;
};

}  // namespace cambium::geom
