// SPDX-License-Identifier: Apache-2.0
// The background scene (CPFG manual 5.4.10, view file `background scene:`): OpenGL-like
// statements read into plain geometry with its own materials.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "geom/scene.h"
#include "geom/view_file.h"

namespace cambium::geom {

/// Geometry in world coordinates whose material indices point into `materials`
/// (local indices, 0-based): the app appends `materials` to Scene::materials and
/// shifts the indices with offset_materials().
///
/// What each statement becomes (cpfg's background.c):
/// - polygon, polygonuv, rectangle a b [x0 y0 [emission]], mesh, box/prism a b c:
///   triangles in `geometry.mesh` (flat normals for polygon/rectangle/mesh/box, the
///   given ones for polygonuv); uvs are zero.
/// - sphere r: a sphere at the transformed origin with radius r, not scaled by the
///   matrix (cpfg draws it with the turtle's sphere at that point).
/// - cylinder r h, cone r1 r2 h: one round linear segment from the transformed origin
///   to the transformed (0, h, 0), radii unscaled, in `geometry.lines`, plus a disc
///   closing each end in `geometry.discs` (cpfg draws a turtle segment and two discs).
/// - material (up to 17 values: ambient rgba, diffuse rgba, specular rgba, emission
///   rgba, shininess): changes the current material from then on; fewer values change
///   only the groups given. The first material is `initial_material` (cpfg uses the
///   palette's entry 0). Transparency is 1 − diffuse alpha.
/// - loadidentity, loadmatrix (16 values, column-major), pushmatrix, popmatrix,
///   translate, rotate (degrees about an axis), scale, multmatrix: the current matrix,
///   as OpenGL's modelview (each right-multiplies).
/// A file with a line starting with '#' is run through cpp first (cpfg preprocesses
/// background files; lsys::preprocess, include path = the file's folder); line markers
/// and C comments are skipped.
struct BackgroundScene {
    Geometry geometry;
    std::vector<Material> materials;
};

/// Limits: 4 million primitives and 64 million numbers in all; matrix stack depth 1024.
inline constexpr std::size_t max_background_primitives = 4u << 20;
inline constexpr std::size_t max_background_numbers = 64u << 20;
inline constexpr std::size_t max_background_matrix_depth = 1024;

/// One statement of a background file: its keyword (lower-case as written) and the
/// numbers after it.
struct BackgroundStatement {
    std::string keyword;
    std::vector<double> numbers;
    FileLoc loc;
};

/// Splits one background file's text into statements, as cpfg reads it (a keyword, then
/// every number up to the next word). Unknown keywords warn and are dropped with their
/// numbers; a word that is neither keyword nor number where a keyword is expected is
/// the same. Limits (Error): max_background_primitives, max_background_numbers.
std::vector<BackgroundStatement> parse_background_text(std::string_view text,
                                                       const std::string& file_name);

/// Executes the statements of all files in order (one matrix and material state for
/// all of them, as cpfg). A primitive with too few numbers warns and is skipped (cpfg);
/// popmatrix on an empty stack warns; a matrix stack deeper than
/// max_background_matrix_depth is an Error.
BackgroundScene build_background_scene(const std::vector<BackgroundStatement>& statements,
                                       const Material& initial_material);

/// `background scene: list`: every file of the list (relative to `base_dir`), in order. A missing file is an Error. Files run through
/// cpp may #include only files inside `confine_to` when it is set (the model's folder,
/// docs/security.md); the listed files themselves are checked by the view's reader.
BackgroundScene read_background_scene(std::span<const std::filesystem::path> files,
                                      const std::filesystem::path& base_dir,
                                      const Material& initial_material, const FileLoc& loc,
                                      const std::optional<std::filesystem::path>& confine_to);

/// All `background scene:` commands of the view file (usually one), or an empty scene.
BackgroundScene load_view_background(const ViewFile& view, const Material& initial_material,
                                     const std::optional<std::filesystem::path>& confine_to);

/// Appends `from` to `into` (index arrays shifted; missing optional attributes of either
/// side filled with v = 0 / no_texture so the arrays stay parallel).
void append_geometry(Geometry& into, const Geometry& from);

/// Background cylinders and cones as smooth-shaded triangle frustums of `sides` sides (their
/// end discs stay discs), in place of `geometry.lines`: for a scene whose own lines are
/// pixel-width (`line style: pixel`), where every line of the Scene is read in pixels,
/// while a background object keeps its world size.
void cylinders_as_mesh(Geometry& geometry, int sides);

/// Adds `offset` to every material index of `geometry` (mesh, lines, curves, spheres,
/// discs), leaving inherit_material alone.
void offset_materials(Geometry& geometry, std::uint16_t offset);

}  // namespace cambium::geom
