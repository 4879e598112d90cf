// SPDX-License-Identifier: Apache-2.0
#include "geom/mesh_export.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "base/atomic_file.h"
#include "base/diagnostics.h"
#include "geom/gltf_export.h"

namespace cambium::geom {

const Material& exported_material(const Scene& scene, std::uint16_t index)
{
    static const Material fallback;
    return index < scene.materials.size() ? scene.materials[index] : fallback;
}

namespace {


/// Opens `path` for writing binary data, or throws naming `file`.
std::ofstream open_output(const std::filesystem::path& path, const std::filesystem::path& file)
{
    std::ofstream out(path, std::ios::binary);
    if (!out)
        throw Error(file.string() + ": cannot write: " + std::strerror(errno));
    return out;
}

void finish(std::ofstream& out, const std::filesystem::path& file)
{
    out.flush();
    if (!out)
        throw Error(file.string() + ": cannot write: " + std::strerror(errno));
}

/// The triangles in order of (material, texture): an OBJ switches material once a group.
std::vector<std::size_t> by_material(const TriangleMesh& mesh)
{
    std::vector<std::size_t> order(mesh.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return std::pair(mesh.material[a], mesh.texture[a]) < std::pair(mesh.material[b], mesh.texture[b]);
    });
    return order;
}

std::string material_name(std::uint16_t material, std::int16_t texture)
{
    return "colour" + std::to_string(material) + (texture == no_texture ? "" : "_texture" + std::to_string(texture));
}

/// A texture's file as the exported file should name it: relative to the export's folder.
std::string texture_path(const Scene& scene, std::int16_t texture, const MeshExportOptions& options,
                         const std::filesystem::path& file)
{
    std::filesystem::path t = scene.textures.at(static_cast<std::size_t>(texture)).file;
    if (t.is_relative())
        t = options.texture_folder / t;
    std::error_code ec;
    const std::filesystem::path folder = std::filesystem::absolute(file, ec).parent_path();
    std::filesystem::path relative = std::filesystem::absolute(t, ec).lexically_relative(folder);
    return (relative.empty() ? t : relative).generic_string();
}

void write_mtl(const Scene& scene, const TriangleMesh& mesh, const std::vector<std::size_t>& order,
               const MeshExportOptions& options, const std::filesystem::path& file,
               std::ofstream& out)
{
    out << "# Cambium: cpfg materials (display values) as Wavefront MTL\n";
    std::pair<int, int> last{-1, -2};
    char line[256];
    for (std::size_t t : order) {
        const std::pair<int, int> key{mesh.material[t], mesh.texture[t]};
        if (key == last)
            continue;
        last = key;
        const Material& m = exported_material(scene, mesh.material[t]);
        out << "\nnewmtl " << material_name(mesh.material[t], mesh.texture[t]) << '\n';
        std::snprintf(line, sizeof line,
                      "Ka %g %g %g\nKd %g %g %g\nKs %g %g %g\nKe %g %g %g\nNs %g\nd %g\nillum 2\n",
                      m.ambient.r, m.ambient.g, m.ambient.b, m.diffuse.r, m.diffuse.g, m.diffuse.b,
                      m.specular.r, m.specular.g, m.specular.b, m.emission.r, m.emission.g,
                      m.emission.b, m.shininess, 1.0 - m.transparency);
        out << line;
        if (mesh.texture[t] != no_texture) {
            const std::string texture = texture_path(scene, mesh.texture[t], options, file);
            // its alpha cuts leaves out, as the renderer does (docs/materials.md)
            out << "map_Kd " << texture << "\nmap_d " << texture << '\n';
        }
    }
}

void write_obj(const Scene& scene, const TriangleMesh& mesh, const MeshExportOptions& options,
               const std::filesystem::path& file)
{
    const std::vector<std::size_t> order = by_material(mesh);
    std::filesystem::path mtl = file;
    mtl.replace_extension(".mtl");
    write_file_atomically(mtl, [&](const std::filesystem::path& temporary) {
        std::ofstream out = open_output(temporary, mtl);
        write_mtl(scene, mesh, order, options, file, out);
        finish(out, mtl);
    });
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out = open_output(temporary, file);
        out << "# Cambium: the plant as triangles\nmtllib " << mtl.filename().string() << '\n';
        char line[160];
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            const Float3& p = mesh.positions[i];
            const Float3& n = mesh.normals[i];
            const Float2& uv = mesh.uvs[i];
            std::snprintf(line, sizeof line, "v %g %g %g\nvn %g %g %g\nvt %g %g\n", p[0], p[1],
                          p[2], n[0], n[1], n[2], uv[0], uv[1]);
            out << line;
        }
        std::pair<int, int> last{-1, -2};
        for (std::size_t t : order) {
            const std::pair<int, int> key{mesh.material[t], mesh.texture[t]};
            if (key != last)
                out << "usemtl " << material_name(mesh.material[t], mesh.texture[t]) << '\n';
            last = key;
            const auto& tri = mesh.triangles[t];
            std::snprintf(line, sizeof line, "f %u/%u/%u %u/%u/%u %u/%u/%u\n", tri[0] + 1,
                          tri[0] + 1, tri[0] + 1, tri[1] + 1, tri[1] + 1, tri[1] + 1, tri[2] + 1,
                          tri[2] + 1, tri[2] + 1);
            out << line;
        }
        finish(out, file);
    });
}

