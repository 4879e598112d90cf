// SPDX-License-Identifier: Apache-2.0
// Hostile numbers in geometry: dropped or refused with a message before render sees them.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "geom/function.h"
#include "geom/interpreter.h"
#include "geom/scene_limits.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

constexpr float nan_value = std::numeric_limits<float>::quiet_NaN();

/// The warnings drop_unrenderable prints, and what it dropped.
std::string dropping(Scene& scene, DroppedGeometry* dropped = nullptr)
{
    testing::internal::CaptureStderr();
    DroppedGeometry d;
    try {
        d = drop_unrenderable(scene);
    } catch (...) {
        testing::internal::GetCapturedStderr();  // one capture at a time
        throw;
    }
    if (dropped)
        *dropped = d;
    return testing::internal::GetCapturedStderr();
}

void add_line(Scene& s, Float4 a, Float4 b)
{
    LinearCurves& l = s.geometry.lines;
    auto first = static_cast<std::uint32_t>(l.keys.size());
    l.keys.push_back(a);
    l.keys.push_back(b);
    l.segments.push_back(first);
    l.flags.push_back(0);
    l.material.push_back(1);
    l.texture.push_back(no_texture);
}

}  // namespace

TEST(SceneLimits, WholeNumbersRefuseWhatNoIntHolds)
{
    EXPECT_EQ(whole_number(2.7), 2);
    EXPECT_EQ(whole_number(-2.7), -2);
    EXPECT_EQ(whole_number(1e9), 1'000'000'000);
    EXPECT_FALSE(whole_number(1e30));
    EXPECT_FALSE(whole_number(-1e10));
    EXPECT_FALSE(whole_number(std::nan("")));
    EXPECT_FALSE(whole_number(std::numeric_limits<double>::infinity()));
}

TEST(SceneLimits, HugeAndNotFiniteSegmentsAreDroppedWithOneCountedWarning)
{
    // a hostile string: F(1e38) goes far out, F(-1e38) comes back; both segments go
    Scene scene = interpret_text("F(1e38)F(-1e38)F");
    scene.bounds = Bounds3{};  // (the view volume is checked separately below)
    scene.bounds.extend(Vec3{0, 0, 0});
    DroppedGeometry d;
    std::string err = dropping(scene, &d);
    EXPECT_EQ(d.line_segments, 2u);
    ASSERT_EQ(scene.geometry.lines.segment_count(), 1u);  // the last F, at the origin
    EXPECT_EQ(scene.geometry.lines.flags[0], 0);  // its neighbour is gone: no joint
    for (const Float4& k : scene.geometry.lines.keys)
        for (float v : k)
            EXPECT_TRUE(std::isfinite(v) && std::abs(v) <= max_coordinate);
    EXPECT_NE(err.find("warning: 2 line segment(s) with coordinates or widths not finite or beyond 1e+10 dropped"),
              std::string::npos)
        << err;
}

TEST(SceneLimits, TheIssuesStringIsRefusedForItsViewVolume)
{
    Scene scene = interpret_text("F(1e38)F(-1e38)@c(1)");
    try {
        dropping(scene);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("the view volume reaches 1e+38"), std::string::npos) << e.what();
    }
}

