// SPDX-License-Identifier: Apache-2.0
// Tests of `-o>` object instancing: prototypes, instances and the turtle after an object,
// each checked against the same model written with `-->` (expanded inline).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "geom/interpreter.h"
#include "geom/object_instancing.h"
#include "lsys/lsystem.h"
#include "test_util.h"

using namespace cambium;
using namespace cambium::geom;

namespace {

/// A model interpreted twice: with its `-o>` productions instanced, and with every
/// `-o>` turned into `-->` and the homomorphism applied to the whole string.
struct Pair {
    Scene instanced;
    Scene expanded;
};

std::string replace_all(std::string text, const std::string& from, const std::string& to)
{
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    return text;
}

/// The test models give homomorphism productions to object symbols only, so the string
/// with objects kept is the derived string itself.
Scene interpret_instanced(const std::string& source, const ViewFile& view)
{
    lsys::LSystem ls = lsys::LSystem::from_source(source);
    lsys::ModuleString derived = ls.derive();
    InterpretOptions options;
    options.is_object = [&ls](lsys::SymbolId s) { return ls.is_object_symbol(s); };
    options.expand_object = [&ls](lsys::ModuleRef m) { return ls.expand_object(m); };
    return interpret(derived, ls.symbols(), view, options);
}

Scene interpret_inline(const std::string& source, const ViewFile& view)
{
    lsys::LSystem ls = lsys::LSystem::from_source(replace_all(source, "-o>", "-->"));
    return interpret(ls.interpretation_string(ls.derive()), ls.symbols(), view);
}

Pair both(const std::string& source, const std::string& view_text = "angle increment: 90\nline style: cylinder\n")
{
    ViewFile view = parse_view_file(view_text, "t.v");
    return {interpret_instanced(source, view), interpret_inline(source, view)};
}

struct Segment {
    std::array<double, 3> a, b;
    double ra, rb;
};

std::array<double, 3> apply(const std::array<float, 12>& m, const Float4& p)
{
    std::array<double, 3> out{};
    for (int r = 0; r < 3; ++r)
        out[r] = double(m[r]) * p[0] + double(m[3 + r]) * p[1] + double(m[6 + r]) * p[2] + m[9 + r];
    return out;
}

void add_segments(std::vector<Segment>& out, const LinearCurves& lines, const std::array<float, 12>& m)
{
    for (std::uint32_t first : lines.segments) {
        const Float4& a = lines.keys.at(first);
        const Float4& b = lines.keys.at(first + 1);
        out.push_back({apply(m, a), apply(m, b), a[3], b[3]});
    }
}

/// Every round segment of a scene in world space: its own and its instances'.
std::vector<Segment> world_segments(const Scene& scene)
{
    std::vector<Segment> out;
    add_segments(out, scene.geometry.lines, Instance{}.transform);
    for (const Instance& i : scene.instances)
        add_segments(out, scene.prototypes.at(i.prototype).geometry.lines, i.transform);
    return out;
}

/// Whether both lists hold the same segments (in any order) within `tolerance`.
::testing::AssertionResult same_segments(const std::vector<Segment>& x, const std::vector<Segment>& y,
                                         double tolerance = 1e-5)
{
    if (x.size() != y.size())
        return ::testing::AssertionFailure() << x.size() << " segments against " << y.size();
    auto close = [&](const Segment& s, const Segment& t) {
        for (int k = 0; k < 3; ++k)
            if (std::abs(s.a[k] - t.a[k]) > tolerance || std::abs(s.b[k] - t.b[k]) > tolerance)
                return false;
        return std::abs(s.ra - t.ra) <= tolerance && std::abs(s.rb - t.rb) <= tolerance;
    };
    std::vector<bool> used(y.size(), false);
    for (const Segment& s : x) {
        bool found = false;
        for (std::size_t j = 0; j < y.size() && !found; ++j)
            if (!used[j] && close(s, y[j]))
                used[j] = found = true;
        if (!found)
            return ::testing::AssertionFailure()
                   << "no match for (" << s.a[0] << ", " << s.a[1] << ", " << s.a[2] << ") - (" << s.b[0]
                   << ", " << s.b[1] << ", " << s.b[2] << ")";
    }
    return ::testing::AssertionSuccess();
}

void expect_same_bounds(const Scene& a, const Scene& b)
{
    EXPECT_NEAR(a.bounds.lo.x, b.bounds.lo.x, 1e-9);
    EXPECT_NEAR(a.bounds.lo.y, b.bounds.lo.y, 1e-9);
    EXPECT_NEAR(a.bounds.lo.z, b.bounds.lo.z, 1e-9);
    EXPECT_NEAR(a.bounds.hi.x, b.bounds.hi.x, 1e-9);
    EXPECT_NEAR(a.bounds.hi.y, b.bounds.hi.y, 1e-9);
    EXPECT_NEAR(a.bounds.hi.z, b.bounds.hi.z, 1e-9);
}

/// Joints flagged as continued must be continued by the next segment's first key.
void expect_consistent_flags(const LinearCurves& lines)
{
    for (std::size_t i = 0; i < lines.segment_count(); ++i)
        if (lines.flags[i] & LinearCurves::neighbour_right) {
            ASSERT_LT(i + 1, lines.segment_count());
            EXPECT_EQ(lines.segments[i + 1], lines.segments[i] + 1);
        }
}

const char* const three_leaves = R"(lsystem: 1
axiom: A /(30) F(1) A &(45) +(20) F(2) A F(1)
homomorphism
A -o> F(1)[+F(1)]
endlsystem
)";

}  // namespace

