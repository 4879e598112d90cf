// SPDX-License-Identifier: Apache-2.0
// Golden tests for details of cpfg's generator and evaluator that the corpus exposed.
#include "test_util.h"

namespace cambium::lsys {
namespace {

using testing::derive_text;

/// One module A rewritten once; its single parameter is `expr`.
std::string value_of(const std::string& expr, const std::string& start = "")
{
    std::string src = "lsystem: 1\n";
    if (!start.empty())
        src += "Start: {" + start + "}\n";
    src += "derivation length: 1\naxiom: A\nA --> B(" + expr + ")\nendlsystem\n";
    return derive_text(src);
}

TEST(CpfgSemantics, TruncRoundsToNearest)
{
    // cpfg evaluates trunc(x) as floor(x + 0.5)
    EXPECT_EQ(value_of("trunc(2.7)"), "B(3)");
    EXPECT_EQ(value_of("trunc(-2.7)"), "B(-3)");
}

TEST(CpfgSemantics, RemainderIsOnIntegers)
{
    EXPECT_EQ(value_of("7.9 % 3"), "B(1)");
    EXPECT_EQ(value_of("-7 % 3"), "B(-1)");
}

TEST(CpfgSemantics, DivisionByZeroDividesByOne)
{
    EXPECT_EQ(value_of("5 / 0"), "B(5)");
}

TEST(CpfgSemantics, Atan2TakesArgumentsSwapped)
{
    // cpfg's atan2(a, b) is C's atan2(b, a), in degrees
    EXPECT_EQ(value_of("atan2(0, 1)"), "B(90)");
    EXPECT_EQ(value_of("atan2(1, 0)"), "B(0)");
}

TEST(CpfgSemantics, RanStartsFromUnseededErand48State)
{
    // erand48 from the state 0x330E (cpfg's main_xsubi before any srand)
    EXPECT_EQ(value_of("ran(1)"), "B(0.170828)");
    // srand(s) sets the state as srand48(s) does
    EXPECT_EQ(value_of("ran(1)", "srand(0);"), "B(0.170828)");
    EXPECT_NE(value_of("ran(1)", "srand(5);"), "B(0.170828)");
}

TEST(CpfgSemantics, FirstNranBeforeSrandReturnsMean)
{
    // cpfg's nrand starts with a cached deviate of 0 that only srand() clears
    EXPECT_EQ(value_of("nran(4, 2)"), "B(4)");
    EXPECT_NE(value_of("nran(4, 2)", "srand(1);"), "B(4)");
}

TEST(CpfgSemantics, StochasticChoiceDrawsOncePerModule)
{
    // The choice draws erand48 from state 0 for every module, applicable or not:
    // draws 1-4 are below 0.1 and pick B, draw 5 (0.3646) picks C.
    const char* alone = "lsystem: 1\nseed: 2454\nderivation length: 1\naxiom: A\n"
                        "A --> B : 1\nA --> C : 9\nendlsystem\n";
    const char* fifth = "lsystem: 1\nseed: 2454\nderivation length: 1\naxiom: xxxxA\n"
                        "A --> B : 1\nA --> C : 9\nendlsystem\n";
    EXPECT_EQ(derive_text(alone), "B");
    EXPECT_EQ(derive_text(fifth), "xxxxC");
}

TEST(CpfgSemantics, StochasticRunsPostBlockOfChosenProductionOnly)
{
    // Both productions apply (pre-blocks run for each); only the chosen one's
    // post-block runs, once, with its own bindings.
    const char* src = R"(lsystem: 1
seed: 1
Start: {pre=0; post=0;}
derivation length: 1
axiom: A(2)
A(x) : {pre=pre+1;} 1 {post=post+x;} --> B(pre,post) : 1
A(x) : {pre=pre+1;} 1 {post=post+10*x;} --> C(pre,post) : 9
endlsystem
)";
    EXPECT_EQ(derive_text(src), "B(2,2)");
}

// 10-manuals/11-CPFG/Ring: in a `ring lsystem` the first module's left neighbour is the
// last and the last's right neighbour the first; an ordinary L-system has none there.
TEST(CpfgSemantics, RingLsystemContextsWrapAround)
{
    const char* ring = R"(lsystem: 1
ring lsystem
derivation length: 1
axiom: A B B C
B > A --> X
C > A --> Y
B < A --> Z
endlsystem
)";
    EXPECT_EQ(derive_text(ring), "ABBY");
    const char* left = R"(lsystem: 1
ring lsystem
derivation length: 1
axiom: A B C
C < A --> Z
endlsystem
)";
    EXPECT_EQ(derive_text(left), "ZBC");
    std::string open = left;
    open.erase(open.find("ring lsystem\n"), 13);
    EXPECT_EQ(derive_text(open.c_str()), "ABC");
}

