// SPDX-License-Identifier: Apache-2.0
// The view file (.v, CPFG manual 5.2): every setting with cpfg's default.
#include "geom/view_file.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "geom/scene_limits.h"
#include "geom/text_input.h"
#include "geom/view_drawing.h"

namespace cambium::geom {
namespace {

Vec3 parse_vec3(ValueReader& in)
{
    double x = in.number(), y = in.number(), z = in.number();
    return {x, y, z};
}

/// A position, distance or direction of the camera or a light: within max_coordinate,
/// so that no ray the renderer makes from it is beyond Embree's range.
double parse_coordinate(ValueReader& in)
{
    FileLoc where = in.loc();
    double v = in.number();
    if (!in_range(v)) {
        char text[32];
        std::snprintf(text, sizeof text, "%g", v);
        throw Error(where, std::string("value ") + text +
                               " is out of range: camera and light values must be within +-1e10");
    }
    return v;
}

Vec3 parse_position(ValueReader& in)
{
    double x = parse_coordinate(in), y = parse_coordinate(in), z = parse_coordinate(in);
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
        double lo = parse_coordinate(in), hi = parse_coordinate(in);
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
        case 'O': light.position = parse_position(in); break;
        case 'V':
            light.kind = Light::Kind::directional;
            light.direction = parse_position(in);
            break;
        case 'A': light.ambient = parse_rgb(in); break;
        case 'D': light.diffuse = parse_rgb(in); break;
        case 'S': light.specular = parse_rgb(in); break;
        case 'P':
            light.kind = Light::Kind::spot;
            light.spot_direction = parse_position(in);
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

/// `tropism: T: x y z [A: angle] [I: intensity] [E: elasticity] [S: step]`, and
/// `torque:` with the same subcommands (A: ignored). The direction is normalised and
/// scaled by clamp(I / |T|, -1, 1), as cpfg's read_movement does.
Movement parse_movement(ValueReader& in, Movement::Kind kind)
{
    Movement m;
    m.kind = kind;
    bool has_direction = false;
    double intensity = 1;
    while (!in.at_end()) {
        FileLoc where = in.loc();
        char sub = in.subcommand("a tropism subcommand (T: A: I: E: S:)");
        switch (sub) {
        case 'T':
            m.direction = parse_vec3(in);
            has_direction = true;
            if (dot(m.direction, m.direction) == 0)
                throw Error(where, "the tropism vector must not be zero");
            break;
        case 'A': m.angle_deg = in.number(); break;
        case 'I':
            intensity = in.number();
            if (intensity == 0)
                throw Error(where, "the tropism intensity must not be zero");
            break;
        case 'E': m.initial_elasticity = in.number(); break;
        case 'S': m.elasticity_step = in.number(); break;
        default: throw Error(where, std::string("unknown tropism subcommand '") + sub + ":'");
        }
    }
    if (!has_direction)
        throw in.error("a tropism needs its vector 'T: x y z'");
    double scale = std::clamp(intensity / length(m.direction), -1.0, 1.0);
    m.direction = m.direction * scale;
    if (kind == Movement::Kind::torque)
        m.angle_deg = 0;
    return m;
}

/// The whitespace-separated words of a command's text, case kept (file names).
std::vector<std::pair<std::string, int>> raw_words(std::string_view text, std::size_t start)
{
    std::vector<std::pair<std::string, int>> words;
    std::size_t i = start;
    while (i < text.size()) {
        while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r'))
            ++i;
        std::size_t begin = i;
        while (i < text.size() && text[i] != ' ' && text[i] != '\t' && text[i] != '\r')
            ++i;
        if (i > begin)
            words.emplace_back(std::string(text.substr(begin, i - begin)), static_cast<int>(begin) + 1);
    }
    return words;
}

/// `texture: F: file [H: l|n] [L: l|n|m...] [E: m|d|b] [S:] [R: ratio]` (5.2.6).
void parse_texture(ViewFile& v, std::string_view line, std::size_t start, const FileLoc& line_loc)
{
    TextureDef t;
    t.linear_filter = false;  // cpfg's defaults: nearest, no mipmaps
    t.mipmap = false;
    double ratio = 1;
    bool has_file = false;
    bool per_surface = false;
    auto words = raw_words(line, start);
    auto loc_of = [&](std::size_t k) {
        return FileLoc{line_loc.file, line_loc.line, k < words.size() ? words[k].second : 0};
    };
    for (std::size_t k = 0; k < words.size(); ++k) {
        std::string word = words[k].first;
        if (word.empty() || !std::isalpha(static_cast<unsigned char>(word[0])))
            throw Error(loc_of(k), "expected a texture subcommand (F: H: L: E: S: R:), found '" + word + "'");
        char sub = static_cast<char>(std::toupper(static_cast<unsigned char>(word[0])));
        std::string value = word.size() > 2 ? word.substr(2) : "";  // "F:name" glued
        if (word.size() > 1 && word[1] != ':')
            throw Error(loc_of(k), "expected a texture subcommand (F: H: L: E: S: R:), found '" + word + "'");
        if (sub == 'S') {
            per_surface = true;  // takes no value
            continue;
        }
        if (value.empty()) {
            if (++k >= words.size())
                throw Error(loc_of(k - 1), std::string("texture subcommand '") + sub + ":' needs a value");
            value = words[k].first;
        }
        char first = static_cast<char>(std::tolower(static_cast<unsigned char>(value[0])));
        switch (sub) {
        case 'F':
            t.file = value;
            has_file = true;
            break;
        case 'H': t.linear_filter = first == 'l'; break;
        case 'L': t.mipmap = first == 'm'; break;
        case 'E': t.decal = first == 'd'; break;
        case 'R': {
            char* end = nullptr;
            ratio = std::strtod(value.c_str(), &end);
            if (end == value.c_str() || *end != '\0' || ratio <= 0)
                throw Error(loc_of(k), "texture ratio must be a positive number, found '" + value + "'");
            break;
        }
        default: throw Error(loc_of(k), std::string("unknown texture subcommand '") + sub + ":'");
        }
    }
    if (!has_file)
        throw Error(FileLoc{line_loc.file, line_loc.line, static_cast<int>(start) + 1},
                    "a texture needs its image 'F: file'");
    v.textures.push_back(t);
    v.texture_aspect_ratios.push_back(ratio);
    v.texture_per_surface.push_back(per_surface);
}

/// `translucency: FIRST [LAST] AMOUNT` (Cambium extension).
TranslucencySetting parse_translucency(ValueReader& in)
{
    TranslucencySetting t;
    t.loc = in.loc();
    std::vector<std::pair<double, FileLoc>> values;
    while (!in.at_end() && values.size() < 4) {
        FileLoc where = in.loc();
        values.emplace_back(in.number(), where);
    }
    if (values.size() < 2 || values.size() > 3)
        throw Error(t.loc, "expected 'translucency: FIRST [LAST] AMOUNT'");
    auto index = [](const std::pair<double, FileLoc>& v) {
        if (v.first != std::floor(v.first) || v.first < 0 || v.first > 255)
            throw Error(v.second, "colour index must be an integer in 0..255");
        return static_cast<int>(v.first);
    };
    t.first = index(values[0]);
    t.last = values.size() == 3 ? index(values[1]) : t.first;
    if (t.last < t.first)
        throw Error(values[1].second, "LAST must not be below FIRST");
    const auto& amount = values.back();
    if (!(amount.first >= 0 && amount.first <= 1))
        throw Error(amount.second, "translucency must be in 0..1");
    t.amount = static_cast<float>(amount.first);
    return t;
}

/// Applies one `name: value` command of the turtle, the view or the lights to the view
/// file; false when `name` is none of them.
bool apply_command(ViewFile& v, const std::string& name, ValueReader& in)
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
        v.separate_back_color = !in.at_end();
        v.initial_back_color = v.separate_back_color ? in.integer() : v.initial_color;
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
        v.tapered_lines = in.on_off();
    } else if (name == "viewpoint") {
        v.view.viewpoint = parse_position(in);
    } else if (name == "view reference point") {
        v.view.reference_point = parse_position(in);
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
        v.view.front_distance = parse_coordinate(in);
    } else if (name == "back distance") {
        v.view.back_distance = parse_coordinate(in);
    } else if (name == "scale factor") {
        v.view.scale_factor = in.number();
    } else if (name == "box") {
        v.view.box = parse_box(in);
    } else if (name == "light") {
        v.lights.push_back(parse_light(in));
    } else if (name == "light direction") {
        v.light_direction = parse_position(in);
    } else if (name == "tropism") {
        v.movements.push_back(parse_movement(in, Movement::Kind::tropism));
    } else if (name == "torque") {
        v.movements.push_back(parse_movement(in, Movement::Kind::torque));
    } else if (name == "tropism direction") {
        Vec3 d = parse_vec3(in);
        if (dot(d, d) == 0)
            throw in.error("the tropism direction must not be zero");
        v.legacy_tropism_direction = normalize(d);
    } else if (name == "initial elasticity") {
        v.legacy_elasticity = in.number();
    } else if (name == "elasticity increment") {
        v.legacy_elasticity_increment = in.number();
    } else if (name == "translucency") {
        v.translucency.push_back(parse_translucency(in));
    } else {
        return false;
    }
    return true;
}

/// Commands whose value starts with one number. cpfg reads them with sscanf and keeps
/// the default, with a message, when the value is no number at all ("angle increment: ?").
bool keeps_default_without_number(const std::string& name)
{
    static const std::array lenient = {
        "angle factor", "angle increment", "initial color", "color increment",
        "initial line width", "line width increment", "initial scale", "scale multiplier",
        "twist", "viewing angle", "front distance", "back distance", "scale factor",
        "initial elasticity", "elasticity increment"};
    return std::find(lenient.begin(), lenient.end(), name) != lenient.end();
}

/// Whether the text from `start` begins (after blanks) with something strtod reads.
/// An empty value is not covered: it stays an error.
bool starts_without_number(std::string_view line, std::size_t start, int& column)
{
    std::size_t first = line.find_first_not_of(" \t\r", start);
    if (first == std::string_view::npos)
        return false;
    column = static_cast<int>(first) + 1;
    std::string token(line.substr(first, std::min<std::size_t>(64, line.size() - first)));
    char* stop = nullptr;
    std::strtod(token.c_str(), &stop);
    return stop == token.c_str();
}

bool is_applied(const std::string& name)
{
    static const std::array applied = {
        "angle factor", "angle increment", "initial color", "color increment",
        "initial line width", "line width increment", "initial scale", "scale multiplier",
        "line style", "tapered lines", "tappered lines", "viewpoint", "view reference point",
        "twist", "projection", "viewing angle", "front distance", "back distance",
        "scale factor", "box", "light", "light direction", "tropism", "torque",
        "tropism direction", "initial elasticity", "elasticity increment", "translucency"};
    return std::find(applied.begin(), applied.end(), name) != applied.end();
}

/// One `name: values` line of a view file into `v` (`line_loc`: the line, column 0;
/// `loc`: its first character).
void parse_command(ViewFile& v, std::string_view body, std::size_t colon, const FileLoc& line_loc,
                   const FileLoc& loc)
{
    std::string name = normalize_command_name(body.substr(0, colon));
    ValueReader in(body, colon + 1, line_loc);
    if (name == "texture") {
        parse_texture(v, body, colon + 1, line_loc);
        return;  // reads the whole line itself
    } else if (is_applied(name)) {
        int column = 0;
        if (keeps_default_without_number(name) && starts_without_number(body, colon + 1, column)) {
            warn(FileLoc{line_loc.file, line_loc.line, column},
                 "'" + name + ":' needs a number; the default is kept");
            return;
        }
        apply_command(v, name, in);
    } else if (is_drawing_command(name)) {
        apply_drawing_command(v, name, in);
    } else {
        warn(loc, "unknown view-file command '" + name + ":' ignored");
        return;
    }
    if (!in.at_end())
        warn(in.loc(), "extra text after '" + name + ":' ignored");
}

}  // namespace

