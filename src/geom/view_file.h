// SPDX-License-Identifier: Apache-2.0
// The view file (.v, CPFG manual 5.2): every setting with cpfg's default.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/diagnostics.h"
#include "geom/scene.h"
#include "geom/tropism.h"

namespace cambium::geom {

/// How F and G are drawn (`line style:`, or the suffix of `initial line width:`).
enum class LineStyle { pixel, polygon, cylinder };

/// `render mode:` or `shade mode:` (the last one given), as a path tracer draws it.
struct RenderMode {
    Shading shading = Shading::shaded;
    /// cpfg's interpolated fill (`render mode: interpolated`, `shade mode: 2`): shaded
    /// here, with colours blended along generalized cylinders and no lighting by
    /// colour index (cpfg draws it unlit).
    bool interpolated = false;
};

/// `contour: id file`: a contour (or, a Cambium extension, a gallery whose items take
/// the ids id, id + 1, ...) read when the generalized cylinders are set up.
struct ContourFile {
    int id = 0;                  ///< 1.. (0 is the built-in circle)
    std::filesystem::path file;  ///< as written (relative to the view file's folder)
    FileLoc loc;
};

/// The generalized cylinders' commands (manual 5.2.4).
struct CylinderCommands {
    /// `contour sides:` (3..max_contour_sides), or `polygonization level: n` as cpfg's
    /// 2^(n+1) polygons around; the last one given.
    int sides = 8;
    static constexpr int max_contour_sides = 100000;
    static constexpr int max_polygonization_level = 16;
    bool keep_twist = false;  ///< `twist of cylinders: on`
    std::vector<ContourFile> contours;
};

/// A view-file `surface: id file scale [s t] [tex]`, `line:` (the same) or
/// `tsurface: id file scale` command.
struct SurfaceCommand {
    enum class Kind { bicubic, triangles };
    Kind kind = Kind::bicubic;
    char letter = 0;
    std::filesystem::path file;  ///< as written (relative to the view file's folder)
    double scale = 1;            ///< the view file's size for the surface
    int s_steps = 0;             ///< 0: from the file's PRECISION line, else cpfg's default 5
    int t_steps = 0;
    /// The fixed texture: nullopt = the turtle's (`@Tx`), no_texture = none (tex 0),
    /// else an index into Scene::textures (the file's `tex` minus 1).
    std::optional<std::int16_t> texture;
    FileLoc loc;
};

/// `function: file [samples]` or `function set: file`, in the view file's order (a set
/// replaces the functions read before it, as cpfg's list restarts there).
struct FunctionFile {
    std::filesystem::path file;  ///< as written (relative to the view file's folder)
    int samples = 0;             ///< 0: the function's own
    bool is_set = false;         ///< `function set:`
    FileLoc loc;
};

/// `curve: file [samples]`.
struct CurveFile {
    static constexpr int default_samples = 100;
    static constexpr int max_samples = 1 << 20;
    std::filesystem::path file;  ///< as written (relative to the view file's folder)
    int samples = default_samples;  ///< 2..max_samples
    FileLoc loc;
};

/// `background scene: list`: its files (separated by blanks, ',' or ';').
struct BackgroundSceneFiles {
    std::vector<std::filesystem::path> files;  ///< as written (relative to the view file's folder)
    FileLoc loc;
};

/// cpfg's colormap-mode lighting (manual 5.2.5): how far a colour index moves with the
/// cosine to the light, and the surface rule's weights.
struct ColourIndexShading {
    int diffuse_reflection = 10;    ///< `diffuse reflection:`, -255..255
    float surface_ambient = 0.15f;  ///< `surface ambient:`
    float surface_diffuse = 0.75f;  ///< `surface diffuse:`
};

/// `rayshade objects: format [turtle considered]`: how `-o` objects are keyed by their
/// parameters (cpfg's rsReadViewCommand).
struct ObjectKeying {
    std::string format = "%g";  ///< a printf conversion of one float
    bool turtle_considered = false;
};

/// Cambium extension `translucency: FIRST [LAST] AMOUNT`: colour indices FIRST..LAST
/// (inclusive, 0..255) get Material::translucency = AMOUNT (0..1).
struct TranslucencySetting {
    int first = 0;
    int last = 0;
    float amount = 0;
    FileLoc loc;
};

/// The parsed view file. Defaults are cpfg's.
struct ViewFile {
    std::filesystem::path path;  ///< where it was read from (files it names are relative to it)

