// SPDX-License-Identifier: Apache-2.0
// Predefined surfaces `~x` (CPFG manual 5.4.3 `.s` files, 5.4.6 tsurfaces) as prototypes,
// and cpfg's rule for placing them at the turtle.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "geom/scene.h"
#include "geom/vec.h"
#include "geom/view_file.h"

namespace cambium::geom {

/// A patch's own colour indices (manual 5.4.3 `TOP COLOR:`, `BOTTOM COLOR:`): 0 means
/// the turtle's. cpfg's colormap-mode lighting uses them instead of the turtle's index,
/// relative to the selected colormap (so 256..511 lie in the next one); lighting by
/// materials ignores them.
struct PatchColours {
    int top = 0;     ///< the side the normal points to
    int bottom = 0;  ///< the other side
};

/// A predefined surface, ready to be instanced.
///
/// The prototype is in the *turtle frame* of the surface: its x, y, z axes are the
/// turtle's L, H, U at the instance, the origin is the contact point. cpfg builds it so
/// from the file: q = R · (p − contact) · scale / size with R's columns L_s = H_s × U_s,
/// H_s, U_s' = L_s × H_s (the file's heading and up, normalised). Its triangles carry
/// inherit_material (front and back) and the surface's fixed texture or no_texture;
/// uvs are cpfg's "texture per patch" (s, t of each patch).
struct SurfaceDef {
    std::string name;  ///< the file's stem ("leaf")
    char letter = 0;
    SurfaceCommand::Kind kind = SurfaceCommand::Kind::bicubic;
    Prototype prototype;
    /// Per vertex of prototype.geometry.mesh: cpfg's "texture per surface" uvs (x, y of
    /// the prototype mapped to [0,1] over its bounds), for textures with the `S:` flag.
    std::vector<Float2> uvs_per_surface;
    /// Per triangle of prototype.geometry.mesh: its patch's colours; empty when every
    /// patch takes the turtle's (bicubic surfaces only).
    std::vector<PatchColours> patch_colours;

    // As read from the file (bicubic only; a tsurface has zeros and heading +y, up +z).
    Vec3 contact_point, end_point;
    Vec3 heading{0, 1, 0}, up{0, 0, 1};
    double size = 1;   ///< SIZE:
    double scale = 1;  ///< from the view file
    int s_steps = 0, t_steps = 0;  ///< subdivision used
    std::optional<std::int16_t> texture;  ///< see SurfaceCommand::texture

    /// The end point in the prototype frame (cpfg's transformed end_point); the turtle
    /// moves there after `~x` (bicubic only: cpfg does not move for a tsurface).
    Vec3 local_end_point;
    bool moves_turtle = true;

    /// Points of the prototype frame that cpfg's view volume takes for an instance
    /// (viewVol.c): every patch's 16 control points for a bicubic surface, every
    /// triangle vertex for a tsurface. Scaled and placed as the prototype.
    std::vector<Vec3> hull_points;
};

/// Reads the command's file (relative names resolved against `base_dir`, the view
/// file's folder) with the `.s` or the tsurface reader. Missing file: Error.
SurfaceDef read_surface(const SurfaceCommand& command, const std::filesystem::path& base_dir);

/// The bicubic `.s` reader from text (tests); `file_name` is used in messages.
/// Limits: at most 4096 patches (cpfg: 64).
SurfaceDef parse_surface_text(std::string_view text, const std::string& file_name,
                              const SurfaceCommand& command);

/// (The tsurface reader, parse_tsurface_text, is in geom/tsurface.h.)

/// Every `surface:`, `tsurface:` and `line:` of the view file, read, in order. A file that
/// cannot be read or a letter used twice is a warning and the surface is skipped
/// (cpfg does the same); malformed contents are an Error.
std::vector<SurfaceDef> load_view_surfaces(const ViewFile& view);

/// The per-axis scale of `~x`, `~x(s)`, `~x(s, s2)`, `~x(sx, sy, sz)`: no parameter = 1,
/// one or two = uniform first, three or more = per axis; all times the turtle's scale.
Vec3 surface_scale(std::span<const float> parameters, double turtle_scale);

/// The instance transform of `~x` (3x4 column-major, as Instance::transform):
/// columns scale.x·L, scale.y·H, scale.z·U and the position, i.e.
/// world = position + sx·q.x·L + sy·q.y·H + sz·q.z·U for a prototype point q.
/// `scale` is surface_scale(...). The instance materials are the turtle's colour
/// (front) and back colour; its texture the def's fixed one or the turtle's.
std::array<float, 12> surface_instance_transform(const SurfaceDef& def, const Vec3& position,
                                                 const Vec3& heading, const Vec3& left,
                                                 const Vec3& up, const Vec3& scale);

/// Where the turtle is after `~x` (cpfg's determine_end_point): position +
/// scale_x · (e.x·L + e.y·H + e.z·U) with e = local_end_point (all axes use the first
/// scale component, as cpfg does); the position unchanged for a tsurface.
Vec3 surface_end_position(const SurfaceDef& def, const Vec3& position, const Vec3& heading,
                          const Vec3& left, const Vec3& up, double scale_x);

namespace detail {

/// A cursor over a data file's text, reading it as cpfg's fscanf calls do (blanks are
/// free, literals must match exactly), with line and column for messages. Shared by the
/// readers of this folder (surface, tsurface, function, background scene).
class TextCursor {
public:
    /// `first_line` / `first_column`: where `text` starts in the file (for messages).
    TextCursor(std::string_view text, std::string file_name, int first_line = 1,
               int first_column = 1);

    bool at_end();
    /// Skips blanks (space, tab, CR, LF) and returns whether `literal` follows there,
    /// consuming it if so.
    bool try_literal(std::string_view literal);
    /// try_literal or an Error "expected 'literal'".
    void expect(std::string_view literal, const char* context);
    /// A decimal number (strtod syntax, finite), or nullopt without consuming.
    std::optional<double> try_number();
    double number(const char* what);
    int integer(const char* what);
    /// The next run of non-blank characters (Error at the end of the text).
    std::string word(const char* what);
    /// The rest of the current line (without the newline), consumed.
    std::string_view rest_of_line();
    /// Skips blanks other than newlines; true when the line ends there.
    bool at_line_end();

    FileLoc loc() const;
    Error error(const std::string& message) const { return Error(loc(), message); }

private:
    void skip_blanks();
    void advance(std::size_t n);

    std::string_view m_text;
    std::string m_file;
    std::size_t m_pos = 0;
    int m_line = 1;
    int m_column = 1;
};

}  // namespace detail

}  // namespace cambium::geom
