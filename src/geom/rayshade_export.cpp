// SPDX-License-Identifier: Apache-2.0
// cpfg's -ray output: the Scene as a rayshade 4.0 file laid out as cpfg writes it.
#include "geom/rayshade_export.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <cmath>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>
#include <unordered_set>

#include "base/atomic_file.h"
#include "base/diagnostics.h"
#include "geom/tessellate.h"

namespace cambium::geom {
namespace {

constexpr double deg_to_rad = std::numbers::pi / 180.0;
/// cpfg puts a parallel view's eye 100 / scale factor times the viewpoint's distance away.
constexpr double parallel_eye_distance = 100.0;

/// %g with six digits, as cpfg prints coordinates.
std::string num(double v)
{
    if (v == 0)
        v = 0;  // no "-0"
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

/// %f, as cpfg prints the view.
std::string fixed(double v)
{
    char text[48];
    std::snprintf(text, sizeof text, "%f", v);
    return text;
}

/// A surface's name: s and the number in three digits at least.
std::string surface_name(std::size_t id)
{
    char text[24];
    std::snprintf(text, sizeof text, "s%03zu", id);
    return text;
}

std::string point(const Float3& p) { return num(p[0]) + " " + num(p[1]) + " " + num(p[2]); }
std::string point(const Float4& p) { return num(p[0]) + " " + num(p[1]) + " " + num(p[2]); }
std::string point(const Vec3& p) { return num(p.x) + " " + num(p.y) + " " + num(p.z); }
std::string fixed(const Vec3& p) { return fixed(p.x) + " " + fixed(p.y) + " " + fixed(p.z); }
std::string colour(const Rgb& c) { return num(c.r) + " " + num(c.g) + " " + num(c.b); }

Vec3 rotate(const Vec3& v, const Vec3& k, double angle)
{
    double c = std::cos(angle), s = std::sin(angle);
    return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

/// cpfg's surface names: 's', then the colour index plus 256 times the colour block
/// (the selected block is 1, so index i of it is s(256 + i)).
class SurfaceNames {
public:
    SurfaceNames(const Scene& scene, const RayshadeOptions& options)
        : m_scene(scene), m_colormap(options.colormap), m_transparency(options.transparency)
    {
    }

    /// The surface of material `m`, recorded as used; "" for inherit_material.
    std::string use(std::uint16_t m)
    {
        if (m == inherit_material || m >= m_scene.materials.size())
            return {};
        std::size_t id = surface_index(m);
        m_used.emplace(id, m);
        return surface_name(id);
    }
    /// The definitions of every used surface, by name.
    std::string definitions() const
    {
        std::string out;
        for (const auto& [id, m] : m_used) {
            const Material& mat = m_scene.materials[m];
            if (m_colormap) {
                // the colormap's colour as both ambient and diffuse (manual 6.1.1)
                Rgb c = base_colour(m);
                out += "surface " + surface_name(id) + " ambient " + colour(c) +
                       "\n             diffuse " + colour(c) + "\n";
                continue;
            }
            // cpfg scales the colours by the opacity, rayshade adding the transmitted part
            float transparency = m < m_transparency.size() ? m_transparency[m] : mat.transparency;
            float opacity = 1 - transparency;
            auto scaled = [&](const Rgb& c) { return Rgb{c.r * opacity, c.g * opacity, c.b * opacity}; };
            out += "surface " + surface_name(id) + " ambient " + colour(scaled(mat.ambient)) +
                   "\n             diffuse " + colour(scaled(mat.diffuse)) +
                   "\n             specular " + colour(mat.specular) +
                   "\n             specpow " + num(mat.shininess) +
                   "\n             transp " + num(transparency) + "\n             index 1.0\n";
        }
        return out;
    }

private:
    /// The colour index a material stands for: its own, or under colormap-mode index
    /// lighting the index the lighting starts from (cpfg writes the basic colour).
    std::size_t surface_index(std::uint16_t m) const
    {
        const Material& mat = m_scene.materials[m];
        if (m_colormap && mat.index_lighting != IndexLighting::none)
            return 256 + std::size_t(mat.colour_table) + mat.colour_index;
        return 256 + std::size_t(m);
    }
    Rgb base_colour(std::uint16_t m) const
    {
        const Material& mat = m_scene.materials[m];
        if (mat.index_lighting != IndexLighting::none) {
            std::size_t base = std::size_t(mat.colour_table) + mat.colour_index;
            if (base < m_scene.materials.size())
                return m_scene.materials[base].diffuse;
        }
        return mat.diffuse;
    }

    const Scene& m_scene;
    bool m_colormap;
    const std::vector<float>& m_transparency;
    std::map<std::size_t, std::uint16_t> m_used;
};

/// Text appended to a stream as it is made: a scene's body can be larger than memory
/// should hold twice.
class Sink {
public:
    explicit Sink(std::ostream& out) : m_out(out) {}
    Sink& operator+=(const std::string& text)
    {
        m_out << text;
        return *this;
    }
    Sink& operator+=(char c)
    {
        m_out << c;
        return *this;
    }

private:
    std::ostream& m_out;
};

/// The surfaces every primitive and instance of the scene uses, registered before any
/// is written so that the definitions can come first.
void register_surfaces(const Scene& scene, SurfaceNames& surfaces)
{
    auto each = [&](const std::vector<std::uint16_t>& materials) {
        for (std::uint16_t m : materials)
            surfaces.use(m);
    };
    auto geometry = [&](const Geometry& g) {
        each(g.lines.material);
        each(g.curves.material);
        each(g.spheres.material);
        each(g.discs.material);
        each(g.mesh.material);
    };
    geometry(scene.geometry);
    for (const Prototype& p : scene.prototypes)
        geometry(p.geometry);
    for (const Instance& in : scene.instances)
        surfaces.use(in.material);
}

/// The primitives of one Geometry, each naming its surface (none where it inherits the
/// instance's).
void write_geometry(Sink& out, const Geometry& g, SurfaceNames& surfaces, double shortest_segment)
{
    const LinearCurves& lines = g.lines;
    for (std::size_t i = 0; i < lines.segments.size(); ++i) {
        const Float4& a = lines.keys[lines.segments[i]];
        const Float4& b = lines.keys[lines.segments[i] + 1];
        if (std::hypot(double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]) < shortest_segment)
            continue;
        std::string s = surfaces.use(lines.material[i]);
        std::string sp = s.empty() ? "" : s + " ";
        if (a[3] == b[3])
            out += "cylinder " + sp + num(a[3]) + " " + point(a) + "\n " + point(b) + "\n";
        else
            out += "cone " + sp + num(a[3]) + " " + point(a) + "\n " + num(b[3]) + " " + point(b) + "\n";
    }
    for (std::size_t i = 0; i < g.spheres.size(); ++i) {
        const Float4& c = g.spheres.centres[i];
        std::string s = surfaces.use(g.spheres.material[i]);
        out += "sphere " + (s.empty() ? "" : s + " ") + num(c[3]) + " " + point(c) + "\n";
    }
    for (std::size_t i = 0; i < g.discs.size(); ++i) {
        const Float4& c = g.discs.centres[i];
        std::string s = surfaces.use(g.discs.material[i]);
        out += "disc " + (s.empty() ? "" : s + " ") + num(c[3]) + " " + point(c) + " " +
               point(g.discs.normals[i]) + "\n";
    }
    auto write_mesh = [&](const TriangleMesh& mesh) {
        for (std::size_t i = 0; i < mesh.size(); ++i) {
            const auto& t = mesh.triangles[i];
            std::string s = surfaces.use(mesh.material[i]);
            bool uv = !mesh.uvs.empty() && i < mesh.texture.size() && mesh.texture[i] != no_texture;
            out += uv ? "triangleuv" : "triangle";
            if (!s.empty()) {
                out += ' ';
                out += s;
            }
            out += '\n';
            for (std::uint32_t v : t) {
                out += point(mesh.positions[v]) + " " + point(mesh.normals[v]);
                if (uv) {
                    out += ' ';
                    out += num(mesh.uvs[v][0]);
                    out += ' ';
                    out += num(mesh.uvs[v][1]);
                }
                out += '\n';
            }
        }
    };
    write_mesh(g.mesh);
    if (g.curves.segment_count() > 0) {
        // rayshade has no generalized cylinders: their walls as triangles
        Geometry curves;
        curves.curves = g.curves;
        write_mesh(tessellate_geometry(curves, false, Tessellation{}));
    }
}

/// cpfg's name for a character that is not a letter: c and its code in three digits.
std::string character_code(unsigned char c)
{
    char text[8];
    std::snprintf(text, sizeof text, "c%03d", int(c));
    return text;
}

/// A rayshade name for prototype `index`: its own where it is a plain word (a predefined
/// surface's letter), else characters other than letters and digits as cNNN (their
/// code, as cpfg names objects of such modules), made unique.
std::string object_name(const Prototype& p, std::size_t index, std::unordered_set<std::string>& taken)
{
    std::string name;
    for (unsigned char c : p.name)
        if (std::isalnum(c) || c == '_')
            name += char(c);
        else
            name += character_code(c);
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0])))
        name = "o" + name;
    if (!taken.insert(name).second) {
        name += "_" + std::to_string(index);
        taken.insert(name);
    }
    return name;
}

