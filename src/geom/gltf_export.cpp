// SPDX-License-Identifier: Apache-2.0
// The plant as binary glTF 2.0 (.glb) through tinygltf: a node per organ (the module that
// drew it), a shared mesh per placed prototype, metallic-roughness materials.
#include "geom/gltf_export.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <tuple>

#include "base/atomic_file.h"
#include "base/diagnostics.h"
#include "base/input_file.h"
#include "geom/placed_geometry.h"

namespace cambium::geom {
namespace {

/// Embedded texture files may be at most this large each.
constexpr std::uintmax_t max_texture_file_bytes = std::uintmax_t{256} << 20;

double srgb_to_linear(double v)
{
    v = std::clamp(v, 0.0, 1.0);
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

std::vector<double> linear(const Rgb& c) { return {srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b)}; }

/// glTF's roughness for cpfg's shininess s (OpenGL's Blinn-Phong exponent): Cambium's
/// normalized Phong exponent n = s / 4 (docs/materials.md), the Beckmann width
/// alpha = sqrt(2 / (n + 2)) of the same lobe, and roughness = sqrt(alpha) as glTF
/// squares it.
double roughness_of(float shininess)
{
    const double n = std::max(0.0, double(shininess)) / 4.0;
    return std::sqrt(std::sqrt(2.0 / (n + 2.0)));
}

/// The MIME type of an image file glTF can embed (PNG or JPEG by their magic numbers), or "".
std::string embeddable_mime(const std::vector<unsigned char>& bytes)
{
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), "\x89PNG\r\n\x1a\n", 8) == 0)
        return "image/png";
    if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff)
        return "image/jpeg";
    return "";
}

/// Builds the glTF model: one buffer with four views (positions, normals, uvs, indices)
/// that every primitive's accessors point into.
class GltfBuilder {
public:
    GltfBuilder(const Scene& scene, const MeshExportOptions& options)
        : m_scene(scene), m_options(options)
    {
        m_model.asset.version = "2.0";
        m_model.asset.generator = "Cambium";
        m_model.buffers.emplace_back();
    }

    /// The triangles of `mesh` listed in `triangles` as one glTF mesh (a primitive per
    /// material and texture); returns its index, or -1 when there are none.
    /// `segments` of `lines` (pixel-wide lines: `line style: pixel`) join it as line
    /// primitives of unlit materials, as cpfg draws them.
    int add_mesh(const TriangleMesh& mesh, const std::vector<std::size_t>& triangles, const std::string& name,
                 const LinearCurves* lines = nullptr, const std::vector<std::size_t>& segments = {})
    {
        std::map<std::pair<std::uint16_t, std::int16_t>, std::vector<std::size_t>> groups;
        for (std::size_t t : triangles)
            groups[{mesh.material[t], mesh.texture[t]}].push_back(t);
        tinygltf::Mesh out;
        out.name = name;
        for (const auto& [key, group] : groups)
            out.primitives.push_back(primitive(mesh, group, key.first, key.second));
        std::map<std::uint16_t, std::vector<std::size_t>> line_groups;
        for (std::size_t s : segments)
            line_groups[lines->material[s]].push_back(s);
        for (const auto& [material, group] : line_groups)
            out.primitives.push_back(line_primitive(*lines, group, material));
        if (out.primitives.empty())
            return -1;
        m_model.meshes.push_back(std::move(out));
        return static_cast<int>(m_model.meshes.size() - 1);
    }

    int add_node(tinygltf::Node node)
    {
        m_model.nodes.push_back(std::move(node));
        return static_cast<int>(m_model.nodes.size() - 1);
    }