ViewFile parse_view_file(std::string_view text, const std::string& file_name)
{
    ViewFile v;
    ErrorList errors(file_name);
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
        try {
            parse_command(v, body, colon, FileLoc{file_name, line.number, 0}, loc);
        } catch (const Error& e) {
            errors.add(e);  // and on to the next line
        }
    }
    errors.finish();
    return v;
}

ViewFile read_view_file(const std::filesystem::path& file)
{
    ViewFile v = parse_view_file(read_text_file(file, "view file"), file.string());
    v.path = file;
    // Texture images are relative to the view file's folder; made absolute so that the
    // renderer finds them from any working directory.
    std::filesystem::path folder = std::filesystem::absolute(file).parent_path();
    for (TextureDef& t : v.textures)
        if (!t.file.empty() && t.file.is_relative())
            t.file = (folder / t.file).lexically_normal();
    return v;
}

std::vector<std::pair<std::filesystem::path, FileLoc>> named_files(const ViewFile& view)
{
    std::vector<std::pair<std::filesystem::path, FileLoc>> files;
    const std::filesystem::path folder = view.path.parent_path();
    auto add = [&](const std::filesystem::path& file, const FileLoc& loc) {
        files.emplace_back(file.is_absolute() ? file : folder / file, loc);
    };
    for (const ContourFile& c : view.cylinders.contours)
        add(c.file, c.loc);
    for (const SurfaceCommand& s : view.surfaces)
        add(s.file, s.loc);
    for (const FunctionFile& f : view.functions)
        add(f.file, f.loc);
    for (const CurveFile& c : view.curves)
        add(c.file, c.loc);
    for (const BackgroundSceneFiles& b : view.background_scenes)
        for (const std::filesystem::path& file : b.files)
            add(file, b.loc);
    return files;
}

}  // namespace cambium::geom
