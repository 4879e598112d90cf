// SPDX-License-Identifier: Apache-2.0
// The plant as binary glTF: read back with tinygltf's loader, the file holds the
// tessellated plant, a node per organ named by its module, one mesh shared by the
// instances of an object, and cpfg's colours as linear base colours.
#include <gtest/gtest.h>

#include <tiny_gltf.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <string>

#include "app/pipeline.h"
#include "app/sequence.h"
#include "base/diagnostics.h"
#include "geom/gltf_export.h"
#include "geom/mesh_export.h"
#include "geom/tessellate.h"
#include "model_folder.h"

using namespace cambium;

namespace {

namespace fs = std::filesystem;

struct Built {
    app::Options options;
    geom::Scene scene;
    fs::path folder;
};

Built build(const std::string& name, const std::string& lsystem)
{
    Built b;
    b.options = cambium::testing::write_model(name, lsystem);
    b.options.quiet = true;
    b.folder = b.options.lsystem.parent_path();
    app::Model model = app::load_model(b.options);
    b.scene = app::interpret(model, app::derive(model, b.options), b.options);
    return b;
}

tinygltf::Model load(const fs::path& file)
{
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string error, warning;
    EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, file.string())) << error;
    return model;
}

/// The float3 values of an accessor.
std::vector<geom::Vec3> points(const tinygltf::Model& m, int accessor)
{
    const tinygltf::Accessor& a = m.accessors.at(std::size_t(accessor));
    const tinygltf::BufferView& v = m.bufferViews.at(std::size_t(a.bufferView));
    const std::size_t stride = v.byteStride ? v.byteStride : 12;
    const unsigned char* base = m.buffers.at(std::size_t(v.buffer)).data.data() + v.byteOffset + a.byteOffset;
    std::vector<geom::Vec3> out;
    for (std::size_t i = 0; i < a.count; ++i) {
        float xyz[3];
        std::memcpy(xyz, base + i * stride, sizeof xyz);
        out.push_back({xyz[0], xyz[1], xyz[2]});
    }
    return out;
}

/// A node's positions moved by its matrix (column-major 4x4) when it has one.
std::vector<geom::Vec3> placed_positions(const tinygltf::Model& m, const tinygltf::Node& node)
{
    std::vector<geom::Vec3> out;
    for (const tinygltf::Primitive& p : m.meshes.at(std::size_t(node.mesh)).primitives)
        for (geom::Vec3 q : points(m, p.attributes.at("POSITION"))) {
            if (!node.matrix.empty()) {
                const auto& t = node.matrix;
                q = {t[0] * q.x + t[4] * q.y + t[8] * q.z + t[12], t[1] * q.x + t[5] * q.y + t[9] * q.z + t[13],
                     t[2] * q.x + t[6] * q.y + t[10] * q.z + t[14]};
            }
            out.push_back(q);
        }
    return out;
}

std::size_t triangles(const tinygltf::Model& m, const tinygltf::Node& node)
{
    std::size_t n = 0;
    for (const tinygltf::Primitive& p : m.meshes.at(std::size_t(node.mesh)).primitives)
        n += m.accessors.at(std::size_t(p.indices)).count / 3;
    return n;
}

