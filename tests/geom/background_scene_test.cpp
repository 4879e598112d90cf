// SPDX-License-Identifier: Apache-2.0
// Tests of the background scene reader: the manual's example, transformations and primitives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <sys/stat.h>

#include "geom/background_scene.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

BackgroundScene build(const std::string& text, const Material& initial = Material{})
{
    return build_background_scene(parse_background_text(text, "bg.dat"), initial);
}

// The example of CPFG manual 5.4.10.
const char* manual_example = R"(
material 0.1 0.1 0.1 1 /* subsequent surfaces are grey */
          0.16 0.21 0.27 1 /* with no specular reflections */
          0 0 0 1 /* and no emissive color */
          0 0 0 1
          0

pushmatrix
translate 3 -20 -3
scale 1 0.7 0.7
sphere 15 /* ellipsoid */
popmatrix

pushmatrix
translate -14 -55.0 8
cone 15 2 14 /* cone */
popmatrix

translate -10 -65 0
box 30 5 30 /* box */
)";

}  // namespace

TEST(BackgroundScene, ManualExample)
{
    BackgroundScene s = build(manual_example);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].diffuse, (Rgb{0.16f, 0.21f, 0.27f}));
    EXPECT_EQ(s.materials[0].ambient, (Rgb{0.1f, 0.1f, 0.1f}));
    EXPECT_FLOAT_EQ(s.materials[0].transparency, 0);

    // The sphere under `scale 1 0.7 0.7` is the manual's ellipsoid: semi-axes 15, 10.5,
    // 10.5 about (3, -20, -3), as cpfg's window draws it.
    EXPECT_EQ(s.geometry.spheres.size(), 0u);
    const std::size_t ellipsoid = 960;  // 32 slices x 16 stacks, one triangle at the poles
    ASSERT_EQ(s.geometry.mesh.size(), ellipsoid + 12);
    double x_lo = 1e9, x_hi = -1e9, y_lo = 1e9, y_hi = -1e9;
    for (std::size_t i = 0; i < 3 * ellipsoid; ++i) {
        const Float3& p = s.geometry.mesh.positions[i];
        Vec3 q{(p[0] - 3) / 15, (p[1] + 20) / 10.5, (p[2] + 3) / 10.5};
        EXPECT_NEAR(dot(q, q), 1, 1e-5);
        x_lo = std::min(x_lo, double(p[0]));
        x_hi = std::max(x_hi, double(p[0]));
        y_lo = std::min(y_lo, double(p[1]));
        y_hi = std::max(y_hi, double(p[1]));
    }
    EXPECT_NEAR(x_hi - x_lo, 30, 1e-4);
    EXPECT_NEAR(y_hi - y_lo, 21, 1e-4);

    // The cone: a segment from (-14,-55,8) radius 15 to (-14,-41,8) radius 2, two discs.
    ASSERT_EQ(s.geometry.lines.segment_count(), 1u);
    EXPECT_EQ(s.geometry.lines.keys[0], (Float4{-14, -55, 8, 15}));
    EXPECT_EQ(s.geometry.lines.keys[1], (Float4{-14, -41, 8, 2}));
    ASSERT_EQ(s.geometry.discs.size(), 2u);
    expect_near(v3(s.geometry.discs.normals[0]), {0, -1, 0}, 1e-6);
    expect_near(v3(s.geometry.discs.normals[1]), {0, 1, 0}, 1e-6);

    // The box: 6 faces, 12 triangles over [-10,20] x [-65,-60] x [0,30].
    const TriangleMesh& m = s.geometry.mesh;
    Vec3 lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
    for (std::size_t i = 3 * ellipsoid; i < m.positions.size(); ++i) {
        const Float3& p = m.positions[i];
        lo = {std::min(lo.x, double(p[0])), std::min(lo.y, double(p[1])), std::min(lo.z, double(p[2]))};
        hi = {std::max(hi.x, double(p[0])), std::max(hi.y, double(p[1])), std::max(hi.z, double(p[2]))};
    }
    expect_near(lo, {-10, -65, 0}, 1e-5);
    expect_near(hi, {20, -60, 30}, 1e-5);
    EXPECT_TRUE(std::all_of(m.material.begin(), m.material.end(), [](auto k) { return k == 0; }));
}

// A rotation with a uniform scale keeps a sphere a sphere, its radius scaled.
TEST(BackgroundScene, UniformScaleScalesTheSphere)
{
    BackgroundScene s = build("translate 1 2 3\nrotate 30 0 0 1\nscale 2 2 2\nsphere 1.5\n");
    ASSERT_EQ(s.geometry.spheres.size(), 1u);
    EXPECT_EQ(s.geometry.mesh.size(), 0u);
    EXPECT_EQ(s.geometry.spheres.centres[0], (Float4{1, 2, 3, 3}));
}