TEST(ObjectInstancing, RepeatedObjectIsOnePrototypeThreeInstancesPlacedAsInline)
{
    Pair p = both(three_leaves);
    ASSERT_EQ(p.instanced.prototypes.size(), 1u);
    ASSERT_EQ(p.instanced.instances.size(), 3u);
    // The prototype is drawn from the origin up +y, the branch turned toward L = -x.
    const LinearCurves& proto = p.instanced.prototypes[0].geometry.lines;
    ASSERT_EQ(proto.segment_count(), 2u);
    std::vector<Segment> in_frame;
    add_segments(in_frame, proto, Instance{}.transform);
    EXPECT_TRUE(same_segments(in_frame, {{{0, 0, 0}, {0, 1, 0}, 0.5, 0.5}, {{0, 1, 0}, {-1, 1, 0}, 0.5, 0.5}}));
    // The first occurrence is at the start: the identity placement.
    std::array<float, 12> identity{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    for (int k = 0; k < 12; ++k)
        EXPECT_NEAR(p.instanced.instances[0].transform[k], identity[k], 1e-7) << k;
    // Only the F(1), F(2), F(1) between the objects are the scene's own.
    EXPECT_EQ(p.instanced.geometry.lines.segment_count(), 3u);
    EXPECT_TRUE(same_segments(world_segments(p.instanced), world_segments(p.expanded)));
    expect_same_bounds(p.instanced, p.expanded);
}

TEST(ObjectInstancing, InstancesCarryNoTextureAndTheTurtlesColour)
{
    Pair p = both(three_leaves, "angle increment: 90\nline style: cylinder\ninitial color: 7\n");
    for (const Instance& i : p.instanced.instances) {
        EXPECT_EQ(i.texture, no_texture);
        EXPECT_EQ(i.material, 7);
    }
    EXPECT_EQ(p.instanced.prototypes[0].geometry.lines.material.at(0), 7);
}

TEST(ObjectInstancing, DifferentParametersGiveDifferentPrototypes)
{
    const char* source = R"(lsystem: 1
axiom: A(1) +(30) A(2) +(30) A(1) A(0.5)
homomorphism
A(s) -o> F(s) +(45) F(s/2)
endlsystem
)";
    Pair p = both(source);
    ASSERT_EQ(p.instanced.prototypes.size(), 3u);
    ASSERT_EQ(p.instanced.instances.size(), 4u);
    EXPECT_EQ(p.instanced.instances[0].prototype, p.instanced.instances[2].prototype);
    EXPECT_NE(p.instanced.instances[0].prototype, p.instanced.instances[1].prototype);
    EXPECT_NE(p.instanced.instances[1].prototype, p.instanced.instances[3].prototype);
    EXPECT_TRUE(same_segments(world_segments(p.instanced), world_segments(p.expanded)));
    expect_same_bounds(p.instanced, p.expanded);
}