double srgb_decoded(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

/// The smallest box around points, as (low, high).
std::pair<geom::Vec3, geom::Vec3> box(const std::vector<geom::Vec3>& p)
{
    geom::Vec3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
    for (const geom::Vec3& q : p) {
        lo = {std::min(lo.x, q.x), std::min(lo.y, q.y), std::min(lo.z, q.z)};
        hi = {std::max(hi.x, q.x), std::max(hi.y, q.y), std::max(hi.z, q.z)};
    }
    return {lo, hi};
}

TEST(GltfExport, EachOrganIsANodeNamedByItsModule)
{
    // modules 0 F, 1 [, 2 +, 3 ;, 4 F, 5 @O, 6 ]: two cylinders in one bent chain (24
    // triangles each and a fan of 12 on each free end; the joint's ring of 24 with the
    // first, whose end it rounds) and a sphere (120)
    Built b = build("gltf_organs", "Lsystem: 1\nderivation length: 0\n"
                                   "Axiom: F(1)[+(30);(2)F(1)@O(0.2)]\nendlsystem\n");
    const fs::path file = b.folder / "plant.glb";
    geom::write_mesh(b.scene, file, MeshFormat::glb);
    const tinygltf::Model m = load(file);
    std::map<std::string, std::size_t> organs;
    std::vector<geom::Vec3> all;
    for (const tinygltf::Node& node : m.nodes) {
        organs[node.name] = triangles(m, node);
        for (const geom::Vec3& p : placed_positions(m, node))
            all.push_back(p);
    }
    EXPECT_EQ(organs, (std::map<std::string, std::size_t>{{"F 0", 60}, {"F 4", 36}, {"@O 5", 120}}));
    // the same plant as the other mesh formats' tessellation
    const geom::TriangleMesh mesh = geom::tessellate(b.scene, {});
    std::vector<geom::Vec3> expected;
    for (const auto& p : mesh.positions)
        expected.push_back({p[0], p[1], p[2]});
    const auto [lo, hi] = box(all);
    const auto [want_lo, want_hi] = box(expected);
    EXPECT_LT(geom::length(lo - want_lo) + geom::length(hi - want_hi), 1e-5);
    // the branch's colour 2, sRGB-decoded (glTF's base colour is linear)
    const geom::Rgb& diffuse = b.scene.materials.at(2).diffuse;
    bool found = false;
    for (const tinygltf::Material& material : m.materials)
        if (material.name == "colour 2") {
            found = true;
            EXPECT_NEAR(material.pbrMetallicRoughness.baseColorFactor[0], srgb_decoded(diffuse.r), 1e-6);
            EXPECT_NEAR(material.pbrMetallicRoughness.baseColorFactor[1], srgb_decoded(diffuse.g), 1e-6);
            EXPECT_EQ(material.pbrMetallicRoughness.metallicFactor, 0.0);
            EXPECT_TRUE(material.doubleSided);
        }
    EXPECT_TRUE(found);
}

TEST(GltfExport, InstancesOfAnObjectShareOneMesh)
{
    // three flowers K, each an -o> object of a cylinder and a sphere
    Built b = build("gltf_objects", "lsystem: 1\nderivation length: 3\naxiom: A\n"
                                    "A --> F(2)[+(40)K]/(137)A\nhomomorphism\n"
                                    "K -o> F(1)[;(2)@O(0.8)]\nendlsystem\n");
    ASSERT_EQ(b.scene.instances.size(), 3u);
    const fs::path file = b.folder / "plant.glb";
    geom::write_mesh(b.scene, file, MeshFormat::glb);
    const tinygltf::Model m = load(file);
    std::vector<const tinygltf::Node*> flowers;  // in the order of the scene's instances
    for (const tinygltf::Node& node : m.nodes)
        if (!node.matrix.empty()) {
            flowers.push_back(&node);
            EXPECT_EQ(node.name.substr(0, 2), "K ");
        }
    ASSERT_EQ(flowers.size(), 3u);
    EXPECT_EQ(flowers[0]->mesh, flowers[1]->mesh);
    EXPECT_EQ(flowers[0]->mesh, flowers[2]->mesh);
    // placed by their matrices, each flower's sphere lies where its instance puts the
    // prototype's sphere: every vertex at the radius from that centre
    const geom::Float4 sphere = b.scene.prototypes.at(0).geometry.spheres.centres.at(0);
    for (std::size_t k = 0; k < flowers.size(); ++k) {
        const auto& t = b.scene.instances[k].transform;
        const geom::Vec3 centre{t[0] * sphere[0] + t[3] * sphere[1] + t[6] * sphere[2] + t[9],
                                t[1] * sphere[0] + t[4] * sphere[1] + t[7] * sphere[2] + t[10],
                                t[2] * sphere[0] + t[5] * sphere[1] + t[8] * sphere[2] + t[11]};
        tinygltf::Node node = *flowers[k];
        tinygltf::Mesh only_sphere = m.meshes.at(std::size_t(node.mesh));
        std::erase_if(only_sphere.primitives, [&](const tinygltf::Primitive& p) {
            return m.materials.at(std::size_t(p.material)).name != "colour 2";
        });
        ASSERT_EQ(only_sphere.primitives.size(), 1u);
        for (const geom::Vec3& p : points(m, only_sphere.primitives[0].attributes.at("POSITION"))) {
            const geom::Vec3 q{node.matrix[0] * p.x + node.matrix[4] * p.y + node.matrix[8] * p.z + node.matrix[12],
                               node.matrix[1] * p.x + node.matrix[5] * p.y + node.matrix[9] * p.z + node.matrix[13],
                               node.matrix[2] * p.x + node.matrix[6] * p.y + node.matrix[10] * p.z + node.matrix[14]};
            EXPECT_NEAR(geom::length(q - centre), sphere[3], 1e-4) << "flower " << k;
        }
    }
    EXPECT_EQ(geom::gltf_primitives(b.scene, {}), geom::tessellated_triangles(b.scene.geometry, false, {}) +
                                                      geom::tessellated_triangles(b.scene.prototypes[0].geometry, false, {}));
}

// glTF embeds PNG and JPEG only: an SGI texture (cpfg's usual format) is re-encoded as a
// PNG of the same pixels rather than left out.
TEST(GltfExport, SgiTextureIsEmbeddedAsAPngOfItsPixels)
{
    app::Options options = cambium::testing::write_model(
        "gltf_sgi", "Lsystem: 1\nderivation length: 0\nAxiom: @Tx(1) F(1)\nendlsystem\n");
    options.quiet = true;
    const fs::path folder = options.lsystem.parent_path();
    std::ofstream(options.view, std::ios::app) << "texture: F: bark.rgb\n";
    // 4 x 2 texels of distinct colours
    constexpr int w = 4, h = 2;
    std::vector<unsigned char> texels(w * h * 3);
    for (std::size_t i = 0; i < texels.size(); ++i)
        texels[i] = static_cast<unsigned char>(17 + 29 * i);
    {
        auto out = OIIO::ImageOutput::create((folder / "bark.rgb").string());
        ASSERT_TRUE(out);
        ASSERT_TRUE(out->open((folder / "bark.rgb").string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::UINT8)));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels.data()));
        out->close();
    }
    app::Model model = app::load_model(options);
    const geom::Scene scene = app::interpret(model, app::derive(model, options), options);
    app::write_geometry_output(scene, options, folder / "bark.glb");

    const tinygltf::Model m = load(folder / "bark.glb");
    ASSERT_EQ(m.images.size(), 1u);
    const tinygltf::Image& image = m.images[0];
    EXPECT_EQ(image.mimeType, "image/png");
    ASSERT_EQ(image.width, w);
    ASSERT_EQ(image.height, h);
    ASSERT_GE(image.component, 3);
    for (int p = 0; p < w * h; ++p)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(int(image.image[std::size_t(p * image.component + c)]), int(texels[std::size_t(p * 3 + c)]))
                << "texel " << p << " channel " << c;
    ASSERT_EQ(m.textures.size(), 1u);
    EXPECT_GE(m.materials.at(0).pbrMetallicRoughness.baseColorTexture.index, 0);
}

TEST(GltfExport, PastTheMemoryBudgetNothingIsWritten)
{
    Built b = build("gltf_budget", "Lsystem: 1\nderivation length: 0\nAxiom: F(1)F(1)\nendlsystem\n");
    geom::MeshExportOptions small;
    small.max_memory_bytes = 1000;
    EXPECT_THROW(geom::write_mesh(b.scene, b.folder / "big.glb", MeshFormat::glb, small), Error);
    EXPECT_FALSE(fs::exists(b.folder / "big.glb"));
}

}  // namespace
