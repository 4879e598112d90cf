// SPDX-License-Identifier: Apache-2.0
// The view file's drawing commands, each parsed once into ViewFile's typed settings.
#include "geom/view_drawing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string_view>

namespace cambium::geom {
namespace {

/// Commands that only concern cpfg's OpenGL window (depth buffer, fog, zoom limits,
/// its own lights and background...): accepted and left without effect.
constexpr std::array window_commands = {
    "z buffer", "cue range", "interpretation step", "antialiasing", "min zoom", "max zoom",
    "concave polygons", "shadow map", "corner", "ambient light", "background color"};

bool is_window_command(const std::string& name)
{
    return std::find(window_commands.begin(), window_commands.end(), name) != window_commands.end();
}

/// An integer in [lo, hi]; `what` names it in the error.
int bounded_integer(ValueReader& in, int lo, int hi, const std::string& what)
{
    FileLoc where = in.loc();
    double value = in.number();
    if (value != std::floor(value) || value < lo || value > hi)
        throw Error(where, what + " must be a whole number from " + std::to_string(lo) + " to " +
                               std::to_string(hi));
    return static_cast<int>(value);
}

/// `render mode:` (manual 5.2.3). `fast` is filled (cpfg's wireframe spheres aside);
/// `interpolated` and `shadows` are shaded, the former with its colour blending.
RenderMode parse_render_mode(ValueReader& in)
{
    FileLoc where = in.loc();
    std::string word = in.word("a render mode");
    if (word == "flat")
        return {Shading::flat, false};
    if (word == "filled" || word == "fast")
        return {Shading::filled, false};
    if (word == "wireframe")
        return {Shading::wireframe, false};
    if (word == "interpolated")
        return {Shading::shaded, true};
    if (word == "shaded" || word == "shadows")
        return {Shading::shaded, false};
    throw Error(where, "expected 'fast', 'filled', 'flat', 'shaded', 'interpolated', 'shadows' or "
                       "'wireframe', found '" + word + "'");
}

/// The older `shade mode:` numbers as cpfg converts them: 1 simple fill (filled), 2
/// interpolated fill, 3 Gouraud and 6 two-sided (shaded), 4 and 5 B-spline polygons and 7
/// wireframe (wireframe).
RenderMode parse_shade_mode(ValueReader& in)
{
    switch (bounded_integer(in, 1, 7, "shade mode")) {
    case 1: return {Shading::filled, false};
    case 2: return {Shading::shaded, true};
    case 4:
    case 5:
    case 7: return {Shading::wireframe, false};
    default: return {Shading::shaded, false};
    }
}

/// `contour: id file`.
ContourFile parse_contour(ValueReader& in)
{
    ContourFile c;
    c.loc = in.loc();
    c.id = bounded_integer(in, 1, 1 << 30, "a contour id (0 is the built-in circle)");
    c.file = in.name("the contour's file name");
    return c;
}

/// `surface: id file scale [s t] [tex]`, `line:` and `tsurface: id file scale`.
///
/// `line: id file size [s t [tex]]` defines a bicubic surface exactly as `surface:` does
/// (cpfg reads it with the same read_surface; `~id` draws it). cpfg also records the id
/// as its "line type", meant for drawing F segments as that surface, but that drawing is
/// disabled in cpfg (its segment code is commented out), so segments are not affected
/// here either. Unlike `surface:`, a single number after the size is not a texture:
/// cpfg reads precisions as a pair, then the texture; a lone number is ignored (with a
/// warning).
SurfaceCommand parse_surface(const std::string& name, ValueReader& in)
{
    SurfaceCommand sc;
    sc.loc = in.loc();
    sc.kind = name == "tsurface" ? SurfaceCommand::Kind::triangles : SurfaceCommand::Kind::bicubic;
    std::string id = in.name("the surface's letter");
    if (id.size() != 1)
        throw Error(sc.loc, name + ": the identifier must be one character, not '" + id + "'");
    sc.letter = id[0];
    sc.file = in.name("the surface's file name");
    sc.scale = in.number();
    std::vector<std::pair<int, FileLoc>> rest;
    while (!in.at_end()) {
        if (rest.size() == 3)
            throw in.error(name + ": too many values");
        FileLoc where = in.loc();
        rest.emplace_back(in.integer(), where);
    }
    if (sc.kind == SurfaceCommand::Kind::triangles) {
        if (!rest.empty())
            warn(rest.front().second, "tsurface: values after the scale ignored");
        return sc;
    }
    if (rest.size() >= 2) {
        sc.s_steps = rest[0].first;
        sc.t_steps = rest[1].first;
    }
    if (name == "line" && rest.size() == 1) {
        warn(rest.front().second, "line: a single number after the size is not read by cpfg (it "
                                  "reads 's t [texture]'); ignored");
        return sc;
    }
    if (rest.size() == 1 || rest.size() == 3) {
        auto [tex, where] = rest.back();
        if (tex < 0 || tex > 32767)
            throw Error(where, "surface texture index out of range: " + std::to_string(tex));
        sc.texture = tex == 0 ? no_texture : static_cast<std::int16_t>(tex - 1);
    }
    return sc;
}

/// `function: file [samples]` or `function set: file`.
FunctionFile parse_function(const std::string& name, ValueReader& in)
{
    FunctionFile f;
    f.loc = in.loc();
    f.file = in.name("a file name");
    f.is_set = name == "function set";
    if (!f.is_set && !in.at_end())
        f.samples = bounded_integer(in, 0, 1 << 30, "the number of samples");
    return f;
}

/// `curve: file [samples]`.
CurveFile parse_curve(ValueReader& in)
{
    CurveFile c;
    c.loc = in.loc();
    c.file = in.name("a file name");
    if (!in.at_end())
        c.samples = bounded_integer(in, 2, CurveFile::max_samples, "curve samples");
    return c;
}

/// `background scene: list`: file names separated by blanks, ',' or ';'.
BackgroundSceneFiles parse_background_scene(ValueReader& in)
{
    BackgroundSceneFiles scene;
    scene.loc = in.loc();
    std::istringstream list(in.rest());
    for (std::string item; std::getline(list, item, ';');) {
        ValueReader files(item, 0, scene.loc);
        while (!files.at_end())
            scene.files.emplace_back(files.name("a file name"));
    }
    if (scene.files.empty())
        throw Error(scene.loc, "background scene: expected a file name");
    return scene;
}

/// A positive whole number of pixels no font is bigger than, or nothing.
std::optional<int> font_size(const std::string& text, int divisor)
{
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || text.size() > 6)
        return std::nullopt;
    int size = std::stoi(text) / divisor;
    if (size < 1 || size > 512)
        return std::nullopt;
    return size;
}

/// An X font name: -foundry-family-weight-slant-setwidth-style-pixels-points-...
LabelFont x_font(const std::string& name)
{
    LabelFont font;
    std::vector<std::string> fields;  // "", foundry, family, weight, slant, setwidth, style, px, pt
    std::stringstream in(name);
    for (std::string field; std::getline(in, field, '-');)
        fields.push_back(field);
    auto field = [&](std::size_t i) { return i < fields.size() && fields[i] != "*" ? fields[i] : ""; };
    if (!field(2).empty())
        font.family = field(2);
    if (!field(3).empty())
        font.bold = field(3) == "bold" || field(3) == "demibold";
    if (!field(4).empty())
        font.italic = field(4) == "i" || field(4) == "o";
    if (std::optional<int> px = font_size(field(7), 1))
        font.pixel_size = *px;
    else if (std::optional<int> px = font_size(field(8), 10))
        font.pixel_size = *px;  // decipoints at X's 75 dpi are about pixels / 10
    return font;
}

/// `winfont: name size flags`, the name perhaps quoted.
LabelFont windows_font(const std::string& value)
{
    LabelFont font;
    std::istringstream in(value);
    std::string name, size, flags;
    in >> std::ws;
    if (in.peek() == '"')
        in >> std::quoted(name);
    else
        in >> name;
    in >> size >> flags;
    if (!name.empty())
        font.family = name;
    if (std::optional<int> px = font_size(size, 1))
        font.pixel_size = *px;
    font.bold = flags.find_first_of("bB") != std::string::npos;
    font.italic = flags.find_first_of("iI") != std::string::npos;
    return font;
}

/// Whether `format` is text around exactly one printf conversion of a double: flags,
/// width and precision of at most two digits each, conversion e E f F g G (an `l` may
/// precede it, as in cpfg's "%lg"). Anything else must not reach snprintf.
bool is_float_format(const std::string& format)
{
    std::size_t percent = format.find('%');
    if (percent == std::string::npos || format.find('%', percent + 1) != std::string::npos)
        return false;
    std::size_t i = format.find_first_not_of("-+ #0", percent + 1);
    auto digits = [&](std::size_t& at) {
        std::size_t start = at;
        while (at < format.size() && at - start < 3 && format[at] >= '0' && format[at] <= '9')
            ++at;
        return at - start <= 2;
    };
    if (i == std::string::npos || !digits(i))
        return false;
    if (i < format.size() && format[i] == '.' && !digits(++i))
        return false;
    if (i < format.size() && format[i] == 'l')
        ++i;
    return i < format.size() && std::string_view("eEfFgG").find(format[i]) != std::string_view::npos;
}

/// `rayshade objects: format [turtle considered]`: tokens split at blanks and colons,
/// as cpfg's rsReadViewCommand does.
ObjectKeying parse_object_keying(ValueReader& in)
{
    FileLoc where = in.loc();
    std::string text = in.rest();
    std::replace(text.begin(), text.end(), ':', ' ');
    std::istringstream words(text);
    ObjectKeying keying;
    std::string word, flag;
    words >> keying.format;
    if (!is_float_format(keying.format))
        throw Error(where, "rayshade objects: '" + keying.format +
                               "' is not a printf format of one number (such as %g)");
    if (words >> word >> flag && word == "turtle" && flag.starts_with("considered"))
        keying.turtle_considered = true;
    return keying;
}

double positive_number(ValueReader& in, const std::string& what)
{
    FileLoc where = in.loc();
    double value = in.number();
    if (!(value > 0))
        throw Error(where, what + " must be a positive number");
    return value;
}

/// The commands of the generalized cylinders (manual 5.2.4).
bool apply_cylinder_command(CylinderCommands& c, const std::string& name, ValueReader& in)
{
    if (name == "contour sides")
        c.sides = bounded_integer(in, 3, CylinderCommands::max_contour_sides, "contour sides");
    else if (name == "polygonization level")  // cpfg: 2^(n+1) polygons around
        c.sides = 1 << (bounded_integer(in, 1, CylinderCommands::max_polygonization_level,
                                        "polygonization level") + 1);
    else if (name == "twist of cylinders")
        c.keep_twist = in.on_off();
    else if (name == "contour")
        c.contours.push_back(parse_contour(in));
    else
        return false;
    return true;
}

/// A number, the error naming the command `name` (a coefficient's name says more than
/// its column).
double named_number(ValueReader& in, const std::string& name)
{
    FileLoc where = in.loc();
    try {
        return in.number();
    } catch (const Error&) {
        throw Error(where, name + ": expected a number");
    }
}

/// cpfg's colormap-mode lighting (manual 5.2.5).
bool apply_colour_index_command(ColourIndexShading& s, const std::string& name, ValueReader& in)
{
    if (name == "diffuse reflection")
        // Beyond the 256 colour indices a shift means nothing; bounded, as the ramps it
        // sizes must be.
        s.diffuse_reflection = static_cast<int>(std::clamp(named_number(in, name), -255.0, 255.0));
    else if (name == "surface ambient")
        s.surface_ambient = static_cast<float>(named_number(in, name));
    else if (name == "surface diffuse")
        s.surface_diffuse = static_cast<float>(named_number(in, name));
    else
        return false;
    return true;
}

/// Commands naming the files of surfaces, functions, curves and background scenes.
bool apply_file_command(ViewFile& v, const std::string& name, ValueReader& in)
{
    if (name == "surface" || name == "tsurface" || name == "line")
        v.surfaces.push_back(parse_surface(name, in));
    else if (name == "function" || name == "function set")
        v.functions.push_back(parse_function(name, in));
    else if (name == "curve")
        v.curves.push_back(parse_curve(in));
    else if (name == "background scene")
        v.background_scenes.push_back(parse_background_scene(in));
    else
        return false;
    return true;
}

}  // namespace