TEST(CpfgSemantics, RightContextEqualsSkipsToBranchEnd)
{
    // '=' jumps to the end of the current branch; ']' then matches literally
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: F[+DF]G
F > [+D=] --> X
endlsystem
)";
    EXPECT_EQ(derive_text(src), "X[+DF]G");
}

TEST(CpfgSemantics, RightContextEqualsWithLaterBranch)
{
    // F > [=][-D=]: skip the first branch's content, then match the second
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: F[+AB][-DC]
F > [=][-D=] --> X
endlsystem
)";
    EXPECT_EQ(derive_text(src), "X[+AB][-DC]");
}

TEST(CpfgSemantics, ConsiderWithoutBracketsStepsIntoBranches)
{
    // consider: lists no '[', so cpfg ignores brackets in right context
    const char* src = R"(lsystem: 1
derivation length: 1
consider: AB
axiom: A[B]
A > B --> X
endlsystem
)";
    EXPECT_EQ(derive_text(src), "X[B]");
}

// The pipe model: a node's width is the sum of its lateral branches' and its
// continuation's first widths. Under consider: I[] the right context [I(...)=] matches
// the '[' that opens a lateral branch, its first I, then '=' skips to that branch's ']'
// (past a nested branch and modules consider: leaves out), so I(0,0,0) sums 1 + 2 + 4
// and nothing from the nested branches; no other I is followed by a whole
// [I=][I=]I pattern. The axiom is decomposed only after the first step (manual 5.1.8),
// so the second step is the first to see the I modules and make the sum: a pipe-model
// sum lags the decomposition by a step, as in cpfg's Lilac (the stem's 552, not 618).
TEST(CpfgSemantics, PipeModelSumsTheFirstWidthOfEachBranch)
{
    const char* src = R"(lsystem: 1
derivation length: 2
consider: I[]
axiom: A
I(o,i,w) > [I(o1,i1,w1)=][I(o2,i2,w2)=]I(o3,i3,w3) --> I(o,i,w1+w2+w3)
decomposition
maximum depth: 2
A --> I(0,0,0)[I(1,0,1)B][I(2,0,2)C]I(3,0,4)
B --> I(5,0,10)[I(6,0,20)]
endlsystem
)";
    EXPECT_EQ(derive_text(src, 0), "A");
    EXPECT_EQ(derive_text(src, 1), "I(0,0,0)[I(1,0,1)I(5,0,10)[I(6,0,20)]][I(2,0,2)C]I(3,0,4)");
    EXPECT_EQ(derive_text(src), "I(0,0,7)[I(1,0,1)I(5,0,10)[I(6,0,20)]][I(2,0,2)C]I(3,0,4)");
}

TEST(CpfgSemantics, SpaceAfterAtIsSkipped)
{
    const char* src = "lsystem: 1\nderivation length: 0\naxiom: @ Tx(1)F\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "@Tx(1)F");
}

TEST(ModuleStringStorage, WidensPastByteSymbolIds)
{
    // symbols are stored in one byte until an id above 255 arrives
    ModuleString s;
    const float p[] = {1.5f};
    s.append(7, p);
    s.append(300);
    ModuleString copy;
    copy.append_range(s, 0, 2, 0);
    ASSERT_EQ(copy.size(), 2u);
    EXPECT_EQ(copy.symbol(0), 7);
    EXPECT_EQ(copy.symbol(1), 300);
    EXPECT_EQ(copy.param_count(0), 1u);
    EXPECT_EQ(copy.param_data()[0], 1.5f);
}

}  // namespace
}  // namespace cambium::lsys
