// SPDX-License-Identifier: Apache-2.0
// Tests of `~x` surfaces, `@PS @PC @PD` patches and the lenient view-file numbers in the
// interpreter, with hand-computed expectations.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "base/diagnostics.h"
#include "geom/interpreter.h"
#include "geom/view_file.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

using Module = std::pair<std::string, std::vector<float>>;

lsys::ModuleString make_string(lsys::SymbolTable& symbols, const std::vector<Module>& modules)
{
    lsys::ModuleString s;
    for (const auto& [name, params] : modules)
        s.append(symbols.intern(name), params);
    return s;
}

Scene run(const std::vector<Module>& modules, const ViewFile& view)
{
    lsys::SymbolTable symbols;
    lsys::ModuleString s = make_string(symbols, modules);
    return interpret(s, symbols, view);
}

/// A folder of its own under the test's temporary directory.
std::filesystem::path scratch(const std::string& name)
{
    auto dir = std::filesystem::temp_directory_path() / ("cambium_surface_interp_" + name);
    std::filesystem::create_directories(dir);
    return dir;
}

void write(const std::filesystem::path& file, const std::string& text)
{
    std::ofstream(file) << text;
}

ViewFile surface_view(const std::string& name)
{
    auto dir = scratch(name);
    write(dir / "square.s", unit_square_surface());
    write(dir / "plant.v", "angle increment: 90\nsurface: a square.s 2\n");
    return read_view_file(dir / "plant.v");
}

Vec3 column(const std::array<float, 12>& m, int c)
{
    auto k = static_cast<std::size_t>(3 * c);
    return {m[k], m[k + 1], m[k + 2]};
}

Vec3 key_position(const Scene& scene, std::size_t k)
{
    const auto& key = scene.geometry.lines.keys[k];
    return {key[0], key[1], key[2]};
}

}  // namespace

// The turtle starts with H = +y, L = -x, U = -z. f(1) moves it to (0,1,0); +(90) turns
// H toward L: H = (-1,0,0), L = (0,-1,0), U = (0,0,-1). ~a(1.5) then places the square
// (prototype corner (2,2,0) at view scale 2) with columns 1.5 L, 1.5 H, 1.5 U.
TEST(SurfaceInterpretation, InstanceAtARotatedTurtle)
{
    ViewFile view = surface_view("rotated");
    Scene scene = run({{"f", {1}}, {"+", {}}, {";", {7}}, {"~a", {1.5f}}, {"F", {}}}, view);
    ASSERT_EQ(scene.prototypes.size(), 1u);
    ASSERT_EQ(scene.instances.size(), 1u);
    const Instance& inst = scene.instances[0];
    EXPECT_EQ(inst.prototype, 0u);
    EXPECT_EQ(inst.material, 7);
    EXPECT_EQ(inst.texture, no_texture);
    expect_near(column(inst.transform, 0), {0, -1.5, 0});
    expect_near(column(inst.transform, 1), {-1.5, 0, 0});
    expect_near(column(inst.transform, 2), {0, 0, -1.5});
    expect_near(column(inst.transform, 3), {0, 1, 0});

    // The turtle moved to the end point (0, 2, 0)·1.5 along H: (-3, 1, 0); F goes on by H.
    ASSERT_EQ(scene.geometry.lines.segment_count(), 1u);
    expect_near(key_position(scene, 0), {-3, 1, 0});
    expect_near(key_position(scene, 1), {-4, 1, 0});

    // cpfg's view volume: the placed control points, x = -1.5 q.y in [-3, 0],
    // y = 1 - 1.5 q.x in [-2, 1]; F reaches x = -4.
    expect_near(scene.bounds.lo, {-4, -2, 0});
    expect_near(scene.bounds.hi, {0, 1, 0});
}

// ~a(1, 2, 3): per-axis scale; the end point uses the first component only (cpfg).
TEST(SurfaceInterpretation, NonUniformScaleAndEndPoint)
{
    ViewFile view = surface_view("nonuniform");
    Scene scene = run({{"f", {1}}, {"+", {}}, {"~a", {1, 2, 3}}, {"F", {}}}, view);
    ASSERT_EQ(scene.instances.size(), 1u);
    const auto& m = scene.instances[0].transform;
    expect_near(column(m, 0), {0, -1, 0});
    expect_near(column(m, 1), {-2, 0, 0});
    expect_near(column(m, 2), {0, 0, -3});
    expect_near(key_position(scene, 0), {-2, 1, 0});
}