struct ViewLines {
    Vec3 eye, look, up;
    double fov_deg = 0;
};

/// cpfg's rayshade view: perspective as the window's (eye = reference + (viewpoint -
/// reference) / scale factor, horizontal field of view); a parallel view becomes a
/// distant perspective one looking at the box's centre and framing it as the window does.
ViewLines view_lines(const Scene& scene, const RayshadeOptions& o)
{
    const View& v = scene.view;
    Vec3 forward = normalize(v.reference_point - v.viewpoint);
    if (length(forward) == 0)
        forward = {0, 0, 1};
    Vec3 hint{0, 1, 0};
    if (std::abs(dot(forward, hint)) > 1 - 1e-12)
        hint = forward.y < 0 ? Vec3{0, 0, -1} : Vec3{0, 0, 1};
    Vec3 right = normalize(cross(forward, hint));
    Vec3 up = cross(right, forward);
    if (v.twist_deg != 0) {
        up = rotate(up, forward * -1.0, v.twist_deg * deg_to_rad);
        right = cross(forward, up);
    }
    double aspect = double(o.width) / double(o.height);
    double sf = v.scale_factor > 0 ? v.scale_factor : 1;
    ViewLines out;
    out.up = up;
    if (v.perspective) {
        out.look = v.reference_point;
        out.eye = v.reference_point + (v.viewpoint - v.reference_point) / sf;
        out.fov_deg = 2 * std::atan(aspect * std::tan(v.viewing_angle_deg * deg_to_rad / 2)) / deg_to_rad;
        return out;
    }
    Bounds3 box = v.box.value_or(scene.bounds);
    if (box.empty())
        box.extend(Vec3{0, 0, 0});
    out.look = (box.lo + box.hi) * 0.5;
    Vec3 away = v.viewpoint - v.reference_point;
    if (length(away) == 0)
        away = {0, 0, -1};
    out.eye = out.look + away * (parallel_eye_distance / sf);
    // the box's extent across the view, as the parallel window fits it
    double w = 0, h = 0;
    for (int c = 0; c < 8; ++c) {
        Vec3 corner{(c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y,
                    (c & 4) ? box.hi.z : box.lo.z};
        Vec3 d = corner - out.look;
        w = std::max(w, 2 * std::abs(dot(d, right)));
        h = std::max(h, 2 * std::abs(dot(d, up)));
    }
    double units_per_pixel = 1 / (sf * std::min(w > 0 ? o.width / w : 1e30, h > 0 ? o.height / h : 1e30));
    if (!std::isfinite(units_per_pixel) || units_per_pixel <= 0)
        units_per_pixel = 1.0 / o.width;
    double half_width = 0.5 * o.width * units_per_pixel;
    out.fov_deg = 2 * std::atan(half_width / length(out.eye - out.look)) / deg_to_rad;
    return out;
}

std::string light_lines(const Scene& scene)
{
    Rgb ambient{0, 0, 0};
    for (const Light& l : scene.lights)
        ambient = {ambient.r + l.ambient.r, ambient.g + l.ambient.g, ambient.b + l.ambient.b};
    std::string out = "light " + colour(ambient) + " ambient\n";
    for (const Light& l : scene.lights) {
        switch (l.kind) {
        case Light::Kind::directional:
            out += "light " + colour(l.diffuse) + " directional " + point(l.direction) + "\n";
            break;
        case Light::Kind::point:
            out += "light " + colour(l.diffuse) + " point " + point(l.position) + "\n";
            break;
        case Light::Kind::spot: {
            // rayshade's spot: position, a point it aims at, falloff exponent, cone angles
            double cut = std::min<double>(l.spot_cutoff_deg, 90);
            out += "light " + colour(l.diffuse) + " spot " + point(l.position) + " " +
                   point(l.position + l.spot_direction) + " " + num(l.spot_exponent) + " " +
                   num(cut) + " " + num(cut) + "\n";
            break;
        }
        }
    }
    return out;
}

}  // namespace