TEST(BackgroundScene, RotationFollowsOpenGL)
{
    // Rotating 90 degrees about z takes +x to +y; the square's normal stays +z.
    BackgroundScene s = build("rotate 90 0 0 1\npolygon 0 0 0  1 0 0  1 1 0  0 1 0\n");
    const TriangleMesh& m = s.geometry.mesh;
    ASSERT_EQ(m.size(), 2u);
    expect_near(v3(m.positions[1]), {0, 1, 0}, 1e-6);
    expect_near(v3(m.positions[2]), {-1, 1, 0}, 1e-6);
    for (const Float3& n : m.normals)
        expect_near(v3(n), {0, 0, 1}, 1e-6);
}

TEST(BackgroundScene, MatrixOrderIsRightMultiplied)
{
    // translate then scale: p' = T (S p); (1,0,0) -> (2,0,0) + (5,0,0).
    BackgroundScene s = build("translate 5 0 0 scale 2 2 2 polygon 1 0 0 1 1 0 0 1 0\n");
    expect_near(v3(s.geometry.mesh.positions[0]), {7, 0, 0}, 1e-6);
    // loadmatrix is column-major; loadidentity resets.
    s = build("loadmatrix 1 0 0 0  0 1 0 0  0 0 1 0  4 5 6 1\nsphere 1\nloadidentity\nsphere 2\n");
    EXPECT_EQ(s.geometry.spheres.centres[0], (Float4{4, 5, 6, 1}));
    EXPECT_EQ(s.geometry.spheres.centres[1], (Float4{0, 0, 0, 2}));
}

TEST(BackgroundScene, MeshRectanglesAndInitialMaterial)
{
    Material initial;
    initial.diffuse = {1, 0, 0};
    BackgroundScene s = build("mesh 0 0 0  0 1 0  1 0 0  1 1 0  2 0 0  2 1 0\n", initial);
    EXPECT_EQ(s.geometry.mesh.size(), 4u);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].diffuse, initial.diffuse);
    // Partial material: only ambient and diffuse change; the diffuse alpha sets transparency.
    s = build("material 0 0 1 1  0 1 0 0.25\nrectangle 2 3\n", initial);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].diffuse, (Rgb{0, 1, 0}));
    EXPECT_FLOAT_EQ(s.materials[0].transparency, 0.75f);
    EXPECT_EQ(s.geometry.mesh.material[0], 0);
    expect_near(v3(s.geometry.mesh.positions[2]), {2, 3, 0}, 1e-6);
}

TEST(BackgroundScene, RectangleEmissionFactorAppliesToItOnly)
{
    Material initial;
    initial.emission = {0.5f, 0.5f, 0.5f};
    BackgroundScene s = build("rectangle 1 1 0 0 2\nrectangle 1 1\n", initial);
    ASSERT_EQ(s.geometry.mesh.size(), 4u);
    const auto& mat = s.geometry.mesh.material;
    EXPECT_EQ(s.materials[mat[0]].emission, (Rgb{1, 1, 1}));
    EXPECT_EQ(s.materials[mat[2]].emission, (Rgb{0.5f, 0.5f, 0.5f}));
}

TEST(BackgroundScene, BadStatementsWarnAndAreSkipped)
{
    set_warnings_enabled(false);
    BackgroundScene s = build("# 1 \"file\"\nteapot 3 4\npopmatrix\npolygon 0 0 0 1 1 1\nsphere 1\n");
    set_warnings_enabled(true);
    EXPECT_EQ(s.geometry.mesh.size(), 0u);
    EXPECT_EQ(s.geometry.spheres.size(), 1u);
}

TEST(BackgroundScene, TruncatedTextNeverCrashes)
{
    set_warnings_enabled(false);
    std::string text = manual_example;
    for (std::size_t n = 0; n <= text.size(); n += 2) {
        try {
            build(text.substr(0, n));
        } catch (const Error&) {
        }
    }
    set_warnings_enabled(true);
}

