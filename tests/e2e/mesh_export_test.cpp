// SPDX-License-Identifier: Apache-2.0
// The plant as mesh files: OBJ, PLY and GLS hold the tessellated plant, each read back
// by a reader that is not the writer's (the scene files' OBJ reader, the background
// scene's GLS reader, the PLY header and bytes by hand).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "app/pipeline.h"
#include "app/scene_file.h"
#include "base/diagnostics.h"
#include "geom/background_scene.h"
#include "geom/inventor_export.h"
#include "geom/mesh_export.h"
#include "geom/tessellate.h"
#include "model_folder.h"

using namespace cambium;

namespace {

namespace fs = std::filesystem;

geom::Vec3 vec(const geom::Float3& p) { return {p[0], p[1], p[2]}; }

/// A stem with a coloured branch ending in a sphere: two cylinders of 12 sides (24
/// triangles each) in one chain bent by 30 degrees (the branch continues the stem's
/// polyline), closed by a fan of 12 at each free end and one ring of the joint's sphere
/// (24), and a sphere of 12 meridians and 6 bands (120 triangles).
struct Plant {
    app::Options options;
    geom::Scene scene;
    fs::path folder;

    explicit Plant(const char* axiom = "F(1)[+(30);(2)F(1)@O(0.2)]")
    {
        options = cambium::testing::write_model("mesh_export", std::string("Lsystem: 1\nderivation length: 0\n"
                                                      "Axiom: ") + axiom + "\nendlsystem\n");
        options.quiet = true;
        folder = options.lsystem.parent_path();
        app::Model model = app::load_model(options);
        scene = app::interpret(model, app::derive(model, options), options);
    }
};

TEST(Tessellate, EveryTriangleFacesWhereItsNormalsPoint)
{
    Plant plant;
    const geom::TriangleMesh mesh = geom::tessellate(plant.scene, {});
    ASSERT_EQ(mesh.size(), 2 * 24u + 2 * 12u + 24u + 120u);
    EXPECT_EQ(geom::tessellated_triangles(plant.scene, {}), mesh.size());
    // the joint's zone turns the whole end ring: its half on the bend's inner side lies
    // inside both cylinders, folded back (the two halves' volumes cancel, so the surface
    // stays closed), and faces inward
    const geom::LinearCurves& lines = plant.scene.geometry.lines;
    ASSERT_EQ(lines.keys.size(), 3u);
    const geom::Vec3 joint{lines.keys[1][0], lines.keys[1][1], lines.keys[1][2]};
    auto key = [&](int k) { return geom::Vec3{lines.keys[k][0], lines.keys[k][1], lines.keys[k][2]}; };
    const geom::Vec3 inner = geom::normalize(key(2) - key(1)) - geom::normalize(key(1) - key(0));
    const double r = lines.keys[1][3];
    auto folded_back = [&](const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c) {
        for (const geom::Vec3& p : {a, b, c})
            if (std::abs(geom::length(p - joint) - r) > 1e-5 * r)
                return false;
        return geom::dot((a + b + c) / 3 - joint, inner) > 0;
    };
    for (const auto& t : mesh.triangles) {
        const geom::Vec3 a = vec(mesh.positions[t[0]]), b = vec(mesh.positions[t[1]]),
                         c = vec(mesh.positions[t[2]]);
        const geom::Vec3 face = geom::cross(b - a, c - a);
        if (geom::length(face) < 1e-9 || folded_back(a, b, c))
            continue;  // a pole's sliver, or inside the cylinders
        const geom::Vec3 n = vec(mesh.normals[t[0]]) + vec(mesh.normals[t[1]]) + vec(mesh.normals[t[2]]);
        EXPECT_GT(geom::dot(face, n), 0);
    }
}

/// The volume the triangles enclose, measured from `origin`: the same from every origin
/// only when the surface is closed.
double enclosed_volume(const geom::TriangleMesh& mesh, const geom::Vec3& origin)
{
    double volume = 0;
    for (const auto& t : mesh.triangles) {
        const geom::Vec3 a = vec(mesh.positions[t[0]]) - origin, b = vec(mesh.positions[t[1]]) - origin,
                         c = vec(mesh.positions[t[2]]) - origin;
        volume += geom::dot(a, geom::cross(b, c)) / 6;
    }
    return volume;
}

// A bent chain of two cylinders is closed as the renderer closes it: a fan on each free
// end and, at the 45 degree joint, two rings' zone of the joint's sphere (one ring per
// 30 degrees of bend), so the surface encloses the same volume from any origin: the two
// 12-sided prisms' (the zone's inner and outer halves cancel).
TEST(Tessellate, BentChainIsClosedAtItsEndsAndJoint)
{
    Plant plant("F(1)+(45)F(1)");
    const geom::TriangleMesh mesh = geom::tessellate(plant.scene, {});
    ASSERT_EQ(mesh.size(), 2 * 24u + 2 * 12u + 2 * 24u);
    EXPECT_EQ(geom::tessellated_triangles(plant.scene, {}), mesh.size());
    const double r = plant.scene.geometry.lines.keys.at(0)[3];
    ASSERT_GT(r, 0);
    const double prisms = 2 * 6 * r * r * std::sin(2 * std::acos(-1.0) / 12) * 1.0;
    for (const geom::Vec3 origin : {geom::Vec3{0, 0, 0}, geom::Vec3{5, -3, 7}, geom::Vec3{-20, 10, 2}})
        EXPECT_NEAR(enclosed_volume(mesh, origin), prisms, 1e-4 * prisms);
    EXPECT_EQ(geom::tessellate(plant.scene, {12, 4, false}).size(), 2 * 24u);
}

TEST(MeshExport, ObjPlyAndGlsHoldTheTessellatedPlant)
{
    Plant plant;
    const geom::TriangleMesh mesh = geom::tessellate(plant.scene, {});
    for (const char* name : {"plant.obj", "plant.ply", "plant.gls"})
        geom::write_mesh(plant.scene, plant.folder / name,
                         find_output_format(plant.folder / name)->mesh);

    // OBJ: the positions in order, through the scene files' OBJ reader
    const app::GroundMesh obj = app::read_obj_mesh(plant.folder / "plant.obj", app::SceneLimits{});
    ASSERT_EQ(obj.triangles.size(), mesh.size());
    ASSERT_EQ(obj.positions.size(), mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
        EXPECT_LT(geom::length(vec(obj.positions[i]) - vec(mesh.positions[i])), 1e-5);
    std::ifstream mtl(plant.folder / "plant.mtl");
    std::stringstream materials;
    materials << mtl.rdbuf();
    EXPECT_NE(materials.str().find("newmtl colour2"), std::string::npos);  // the branch's ;(2)

    // GLS: the background scene's reader builds the same triangles with the same colours
    const geom::BackgroundScene gls = geom::read_background_scene(
        std::vector<std::filesystem::path>{"plant.gls"}, plant.folder, geom::Material{}, FileLoc{}, plant.folder);
    ASSERT_EQ(gls.geometry.mesh.size(), mesh.size());
    for (std::size_t t = 0; t < mesh.size(); ++t)
        for (int k = 0; k < 3; ++k)
            EXPECT_LT(geom::length(vec(gls.geometry.mesh.positions[gls.geometry.mesh.triangles[t][k]]) -
                                   vec(mesh.positions[mesh.triangles[t][k]])),
                      1e-6);
    const geom::Material& branch = plant.scene.materials[2];
    const geom::Material& read = gls.materials.at(gls.geometry.mesh.material.back());
    EXPECT_EQ(read.diffuse, branch.diffuse);
    EXPECT_EQ(read.ambient, branch.ambient);

    // PLY: binary little-endian vertices with the material's diffuse colour as bytes
    std::ifstream ply(plant.folder / "plant.ply", std::ios::binary);
    std::string line, header;
    while (std::getline(ply, line) && line != "end_header")
        header += line + "\n";
    EXPECT_NE(header.find("element vertex " + std::to_string(mesh.positions.size())), std::string::npos);
    EXPECT_NE(header.find("element face " + std::to_string(mesh.size())), std::string::npos);
    float xyz[6];
    unsigned char rgb[3];
    ply.read(reinterpret_cast<char*>(xyz), sizeof xyz);
    ply.read(reinterpret_cast<char*>(rgb), sizeof rgb);
    EXPECT_EQ(xyz[0], mesh.positions[0][0]);
    EXPECT_EQ(rgb[0], static_cast<unsigned char>(
                          std::lround(plant.scene.materials[mesh.material[0]].diffuse.r * 255)));
}

/// The numbers of an Inventor field's list `name [ ... ]` after `from` in `text`.
std::vector<double> inventor_list(const std::string& text, const std::string& name, std::size_t from = 0)
{
    const std::size_t at = text.find(name + " [", from);
    if (at == std::string::npos)
        return {};
    const std::size_t end = text.find(']', at);
    std::string inside = text.substr(at + name.size() + 2, end - at - name.size() - 2);
    for (char& c : inside)
        c = c == ',' ? ' ' : c;
    std::istringstream in(inside);
    std::vector<double> out;
    for (double v; in >> v;)
        out.push_back(v);
    return out;
}

// -iv: the Inventor 2.1 scene holds the tessellated plant: its points in order, one face
// of three indices a triangle, and a material a face whose diffuse colour is the
// triangle's material's.
TEST(MeshExport, InventorHoldsTheTessellatedPlant)
{
    Plant plant;
    const geom::TriangleMesh mesh = geom::tessellate(plant.scene, {});
    geom::write_inventor(plant.scene, plant.folder / "plant.iv");
    std::ifstream in(plant.folder / "plant.iv");
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string iv = buffer.str();
    EXPECT_EQ(iv.rfind("#Inventor V2.1 ascii\n", 0), 0u);
    const std::vector<double> points = inventor_list(iv, "point");
    ASSERT_EQ(points.size(), 3 * mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(points[3 * i + k], mesh.positions[i][k], 1e-6);
    const std::vector<double> faces = inventor_list(iv, "coordIndex");
    ASSERT_EQ(faces.size(), 4 * mesh.size());
    for (std::size_t t = 0; t < mesh.size(); ++t) {
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(faces[4 * t + k], mesh.triangles[t][k]);
        EXPECT_EQ(faces[4 * t + 3], -1);
    }
    const std::vector<double> diffuse = inventor_list(iv, "diffuseColor");
    const std::vector<double> index = inventor_list(iv, "materialIndex");
    ASSERT_EQ(index.size(), mesh.size());
    EXPECT_EQ(diffuse.size(), 3 * 2u);  // the stem's colour and the branch's ;(2)
    for (std::size_t t = 0; t < mesh.size(); ++t) {
        const auto slot = static_cast<std::size_t>(index[t]);
        ASSERT_LT(3 * slot + 2, diffuse.size());
        EXPECT_NEAR(diffuse[3 * slot], plant.scene.materials[mesh.material[t]].diffuse.r, 1e-6);
        EXPECT_NEAR(diffuse[3 * slot + 2], plant.scene.materials[mesh.material[t]].diffuse.b, 1e-6);
    }
    EXPECT_EQ(iv.find("Camera"), std::string::npos);  // cpfg writes no camera (manual 6.5)

    geom::MeshExportOptions small;
    small.max_memory_bytes = 1000;
    EXPECT_THROW(geom::write_inventor(plant.scene, plant.folder / "big.iv", small), Error);
    EXPECT_FALSE(fs::exists(plant.folder / "big.iv"));
}

TEST(MeshExport, PastTheMemoryBudgetNothingIsWritten)
{
    Plant plant;
    geom::MeshExportOptions small;
    small.max_memory_bytes = 1000;
    EXPECT_THROW(geom::write_mesh(plant.scene, plant.folder / "big.obj", MeshFormat::obj, small), Error);
    EXPECT_FALSE(fs::exists(plant.folder / "big.obj"));
    EXPECT_FALSE(fs::exists(plant.folder / "big.mtl"));
}

}  // namespace
