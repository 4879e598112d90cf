// SPDX-License-Identifier: Apache-2.0
// The view file (.v, CPFG manual 5.2): every setting with cpfg's default.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "geom/scene.h"
#include "geom/tropism.h"

namespace cambium::geom {

/// How F and G are drawn (`line style:`, or the suffix of `initial line width:`).
enum class LineStyle { pixel, polygon, cylinder };

/// A view-file command that Cambium reads but does not use yet, kept with its
/// location so later stages can find it.
struct ViewCommand {
    std::string name;   ///< lower-case, without the colon: "contour", "tropism"...
    std::string value;  ///< the text after the colon, comments removed
    FileLoc loc;
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

    /// Recognised commands whose meaning is implemented later (surfaces, tropisms...).
    std::vector<ViewCommand> deferred;
};

/// Reads a view file. Unknown commands are a warning naming file and line (as in
/// cpfg); malformed values of known commands are errors naming line and column, each
/// reported (ErrorList) and the reading going on at the next line, thrown together
/// at the end.
ViewFile read_view_file(const std::filesystem::path& file);

/// The same from text (tests); `file_name` is used in messages.
ViewFile parse_view_file(std::string_view text, const std::string& file_name);

/// The view file's `render mode:` or `shade mode:` (the last one given), as a path
/// tracer draws it (geom::Shading).
Shading render_mode(const ViewFile& view);

}  // namespace cambium::geom
