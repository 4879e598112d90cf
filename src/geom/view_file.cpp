// SPDX-License-Identifier: Apache-2.0
// The view file (.v, CPFG manual 5.2): every setting with cpfg's default.
#include "geom/view_file.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "geom/text_input.h"

namespace cambium::geom {
namespace {

/// Commands of manual 5.2 (and a few cpfg accepts that the manual omits) that are
/// parsed and kept for later stages, or that only concern cpfg's OpenGL window.
constexpr std::array deferred_commands = {
    "render mode", "shade mode", "z buffer", "cue range", "font", "winfont",
    "interpretation past %", "interpretation step", "rayshade objects", "rayshade scale",
    "antialiasing", "min zoom", "max zoom", "polygonization level", "contour",
    "contour sides", "surface", "line", "tsurface", "twist of cylinders",
    "background scene", "ambient light", "diffuse reflection", "surface ambient",
    "surface diffuse", "background color", "texture", "tropism direction",
    "initial elasticity", "elasticity increment", "tropism", "torque", "function",
    "function set", "concave polygons", "shadow map", "curve", "corner"};

bool parse_flag(ValueReader& in)
{
    std::string word = in.word("on or off");
    if (word == "on")
        return true;
    if (word == "off")
        return false;
    throw in.error("expected 'on' or 'off', found '" + word + "'");
}

Vec3 parse_vec3(ValueReader& in)
{
    double x = in.number(), y = in.number(), z = in.number();
    return {x, y, z};
}

Rgb parse_rgb(ValueReader& in)
{
    auto r = static_cast<float>(in.number());
    auto g = static_cast<float>(in.number());
    auto b = static_cast<float>(in.number());
    return {r, g, b};
}

/// `initial line width: x [pixels|p|shaded|s]` (the suffix is the pre-3.0 line style).
void parse_initial_line_width(ViewFile& v, ValueReader& in)
{
    v.initial_line_width = in.number();
    if (in.at_end()) {
        v.line_style = LineStyle::polygon;
        return;
    }
    std::string unit = in.word("a line style");
    if (unit == "pixels" || unit == "p" || unit == "pixel")
        v.line_style = LineStyle::pixel;
    else if (unit == "shaded" || unit == "s")
        v.line_style = LineStyle::cylinder;
    else
        throw in.error("expected 'pixels' or 'shaded' after the width, found '" + unit + "'");
}

LineStyle parse_line_style(ValueReader& in)
{
    std::string style = in.word("a line style");
    if (style == "pixel" || style == "pixels")
        return LineStyle::pixel;
    if (style == "polygon")
        return LineStyle::polygon;
    if (style == "cylinder")
        return LineStyle::cylinder;
    if (style == "wireframe") {
        warn(in.loc(), "line style 'wireframe' is drawn as 'pixel'");
        return LineStyle::pixel;
    }
    throw in.error("expected 'pixel', 'polygon' or 'cylinder', found '" + style + "'");
}

/// `box: x: xmin,xmax y: ymin,ymax z: zmin,zmax`
Bounds3 parse_box(ValueReader& in)
{
    Bounds3 box;
    for (char axis : {'x', 'y', 'z'}) {
        in.expect_label(std::string(1, axis));
        double lo = in.number(), hi = in.number();
        int i = axis - 'x';
        (i == 0 ? box.lo.x : i == 1 ? box.lo.y : box.lo.z) = std::min(lo, hi);
        (i == 0 ? box.hi.x : i == 1 ? box.hi.y : box.hi.z) = std::max(lo, hi);
    }
    return box;
}

/// `light: O: x y z | V: x y z | A: r g b | D: r g b | S: r g b | P: x y z e c | T: c l q`
Light parse_light(ValueReader& in)
{
    Light light;
    while (!in.at_end()) {
        char sub = in.subcommand("a light subcommand (O: V: A: D: S: P: T:)");
        switch (sub) {
        case 'O': light.position = parse_vec3(in); break;
        case 'V':
            light.kind = Light::Kind::directional;
            light.direction = parse_vec3(in);
            break;
        case 'A': light.ambient = parse_rgb(in); break;
        case 'D': light.diffuse = parse_rgb(in); break;
        case 'S': light.specular = parse_rgb(in); break;
        case 'P':
            light.kind = Light::Kind::spot;
            light.spot_direction = parse_vec3(in);
            light.spot_exponent = static_cast<float>(in.number());
            light.spot_cutoff_deg = static_cast<float>(in.number());
            break;
        case 'T':
            light.attenuation_constant = static_cast<float>(in.number());
            light.attenuation_linear = static_cast<float>(in.number());
            light.attenuation_quadratic = static_cast<float>(in.number());
            break;
        default: throw in.error(std::string("unknown light subcommand '") + sub + ":'");
        }
    }
    return light;
}

/// Applies one `name: value` command to the view file.
void apply_command(ViewFile& v, const std::string& name, ValueReader& in)
{
    if (name == "angle factor") {
        double factor = in.number();
        if (factor == 0)
            throw in.error("angle factor must not be 0");
        v.angle_increment_deg = 360.0 / factor;
    } else if (name == "angle increment") {
        v.angle_increment_deg = in.number();
    } else if (name == "initial color") {
        v.initial_color = in.integer();
        v.initial_back_color = in.at_end() ? v.initial_color : in.integer();
    } else if (name == "color increment") {
        v.color_increment = in.integer();
        v.back_color_increment = in.at_end() ? v.color_increment : in.integer();
    } else if (name == "initial line width") {
        parse_initial_line_width(v, in);
    } else if (name == "line width increment") {
        v.line_width_increment = in.number();
    } else if (name == "initial scale") {
        v.initial_scale = in.number();
    } else if (name == "scale multiplier") {
        v.scale_multiplier = in.number();
    } else if (name == "line style") {
        v.line_style = parse_line_style(in);
    } else if (name == "tapered lines" || name == "tappered lines") {
        v.tapered_lines = parse_flag(in);
    } else if (name == "viewpoint") {
        v.view.viewpoint = parse_vec3(in);
    } else if (name == "view reference point") {
        v.view.reference_point = parse_vec3(in);
    } else if (name == "twist") {
        v.view.twist_deg = in.number() / 10.0;  // tenths of degrees
    } else if (name == "projection") {
        std::string kind = in.word("'parallel' or 'perspective'");
        if (kind != "parallel" && kind != "perspective")
            throw in.error("expected 'parallel' or 'perspective', found '" + kind + "'");
        v.view.perspective = kind == "perspective";
    } else if (name == "viewing angle") {
        v.view.viewing_angle_deg = in.number();
    } else if (name == "front distance") {
        v.view.front_distance = in.number();
    } else if (name == "back distance") {
        v.view.back_distance = in.number();
    } else if (name == "scale factor") {
        v.view.scale_factor = in.number();
    } else if (name == "box") {
        v.view.box = parse_box(in);
    } else if (name == "light") {
        v.lights.push_back(parse_light(in));
    } else if (name == "light direction") {
        v.light_direction = parse_vec3(in);
    } else {
        return;  // handled by the caller
    }
    if (!in.at_end())
        warn(in.loc(), "extra text after '" + name + ":' ignored");
}

bool is_applied(const std::string& name)
{
    static const std::array applied = {
        "angle factor", "angle increment", "initial color", "color increment",
        "initial line width", "line width increment", "initial scale", "scale multiplier",
        "line style", "tapered lines", "tappered lines", "viewpoint", "view reference point",
        "twist", "projection", "viewing angle", "front distance", "back distance",
        "scale factor", "box", "light", "light direction"};
    return std::find(applied.begin(), applied.end(), name) != applied.end();
}

}  // namespace

ViewFile parse_view_file(std::string_view text, const std::string& file_name)
{
    ViewFile v;
    std::vector<SourceLine> lines = split_lines_without_comments(text);
    for (const SourceLine& line : lines) {
        std::string_view body = line.text;
        std::size_t first = body.find_first_not_of(" \t\r");
        if (first == std::string_view::npos)
            continue;
        FileLoc loc{file_name, line.number, static_cast<int>(first) + 1};
        std::size_t colon = body.find(':');
        if (colon == std::string_view::npos) {
            warn(loc, "view-file line without ':' ignored");
            continue;
        }
        std::string name = normalize_command_name(body.substr(0, colon));
        ValueReader in(body, colon + 1, FileLoc{file_name, line.number, 0});
        if (is_applied(name)) {
            apply_command(v, name, in);
        } else if (std::find(deferred_commands.begin(), deferred_commands.end(), name) !=
                   deferred_commands.end()) {
            v.deferred.push_back({name, std::string(body.substr(colon + 1)), loc});
        } else {
            warn(loc, "unknown view-file command '" + name + ":' ignored");
        }
    }
    return v;
}

ViewFile read_view_file(const std::filesystem::path& file)
{
    ViewFile v = parse_view_file(read_text_file(file, "view file"), file.string());
    v.path = file;
    return v;
}

}  // namespace cambium::geom