// A letter without a `surface:` draws nothing and leaves the turtle where it is.
TEST(SurfaceInterpretation, UndefinedLetterDrawsNothing)
{
    ViewFile view = surface_view("undefined");
    Scene scene = run({{"~q", {}}, {"F", {}}}, view);
    EXPECT_TRUE(scene.instances.empty());
    ASSERT_EQ(scene.geometry.lines.segment_count(), 1u);
    expect_near(key_position(scene, 0), {0, 0, 0});
}

// The surface's texture `@Tx` of the turtle reaches the instance when the surface has
// no fixed texture.
TEST(SurfaceInterpretation, InstanceTakesTheTurtlesTexture)
{
    auto dir = scratch("texture");
    write(dir / "square.s", unit_square_surface());
    write(dir / "plant.v", "surface: a square.s 1\ntexture: F: bark.rgb\n");
    ViewFile view = read_view_file(dir / "plant.v");
    Scene scene = run({{"@Tx", {1}}, {"~a", {}}}, view);
    ASSERT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.instances[0].texture, 0);
}

// `S:` textures map over the whole surface: uv = (x, y) / extent in the prototype
// frame, where the default maps each patch's (s, t), s along the rows (y), t along x.
TEST(SurfaceInterpretation, PerSurfaceTextureUsesItsOwnPrototype)
{
    auto dir = scratch("per_surface");
    write(dir / "square.s", unit_square_surface());
    write(dir / "plant.v", "surface: a square.s 2\ntexture: F: a.rgb S:\ntexture: F: b.rgb\n");
    ViewFile view = read_view_file(dir / "plant.v");
    Scene scene = run({{"@Tx", {1}}, {"~a", {}}, {"@Tx", {2}}, {"~a", {}}, {"~a", {}}}, view);
    ASSERT_EQ(scene.instances.size(), 3u);
    ASSERT_EQ(scene.prototypes.size(), 2u);
    EXPECT_EQ(scene.instances[0].prototype, 1u);  // the per-surface copy
    EXPECT_EQ(scene.instances[1].prototype, 0u);
    EXPECT_EQ(scene.instances[2].prototype, 0u);
    auto uv_at = [](const TriangleMesh& mesh, float x, float y) {
        for (std::size_t i = 0; i < mesh.positions.size(); ++i)
            if (std::fabs(mesh.positions[i][0] - x) < 1e-5f && std::fabs(mesh.positions[i][1] - y) < 1e-5f)
                return mesh.uvs[i];
        ADD_FAILURE() << "no vertex at " << x << ", " << y;
        return Float2{-1, -1};
    };
    Float2 per_surface = uv_at(scene.prototypes[1].geometry.mesh, 2, 0);
    Float2 per_patch = uv_at(scene.prototypes[0].geometry.mesh, 2, 0);
    EXPECT_NEAR(per_surface[0], 1, 1e-5);
    EXPECT_NEAR(per_surface[1], 0, 1e-5);
    EXPECT_NEAR(per_patch[0], 0, 1e-5);
    EXPECT_NEAR(per_patch[1], 1, 1e-5);
}

namespace {

/// @PS(1) and the 16 control points (3c/3, 2r/3, 0) visited with @M: a flat 3 x 2
/// rectangle (a Bézier patch with evenly spaced collinear rows is bilinear).
std::vector<Module> flat_patch_modules()
{
    std::vector<Module> m{{";", {9}}, {"@PS", {1}}};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            m.push_back({"@M", {static_cast<float>(c), static_cast<float>(2.0 * r / 3.0), 0}});
            m.push_back({"@PC", {1, static_cast<float>(r), static_cast<float>(c)}});
        }
    return m;
}

double mesh_area(const TriangleMesh& mesh)
{
    double area = 0;
    for (const auto& t : mesh.triangles) {
        auto p = [&](int k) {
            const Float3& f = mesh.positions[t[static_cast<std::size_t>(k)]];
            return Vec3{f[0], f[1], f[2]};
        };
        area += 0.5 * length(cross(p(1) - p(0), p(2) - p(0)));
    }
    return area;
}

}  // namespace

