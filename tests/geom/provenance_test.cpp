// SPDX-License-Identifier: Apache-2.0
// Tests of provenance: each primitive and instance names the module of the derived string
// that drew it, and the scene's module table its symbol and age.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "geom/flatten.h"
#include "geom/interpreter.h"
#include "geom/scene_limits.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

ViewFile surface_view()
{
    auto dir = temp_dir("provenance");
    std::ofstream(dir / "square.s") << unit_square_surface();
    std::ofstream(dir / "plant.v") << "angle increment: 90\nline style: cylinder\nsurface: l square.s 1\n";
    return read_view_file(dir / "plant.v");
}

std::string symbol_of(const Scene& scene, std::uint32_t module)
{
    const ModuleRecord* r = scene.geometry.modules.find(module);
    return r ? std::string(scene.geometry.modules.name(*r)) : std::string("<none>");
}

}  // namespace

// A F(1) B [ ~l ] @O: the segment is module 1's, the surface's instance module 4's, the
// sphere module 6's; A, B and the brackets draw nothing and have no record.
TEST(Provenance, EachPrimitiveNamesItsModule)
{
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, "A F(1) B [ ~l ] @O(0.5)");
    ViewFile view = surface_view();
    InterpretOptions options;
    Scene scene = interpret(s, symbols, view, options);
    ASSERT_EQ(scene.geometry.lines.segment_count(), 1u);
    ASSERT_EQ(scene.geometry.lines.module.size(), 1u);
    EXPECT_EQ(scene.geometry.lines.module[0], 1u);
    EXPECT_EQ(symbol_of(scene, 1), "F");
    ASSERT_EQ(scene.geometry.spheres.size(), 1u);
    ASSERT_EQ(scene.geometry.spheres.module.size(), 1u);
    EXPECT_EQ(scene.geometry.spheres.module[0], 6u);
    EXPECT_EQ(symbol_of(scene, 6), "@O");
    ASSERT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.instances[0].module, 4u);
    EXPECT_EQ(symbol_of(scene, 4), "~l");
    ASSERT_EQ(scene.geometry.modules.records.size(), 3u);
    EXPECT_EQ(scene.geometry.modules.find(0), nullptr);  // A drew nothing

    // flattened into the scene's mesh, the surface's triangles keep the instance's module
    FlattenLimits limits;
    ASSERT_EQ(flatten_small_instances(scene, limits), 1u);
    ASSERT_GT(scene.geometry.mesh.size(), 0u);
    ASSERT_EQ(scene.geometry.mesh.module.size(), scene.geometry.mesh.size());
    for (std::uint32_t m : scene.geometry.mesh.module)
        EXPECT_EQ(m, 4u);
}

// A polygon is its `{`'s organ, though its `}` draws it.
TEST(Provenance, PolygonIsItsOpeningBracesModule)
{
    Scene scene = interpret_text("F(1) { . f(1) + . f(1) + . } F(1)", "angle increment: 90\n");
    ASSERT_EQ(scene.geometry.mesh.size(), 1u);
    ASSERT_EQ(scene.geometry.mesh.module.size(), 1u);
    EXPECT_EQ(scene.geometry.mesh.module[0], 1u);
    EXPECT_EQ(symbol_of(scene, 1), "{");
    ASSERT_EQ(scene.geometry.lines.module.size(), 2u);
    EXPECT_EQ(scene.geometry.lines.module[0], 0u);
    EXPECT_EQ(scene.geometry.lines.module[1], 10u);
    // the table stays in string order with the brace's record inserted late
    for (std::size_t i = 1; i < scene.geometry.modules.records.size(); ++i)
        EXPECT_LT(scene.geometry.modules.records[i - 1].index, scene.geometry.modules.records[i].index);
}

// Through the homomorphism: X --> F F gives two segments, both X's, named X; the ages
// come from the derivation's lineage.
TEST(Provenance, HomomorphismSuccessorsAreTheirPredecessors)
{
    lsys::LSystem ls = lsys::LSystem::from_source(R"(lsystem: 1
derivation length: 2
axiom: A
A --> F A X
homomorphism
X --> F(1) F(1)
endlsystem
)");
    std::vector<std::uint16_t> ages;
    lsys::ModuleString derived = ls.derive_with_ages(std::nullopt, ages);
    // F A X -> F F A X X: F(0) from step 1, F from step 2, A from step 0, X step 2, X step 1
    ASSERT_EQ(derived.size(), 5u);
    EXPECT_EQ(ages, (std::vector<std::uint16_t>{1, 2, 0, 2, 1}));
    std::vector<std::uint32_t> origins;
    lsys::ModuleString turtle = ls.interpretation_string(derived, lsys::ObjectHandling::expand, origins);
    ASSERT_EQ(origins.size(), turtle.size());
    InterpretOptions options;
    options.origins = origins;
    options.derived = &derived;
    options.ages = ages;
    Scene scene = interpret(turtle, ls.symbols(), parse_view_file("line style: cylinder\n", "t.v"), options);
    const LinearCurves& l = scene.geometry.lines;
    ASSERT_EQ(l.segment_count(), 6u);
    EXPECT_EQ(l.module, (std::vector<std::uint32_t>{0, 1, 3, 3, 4, 4}));
    EXPECT_EQ(symbol_of(scene, 3), "X");
    EXPECT_EQ(symbol_of(scene, 0), "F");
    EXPECT_EQ(scene.geometry.modules.find(3)->age, 2);
    EXPECT_EQ(scene.geometry.modules.find(4)->age, 1);
    EXPECT_EQ(scene.geometry.modules.find(1)->age, 2);
}