template <typename T>
void put(std::ofstream& out, T value)
{
    out.write(reinterpret_cast<const char*>(&value), sizeof value);  // little endian, as declared
}

std::uint8_t byte_of(float display)
{
    return static_cast<std::uint8_t>(std::clamp(display, 0.0f, 1.0f) * 255.0f + 0.5f);
}

void write_ply(const Scene& scene, const TriangleMesh& mesh, const std::filesystem::path& file)
{
    // a vertex takes its triangle's colour: vertices shared by triangles of several
    // colours (none the tessellation makes) take the last one's
    std::vector<Rgb> colour(mesh.positions.size());
    for (std::size_t t = 0; t < mesh.size(); ++t)
        for (std::uint32_t i : mesh.triangles[t])
            colour[i] = exported_material(scene, mesh.material[t]).diffuse;
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out = open_output(temporary, file);
        out << "ply\nformat binary_little_endian 1.0\ncomment Cambium: the plant as triangles\n"
            << "element vertex " << mesh.positions.size()
            << "\nproperty float x\nproperty float y\nproperty float z\n"
               "property float nx\nproperty float ny\nproperty float nz\n"
               "property uchar red\nproperty uchar green\nproperty uchar blue\n"
            << "element face " << mesh.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            for (float x : mesh.positions[i]) put(out, x);
            for (float x : mesh.normals[i]) put(out, x);
            put(out, byte_of(colour[i].r));
            put(out, byte_of(colour[i].g));
            put(out, byte_of(colour[i].b));
        }
        for (const auto& tri : mesh.triangles) {
            put(out, std::uint8_t{3});
            for (std::uint32_t i : tri) put(out, static_cast<std::int32_t>(i));
        }
        finish(out, file);
    });
}

void write_gls(const Scene& scene, const TriangleMesh& mesh, const std::filesystem::path& file)
{
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out = open_output(temporary, file);
        out << "/* Cambium: the plant as cpfg's graphics library statements */\n";
        char text[512];
        int last = -1;
        for (std::size_t t = 0; t < mesh.size(); ++t) {
            if (mesh.material[t] != last) {
                last = mesh.material[t];
                const Material& m = exported_material(scene, mesh.material[t]);
                const double alpha = 1.0 - m.transparency;
                std::snprintf(text, sizeof text,
                              "material %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g "
                              "%.9g %.9g %.9g %.9g %.9g %.9g\n",
                              m.ambient.r, m.ambient.g, m.ambient.b, alpha, m.diffuse.r,
                              m.diffuse.g, m.diffuse.b, alpha, m.specular.r, m.specular.g,
                              m.specular.b, alpha, m.emission.r, m.emission.g, m.emission.b,
                              alpha, m.shininess);
                out << text;
            }
            out << "polygonuv";
            for (std::uint32_t i : mesh.triangles[t]) {
                const Float3& p = mesh.positions[i];
                const Float3& n = mesh.normals[i];
                std::snprintf(text, sizeof text, " %.9g %.9g %.9g %.9g %.9g %.9g", p[0], p[1], p[2],
                              n[0], n[1], n[2]);
                out << text;
            }
            out << '\n';
        }
        finish(out, file);
    });
}

}  // namespace

void write_mesh(const Scene& scene, const std::filesystem::path& file, MeshFormat format,
                const MeshExportOptions& options)
{
    const std::uint64_t triangles = format == MeshFormat::glb
                                        ? gltf_primitives(scene, options.tessellation)
                                        : tessellated_triangles(scene, options.tessellation);
    if (triangles > options.max_memory_bytes / exported_triangle_bytes)
        throw Error(file.string() + ": the plant's " + std::to_string(triangles) +
                    " triangles need " + byte_size_text(triangles * exported_triangle_bytes) +
                    ", more than the memory budget of " + byte_size_text(options.max_memory_bytes) +
                    " (--max-memory)");
    if (format == MeshFormat::glb)
        return write_glb(scene, file, options);
    const TriangleMesh mesh = tessellate(scene, options.tessellation);
    switch (format) {
    case MeshFormat::glb: break;
    case MeshFormat::obj: write_obj(scene, mesh, options, file); break;
    case MeshFormat::ply: write_ply(scene, mesh, file); break;
    case MeshFormat::gls: write_gls(scene, mesh, file); break;
    case MeshFormat::none: throw Error(file.string() + ": not a mesh format");
    }
}

}  // namespace cambium::geom