    tinygltf::Model finish(std::vector<int> roots)
    {
        tinygltf::Buffer& buffer = m_model.buffers[0];
        auto view = [&](std::vector<unsigned char>& bytes, int target, int stride) {
            while (buffer.data.size() % 4 != 0)
                buffer.data.push_back(0);
            tinygltf::BufferView v;
            v.buffer = 0;
            v.byteOffset = buffer.data.size();
            v.byteLength = bytes.size();
            v.target = target;
            v.byteStride = stride;  // vertex attributes of many primitives share a view
            buffer.data.insert(buffer.data.end(), bytes.begin(), bytes.end());
            m_model.bufferViews.push_back(v);
        };
        // the accessors were numbered with these views' indices: 0 positions, 1 normals,
        // 2 uvs, 3 indices; images' views follow
        view(m_positions, TINYGLTF_TARGET_ARRAY_BUFFER, 12);
        view(m_normals, TINYGLTF_TARGET_ARRAY_BUFFER, 12);
        view(m_uvs, TINYGLTF_TARGET_ARRAY_BUFFER, 8);
        view(m_indices, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, 0);
        for (auto& [image, bytes] : m_image_bytes) {
            view(bytes, 0, 0);
            m_model.images[std::size_t(image)].bufferView = static_cast<int>(m_model.bufferViews.size() - 1);
        }
        // glTF forbids empty buffer views: drop the unused ones (and renumber)
        std::vector<int> renumber(m_model.bufferViews.size(), -1);
        std::vector<tinygltf::BufferView> kept;
        for (std::size_t i = 0; i < m_model.bufferViews.size(); ++i)
            if (m_model.bufferViews[i].byteLength > 0) {
                renumber[i] = static_cast<int>(kept.size());
                kept.push_back(m_model.bufferViews[i]);
            }
        m_model.bufferViews = std::move(kept);
        for (auto& a : m_model.accessors)
            a.bufferView = renumber[std::size_t(a.bufferView)];
        for (auto& i : m_model.images)
            i.bufferView = renumber[std::size_t(i.bufferView)];
        if (buffer.data.empty())  // nothing drawn: glTF allows no buffer, not an empty one
            m_model.buffers.clear();
        tinygltf::Scene scene;
        scene.name = "plant";
        scene.nodes = std::move(roots);
        m_model.scenes.push_back(std::move(scene));
        m_model.defaultScene = 0;
        return std::move(m_model);
    }

private:
    template <typename T>
    static std::size_t append(std::vector<unsigned char>& bytes, const T& value)
    {
        const std::size_t at = bytes.size();
        bytes.resize(at + sizeof value);
        std::memcpy(bytes.data() + at, &value, sizeof value);
        return at;
    }

    int accessor(int view, std::size_t offset, std::size_t count, int type, int component)
    {
        tinygltf::Accessor a;
        a.bufferView = view;
        a.byteOffset = offset;
        a.count = count;
        a.type = type;
        a.componentType = component;
        m_model.accessors.push_back(std::move(a));
        return static_cast<int>(m_model.accessors.size() - 1);
    }