    // Turtle parameters (5.2.1)
    double angle_increment_deg = 45;
    double initial_line_width = 1;
    double line_width_increment = 0;
    LineStyle line_style = LineStyle::pixel;
    int initial_color = 128;
    int initial_back_color = 128;
    /// `initial color:` gave two indices: surfaces may have a different back colour
    /// (`@;`, `@,`); otherwise the back always has the front's colour (manual 5.1.9).
    bool separate_back_color = false;
    int color_increment = 1;
    int back_color_increment = 1;
    double initial_scale = 1;
    double scale_multiplier = 1;
    bool tapered_lines = true;

    // Tropisms (5.2.7): `tropism:` and `torque:` in order (@Ts/@Ti/@Td index them from 1)
    std::vector<Movement> movements;
    // The pre-3.0 tropism (`tropism direction:`, `initial elasticity:`), bent after
    // every move as cpfg's bend() does: normalised direction and elasticity.
    Vec3 legacy_tropism_direction{0, 1, 0};
    double legacy_elasticity = 0;
    double legacy_elasticity_increment = 0;

    // Textures (5.2.6): `texture:` in order; @Tx(i) selects textures[i-1].
    std::vector<TextureDef> textures;
    /// Per texture, `R:` (default 1): v along cylinders advances length / (pi width R).
    std::vector<double> texture_aspect_ratios;
    /// Per texture, `S:`: predefined surfaces map it once over the whole surface (its
    /// x, y extent) instead of once per patch (cpfg's default).
    std::vector<bool> texture_per_surface;

    /// Cambium's `translucency:` commands, in order (the caller applies them).
    std::vector<TranslucencySetting> translucency;

    // View (5.2.2) and lights (5.2.5, 5.2.6)
    View view;
    std::vector<Light> lights;     ///< `light:` commands, in order
    std::optional<Vec3> light_direction;  ///< colormap mode `light direction:`

    // Drawing (5.2.3, 5.2.4)
    RenderMode render_mode;
    /// `interpretation past %:` (5.2.3): whether the turtle goes on after a cut in the
    /// string (cpfg's default) or skips the rest of the cut branch.
    bool interprets_past_cut = true;
    CylinderCommands cylinders;
    /// `surface:`, `line:` and `tsurface:` in order.
    std::vector<SurfaceCommand> surfaces;
    std::vector<FunctionFile> functions;
    std::vector<CurveFile> curves;
    std::vector<BackgroundSceneFiles> background_scenes;
    /// The label font: the last `font:` (X font name -foundry-family-weight-slant-
    /// setwidth-style-pixels-points-...: family, `bold`, slant `i`/`o`, pixels, else
    /// points / 10) or `winfont:` (name, size in pixels, flags `b` `i`). Fields that
    /// are `*` or missing keep cpfg's default, courier bold 12 pixels.
    LabelFont font;
    ColourIndexShading colour_index_shading;
    double rayshade_scale = 1;  ///< `rayshade scale:`, > 0
    ObjectKeying rayshade_objects;
};

/// Reads a view file. Unknown commands are a warning naming file and line (as in
/// cpfg); malformed values of known commands are errors naming line and column, each
/// reported (ErrorList) and the reading going on at the next line, thrown together
/// at the end.
ViewFile read_view_file(const std::filesystem::path& file);

/// The same from text (tests); `file_name` is used in messages.
ViewFile parse_view_file(std::string_view text, const std::string& file_name);

/// The files the view file's commands name, textures aside (read_view_file makes those
/// absolute): contours, surfaces, functions, curves and background scenes, as their
/// readers find them (relative ones under the view file's folder), with their lines.
std::vector<std::pair<std::filesystem::path, FileLoc>> named_files(const ViewFile& view);

}  // namespace cambium::geom