bool is_drawing_command(const std::string& name)
{
    static const std::array drawing = {
        "render mode", "shade mode", "interpretation past %", "contour sides",
        "polygonization level", "twist of cylinders", "contour", "surface", "tsurface", "line",
        "function", "function set", "curve", "background scene", "font", "winfont",
        "diffuse reflection", "surface ambient", "surface diffuse", "rayshade scale",
        "rayshade objects"};
    return is_window_command(name) || std::find(drawing.begin(), drawing.end(), name) != drawing.end();
}

void apply_drawing_command(ViewFile& v, const std::string& name, ValueReader& in)
{
    if (name == "render mode")
        v.render_mode = parse_render_mode(in);
    else if (name == "shade mode")
        v.render_mode = parse_shade_mode(in);
    else if (name == "interpretation past %")
        v.interprets_past_cut = in.on_off();
    else if (name == "font")
        v.font = x_font(in.name("an X font name"));
    else if (name == "winfont")
        v.font = windows_font(in.at_end() ? throw in.error("expected a font name") : in.rest());
    else if (name == "rayshade scale")
        v.rayshade_scale = positive_number(in, "rayshade scale");
    else if (name == "rayshade objects")
        v.rayshade_objects = parse_object_keying(in);
    else if (is_window_command(name))
        in.rest();  // no effect on a path-traced image
    else if (!apply_cylinder_command(v.cylinders, name, in) &&
             !apply_colour_index_command(v.colour_index_shading, name, in))
        apply_file_command(v, name, in);
}

}  // namespace cambium::geom