    tinygltf::Primitive primitive(const TriangleMesh& mesh, const std::vector<std::size_t>& triangles,
                                  std::uint16_t material, std::int16_t texture)
    {
        // the triangles' vertices, renumbered from 0 in this primitive
        std::map<std::uint32_t, std::uint32_t> local;
        std::vector<std::uint32_t> order;
        for (std::size_t t : triangles)
            for (std::uint32_t v : mesh.triangles[t])
                if (local.emplace(v, static_cast<std::uint32_t>(order.size())).second)
                    order.push_back(v);
        const bool textured = texture != no_texture;
        const std::size_t positions_at = m_positions.size(), normals_at = m_normals.size();
        const std::size_t uvs_at = m_uvs.size(), indices_at = m_indices.size();
        std::vector<double> low(3, 1e300), high(3, -1e300);
        for (std::uint32_t v : order) {
            const Float3& p = mesh.positions[v];
            for (int k = 0; k < 3; ++k) {
                append(m_positions, p[k]);
                low[k] = std::min(low[k], double(p[k]));
                high[k] = std::max(high[k], double(p[k]));
            }
            for (float x : unit_normal(mesh, v))
                append(m_normals, x);
            if (textured) {
                const Float2 uv = v < mesh.uvs.size() ? mesh.uvs[v] : Float2{0, 0};
                append(m_uvs, uv[0]);
                append(m_uvs, 1.0f - uv[1]);  // glTF's images start at the top row, OpenGL's at the bottom
            }
        }
        for (std::size_t t : triangles)
            for (std::uint32_t v : mesh.triangles[t])
                append(m_indices, local[v]);
        tinygltf::Primitive p;
        p.mode = TINYGLTF_MODE_TRIANGLES;
        const int position = accessor(0, positions_at, order.size(), TINYGLTF_TYPE_VEC3,
                                      TINYGLTF_COMPONENT_TYPE_FLOAT);
        m_model.accessors[std::size_t(position)].minValues = low;
        m_model.accessors[std::size_t(position)].maxValues = high;
        p.attributes["POSITION"] = position;
        p.attributes["NORMAL"] = accessor(1, normals_at, order.size(), TINYGLTF_TYPE_VEC3,
                                          TINYGLTF_COMPONENT_TYPE_FLOAT);
        if (textured)
            p.attributes["TEXCOORD_0"] = accessor(2, uvs_at, order.size(), TINYGLTF_TYPE_VEC2,
                                                  TINYGLTF_COMPONENT_TYPE_FLOAT);
        p.indices = accessor(3, indices_at, triangles.size() * 3, TINYGLTF_TYPE_SCALAR,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
        p.material = material_index(material, texture);
        return p;
    }

    tinygltf::Primitive line_primitive(const LinearCurves& lines, const std::vector<std::size_t>& segments,
                                       std::uint16_t material)
    {
        const std::size_t positions_at = m_positions.size();
        std::vector<double> low(3, 1e300), high(3, -1e300);
        for (std::size_t s : segments)
            for (std::uint32_t key : {lines.segments[s], lines.segments[s] + 1})
                for (int k = 0; k < 3; ++k) {
                    const float x = lines.keys[key][std::size_t(k)];
                    append(m_positions, x);
                    low[std::size_t(k)] = std::min(low[std::size_t(k)], double(x));
                    high[std::size_t(k)] = std::max(high[std::size_t(k)], double(x));
                }
        tinygltf::Primitive p;
        p.mode = TINYGLTF_MODE_LINE;
        const int position = accessor(0, positions_at, segments.size() * 2, TINYGLTF_TYPE_VEC3,
                                      TINYGLTF_COMPONENT_TYPE_FLOAT);
        m_model.accessors[std::size_t(position)].minValues = low;
        m_model.accessors[std::size_t(position)].maxValues = high;
        p.attributes["POSITION"] = position;
        p.material = material_index(material, no_texture, true);
        return p;
    }

    /// A vertex normal of unit length (glTF requires it): a zero or non-finite one takes
    /// the normal of the first triangle's plane, else +y.
    static Float3 unit_normal(const TriangleMesh& mesh, std::uint32_t v)
    {
        const Float3& n = mesh.normals[v];
        const double l = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
        if (std::isfinite(l) && l > 1e-12)
            return {float(n[0] / l), float(n[1] / l), float(n[2] / l)};
        return {0, 1, 0};
    }

    int material_index(std::uint16_t material, std::int16_t texture, bool unlit = false)
    {
        const auto key = std::tuple(material, texture, unlit);
        if (auto it = m_materials.find(key); it != m_materials.end())
            return it->second;
        static const Material fallback;
        const Material& m = material < m_scene.materials.size() ? m_scene.materials[material] : fallback;
        tinygltf::Material out;
        out.name = "colour " + std::to_string(material) +
                   (texture == no_texture ? "" : " texture " + std::to_string(texture));
        std::vector<double> base = linear(m.diffuse);
        base.push_back(1.0);
        out.pbrMetallicRoughness.baseColorFactor = base;
        out.pbrMetallicRoughness.metallicFactor = 0.0;
        out.pbrMetallicRoughness.roughnessFactor = roughness_of(m.shininess);
        out.emissiveFactor = linear(m.emission);
        out.doubleSided = true;  // leaves and petals are seen from both sides
        if (unlit) {
            out.name += " unlit";
            out.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object{});
            if (std::find(m_model.extensionsUsed.begin(), m_model.extensionsUsed.end(),
                          "KHR_materials_unlit") == m_model.extensionsUsed.end())
                m_model.extensionsUsed.push_back("KHR_materials_unlit");
        }
        tinygltf::Value::Object extras;
        extras["cpfg_colour_index"] = tinygltf::Value(int(material));
        std::vector<tinygltf::Value> specular;
        for (double c : linear(m.specular))
            specular.emplace_back(c);
        extras["specular"] = tinygltf::Value(specular);
        extras["shininess"] = tinygltf::Value(double(m.shininess));
        extras["translucency"] = tinygltf::Value(double(m.translucency));
        extras["transparency"] = tinygltf::Value(double(m.transparency));
        out.extras = tinygltf::Value(extras);
        if (texture != no_texture)
            if (const int image = image_index(texture); image >= 0) {
                tinygltf::Texture t;
                t.source = image;
                m_model.textures.push_back(t);
                out.pbrMetallicRoughness.baseColorTexture.index =
                    static_cast<int>(m_model.textures.size() - 1);
                if (m_scene.textures[std::size_t(texture)].decal)
                    out.pbrMetallicRoughness.baseColorFactor = {1, 1, 1, 1};
                // cut-out leaves: the renderer ignores hits where alpha < 0.5 (docs/materials.md)
                out.alphaMode = "MASK";
                out.alphaCutoff = 0.5;
            }
        m_model.materials.push_back(std::move(out));
        const int index = static_cast<int>(m_model.materials.size() - 1);
        m_materials.emplace(key, index);
        return index;
    }

