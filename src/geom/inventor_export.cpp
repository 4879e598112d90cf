// SPDX-License-Identifier: Apache-2.0
#include "geom/inventor_export.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "base/atomic_file.h"
#include "base/diagnostics.h"
#include "base/limits.h"
#include "geom/mesh_export.h"
#include "geom/primitives.h"
#include "geom/tessellate.h"

namespace cambium::geom {
namespace {

std::string rgb(const Rgb& c)
{
    char text[96];
    std::snprintf(text, sizeof text, "%.6g %.6g %.6g", c.r, c.g, c.b);
    return text;
}

std::string xyz(double x, double y, double z)
{
    char text[96];
    std::snprintf(text, sizeof text, "%.9g %.9g %.9g", x, y, z);
    return text;
}

/// The pixel-width line segments of the scene's own geometry and its placed prototypes,
/// in world space, with their materials.
struct Segments {
    std::vector<Vec3> points;  ///< two a segment
    std::vector<std::uint16_t> material;
    float width = 1;
};

void add_segments(const LinearCurves& lines, const Instance* in, Segments& out)
{
    for (std::size_t i = 0; i < lines.segment_count(); ++i) {
        const Float4& a = lines.keys[lines.segments[i]];
        const Float4& b = lines.keys[lines.segments[i] + 1];
        Vec3 pa{a[0], a[1], a[2]}, pb{b[0], b[1], b[2]};
        std::uint16_t m = i < lines.material.size() ? lines.material[i] : 0;
        if (in) {
            pa = Affine3x4(in->transform).apply(pa);
            pb = Affine3x4(in->transform).apply(pb);
            if (m == inherit_material)
                m = in->material;
        }
        out.points.push_back(pa);
        out.points.push_back(pb);
        out.material.push_back(m);
        out.width = std::max(out.width, 2 * a[3]);  // Inventor has one width a line set
    }
}

void write_lights(std::ofstream& out, const Scene& scene)
{
    for (const Light& l : scene.lights) {
        switch (l.kind) {
        case Light::Kind::directional: {
            // the view file's vector points toward the light; Inventor's the way it shines
            out << "  DirectionalLight {\n    color " << rgb(l.diffuse) << "\n    direction "
                << xyz(-l.direction.x, -l.direction.y, -l.direction.z) << "\n  }\n";
            break;
        }
        case Light::Kind::point:
            out << "  PointLight {\n    color " << rgb(l.diffuse) << "\n    location "
                << xyz(l.position.x, l.position.y, l.position.z) << "\n  }\n";
            break;
        case Light::Kind::spot:
            out << "  SpotLight {\n    color " << rgb(l.diffuse) << "\n    location "
                << xyz(l.position.x, l.position.y, l.position.z) << "\n    direction "
                << xyz(l.spot_direction.x, l.spot_direction.y, l.spot_direction.z)
                << "\n    cutOffAngle " << std::min(l.spot_cutoff_deg, 90.0f) * 3.14159265358979 / 180
                << "\n  }\n";
            break;
        }
    }
}

/// A Material node listing `used` materials in order (their index in the list is what
/// the shapes' materialIndex names).
void write_materials(std::ofstream& out, const Scene& scene, const std::vector<std::uint16_t>& used)
{
    std::string ambient, diffuse, specular, emissive, shininess, transparency;
    for (std::uint16_t i : used) {
        const Material& m = exported_material(scene, i);
        const std::string_view sep = ambient.empty() ? "" : ", ";
        auto add = [&](std::string& list, const std::string& value) {
            list.append(sep);
            list.append(value);
        };
        add(ambient, rgb(m.ambient));
        add(diffuse, rgb(m.diffuse));
        add(specular, rgb(m.specular));
        add(emissive, rgb(m.emission));
        add(shininess, std::to_string(m.shininess / 128.0f));  // Inventor's 0..1
        add(transparency, std::to_string(m.transparency));
    }
    out << "  Material {\n    ambientColor [ " << ambient << " ]\n    diffuseColor [ " << diffuse
        << " ]\n    specularColor [ " << specular << " ]\n    emissiveColor [ " << emissive
        << " ]\n    shininess [ " << shininess << " ]\n    transparency [ " << transparency
        << " ]\n  }\n";
}

}  // namespace

void write_inventor(const Scene& scene, const std::filesystem::path& file,
                    const MeshExportOptions& options)
{
    const std::uint64_t triangles = tessellated_triangles(scene, options.tessellation);
    if (triangles > options.max_memory_bytes / exported_triangle_bytes)
        throw Error(file.string() + ": the plant's " + std::to_string(triangles) +
                    " triangles need " + byte_size_text(triangles * exported_triangle_bytes) +
                    ", more than the memory budget of " + byte_size_text(options.max_memory_bytes) +
                    " (--max-memory)");
    const TriangleMesh mesh = tessellate(scene, options.tessellation);
    Segments lines;
    if (scene.line_radius_in_pixels) {
        add_segments(scene.geometry.lines, nullptr, lines);
        for (const Instance& in : scene.instances)
            if (in.prototype < scene.prototypes.size())
                add_segments(scene.prototypes[in.prototype].geometry.lines, &in, lines);
    }
    // the materials used, numbered in the order they are first met
    std::map<std::uint16_t, std::size_t> slot;
    std::vector<std::uint16_t> used;
    auto slot_of = [&](std::uint16_t m) {
        auto [it, added] = slot.try_emplace(m, used.size());
        if (added)
            used.push_back(m);
        return it->second;
    };
    for (std::uint16_t m : mesh.material)
        slot_of(m);
    for (std::uint16_t m : lines.material)
        slot_of(m);
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        if (!out)
            throw Error(file.string() + ": cannot write: " + std::strerror(errno));
        out << "#Inventor V2.1 ascii\n\n# Cambium: the plant as triangles\nSeparator {\n";
        write_lights(out, scene);
        // cpfg's window lights both sides of a surface
        out << "  ShapeHints {\n    vertexOrdering COUNTERCLOCKWISE\n    shapeType UNKNOWN_SHAPE_TYPE\n  }\n";
        if (!used.empty())
            write_materials(out, scene, used);
        out << "  MaterialBinding {\n    value PER_FACE_INDEXED\n  }\n";
        if (mesh.size() > 0) {
            out << "  Separator {\n    Coordinate3 {\n      point [\n";
            for (const Float3& p : mesh.positions)
                out << "        " << xyz(p[0], p[1], p[2]) << ",\n";
            out << "      ]\n    }\n    Normal {\n      vector [\n";
            for (const Float3& n : mesh.normals)
                out << "        " << xyz(n[0], n[1], n[2]) << ",\n";
            out << "      ]\n    }\n    NormalBinding {\n      value PER_VERTEX_INDEXED\n    }\n"
                << "    IndexedFaceSet {\n      coordIndex [\n";
            for (const auto& t : mesh.triangles)
                out << "        " << t[0] << ", " << t[1] << ", " << t[2] << ", -1,\n";
            out << "      ]\n      materialIndex [\n";
            for (std::uint16_t m : mesh.material)
                out << "        " << slot.at(m) << ",\n";
            out << "      ]\n    }\n  }\n";
        }
        if (!lines.material.empty()) {
            out << "  Separator {\n    LightModel {\n      model BASE_COLOR\n    }\n"
                << "    DrawStyle {\n      lineWidth " << lines.width << "\n    }\n"
                << "    Coordinate3 {\n      point [\n";
            for (const Vec3& p : lines.points)
                out << "        " << xyz(p.x, p.y, p.z) << ",\n";
            out << "      ]\n    }\n    IndexedLineSet {\n      coordIndex [\n";
            for (std::size_t i = 0; i < lines.material.size(); ++i)
                out << "        " << 2 * i << ", " << 2 * i + 1 << ", -1,\n";
            out << "      ]\n      materialIndex [\n";
            for (std::uint16_t m : lines.material)
                out << "        " << slot.at(m) << ",\n";
            out << "      ]\n    }\n  }\n";
        }
        out << "}\n";
        out.flush();
        if (!out)
            throw Error(file.string() + ": cannot write: " + std::strerror(errno));
    });
}

}  // namespace cambium::geom
