// SPDX-License-Identifier: Apache-2.0
// OBJ files read with their MTL materials (app/scene_file.h read_obj_model): the values
// Cambium's exporter writes come back as the materials, normals and uvs they were.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/scene_file.h"
#include "base/diagnostics.h"

namespace fs = std::filesystem;
using cambium::app::ObjModel;
using cambium::app::read_obj_model;
using cambium::app::SceneLimits;

namespace {

class ObjModelTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        dir = fs::temp_directory_path() / ("cambium_obj_model_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }
    void write(const std::string& name, const std::string& text)
    {
        std::ofstream(dir / name, std::ios::binary) << text;
    }
    /// The message read_obj_model throws for plant.obj, or "" when it reads.
    std::string error_of(const SceneLimits& limits = {})
    {
        try {
            read_obj_model(dir / "plant.obj", dir, false, limits);
        } catch (const cambium::Error& e) {
            return e.what();
        }
        return "";
    }
    fs::path dir;
};

const char* const mtl =
    "newmtl colour1\nKa 0.1 0.2 0.3\nKd 0.4 0.5 0.6\nKs 0.7 0.8 0.9\nKe 0.05 0 0\nNs 32\nd 0.75\n"
    "illum 2\n\nnewmtl colour7\nKd 1 0 0\n";

// Two triangles sharing an edge, their normals leaning apart (a smooth, not flat,
// surface), each in its own material.
const char* const obj =
    "mtllib plant.mtl\n"
    "v 0 0 0\nvn -0.6 0 0.8\nvt 0.25 0.5\n"
    "v 1 0 0\nvn 0 0 1\nvt 0.75 0.5\n"
    "v 0 1 0\nvn 0.6 0 0.8\nvt 0.25 1\n"
    "v 1 1 0\nvn 0 0.6 0.8\nvt 0.75 1\n"
    "usemtl colour1\nf 1/1/1 2/2/2 3/3/3\n"
    "usemtl colour7\nf 2/2/2 4/4/4 3/3/3\n";

TEST_F(ObjModelTest, MaterialsNormalsAndUvsComeBack)
{
    write("plant.mtl", mtl);
    write("plant.obj", obj);
    const ObjModel m = read_obj_model(dir / "plant.obj", dir, false, {});
    ASSERT_EQ(m.materials.size(), 2u);
    const cambium::geom::Material& a = m.materials[0];
    EXPECT_FLOAT_EQ(a.ambient.g, 0.2f);
    EXPECT_FLOAT_EQ(a.diffuse.r, 0.4f);
    EXPECT_FLOAT_EQ(a.diffuse.b, 0.6f);
    EXPECT_FLOAT_EQ(a.specular.g, 0.8f);
    EXPECT_FLOAT_EQ(a.emission.r, 0.05f);
    EXPECT_FLOAT_EQ(a.shininess, 32.0f);
    EXPECT_FLOAT_EQ(a.transparency, 0.25f);
    EXPECT_FLOAT_EQ(m.materials[1].diffuse.r, 1.0f);
    EXPECT_FLOAT_EQ(m.materials[1].diffuse.g, 0.0f);
    ASSERT_EQ(m.mesh.size(), 2u);
    EXPECT_EQ(m.mesh.material[0], 0);
    EXPECT_EQ(m.mesh.material[1], 1);
    EXPECT_EQ(m.mesh.back_material[1], 1);
    // the shared corners are one vertex each: 4, not 6
    ASSERT_EQ(m.mesh.positions.size(), 4u);
    const auto& t = m.mesh.triangles[0];
    EXPECT_FLOAT_EQ(m.mesh.normals[t[0]][0], -0.6f);
    EXPECT_FLOAT_EQ(m.mesh.normals[t[2]][0], 0.6f);
    EXPECT_FLOAT_EQ(m.mesh.normals[m.mesh.triangles[1][1]][1], 0.6f);
    EXPECT_FLOAT_EQ(m.mesh.uvs[t[1]][0], 0.75f);
    EXPECT_FLOAT_EQ(m.mesh.uvs[t[2]][1], 1.0f);
    EXPECT_TRUE(m.textures.empty());
    EXPECT_EQ(m.mesh.texture[0], cambium::geom::no_texture);
}

TEST_F(ObjModelTest, FacesWithoutNormalsAreFlatAndMapKdIsATexture)
{
    write("plant.mtl", "newmtl leaf\nKd 1 1 1\nmap_Kd leaf.png\nmap_d leaf.png\n");
    write("leaf.png", "not read here");
    write("plant.obj", "mtllib plant.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl leaf\nf 1 2 3\n");
    const ObjModel m = read_obj_model(dir / "plant.obj", dir, false, {});
    ASSERT_EQ(m.textures.size(), 1u);
    EXPECT_EQ(m.textures[0].file.filename(), "leaf.png");
    EXPECT_TRUE(m.textures[0].file.is_absolute());
    EXPECT_EQ(m.mesh.texture[0], 0);
    for (const auto& n : m.mesh.normals)
        EXPECT_FLOAT_EQ(n[2], 1.0f);  // the face's own normal, +z
}

TEST_F(ObjModelTest, BadInputIsAnErrorAtItsLine)
{
    write("plant.obj", "mtllib missing.mtl\nv 0 0 0\n");
    EXPECT_NE(error_of().find("plant.obj:1:"), std::string::npos) << error_of();
    EXPECT_NE(error_of().find("missing.mtl"), std::string::npos) << error_of();

    write("plant.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    EXPECT_NE(error_of().find("plant.obj:4:"), std::string::npos) << error_of();

    write("plant.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2/1/1 3/1/1\n");
    EXPECT_NE(error_of().find("texture coordinate index 1"), std::string::npos) << error_of();

    write("plant.mtl", mtl);
    write("plant.obj", "mtllib plant.mtl\nv 0 0 0\nusemtl colour2\n");
    EXPECT_NE(error_of().find("plant.obj:3:"), std::string::npos) << error_of();

    write("plant.mtl", "newmtl a\nKd 1 nan 0\n");
    write("plant.obj", "mtllib plant.mtl\n");
    EXPECT_NE(error_of().find("plant.mtl:2:"), std::string::npos) << error_of();

    write("plant.obj", "mtllib ../outside.mtl\n");
    EXPECT_NE(error_of().find("outside the folder"), std::string::npos) << error_of();

    write("plant.mtl", "newmtl a\nmap_Kd ../../etc/passwd\n");
    write("plant.obj", "mtllib plant.mtl\n");
    EXPECT_NE(error_of().find("outside the folder"), std::string::npos) << error_of();

    // counts are bounded before anything grows past them
    SceneLimits small;
    small.max_mesh_triangles = 1;
    write("plant.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n");
    EXPECT_NE(error_of(small).find("plant.obj:5:"), std::string::npos) << error_of(small);
    small.max_mesh_triangles = 10;
    small.max_mesh_materials = 1;
    write("plant.mtl", "newmtl a\nnewmtl b\n");
    write("plant.obj", "mtllib plant.mtl\n");
    EXPECT_NE(error_of(small).find("plant.mtl:2:"), std::string::npos) << error_of(small);
}

}  // namespace
