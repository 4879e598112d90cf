// SPDX-License-Identifier: Apache-2.0
// The -ray writer on a tiny L-system whose primitives are known exactly: cylinders,
// spheres, an `-o>` object defined once and placed twice, surfaces and the view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "base/diagnostics.h"
#include "geom/interpreter.h"
#include "geom/rayshade_export.h"
#include "lsys/lsystem.h"
#include "rayshade_reader.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;
using cambium::test::RayPrimitive;
using cambium::test::RayScene;

namespace {

const char* const tiny_model = R"(
Lsystem: 1
derivation length: 0
Axiom: F(1) A [ +(90) ;(2) F(2) @O(0.5) ] A
homomorphism
A -o> F(1) @O(0.25)
endlsystem
)";

const char* const tiny_view = "angle increment: 90\nline style: cylinder\ninitial line width: 0.2\n"
                              "initial color: 1\n";

/// The model with its `-o>` object instanced, as the command interprets it.
Scene tiny_scene(const std::string& view_text = tiny_view)
{
    lsys::LSystem ls = lsys::LSystem::from_source(tiny_model);
    InterpretOptions options;
    options.is_object = [&ls](lsys::SymbolId s) { return ls.is_object_symbol(s); };
    options.expand_object = [&ls](lsys::ModuleRef m) { return ls.expand_object(m); };
    return interpret(ls.derive(), ls.symbols(), parse_view_file(view_text, "t.v"), options);
}

std::size_t count(const std::string& text, const std::string& word)
{
    std::size_t n = 0;
    for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1))
        ++n;
    return n;
}

/// Whether `scene` holds a primitive of `kind` at exactly these points and radius.
bool holds(const RayScene& scene, RayPrimitive::Kind kind, test::RayPoint a, test::RayPoint b, double radius)
{
    auto near = [](const test::RayPoint& p, const test::RayPoint& q) {
        return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]) < 1e-6;
    };
    return std::any_of(scene.primitives.begin(), scene.primitives.end(), [&](const RayPrimitive& p) {
        if (p.kind != kind || std::fabs(p.radius[0] - radius) > 1e-6)
            return false;
        return kind == RayPrimitive::cylinder ? near(p.p[0], a) && near(p.p[1], b) : near(p.p[0], a);
    });
}

TEST(RayshadeExport, TinyModelHasExactlyItsPrimitives)
{
    Scene scene = tiny_scene();
    RayshadeOptions options;
    options.object_name = "tiny.ray";
    std::string text = rayshade_text(scene, options);
    RayScene ray = test::read_rayshade(text);

    // the object A is defined once and placed twice
    EXPECT_EQ(count(text, "\nname A grid"), 1u) << text;
    EXPECT_EQ(count(text, "\nobject A\n"), 2u) << text;
    EXPECT_EQ(count(text, "\nobject tiny.ray\n"), 1u) << text;

    ASSERT_EQ(ray.primitives.size(), 7u) << text;
    using K = RayPrimitive::Kind;
    EXPECT_TRUE(holds(ray, K::cylinder, {0, 0, 0}, {0, 1, 0}, 0.1)) << text;
    EXPECT_TRUE(holds(ray, K::cylinder, {0, 1, 0}, {0, 2, 0}, 0.1)) << text;   // first A
    EXPECT_TRUE(holds(ray, K::cylinder, {0, 2, 0}, {-2, 2, 0}, 0.1)) << text;  // the branch, turned left
    EXPECT_TRUE(holds(ray, K::cylinder, {0, 2, 0}, {0, 3, 0}, 0.1)) << text;   // second A
    EXPECT_TRUE(holds(ray, K::sphere, {0, 2, 0}, {}, 0.125)) << text;
    EXPECT_TRUE(holds(ray, K::sphere, {-2, 2, 0}, {}, 0.25)) << text;
    EXPECT_TRUE(holds(ray, K::sphere, {0, 3, 0}, {}, 0.125)) << text;

    // colours 1 and 2 of the first colormap are s257 and s258, ambient = diffuse
    ASSERT_EQ(ray.surfaces.count("s257"), 1u) << text;
    ASSERT_EQ(ray.surfaces.count("s258"), 1u) << text;
    EXPECT_EQ(ray.surfaces.size(), 2u) << text;
    for (const auto& [name, s] : ray.surfaces)
        EXPECT_EQ(s.ambient, s.diffuse) << name;
    for (const RayPrimitive& p : ray.primitives)
        if (p.kind == K::sphere && std::fabs(p.radius[0] - 0.25) < 1e-6) {
            EXPECT_EQ(p.surface, "s258");
        }
    // the plant's first segment and the object's own, in its frame
    EXPECT_EQ(count(text, "cylinder s257 0.1 0 0 0\n 0 1 0\n"), 2u) << text;
}

