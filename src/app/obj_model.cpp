// SPDX-License-Identifier: Apache-2.0
// An OBJ file with its MTL materials, read as the plant Cambium exported it
// (docs/export.md "Read back"): smooth normals from `vn`, texture coordinates from `vt`,
// each `usemtl` mapped back to the cpfg material its MTL entry was written from.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>

#include "app/obj_lines.h"
#include "app/scene_file.h"
#include "base/confinement.h"
#include "base/diagnostics.h"
#include "base/input_file.h"

namespace cambium::app {
namespace fs = std::filesystem;
namespace {

/// The rest of a statement's line (a file or material name may hold spaces), trimmed.
std::string rest(const std::string& text, const std::string& kind, const FileLoc& loc)
{
    std::size_t start = text.find(kind) + kind.size();
    std::size_t first = text.find_first_not_of(" \t", start);
    std::size_t last = text.find_last_not_of(" \t");
    if (first == std::string::npos)
        throw Error(loc, "'" + kind + "' needs a name");
    return text.substr(first, last - first + 1);
}

/// `name` (relative to `folder`) as a path inside `allowed`, or an error at `loc`
/// (docs/security.md: a file a scene names must lie in the scene's folder).
fs::path confined(const std::string& name, const fs::path& folder, const fs::path& allowed,
                  bool allow_file_access, const FileLoc& loc)
{
    fs::path p(name);
    fs::path full = p.is_absolute() ? p : folder / p;
    if (!allow_file_access && (p.is_absolute() || !lies_within(full, allowed)))
        throw Error(loc, "'" + name + "' lies outside the folder " + allowed.string() +
                             " (give --allow-file-access to allow it)");
    std::error_code ec;
    fs::path absolute = fs::absolute(full, ec);
    return ec ? full : absolute.lexically_normal();
}

geom::Rgb rgb(std::istringstream& words, const FileLoc& loc, const std::string& kind)
{
    double r, g, b;
    if (!(words >> r >> g >> b) || !std::isfinite(r) || !std::isfinite(g) || !std::isfinite(b))
        throw Error(loc, "expected '" + kind + " r g b' with finite values");
    return {float(r), float(g), float(b)};
}

double number(std::istringstream& words, const FileLoc& loc, const std::string& kind)
{
    double x;
    if (!(words >> x) || !std::isfinite(x))
        throw Error(loc, "expected '" + kind + " value' with a finite value");
    return x;
}

struct MtlEntry {
    geom::Material material;
    std::int16_t texture = geom::no_texture;
};

/// Reads an MTL file's entries into `entries` (by name), their textures into `model`.
void read_mtl(const fs::path& file, const fs::path& allowed, bool allow_file_access,
              const SceneLimits& limits, std::map<std::string, MtlEntry>& entries,
              std::map<fs::path, std::int16_t>& texture_index, ObjModel& model)
{
    MtlEntry* current = nullptr;
    for_each_obj_line(file, "the MTL file", limits, [&](const std::string& kind, std::istringstream& words,
                                                   const std::string& text, const FileLoc& loc) {
        if (kind == "newmtl") {
            if (entries.size() >= limits.max_mesh_materials)
                throw Error(loc, "more than " + std::to_string(limits.max_mesh_materials) +
                                     " materials");
            current = &entries[rest(text, kind, loc)];
            *current = MtlEntry{};
            current->material.specular = {0, 0, 0};
            return;
        }
        static const char* known[] = {"Ka", "Kd", "Ks", "Ke", "Ns", "d", "Tr", "map_Kd"};
        if (std::find(std::begin(known), std::end(known), kind) == std::end(known))
            return;  // illum, map_d (the same texture's alpha), others: nothing to map back
        if (!current)
            throw Error(loc, "'" + kind + "' before any 'newmtl'");
        geom::Material& m = current->material;
        // the inverse of geom/mesh_export.cpp's write_mtl
        if (kind == "Ka") m.ambient = rgb(words, loc, kind);
        else if (kind == "Kd") m.diffuse = rgb(words, loc, kind);
        else if (kind == "Ks") m.specular = rgb(words, loc, kind);
        else if (kind == "Ke") m.emission = rgb(words, loc, kind);
        else if (kind == "Ns") m.shininess = float(std::clamp(number(words, loc, kind), 0.0, 128.0));
        else if (kind == "d") m.transparency = float(1 - std::clamp(number(words, loc, kind), 0.0, 1.0));
        else if (kind == "Tr") m.transparency = float(std::clamp(number(words, loc, kind), 0.0, 1.0));
        else {
            fs::path t = confined(rest(text, kind, loc), file.parent_path(), allowed,
                                  allow_file_access, loc);
            if (!fs::is_regular_file(t))
                throw Error(loc, "the texture '" + t.string() + "' is not a file");
            auto [it, added] = texture_index.emplace(t, std::int16_t(model.textures.size()));
            if (added) {
                if (model.textures.size() >= 32767)
                    throw Error(loc, "more than 32767 textures");
                geom::TextureDef def;
                def.file = t;
                model.textures.push_back(def);
            }
            current->texture = it->second;
        }
    });
}

/// One corner of a face: its v, vt and vn indices (0-based; -1 when not given).
struct Corner {
    long long v = -1, vt = -1, vn = -1;
    bool operator==(const Corner&) const = default;
};
struct CornerHash {
    std::size_t operator()(const Corner& c) const
    {
        return std::hash<long long>()(c.v) ^ (std::hash<long long>()(c.vt) * 31) ^
               (std::hash<long long>()(c.vn) * 1009);
    }
};

}  // namespace

ObjModel read_obj_model(const fs::path& file, const fs::path& allowed, bool allow_file_access,
                        const SceneLimits& limits)
{
    const std::size_t max_triangles = limits.max_mesh_triangles;
    const std::size_t max_vertices = 3 * max_triangles + 3;
    std::vector<geom::Float3> v, vn;
    std::vector<geom::Float2> vt;
    std::map<std::string, MtlEntry> entries;
    std::map<fs::path, std::int16_t> texture_index;
    std::map<std::string, std::uint16_t> material_index;  ///< entries used, by name
    ObjModel model;
    std::unordered_map<Corner, std::uint32_t, CornerHash> corners;
    std::uint16_t material = 0;
    std::int16_t texture = geom::no_texture;
    bool default_material = false;  ///< faces before any usemtl use geom::Material{}
    geom::TriangleMesh& m = model.mesh;

    auto use_default = [&] {
        if (!default_material && model.materials.empty() && m.triangles.empty()) {
            model.materials.push_back(geom::Material{});
            default_material = true;
        }
    };
    auto index = [&](const std::string& w, std::size_t count, const char* what,
                     const FileLoc& loc) -> long long {
        long long i = 0;
        try {
            std::size_t used = 0;
            i = std::stoll(w, &used);
            if (used != w.size())
                throw std::invalid_argument(w);
        } catch (const std::exception&) {
            throw Error(loc, std::string("expected ") + what + " indices in the face, not '" + w + "'");
        }
        const long long n = static_cast<long long>(count);
        const long long k = i < 0 ? n + i : i - 1;
        if (i == 0 || k < 0 || k >= n)
            throw Error(loc, std::string(what) + " index " + std::to_string(i) +
                                 " is not one defined before the face");
        return k;
    };

    for_each_obj_line(file, "the mesh", limits, [&](const std::string& kind, std::istringstream& words,
                                               const std::string& text, const FileLoc& loc) {
        if (kind == "v" || kind == "vn") {
            double x, y, z;
            if (!(words >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) ||
                !std::isfinite(z) || std::max({std::abs(x), std::abs(y), std::abs(z)}) > 1e9)
                throw Error(loc, "expected '" + kind + " x y z' with finite coordinates");
            auto& to = kind == "v" ? v : vn;
            if (to.size() >= max_vertices)
                throw Error(loc, "more than " + std::to_string(max_vertices) + " '" + kind + "' lines");
            to.push_back({float(x), float(y), float(z)});
        } else if (kind == "vt") {
            double s, t = 0;
            if (!(words >> s) || !std::isfinite(s))
                throw Error(loc, "expected 'vt u v' with finite coordinates");
            if (!(words >> t))
                t = 0;
            if (!std::isfinite(t))
                throw Error(loc, "expected 'vt u v' with finite coordinates");
            if (vt.size() >= max_vertices)
                throw Error(loc, "more than " + std::to_string(max_vertices) + " 'vt' lines");
            vt.push_back({float(s), float(t)});
        } else if (kind == "mtllib") {
            // several names on one line are allowed by the format; Cambium writes one
            for (std::string name; words >> name;) {
                fs::path mtl = confined(name, file.parent_path(), allowed, allow_file_access, loc);
                try {
                    read_mtl(mtl, allowed, allow_file_access, limits, entries, texture_index, model);
                } catch (const Error& e) {
                    throw Error(loc, "in the MTL file '" + name + "': " + nested_message(e));
                }
            }
        } else if (kind == "usemtl") {
            const std::string name = rest(text, kind, loc);
            auto entry = entries.find(name);
            if (entry == entries.end())
                throw Error(loc, "no material '" + name + "' in the MTL files named before it");
            auto [it, added] = material_index.emplace(name, std::uint16_t(model.materials.size()));
            if (added) {
                if (model.materials.size() >= limits.max_mesh_materials)
                    throw Error(loc, "more than " + std::to_string(limits.max_mesh_materials) +
                                         " materials");
                model.materials.push_back(entry->second.material);
            }
            material = it->second;
            texture = entry->second.texture;
        } else if (kind == "f") {
            use_default();
            std::vector<Corner> face;
            for (std::string w; words >> w;) {
                if (face.size() >= 1024)
                    throw Error(loc, "a face of more than 1024 corners");
                Corner c;
                std::size_t a = w.find('/');
                c.v = index(w.substr(0, a), v.size(), "vertex", loc);
                if (a != std::string::npos) {
                    std::size_t b = w.find('/', a + 1);
                    std::string t = w.substr(a + 1, b == std::string::npos ? std::string::npos : b - a - 1);
                    if (!t.empty())
                        c.vt = index(t, vt.size(), "texture coordinate", loc);
                    if (b != std::string::npos)
                        c.vn = index(w.substr(b + 1), vn.size(), "normal", loc);
                }
                face.push_back(c);
            }
            if (face.size() < 3)
                throw Error(loc, "a face needs 3 vertices at least");
            if (m.triangles.size() + face.size() - 2 > max_triangles)
                throw Error(loc, "the mesh has more than " + std::to_string(max_triangles) +
                                     " triangles");
            auto position = [&](const Corner& c) {
                const geom::Float3& p = v[std::size_t(c.v)];
                return geom::Vec3{p[0], p[1], p[2]};
            };
            // a face without normals is flat: its corners are its own
            const geom::Vec3 flat = geom::normalize(geom::cross(position(face[1]) - position(face[0]),
                                                                position(face[2]) - position(face[0])));
            std::vector<std::uint32_t> ids;
            for (const Corner& c : face) {
                auto found = c.vn >= 0 ? corners.find(c) : corners.end();
                if (found != corners.end()) {
                    ids.push_back(found->second);
                    continue;
                }
                const auto id = static_cast<std::uint32_t>(m.positions.size());
                m.positions.push_back(v[std::size_t(c.v)]);
                geom::Float3 n = c.vn >= 0 ? vn[std::size_t(c.vn)]
                                           : geom::Float3{float(flat.x), float(flat.y), float(flat.z)};
                m.normals.push_back(n);
                m.uvs.push_back(c.vt >= 0 ? vt[std::size_t(c.vt)] : geom::Float2{0, 0});
                if (c.vn >= 0)
                    corners.emplace(c, id);
                ids.push_back(id);
            }
            for (std::size_t i = 1; i + 1 < ids.size(); ++i) {
                m.triangles.push_back({ids[0], ids[i], ids[i + 1]});
                m.material.push_back(material);
                m.back_material.push_back(material);
                m.texture.push_back(texture);
            }
        }
        // g, o, s, l and the rest carry nothing a surface needs
    });
    if (m.triangles.empty())
        throw Error(FileLoc{file.string()}, "the mesh has no faces");
    return model;
}

}  // namespace cambium::app