TEST(ObjectInstancing, TheFormatDecidesWhichParametersAreTheSame)
{
    const char* source = R"(lsystem: 1
axiom: A(1) A(1.01) A(1.04)
homomorphism
A(s) -o> F(s)
endlsystem
)";
    ViewFile full = parse_view_file("line style: cylinder\n", "t.v");
    EXPECT_EQ(interpret_instanced(source, full).prototypes.size(), 3u);
    // %.1f prints 1.0, 1.0, 1.0: one object, built from the first occurrence (cpfg)
    ViewFile coarse = parse_view_file("line style: cylinder\nrayshade objects: %.1f\n", "t.v");
    Scene scene = interpret_instanced(source, coarse);
    ASSERT_EQ(scene.prototypes.size(), 1u);
    ASSERT_EQ(scene.instances.size(), 3u);
    EXPECT_FLOAT_EQ(scene.prototypes[0].geometry.lines.keys.at(1)[1], 1.0f);
    // ...but the turtle still moves by each occurrence's own length: 1 + 1.01
    EXPECT_NEAR(scene.instances[2].transform[10], 2.01, 1e-6);
}

TEST(ObjectInstancing, TurtleConsideredSeparatesObjectsDrawnWithOtherColours)
{
    const char* source = R"(lsystem: 1
axiom: A ;(3) A A
homomorphism
A -o> F
endlsystem
)";
    Scene ignored = interpret_instanced(source, parse_view_file("line style: cylinder\n", "t.v"));
    ASSERT_EQ(ignored.prototypes.size(), 1u);  // cpfg: the first occurrence's colour throughout
    EXPECT_EQ(ignored.prototypes[0].geometry.lines.material.at(0), 128);
    Scene considered = interpret_instanced(source, parse_view_file("line style: cylinder\nrayshade objects: %g turtle considered\n", "t.v"));
    ASSERT_EQ(considered.prototypes.size(), 2u);
    ASSERT_EQ(considered.instances.size(), 3u);
    EXPECT_EQ(considered.prototypes[considered.instances[1].prototype].geometry.lines.material.at(0), 3);
    EXPECT_EQ(considered.instances[1].prototype, considered.instances[2].prototype);
}

TEST(ObjectInstancing, RayshadeObjectsCommandIsReadAsCpfgDoes)
{
    ObjectKeying k = parse_view_file("rayshade objects: %.3f turtle considered\n", "t.v").rayshade_objects;
    EXPECT_EQ(k.format, "%.3f");
    EXPECT_TRUE(k.turtle_considered);
    k = parse_view_file("rayshade objects: %lg turtle\n", "t.v").rayshade_objects;
    EXPECT_EQ(k.format, "%lg");
    EXPECT_FALSE(k.turtle_considered);
    EXPECT_EQ(parse_view_file("", "t.v").rayshade_objects.format, "%g");
    // not a conversion of one number: an error, never handed to printf
    for (const char* format : {"%s", "%g%n", "%123f"})
        EXPECT_THROW(parse_view_file(std::string("rayshade objects: ") + format + "\n", "t.v"), Error) << format;
}

TEST(ObjectInstancing, ObjectsBreakTheLineChainCleanly)
{
    const char* source = R"(lsystem: 1
axiom: F A F !(0.4) F A
homomorphism
A -o> !(0.2) F F
endlsystem
)";
    Pair p = both(source, "initial line width: 1\nline style: cylinder\n");
    EXPECT_TRUE(same_segments(world_segments(p.instanced), world_segments(p.expanded)));
    expect_consistent_flags(p.instanced.geometry.lines);
    expect_same_bounds(p.instanced, p.expanded);
}

TEST(ObjectInstancing, ObjectThatDrawsNothingPlacesNoInstance)
{
    Pair p = both(R"(lsystem: 1
axiom: F A F A F
homomorphism
A -o> +(90) f(2)
endlsystem
)");
    EXPECT_TRUE(p.instanced.prototypes.empty());
    EXPECT_TRUE(p.instanced.instances.empty());
    EXPECT_TRUE(same_segments(world_segments(p.instanced), world_segments(p.expanded)));
    expect_same_bounds(p.instanced, p.expanded);
}