    /// The embedded image of texture `texture`, or -1 when its file is neither PNG nor
    /// JPEG and the options' png_of cannot re-encode it (glTF embeds only those; the
    /// material keeps its colour, with a warning).
    int image_index(std::int16_t texture)
    {
        if (auto it = m_images.find(texture); it != m_images.end())
            return it->second;
        std::filesystem::path file = m_scene.textures.at(std::size_t(texture)).file;
        if (file.is_relative())
            file = m_options.texture_folder / file;
        int index = -1;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file, ec)) {
            warn(FileLoc{file.string()}, "texture not found; exported without it");
        } else {
            std::vector<unsigned char> bytes = read_binary_file(file, "the texture", max_texture_file_bytes);
            std::string mime = embeddable_mime(bytes);
            if (mime.empty() && m_options.png_of) {  // re-encoded: glTF embeds PNG and JPEG only
                bytes = m_options.png_of(file);
                mime = embeddable_mime(bytes);
            }
            if (mime.empty()) {
                warn(FileLoc{file.string()},
                     "glTF embeds PNG and JPEG textures only; exported without this one");
            } else {
                tinygltf::Image image;
                image.name = file.filename().string();
                image.mimeType = mime;
                m_model.images.push_back(image);
                index = static_cast<int>(m_model.images.size() - 1);
                m_image_bytes.emplace_back(index, std::move(bytes));
            }
        }
        m_images.emplace(texture, index);
        return index;
    }

    const Scene& m_scene;
    const MeshExportOptions& m_options;
    tinygltf::Model m_model;
    std::vector<unsigned char> m_positions, m_normals, m_uvs, m_indices;
    std::map<std::tuple<std::uint16_t, std::int16_t, bool>, int> m_materials;
    std::map<std::int16_t, int> m_images;
    std::vector<std::pair<int, std::vector<unsigned char>>> m_image_bytes;
};

/// "L 1234": the organ's symbol and its index in the derived string; extras give both
/// and its age.
tinygltf::Node organ_node(const ModuleTable& modules, std::uint32_t module)
{
    tinygltf::Node node;
    if (module == no_module) {
        node.name = "unattributed";  // drawn by no module: a background scene, a scene's ground
        return node;
    }
    tinygltf::Value::Object extras;
    extras["module"] = tinygltf::Value(int(module));
    if (const ModuleRecord* r = modules.find(module)) {
        node.name = std::string(modules.name(*r)) + " " + std::to_string(module);
        extras["symbol"] = tinygltf::Value(std::string(modules.name(*r)));
        if (r->age != unknown_age)
            extras["age"] = tinygltf::Value(int(r->age));
    } else {
        node.name = "module " + std::to_string(module);
    }
    node.extras = tinygltf::Value(extras);
    return node;
}

/// An instance's 3x4 column-major transform as glTF's 4x4 column-major matrix.
std::vector<double> matrix_of(const std::array<float, 12>& m)
{
    return {m[0], m[1], m[2], 0, m[3], m[4], m[5], 0, m[6], m[7], m[8], 0, m[9], m[10], m[11], 1};
}

}  // namespace