void write_rayshade(std::ostream& stream, const Scene& scene, const RayshadeOptions& options)
{
    SurfaceNames surfaces(scene, options);
    register_surfaces(scene, surfaces);
    const ViewLines view = view_lines(scene, options);
    Bounds3 box = scene.view.box.value_or(scene.bounds);
    if (box.empty())
        box.extend(Vec3{0, 0, 0});
    Sink out(stream);
    out += "/* rayshade 4.0 scene written by cambium */\n";
    out += "#ifndef NOSURFACES\n" + surfaces.definitions() + "#endif\n";
    out += "#ifndef NOHEADERS\n";
    out += "eyep " + fixed(view.eye) + "\nlookp " + fixed(view.look) + "\nup " + fixed(view.up) + "\n";
    out += "fov " + fixed(view.fov_deg) + "\nscreen " + std::to_string(options.width) + " " +
           std::to_string(options.height) + "\n";
    out += "background " + fixed(scene.background.r) + " " + fixed(scene.background.g) + " " +
           fixed(scene.background.b) + "\n\n";
    out += light_lines(scene);
    out += "#endif\n\n";
    out += "#ifdef BBOX\nname " + options.object_name + "\nbox " + point(box.lo) + " " + point(box.hi) +
           "\n#else\n";
    std::unordered_set<std::string> taken{options.object_name};
    std::vector<std::string> names;
    for (std::size_t i = 0; i < scene.prototypes.size(); ++i) {
        names.push_back(object_name(scene.prototypes[i], i, taken));
        out += "name " + names.back() + " grid 20 20 20\n";
        write_geometry(out, scene.prototypes[i].geometry, surfaces, options.shortest_segment);
        out += "end\n\n";
    }
    out += "name " + options.object_name + "\ngrid 40 40 40\n";
    write_geometry(out, scene.geometry, surfaces, options.shortest_segment);
    for (const Instance& in : scene.instances) {
        if (in.prototype >= names.size())
            continue;
        std::string s = surfaces.use(in.material);
        if (!s.empty())
            out += "applysurf " + s + "\n";
        // rayshade multiplies row vectors: the rows are the images of the axes, which
        // are the columns of the Instance's column-major matrix
        const auto& m = in.transform;
        out += "object " + names[in.prototype] + "\n transform\n  " + num(m[0]) + " " + num(m[1]) +
                " " + num(m[2]) + "  " + num(m[3]) + " " + num(m[4]) + " " + num(m[5]) + "  " +
                num(m[6]) + " " + num(m[7]) + " " + num(m[8]) + "\n translate " + num(m[9]) + " " +
                num(m[10]) + " " + num(m[11]) + "\n";
    }
    out += "end\n";
    out += "#endif\n\n#ifndef NOHEADERS\nobject " + options.object_name;
    if (options.scale != 1)
        out += " scale " + num(options.scale) + " " + num(options.scale) + " " + num(options.scale);
    out += "\n#endif\n";
}

std::string rayshade_text(const Scene& scene, const RayshadeOptions& options)
{
    std::ostringstream out;
    write_rayshade(out, scene, options);
    return out.str();
}

void write_rayshade(const Scene& scene, const std::filesystem::path& file, const RayshadeOptions& options)
{
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        write_rayshade(out, scene, options);
        out.close();
        if (!out)
            throw Error(FileLoc{file.string()}, "cannot write the rayshade file");
    });
}

}  // namespace cambium::geom