TEST(SceneLimits, SpheresDiscsAndTrianglesWithBadNumbersAreDropped)
{
    Scene scene;
    scene.bounds.extend(Vec3{0, 0, 0});
    Geometry& g = scene.geometry;
    g.spheres.centres = {{0, 0, 0, 1}, {0, 0, 0, nan_value}, {1e11f, 0, 0, 1}};
    g.spheres.material = {1, 2, 3};
    g.spheres.texture = {no_texture, no_texture, no_texture};
    g.discs.centres = {{0, 0, 0, 1}, {0, 0, 0, 1}};
    g.discs.normals = {{0, 0, 1}, {0, 0, 0}};  // the second faces nowhere
    g.discs.material = {1, 2};
    g.discs.back_material = {1, 2};
    g.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {std::numeric_limits<float>::infinity(), 0, 0}};
    g.mesh.normals = {{0, 0, 1}, {nan_value, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    g.mesh.uvs = {{0, 0}, {1, 0}, {0, nan_value}, {0, 0}};
    g.mesh.triangles = {{0, 1, 2}, {0, 1, 3}};
    g.mesh.material = {4, 5};
    g.mesh.back_material = {4, 5};
    g.mesh.texture = {no_texture, no_texture};
    DroppedGeometry d;
    std::string err = dropping(scene, &d);
    EXPECT_EQ(d.spheres, 2u);
    ASSERT_EQ(g.spheres.size(), 1u);
    EXPECT_EQ(g.spheres.material[0], 1);
    EXPECT_EQ(d.discs, 1u);
    EXPECT_EQ(g.discs.size(), 1u);
    EXPECT_EQ(d.triangles, 1u);
    ASSERT_EQ(g.mesh.size(), 1u);
    EXPECT_EQ(g.mesh.material[0], 4);
    EXPECT_EQ(g.mesh.positions[3][0], 0);  // no longer infinite
    EXPECT_EQ(d.attributes, 2u);           // a normal and a texture coordinate set to 0
    EXPECT_EQ(g.mesh.normals[1][0], 0);
    EXPECT_NE(err.find("2 sphere(s) with a centre or diameter not finite or beyond 1e+10 dropped"), std::string::npos)
        << err;
    EXPECT_NE(err.find("1 disc(s)"), std::string::npos) << err;
    EXPECT_NE(err.find("1 triangle(s) with vertices not finite"), std::string::npos) << err;
    EXPECT_NE(err.find("2 normal(s) or texture coordinate(s) not finite set to 0"), std::string::npos) << err;
}

TEST(SceneLimits, InstancesThatEmbreeCouldNotInvertAreDropped)
{
    Scene scene;
    scene.bounds.extend(Vec3{0, 0, 0});
    Prototype p;
    add_line(scene, {0, 0, 0, 0.1f}, {0, 1, 0, 0.1f});
    p.geometry.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    p.geometry.mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    p.geometry.mesh.triangles = {{0, 1, 2}};
    scene.prototypes.push_back(p);
    Instance fine;  // identity
    Instance tiny;  // a surface scaled by 1e-7: its inverse would take rays beyond Embree's range
    tiny.transform = {1e-7f, 0, 0, 0, 1e-7f, 0, 0, 0, 1e-7f, 0, 0, 0};
    Instance not_finite;
    not_finite.transform[4] = nan_value;
    Instance far;  // placed beyond max_coordinate
    far.transform[9] = 2e10f;
    Instance flat;  // no inverse at all
    flat.transform[8] = 0;
    scene.instances = {fine, tiny, not_finite, far, flat, fine};
    DroppedGeometry d;
    std::string err = dropping(scene, &d);
    EXPECT_EQ(d.instances, 4u);
    EXPECT_EQ(scene.instances.size(), 2u);
    EXPECT_NE(err.find("4 surface or object instance(s) with a placement not finite, scaling by less than 1e-06"),
              std::string::npos)
        << err;
}

TEST(SceneLimits, NotANumberInModuleParametersDropsOnlyWhatItReaches)
{
    // @O with a NaN diameter, then a good F: the sphere goes, the segment stays
    Scene scene = interpret_text("@O(nan)F");
    DroppedGeometry d;
    dropping(scene, &d);
    EXPECT_EQ(d.spheres, 1u);
    EXPECT_EQ(scene.geometry.spheres.size(), 0u);
    EXPECT_EQ(scene.geometry.lines.segment_count(), 1u);
}

TEST(SceneLimits, GoodScenesAreLeftAlone)
{
    Scene scene = interpret_text("F[+F@O(1)]F{.f.f.}");
    Scene copy = scene;
    DroppedGeometry d;
    std::string err = dropping(scene, &d);
    EXPECT_EQ(d.total(), 0u);
    EXPECT_EQ(err, "");
    EXPECT_EQ(scene.geometry.lines.keys, copy.geometry.lines.keys);
    EXPECT_EQ(scene.geometry.mesh.triangles, copy.geometry.mesh.triangles);
}

// Module parameters no int holds (NaN, 1e30) reach no int conversion: each is ignored
// with a message naming the module (UBSan would abort on the old casts).

TEST(HostileParameters, TextureColourAndTropismIndices)
{
    testing::internal::CaptureStderr();
    Scene scene = interpret_text("@Tx(1e30);(1e30)@Ts(1e30,1)F@Tx(nan);(nan),(-1e30)F", "initial color: 7\n");
    std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find("@Tx(1e+30): no such texture; none used"), std::string::npos) << err;
    EXPECT_NE(err.find("colour index 1e+30 out of range in ;(n) ,(n) @;(n) @,(n) ignored"), std::string::npos)
        << err;
    EXPECT_NE(err.find("tropism index out of range in @Ts/@Ti/@Td ignored"), std::string::npos) << err;
    const LinearCurves& l = scene.geometry.lines;
    ASSERT_EQ(l.segment_count(), 2u);
    EXPECT_EQ(l.material[0], 7);  // the colour was kept
    EXPECT_EQ(l.material[1], 7);
    EXPECT_EQ(l.texture[0], no_texture);
}

TEST(HostileParameters, LabelsWithHugeValues)
{
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, "@L(0,1e30)@L(1e30)@L(nan)");
    std::vector<std::string> strings{"n=%d"};
    InterpretOptions options;
    options.strings = strings;
    testing::internal::CaptureStderr();
    Scene scene = interpret(s, symbols, parse_view_file("", "t.v"), options);
    std::string err = testing::internal::GetCapturedStderr();
    ASSERT_EQ(scene.labels.size(), 3u);
    EXPECT_EQ(scene.labels[0].text, "n=1e+30");  // %d of a value no integer holds
    EXPECT_EQ(scene.labels[1].text, "");
    EXPECT_NE(err.find("@L without a known string: label text left empty"), std::string::npos) << err;
}

TEST(HostileParameters, FunctionsAndCurvesOfNotANumber)
{
    std::filesystem::path dir = std::filesystem::temp_directory_path() / "cambium_limits_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "flat.func") << "fver 1 1\nname: flat\nsamples: 0\nflip: off\npoints: 4\n0 5\n0.3 5\n0.6 5\n1 5\n";
    FunctionSet functions = FunctionSet::from_view_commands(parse_view_file("function: flat.func\n", "v.v").functions, dir);
    testing::internal::CaptureStderr();
    EXPECT_NEAR(functions.evaluate(1, std::nan("")), 5, 1e-9);
    std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find("func(1, x): x is not a number; 0 used"), std::string::npos) << err;
}