TEST(SurfaceInterpretation, LsystemPatchHasTheRectanglesArea)
{
    std::vector<Module> m = flat_patch_modules();
    m.push_back({"@PD", {1}});
    Scene scene = run(m, parse_view_file("", "t.v"));
    const TriangleMesh& mesh = scene.geometry.mesh;
    EXPECT_EQ(mesh.size(), 2u * 5 * 5);  // cpfg's default 5 x 5 steps
    EXPECT_NEAR(mesh_area(mesh), 3.0 * 2.0, 1e-4);
    for (std::size_t i = 0; i < mesh.size(); ++i)
        EXPECT_EQ(mesh.material[i], 9);
}

TEST(SurfaceInterpretation, LsystemPatchStepsAndUnfinishedPatch)
{
    std::vector<Module> m = flat_patch_modules();
    m.push_back({"@PD", {1, 2, 3}});
    m.push_back({"@PS", {2}});
    m.push_back({"@PC", {2, 0, 0}});
    m.push_back({"@PD", {2}});  // 15 points missing: nothing drawn
    Scene scene = run(m, parse_view_file("", "t.v"));
    EXPECT_EQ(scene.geometry.mesh.size(), 2u * 2 * 3);
    EXPECT_NEAR(mesh_area(scene.geometry.mesh), 6.0, 1e-4);
}

TEST(ViewFileLenientNumbers, NotANumberWarnsAndKeepsTheDefault)
{
    Diagnostics sink(Diagnostics::Output::quiet);
    ScopedDiagnostics install(sink);
    ViewFile v = parse_view_file("angle increment: ?\ninitial scale: 2\n", "lenient.v");
    std::string err = sink.text();
    EXPECT_EQ(sink.count(Severity::warning), 1u) << err;
    EXPECT_DOUBLE_EQ(v.angle_increment_deg, 45);  // cpfg's default
    EXPECT_DOUBLE_EQ(v.initial_scale, 2);         // the next line still read
    EXPECT_NE(err.find("lenient.v:1:18"), std::string::npos) << err;
}

TEST(ViewFileLenientNumbers, OtherMalformedValuesStayErrors)
{
    EXPECT_THROW(parse_view_file("angle increment:\n", "t.v"), Error);  // no value at all
    EXPECT_THROW(parse_view_file("viewpoint: 0 ? 1\n", "t.v"), Error);
    EXPECT_THROW(parse_view_file("angle increment: inf\n", "t.v"), Error);
}

TEST(ViewFileTextures, RelativeTextureFilesBecomeAbsolute)
{
    auto dir = scratch("texture_path");
    write(dir / "plant.v", "texture: F: images/bark.rgb\n");
    ViewFile v = read_view_file(dir / "plant.v");
    ASSERT_EQ(v.textures.size(), 1u);
    EXPECT_TRUE(v.textures[0].file.is_absolute());
    auto expected = (std::filesystem::absolute(dir) / "images" / "bark.rgb").lexically_normal();
    EXPECT_EQ(v.textures[0].file, expected);
}

// Colormap-mode lighting lights surfaces by another rule than lines (manual 5.2.5): the
// pipeline gives them the materials 256..511, the interpreter adds the offset to
// surfaces' colour indices and to nothing else.
TEST(SurfaceInterpretation, SurfaceMaterialOffsetMovesOnlySurfaces)
{
    ViewFile view = surface_view("offset");
    lsys::SymbolTable symbols;
    lsys::ModuleString s = make_string(symbols, {{";", {7}}, {"F", {1}}, {"~a", {1}}});
    InterpretOptions options;
    options.surface_material_offset = 256;
    Scene scene = interpret(s, symbols, view, options);
    ASSERT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.instances[0].material, 256 + 7);
    EXPECT_EQ(scene.instances[0].back_material, 256 + 7);
    ASSERT_EQ(scene.geometry.lines.material.size(), 1u);
    EXPECT_EQ(scene.geometry.lines.material[0], 7);
    Scene plain = interpret(s, symbols, view);
    EXPECT_EQ(plain.instances[0].material, 7);
}
