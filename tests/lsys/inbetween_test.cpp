// SPDX-License-Identifier: Apache-2.0
// Lineage of derivation steps and the in-between strings of --inbetween.
#include "test_util.h"

#include "lsys/inbetween.h"

namespace cambium::lsys {
namespace {

/// The symbols F (F alone is F(1)) and ! grow from zero.
std::vector<Growth> lengths(const LSystem& ls)
{
    std::vector<Growth> grows(ls.symbols().size());
    if (int id = ls.symbols().find("F"); id >= 0)
        grows[std::size_t(id)] = {true, 1};
    if (int id = ls.symbols().find("!"); id >= 0)
        grows[std::size_t(id)] = {true, 0};
    return grows;
}

TEST(Lineage, ProductionsContinueTheirPredecessorsSymbol)
{
    LSystem ls = LSystem::from_source(
        "lsystem: 1\nderivation length: 2\naxiom: F(1) A\n"
        "F(x) --> F(x+1)\nA --> F(1)[+A]A\nendlsystem\n");
    Derivation d = ls.start();
    d.track_lineage();
    d.advance(1);
    // F(2) F(1) [ + A ] A: F continues F (0); A's successor: its first A (in the branch)
    // continues it; F(1), [, +, ], and the second A appeared.
    EXPECT_EQ(to_text(d.string(), ls.symbols()), "F(2)F(1)[+A]A");
    std::vector<std::uint32_t> expected = {0, no_parent, no_parent, no_parent, 1,
                                           no_parent, no_parent};
    EXPECT_EQ(d.lineage(), expected);
}

TEST(Lineage, ComposesAcrossStepsAndDecomposition)
{
    LSystem ls = LSystem::from_source(
        "lsystem: 1\nderivation length: 2\naxiom: F(1)\n"
        "F(x) --> F(x+1) B(x)\n"
        "decomposition\nB(x) --> !(x)\nendlsystem\n");
    Derivation d = ls.start();
    d.track_lineage();
    d.advance(1);
    EXPECT_EQ(to_text(d.string(), ls.symbols()), "F(2)!(1)");
    EXPECT_EQ(d.lineage(), (std::vector<std::uint32_t>{0, no_parent}));
    d.advance(1);
    // !(1) is copied (no production rewrites !): it continues module 1
    EXPECT_EQ(to_text(d.string(), ls.symbols()), "F(3)!(2)!(1)");
    EXPECT_EQ(d.lineage(), (std::vector<std::uint32_t>{0, no_parent, 1}));
    // advance(2) from the axiom: composed over both steps
    Derivation two = ls.start();
    two.track_lineage();
    two.advance(2);
    EXPECT_EQ(two.lineage(), (std::vector<std::uint32_t>{0, no_parent, no_parent}));
}

TEST(Inbetween, ContinuingModulesInterpolateAndNewOnesGrowFromZero)
{
    LSystem ls = LSystem::from_source(
        "lsystem: 1\nderivation length: 1\naxiom: F(1) A !(4)\n"
        "F(x) --> F(x+1)\nA --> +(30) F(2) A\n!(w) --> !(w*2)\nendlsystem\n");
    Derivation d = ls.start();
    ModuleString before = d.string();
    d.track_lineage();
    d.advance(1);
    ASSERT_EQ(to_text(d.string(), ls.symbols()), "F(2)+(30)F(2)A!(8)");
    std::vector<std::string> frames;
    for (int k = 1; k <= 3; ++k)  // K = 3: t = 1/4, 2/4, 3/4
        frames.push_back(to_text(inbetween(before, d.string(), d.lineage(), k / 4.0f, lengths(ls)),
                                 ls.symbols()));
    // F(x) --> F(x+1): 1.25, 1.5, 1.75; !(w) thickens 4 -> 8; the new F(2) grows from 0;
    // the new +(30) is not a length: it turns at once.
    EXPECT_EQ(frames[0], "F(1.25)+(30)F(0.5)A!(5)");
    EXPECT_EQ(frames[1], "F(1.5)+(30)F(1)A!(6)");
    EXPECT_EQ(frames[2], "F(1.75)+(30)F(1.5)A!(7)");
    // the ends are the steps themselves
    EXPECT_EQ(to_text(inbetween(before, d.string(), d.lineage(), 1, lengths(ls)), ls.symbols()),
              to_text(d.string(), ls.symbols()));
    EXPECT_THROW(inbetween(before, d.string(), {}, 0.5f, lengths(ls)), std::invalid_argument);
}

TEST(Inbetween, ParameterlessLengthsGrowFromTheirImpliedValue)
{
    LSystem ls = LSystem::from_source(
        "lsystem: 1\nderivation length: 1\naxiom: A\nA --> F!F(2,7)A\nendlsystem\n");
    Derivation d = ls.start();
    ModuleString before = d.string();
    d.track_lineage();
    d.advance(1);
    // F stands for F(1); ! (narrower by the increment) has no implied value; of F(l, o)
    // only the length grows
    EXPECT_EQ(to_text(inbetween(before, d.string(), d.lineage(), 0.5f, lengths(ls)), ls.symbols()),
              "F(0.5)!F(1,7)A");
}

}  // namespace
}  // namespace cambium::lsys