TEST(RayshadeExport, MaterialsKeepTheirComponents)
{
    Scene scene = tiny_scene();
    scene.materials[1].diffuse = {0.5f, 0.25f, 1};
    scene.materials[1].ambient = {0.1f, 0.2f, 0.3f};
    scene.materials[1].shininess = 20;
    RayshadeOptions options;
    options.colormap = false;
    RayScene ray = test::read_rayshade(rayshade_text(scene, options));
    ASSERT_EQ(ray.surfaces.count("s257"), 1u);
    test::RayPoint diffuse{0.5, 0.25, 1}, ambient{0.1, 0.2, 0.3};
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(ray.surfaces["s257"].diffuse[c], diffuse[c], 1e-6);
        EXPECT_NEAR(ray.surfaces["s257"].ambient[c], ambient[c], 1e-6);
    }
}

TEST(RayshadeExport, PerspectiveViewAndLightsAsCpfgWritesThem)
{
    Scene scene = tiny_scene(std::string(tiny_view) +
                             "projection: perspective\nviewpoint: 0,0.1,10\nview reference point: 0.5,1,0\n"
                             "viewing angle: 45\nscale factor: 2\nlight: V: 1 2 3\nlight: O: 4 5 6\n");
    RayshadeOptions options;
    std::string text = rayshade_text(scene, options);
    RayScene ray = test::read_rayshade(text);
    // eye = reference + (viewpoint - reference) / scale factor; horizontal fov at 4:3
    EXPECT_NEAR(ray.eyep[0], 0.25, 1e-6);
    EXPECT_NEAR(ray.eyep[1], 0.55, 1e-6);
    EXPECT_NEAR(ray.eyep[2], 5, 1e-6);
    EXPECT_NEAR(ray.lookp[0], 0.5, 1e-6);
    EXPECT_NEAR(ray.fov, 57.822402, 1e-5);
    EXPECT_NEAR(ray.up[0], -0.004471, 1e-6);
    EXPECT_NEAR(ray.up[1], 0.995984, 1e-6);
    EXPECT_NEAR(ray.up[2], 0.089415, 1e-6);
    ASSERT_EQ(ray.lights.size(), 3u) << text;
    EXPECT_EQ(ray.lights[0].kind, "ambient");
    EXPECT_EQ(ray.lights[1].kind, "directional");
    EXPECT_EQ(ray.lights[2].kind, "point");
    EXPECT_NE(text.find("light 1 1 1 directional 1 2 3\n"), std::string::npos) << text;
    EXPECT_NE(text.find("light 1 1 1 point 4 5 6\n"), std::string::npos) << text;
}

TEST(RayshadeExport, RayshadeScaleIsReadAndBadValuesAreErrors)
{
    EXPECT_EQ(parse_view_file("rayshade scale: 2.5\n", "t.v").rayshade_scale, 2.5);
    EXPECT_EQ(parse_view_file("", "t.v").rayshade_scale, 1.0);
    set_warnings_enabled(false);
    EXPECT_THROW(parse_view_file("rayshade scale: big\n", "t.v"), Error);
    EXPECT_THROW(parse_view_file("rayshade scale: 0\n", "t.v"), Error);
    set_warnings_enabled(true);
    RayshadeOptions options;
    options.object_name = "p.ray";
    options.scale = 2.5;
    std::string text = rayshade_text(tiny_scene(), options);
    EXPECT_NE(text.find("object p.ray scale 2.5 2.5 2.5\n"), std::string::npos);
}

}  // namespace