// `-o>` objects: the instance is the object module's, in the derived string.
TEST(Provenance, ObjectInstancesKeepTheirModule)
{
    lsys::LSystem ls = lsys::LSystem::from_source(R"(lsystem: 1
axiom: F(1) A F(1) A
homomorphism
A -o> F(1) [ + F(1) ]
endlsystem
)");
    lsys::ModuleString derived = ls.derive();
    InterpretOptions options;
    options.is_object = [&ls](lsys::SymbolId s) { return ls.is_object_symbol(s); };
    options.expand_object = [&ls](lsys::ModuleRef m) { return ls.expand_object(m); };
    Scene scene = interpret(derived, ls.symbols(),
                            parse_view_file("angle increment: 90\nline style: cylinder\n", "t.v"), options);
    ASSERT_EQ(scene.instances.size(), 2u);
    EXPECT_EQ(scene.instances[0].module, 1u);
    EXPECT_EQ(scene.instances[1].module, 3u);
    EXPECT_EQ(symbol_of(scene, 3), "A");
    // the object's expansion moved the turtle but left no primitive of its own in the scene
    EXPECT_EQ(scene.geometry.lines.module, (std::vector<std::uint32_t>{0, 2}));
    EXPECT_TRUE(scene.prototypes.at(0).geometry.lines.module.empty());
}

// Dropping primitives Embree cannot take drops their entries too.
TEST(Provenance, DroppedPrimitivesTakeTheirEntries)
{
    Scene scene = interpret_text("F(1) @O(0.5) F(1) @O(0.25)", "line style: cylinder\n");
    ASSERT_EQ(scene.geometry.spheres.module, (std::vector<std::uint32_t>{1, 3}));
    scene.geometry.spheres.centres[0][0] = std::numeric_limits<float>::infinity();
    drop_unrenderable(scene);
    EXPECT_EQ(scene.geometry.spheres.module, (std::vector<std::uint32_t>{3}));
}

// Off, nothing is recorded.
TEST(Provenance, Off)
{
    lsys::SymbolTable symbols;
    lsys::ModuleString s = text_modules(symbols, "F(1) @O(1)");
    InterpretOptions options;
    options.provenance = false;
    Scene scene = interpret(s, symbols, parse_view_file("", "t.v"), options);
    EXPECT_TRUE(scene.geometry.lines.module.empty());
    EXPECT_TRUE(scene.geometry.modules.records.empty());
}

// Organ masks' branch order: the brackets open around each drawing module where the
// turtle meets it; recorded only when asked for, parallel to the records.
TEST(Provenance, BranchOrdersWhenAskedFor)
{
    lsys::SymbolTable symbols;
    // modules: 0 F, 1 [, 2 F, 3 [, 4 F, 5 ], 6 ], 7 F, 8 [, 9 F, 10 ]
    lsys::ModuleString s = text_modules(symbols, "F(1) [ F(1) [ F(1) ] ] F(1) [ F(1) ]");
    ViewFile view = surface_view();
    InterpretOptions options;
    EXPECT_TRUE(interpret(s, symbols, view, options).geometry.modules.orders.empty());
    options.branch_orders = true;
    Scene scene = interpret(s, symbols, view, options);
    const ModuleTable& t = scene.geometry.modules;
    ASSERT_EQ(t.records.size(), 5u);
    ASSERT_EQ(t.orders.size(), t.records.size());
    const std::vector<std::pair<std::uint32_t, std::uint16_t>> expected{
        {0, 0}, {2, 1}, {4, 2}, {7, 0}, {9, 1}};
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(t.records[i].index, expected[i].first);
        EXPECT_EQ(t.orders[i], expected[i].second) << "module " << expected[i].first;
    }
}

// Through a homomorphism the order is the derived module's: a successor that opens its
// own bracket (K --> [F]) does not raise its module's order.
TEST(Provenance, BranchOrderOfAModuleWhoseSuccessorOpensABracket)
{
    lsys::SymbolTable symbols;
    // turtle string F [ F ] from the derived string F K: K's successor is [ F ]
    lsys::ModuleString s = text_modules(symbols, "F(1) [ F(1) ]");
    ViewFile view = surface_view();
    InterpretOptions options;
    options.branch_orders = true;
    const std::vector<std::uint32_t> origins{0, 1, 1, 1};
    options.origins = origins;
    Scene scene = interpret(s, symbols, view, options);
    const ModuleTable& t = scene.geometry.modules;
    ASSERT_EQ(t.records.size(), 2u);
    ASSERT_EQ(t.orders.size(), 2u);
    EXPECT_EQ(t.records[1].index, 1u);
    EXPECT_EQ(t.orders[1], 0u) << "K itself is in no branch";
}