TEST(ObjectInstancing, PolygonBegunBeforeAnObjectIsTheScenesOwn)
{
    Pair p = both(R"(lsystem: 1
axiom: {(0) . f(1) . +(90) A
homomorphism
A -o> f(1) . }(0)
endlsystem
)");
    ASSERT_EQ(p.instanced.geometry.mesh.triangles.size(), 1u);
    ASSERT_EQ(p.expanded.geometry.mesh.triangles.size(), 1u);
    EXPECT_EQ(p.instanced.geometry.mesh.positions, p.expanded.geometry.mesh.positions);
    EXPECT_TRUE(p.instanced.instances.empty());
}

TEST(ObjectInstancing, ObjectsWithinAnObjectAreItsOwnGeometry)
{
    const char* source = R"(lsystem: 1
axiom: B +(30) B
homomorphism
maximum depth: 2
B -o> F [ A ] /(90) A
A -o> &(45) F(0.5)
endlsystem
)";
    Pair p = both(source);
    ASSERT_EQ(p.instanced.prototypes.size(), 1u);  // B only; its A's are inside it
    EXPECT_EQ(p.instanced.prototypes[0].geometry.lines.segment_count(), 3u);
    EXPECT_TRUE(same_segments(world_segments(p.instanced), world_segments(p.expanded)));
    expect_same_bounds(p.instanced, p.expanded);
}

namespace {

/// Every triangle corner of a scene's instances in world space, with its material.
std::vector<std::pair<std::array<double, 3>, int>> world_corners(const Scene& scene)
{
    std::vector<std::pair<std::array<double, 3>, int>> out;
    for (const Instance& i : scene.instances) {
        const TriangleMesh& mesh = scene.prototypes.at(i.prototype).geometry.mesh;
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
            int material = mesh.material[t] == inherit_material ? i.material : mesh.material[t];
            for (std::uint32_t v : mesh.triangles[t]) {
                const Float3& p = mesh.positions[v];
                out.push_back({apply(i.transform, {p[0], p[1], p[2], 0}), material});
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

TEST(ObjectInstancing, SurfacesInsideAnObjectBecomeItsTriangles)
{
    auto dir = std::filesystem::temp_directory_path() / "cambium_object_instancing_surface";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "square.s") << unit_square_surface();
    std::ofstream(dir / "plant.v") << "angle increment: 90\nline style: cylinder\nsurface: a square.s 2\n";
    ViewFile view = read_view_file(dir / "plant.v");
    const char* source = R"(lsystem: 1
axiom: A +(30) &(20) A
homomorphism
A -o> F ;(7) /(45) ~a(1.5) F
endlsystem
)";
    Scene instanced = interpret_instanced(source, view);
    Scene expanded = interpret_inline(source, view);
    ASSERT_EQ(instanced.prototypes.size(), 2u);  // the surface and the object
    ASSERT_EQ(instanced.instances.size(), 2u);   // the objects only: one level deep
    const Geometry& object = instanced.prototypes[instanced.instances[0].prototype].geometry;
    ASSERT_GT(object.mesh.size(), 0u);
    for (std::uint16_t m : object.mesh.material)
        EXPECT_EQ(m, 7);
    auto a = world_corners(instanced), b = world_corners(expanded);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a[k].first[c], b[k].first[c], 1e-5);
        EXPECT_EQ(a[k].second, b[k].second);
    }
    EXPECT_TRUE(same_segments(world_segments(instanced), world_segments(expanded)));
    expect_same_bounds(instanced, expanded);
}

TEST(ObjectInstancing, PixelWideLinesAreInstancedToo)
{
    // the renderer sizes a prototype's pixel lines per placed copy
    Pair p = both(three_leaves, "angle increment: 90\nline style: pixel\n");
    EXPECT_EQ(p.instanced.prototypes.size(), 1u);
    EXPECT_EQ(p.instanced.instances.size(), 3u);
    EXPECT_TRUE(same_segments(world_segments(p.instanced), world_segments(p.expanded)));
}

TEST(ObjectInstancing, WithoutHooksTheStringIsInterpretedAsItIs)
{
    lsys::LSystem ls = lsys::LSystem::from_source(three_leaves);
    Scene scene = interpret(ls.derive(), ls.symbols(), parse_view_file("", "t.v"));
    EXPECT_TRUE(scene.instances.empty());
    EXPECT_EQ(scene.geometry.lines.segment_count(), 3u);  // A draws nothing by itself
}