TEST(BackgroundScene, AppendAndOffset)
{
    BackgroundScene a = build("cylinder 1 2\nbox 1 1 1\n");
    BackgroundScene b = build("material 1 1 1 1\ncylinder 1 3\nsphere 1\n");
    offset_materials(b.geometry, 5);
    append_geometry(a.geometry, b.geometry);
    EXPECT_EQ(a.geometry.lines.segment_count(), 2u);
    EXPECT_EQ(a.geometry.lines.segments[1], 2u);  // shifted past a's two keys
    EXPECT_EQ(a.geometry.lines.material[1], 5);
    EXPECT_EQ(a.geometry.lines.v.size(), a.geometry.lines.keys.size());
    EXPECT_EQ(a.geometry.spheres.material[0], 5);
    EXPECT_EQ(a.geometry.discs.size(), 4u);
}

TEST(BackgroundSceneConformance, CorpusBackgroundsRead)
{
    const char* env = std::getenv("CAMBIUM_CORPUS");
    std::filesystem::path root = std::filesystem::path(env ? env : CAMBIUM_CORPUS_DEFAULT) / "cpfg";
    std::filesystem::path plant = root / "10-manuals/11-CPFG/BackgroundScene";
    if (!std::filesystem::exists(plant / "background.dat"))
        GTEST_SKIP() << "corpus not found";
    // background.dat uses `#define TR1 0.5` for the material's alphas: cpp must run.
    BackgroundScene s = read_background_scene(std::vector<std::filesystem::path>{"background.dat"}, plant, Material{}, FileLoc{"plant.v", 14, 1}, std::nullopt);
    ASSERT_FALSE(s.materials.empty());
    EXPECT_FLOAT_EQ(s.materials[0].transparency, 0.5f);
    EXPECT_EQ(s.materials[0].diffuse, (Rgb{0.5f, 0.2f, 0.2f}));
    // The first sphere (0.5 under translate 2 2 0, rotate, scale 2 1 1) is an ellipsoid
    // about (2, 2, 0) with semi-axes 1, 0.5, 0.5: the first 960 triangles.
    ASSERT_GE(s.geometry.mesh.size(), 960u + 2u);
    double nearest = 1e9, farthest = 0;
    for (std::size_t i = 0; i < 3 * 960; ++i) {
        const Float3& p = s.geometry.mesh.positions[i];
        double d = length(Vec3{p[0] - 2.0, p[1] - 2.0, p[2]});
        nearest = std::min(nearest, d);
        farthest = std::max(farthest, d);
    }
    EXPECT_NEAR(farthest, 1.0, 1e-3);
    EXPECT_NEAR(nearest, 0.5, 1e-2);
    // The last, `sphere 1.0` under no scale, stays a sphere.
    EXPECT_EQ(s.geometry.spheres.size(), 1u);
    EXPECT_GE(s.geometry.lines.segment_count(), 2u);

    std::filesystem::path knot = root / "10-manuals/20-EnviroPgms/CPFG-CelticKnot/background.dat";
    BackgroundScene k = read_background_scene(std::span(&knot, 1), "/", Material{}, FileLoc{"viewfile.v", 1, 1}, std::nullopt);
    EXPECT_GT(k.geometry.lines.segment_count(), 0u);
}

// Generalized cylinders whose colour changes carry end materials; appending keeps them
// per segment (the other side's segments end in their start colour) and offsets them.
TEST(BackgroundScene, AppendKeepsCurveEndMaterials)
{
    auto one_segment = [](std::uint16_t start, std::uint16_t end) {
        Geometry g;
        g.curves.points = {{0, 0, 0, 1}, {0, 1, 0, 1}};
        g.curves.tangents = {{0, 1, 0, 0}, {0, 1, 0, 0}};
        g.curves.segments = {0};
        g.curves.material = {start};
        if (start != end)
            g.curves.end_material = {end};
        return g;
    };
    Geometry a = one_segment(1, 1), b = one_segment(2, 3);
    offset_materials(b, 10);
    append_geometry(a, b);
    ASSERT_EQ(a.curves.end_material.size(), 2u);
    EXPECT_EQ(a.curves.end_material[0], 1);   // a's segment: one colour
    EXPECT_EQ(a.curves.material[1], 12);
    EXPECT_EQ(a.curves.end_material[1], 13);
    EXPECT_EQ(a.curves.segments[1], 2u);
}