std::size_t gltf_primitives(const Scene& scene, const Tessellation& how)
{
    std::size_t n = tessellated_triangles(scene.geometry, scene.line_radius_in_pixels, how);
    if (scene.line_radius_in_pixels)
        n += scene.geometry.lines.segment_count();
    // one shared mesh per prototype and instance look (material, texture)
    std::map<std::tuple<std::uint32_t, std::uint16_t, std::uint16_t, std::int16_t>, bool> looks;
    for (const Instance& i : scene.instances)
        if (looks.emplace(std::tuple(i.prototype, i.material, i.back_material, i.texture), true).second)
            n += tessellated_triangles(scene.prototypes.at(i.prototype).geometry,
                                       scene.line_radius_in_pixels, how);
    return n;
}

void write_glb(const Scene& scene, const std::filesystem::path& file, const MeshExportOptions& options)
{
    GltfBuilder builder(scene, options);
    std::vector<int> roots;
    // the scene's own primitives: a node per organ
    {
        const TriangleMesh mesh = tessellate_geometry(scene.geometry, scene.line_radius_in_pixels,
                                                      options.tessellation);
        // per organ, its triangles and (pixel-wide lines, which tessellation leaves out) its segments
        std::map<std::uint32_t, std::pair<std::vector<std::size_t>, std::vector<std::size_t>>> organs;
        for (std::size_t t = 0; t < mesh.size(); ++t)
            organs[t < mesh.module.size() ? mesh.module[t] : no_module].first.push_back(t);
        const LinearCurves& lines = scene.geometry.lines;
        if (scene.line_radius_in_pixels)
            for (std::size_t s = 0; s < lines.segment_count(); ++s)
                organs[s < lines.module.size() ? lines.module[s] : no_module].second.push_back(s);
        for (const auto& [module, primitives] : organs) {
            tinygltf::Node node = organ_node(scene.geometry.modules, module);
            node.mesh = builder.add_mesh(mesh, primitives.first, node.name, &lines, primitives.second);
            if (node.mesh >= 0)
                roots.push_back(builder.add_node(std::move(node)));
        }
    }
    // placed prototypes: one mesh per prototype and look, a node per instance
    std::map<std::tuple<std::uint32_t, std::uint16_t, std::uint16_t, std::int16_t>, int> shared;
    const OrganModules organ_modules(scene);
    for (const Instance& instance : scene.instances) {
        const auto look = std::tuple(instance.prototype, instance.material, instance.back_material,
                                     instance.texture);
        auto it = shared.find(look);
        if (it == shared.end()) {
            // the instance's materials and texture, without its transform (the node has it)
            Instance colouring = instance;
            colouring.transform = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
            Geometry coloured = scene.prototypes.at(instance.prototype).geometry;
            place_geometry(coloured, colouring);
            const TriangleMesh mesh =
                tessellate_geometry(coloured, scene.line_radius_in_pixels, options.tessellation);
            std::vector<std::size_t> all(mesh.size());
            for (std::size_t t = 0; t < all.size(); ++t)
                all[t] = t;
            const Prototype& prototype = scene.prototypes.at(instance.prototype);
            it = shared.emplace(look, builder.add_mesh(mesh, all, prototype.name)).first;
        }
        if (it->second < 0)
            continue;
        tinygltf::Node node = organ_node(organ_modules.of(instance), instance.module);
        if (instance.module == no_module && instance.plant != Instance::no_plant) {
            // a scene file's plant: named by its placement
            node.name = "plant " + std::to_string(instance.plant) + " " +
                        scene.prototypes.at(instance.prototype).name;
            node.extras = tinygltf::Value(tinygltf::Value::Object{{"placement", tinygltf::Value(int(instance.plant))}});
        }
        node.mesh = it->second;
        node.matrix = matrix_of(instance.transform);
        roots.push_back(builder.add_node(std::move(node)));
    }
    tinygltf::Model model = builder.finish(std::move(roots));
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        tinygltf::TinyGLTF writer;
        if (!out || !writer.WriteGltfSceneToStream(&model, out, false, true))
            throw Error(file.string() + ": cannot write: " + std::strerror(errno));
        out.flush();
        if (!out)
            throw Error(file.string() + ": cannot write: " + std::strerror(errno));
    });
}

}  // namespace cambium::geom