namespace {

/// Runs `body` with the current folder set to `folder`, restoring it afterwards.
template <class Body>
void in_folder(const std::filesystem::path& folder, Body body)
{
    std::filesystem::path saved = std::filesystem::current_path();
    std::filesystem::current_path(folder);
    try {
        body();
    } catch (...) {
        std::filesystem::current_path(saved);
        throw;
    }
    std::filesystem::current_path(saved);
}

std::string error_of(const std::filesystem::path& file, const std::filesystem::path& base)
{
    try {
        read_background_scene(std::span(&file, 1), base, Material{}, FileLoc{"plant.v", 14, 1}, std::nullopt);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// Run inside the model's folder (`cambium plant.l plant.v`, view file named without a
// folder), a preprocessed background file is read: cpp must not get an empty -I (it
// would read standard input instead).
TEST(BackgroundScene, RelativeFileInTheCurrentFolderIsPreprocessed)
{
    std::filesystem::path dir = std::filesystem::temp_directory_path() / "cambium_bg_relative";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "bg.dat") << "#define R 0.25\nsphere R\n";
    in_folder(dir, [] {
        BackgroundScene s = read_background_scene(std::vector<std::filesystem::path>{"bg.dat"}, "", Material{}, FileLoc{"plant.v", 1, 1}, std::nullopt);
        ASSERT_EQ(s.geometry.spheres.size(), 1u);
        EXPECT_EQ(s.geometry.spheres.centres[0], (Float4{0, 0, 0, 0.25f}));
    });
    const char* env = std::getenv("CAMBIUM_CORPUS");
    std::filesystem::path plant = std::filesystem::path(env ? env : CAMBIUM_CORPUS_DEFAULT) /
                                  "cpfg/10-manuals/11-CPFG/BackgroundScene";
    if (!std::filesystem::exists(plant / "background.dat"))
        return;
    in_folder(plant, [] {
        BackgroundScene s = read_background_scene(std::vector<std::filesystem::path>{"background.dat"}, "", Material{}, FileLoc{"plant.v", 14, 1}, std::nullopt);
        // `sphere 0.5`, and `sphere 1.0` under `scale 2 1 1`: an ellipsoid, as cpfg draws it
        EXPECT_EQ(s.geometry.spheres.size(), 1u);
        EXPECT_GE(s.geometry.mesh.size(), 960u);
        EXPECT_FLOAT_EQ(s.materials.at(0).transparency, 0.5f);
    });
}

// A background file that cannot be read is an error naming it, never a warning.
TEST(BackgroundScene, UnreadableFileIsAnErrorNamingIt)
{
    std::filesystem::path dir = std::filesystem::temp_directory_path() / "cambium_bg_unreadable";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::string message = error_of("missing.dat", dir);
    EXPECT_NE(message.find("plant.v:14:1: error: cannot read the background scene file " +
                           (dir / "missing.dat").string() + ": no such file"),
              std::string::npos)
        << message;
    ASSERT_EQ(::mkfifo((dir / "fifo.dat").c_str(), 0600), 0);
    message = error_of("fifo.dat", dir);
    EXPECT_NE(message.find((dir / "fifo.dat").string() + ": not a regular file"), std::string::npos)
        << message;
    std::ofstream(dir / "bad.dat") << "#include \"nowhere.h\"\nsphere 1\n";
    message = error_of("bad.dat", dir);
    EXPECT_NE(message.find("bad.dat:1:10: fatal error: nowhere.h: No such file"), std::string::npos)
        << message;
}

// In a `line style: pixel` scene every line of the Scene is read in pixels; background
// cylinders become triangles that keep their world radius (and their end discs).
TEST(BackgroundScene, CylindersAsMeshKeepTheirWorldRadius)
{
    BackgroundScene s = build("translate 1 0 0\ncone 2 1 5\n");
    ASSERT_EQ(s.geometry.lines.segment_count(), 1u);
    const std::size_t discs = s.geometry.discs.size();
    cylinders_as_mesh(s.geometry, 32);
    EXPECT_EQ(s.geometry.lines.segment_count(), 0u);
    EXPECT_EQ(s.geometry.discs.size(), discs);
    const TriangleMesh& m = s.geometry.mesh;
    ASSERT_EQ(m.triangles.size(), 64u);
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        const Float3& p = m.positions[i];
        const double radius = std::hypot(p[0] - 1.0, p[2]);
        const double expected = p[1] < 2.5 ? 2.0 : 1.0;  // the base at y 0, the top at y 5
        EXPECT_NEAR(radius, expected, 1e-5) << i;
        EXPECT_TRUE(std::abs(p[1]) < 1e-5 || std::abs(p[1] - 5) < 1e-5) << i;
        // outward, leaning up toward the narrower top: (5, 1) / |(5, 1)| in (radial, y)
        const Float3& n = m.normals[i];
        EXPECT_NEAR(n[1], 1 / std::sqrt(26.0), 1e-5) << i;
        EXPECT_GT(n[0] * (p[0] - 1.0) + n[2] * p[2], 0) << i;
    }
}
