// SPDX-License-Identifier: Apache-2.0
// Golden derivations of small inline L-systems, worked out by hand.
#include "test_util.h"

namespace cambium::lsys {
namespace {

using testing::derive_text;

const char* koch = R"(lsystem: 1
derivation length: 2
axiom: F
F --> F+F-F-FF+F+F-F
endlsystem
)";

TEST(Derive, KochOneStep)
{
    EXPECT_EQ(derive_text(koch, 1), "F+F-F-FF+F+F-F");
}

TEST(Derive, KochTwoStepsIsDerivationLength)
{
    EXPECT_EQ(derive_text(koch),
              "F+F-F-FF+F+F-F+F+F-F-FF+F+F-F-F+F-F-FF+F+F-F-F+F-F-FF+F+F-FF+F-F-FF+F+F-F+F+F-"
              "F-FF+F+F-F+F+F-F-FF+F+F-F-F+F-F-FF+F+F-F");
}

TEST(Derive, ZeroStepsGivesAxiom)
{
    EXPECT_EQ(derive_text(koch, 0), "F");
}

TEST(Derive, ParametricHalving)
{
    const char* src = R"(Lsystem: 1
derivation length: 2
Axiom: F(1)
F(x) --> F(x*0.5)+F(x*0.5)
endLsystem
)";
    EXPECT_EQ(derive_text(src, 1), "F(0.5)+F(0.5)");
    EXPECT_EQ(derive_text(src), "F(0.25)+F(0.25)+F(0.25)+F(0.25)");
}

TEST(Derive, FirstMatchingProductionWinsAndConditionsSelect)
{
    const char* src = R"(lsystem: 1
derivation length: 3
axiom: A(0)
A(n) : n < 2 --> B A(n+1)
A(n) : n >= 2 --> C(n*10)
A(n) --> X
endlsystem
)";
    EXPECT_EQ(derive_text(src), "BBC(20)");
}

TEST(Derive, ExpressionOperatorsAndFunctions)
{
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: A(2,3)
A(x,y) --> B(x^y, -x^2, 7%3, x<y && y<4, !(x==2) || 0, sin(90), sqrt(16), floor(-1.5), sign(-3), atan2(1,1), x>1 ? 5 : 6)
endlsystem
)";
    EXPECT_EQ(derive_text(src), "B(8,4,1,1,0,1,4,-2,-1,45,5)");
}

TEST(Derive, ParametersAreStoredAsFloat)
{
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: A(0.1)
A(x) --> B(x*3)
endlsystem
)";
    LSystem ls = LSystem::from_source(src);
    ModuleString s = ls.derive();
    float expected = static_cast<float>(static_cast<double>(0.1f) * 3.0);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ((*s.begin()).params[0], expected);
}

TEST(Derive, UnmatchedModulesAreCopiedWithParameters)
{
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: +(30)[F(2)]A
A --> B
endlsystem
)";
    EXPECT_EQ(derive_text(src), "+(30)[F(2)]B");
}

TEST(Derive, EmptySuccessorDeletes)
{
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: ABA\nA --> *\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "B");
}

TEST(Derive, MultiModulePredecessorConsumesAll)
{
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: ABAC\nAB --> X\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "XAC");
}

TEST(Derive, GrowthLimitIsAClearError)
{
    LoadOptions options;
    options.max_modules = 1000;
    LSystem ls = LSystem::from_source(
        "lsystem: 1\nderivation length: 20\naxiom: F\nF --> FF\nendlsystem\n", "grow.l", options);
    try {
        ls.derive();
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("grew past 1000 modules"), std::string::npos)
            << e.what();
    }
}

TEST(DeriveContext, LeftContextSkipsBranchesAndIgnored)
{
    // B's left neighbour, skipping the branch [C] and the ignored '+', is A.
    const char* src = R"(lsystem: 1
derivation length: 1
ignore: +
axiom: A(7)[C]+B
A(x) < B --> D(x)
endlsystem
)";
    EXPECT_EQ(derive_text(src), "A(7)[C]+D(7)");
}

TEST(DeriveContext, LeftContextCrossesIntoParentBranch)
{
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: A[B]\nA < B --> X\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "A[X]");
}

TEST(DeriveContext, RightContextSkipsLateralBranchesButNotBranchEnd)
{
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: A[B]C[A]
A > C --> X
endlsystem
)";
    EXPECT_EQ(derive_text(src), "X[B]C[A]");
}

TEST(DeriveContext, SignalPropagatesOneModulePerStep)
{
    const char* src = R"(lsystem: 1
derivation length: 2
axiom: S A A A
S < A --> S
endlsystem
)";
    EXPECT_EQ(derive_text(src), "SSSA");
}

TEST(DeriveBlocks, PreAndPostConditionBlocks)
{
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: A(4) A(1)
A(y) : {x = y/2; s = x*x;} s < 5 {z = sqrt(y);} --> B(z) C(z+1)
endlsystem
)";
    // A(4): x=2, s=4 < 5, z=2; A(1): x=0.5, s=0.25, z=1
    EXPECT_EQ(derive_text(src), "B(2)C(3)B(1)C(2)");
}

TEST(DeriveBlocks, GlobalBlocksAndStatements)
{
    const char* src = R"(lsystem: 1
derivation length: 3
Start: {age = 0; total = 0;}
StartEach: {age = age + 1;}
EndEach: {i = 0; while (i < 2) {total = total + 1; i = i + 1;} if (age == 2) {total = total + 100;} else {do {total = total + 0;} while (0);}}
axiom: A
A --> B(age, total) A
endlsystem
)";
    EXPECT_EQ(derive_text(src), "B(1,0)B(2,2)B(3,104)A");
}

TEST(DeriveBlocks, DefinedArrays)
{
    const char* src = R"(lsystem: 1
define: { array rate[2][2] = {1, 2, 3, 4}, v[3]; }
derivation length: 1
axiom: A(1)
A(i) : {v[2] = rate[i][0] + rate[i][1];} 1 --> B(v[2], rate[0][1])
endlsystem
)";
    EXPECT_EQ(derive_text(src), "B(7,2)");
}

TEST(DeriveDecomposition, AppliedAfterEachStepToMaximumDepth)
{
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: A
A --> M
decomposition
maximum depth: 2
M --> N N
N --> x
homomorphism
x --> F
endlsystem
)";
    EXPECT_EQ(derive_text(src), "xx");
}

// Manual 5.1.8: decomposition replaces modules "after each simulation step, before the
// string is interpreted", so the axiom is not decomposed: the first step's productions
// see X(3), and only its decomposition gives A B B (cpfg's Ring: A and 31 B).
TEST(DeriveDecomposition, AxiomIsDecomposedOnlyAfterTheFirstStep)
{
    const char* src = R"(lsystem: 1
derivation length: 2
axiom: X(3)
A < B --> A
A --> B
decomposition
maximum depth: 10
X(n) : n > 1 --> X(n-1)B
X(n) : n == 1 --> A
endlsystem
)";
    EXPECT_EQ(derive_text(src, 0), "X(3)");
    EXPECT_EQ(derive_text(src, 1), "ABB");
    EXPECT_EQ(derive_text(src, 2), "BAB");
}

// The same in a ring L-system, whose first module's left context is the last one
TEST(DeriveDecomposition, RingAxiomIsDecomposedOnlyAfterTheFirstStep)
{
    const char* src = R"(lsystem: 1
ring lsystem
derivation length: 1
axiom: X(4)
A < B --> A
A --> B
decomposition
maximum depth: 10
X(n) : n > 1 --> X(n-1)B
X(n) : n == 1 --> A
endlsystem
)";
    EXPECT_EQ(derive_text(src), "ABBB");
}

TEST(DeriveCut, PercentRemovesRestOfBranch)
{
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: A[B%CD[E]F]G\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "A[B]G");
}

// Manual 5.1.9: @mc(flag) "operates as the module % (with no parameter) only if the
// value of flag is equal to 1. Otherwise, it has no effect."
TEST(DeriveCut, ConditionalCutCutsOnlyWhenFlagIsOne)
{
    const char* src = "lsystem: 1\nderivation length: 1\n"
                      "axiom: A[B@mc(1)CD[E]F]G[H@mc(0)I]J[K@mc(2)L]\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "A[B]G[H@mc(0)I]J[K@mc(2)L]");
}

TEST(DeriveCut, ConditionalCutFlagComesFromTheProduction)
{
    // the cut happens in the step after @mc(1) is produced, as with %
    const char* src = "lsystem: 1\nderivation length: 2\naxiom: A(0)[A(1)]\n"
                      "A(n) --> B@mc(n)C\nendlsystem\n";
    EXPECT_EQ(derive_text(src, 1), "B@mc(0)C[B@mc(1)C]");
    EXPECT_EQ(derive_text(src, 2), "B@mc(0)C[B]");
}

// Manual 5.1.9: %(par) supports fragmentation: after the step, the substring after it
// "up to the closing ']' at the same level or up to the next %(par)" is "moved to the end
// of the L-system string and it is preceded by a symbol %(par, turtle_index)". The
// fragment is derived in that step (cpfg's Derive goes on past the string's end). Without
// a turtle pass (no view), every %(par) is a fragment start, numbered in string order.
TEST(DeriveFragment, FragmentMovesToTheEndBehindItsTurtleIndex)
{
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: A[B%(1)CD]G\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "A[B]G%(1,0)CD");
}

// Worked by hand from the manual's rule:
//   axiom  F [ + %(7) B [ C ] D ] E %(8) G
//   step 1: %(7)'s fragment is "B [ C ] D" (to its branch's ']'), %(8)'s is "G" (to the
//     end); both derived at the end, turtles 0 and 1:
//     F [ + ] E  %(7,0) BB [ CC ] D%(9)K  %(8,1) H
//   step 2: the new %(9) is reached first (turtle 2, counted over the run); its fragment
//     "K" ends at the next % with parameters. "E < B" does not apply although % is
//     ignored: "the context searches are not passing over this module".
TEST(DeriveFragment, HandDerivedTwoSteps)
{
    const char* src = "lsystem: 1\nderivation length: 2\nignore: %\n"
                      "axiom: F[+%(7)B[C]D]E%(8)G\n"
                      "E < B --> Y\nB --> BB\nC --> CC\nG --> H\nD --> D%(9)K\nendlsystem\n";
    EXPECT_EQ(derive_text(src, 1), "F[+]E%(7,0)BB[CC]D%(9)K%(8,1)H");
    EXPECT_EQ(derive_text(src, 2), "F[+]E%(7,0)BBBB[CCCC]D%(9)K%(8,1)H%(9,2)K");
}

TEST(DeriveFragment, SavedTurtlesAreBounded)
{
    // each step doubles the fragment starts: 2 + 4 turtles by step 3 pass a limit of 5
    LoadOptions options;
    options.max_saved_turtles = 5;
    LSystem ls = LSystem::from_source("lsystem: 1\nderivation length: 3\naxiom: A\n"
                                      "A --> [%(1)A][%(1)A]\nendlsystem\n",
                                      "test.l", options);
    EXPECT_NO_THROW(ls.derive(2));
    try {
        ls.derive(3);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("test.l"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("more than 5 fragment starts"), std::string::npos)
            << e.what();
    }
}

// The turtle pass reads the string through the homomorphism; the fragment starts it
// reaches are found again in the derived string. A %(par) that the homomorphism writes
// takes a turtle index in the pass but has no fragment to move (docs/deviations.md).
TEST(DeriveFragment, TurtlePassThroughTheHomomorphism)
{
    std::vector<std::uint32_t> firsts;
    LoadOptions options;
    options.fragment_pass = [&](const ModuleString& s, std::uint32_t first) {
        firsts.push_back(first);
        std::vector<std::uint32_t> reached;
        // every one-parameter module the turtle meets is a `%` here
        for (std::size_t i = 0; i < s.size(); ++i)
            if (s.param_count(i) == 1)
                reached.push_back(static_cast<std::uint32_t>(i));
        return reached;
    };
    LSystem ls = LSystem::from_source("lsystem: 1\nderivation length: 1\naxiom: B[A%(3)C]D\n"
                                      "homomorphism\nB --> FFF\nA --> %(9)G\nendlsystem\n",
                                      "test.l", options);
    // interpreted: F F F [ %(9) G %(3) C ] D: %(9) takes turtle 0, %(3) turtle 1
    EXPECT_EQ(to_text(ls.derive(), ls.symbols()), "B[A]D%(3,1)C");
    EXPECT_EQ(firsts, std::vector<std::uint32_t>{0});
}

TEST(DeriveFragment, ContextStopsAtPercentWithParameters)
{
    // right context too; a context that names % itself still matches it
    const char* src = "lsystem: 1\nderivation length: 1\nignore: %\n"
                      "axiom: A%(1,0)B C%(2,0)D\n"
                      "A > B --> X\nC > %(p,q) --> Z\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "A%(1,0)BZ%(2,0)D");
}

TEST(DeriveFragment, PlainCutStopsAtTheNextFragmentStart)
{
    // cpfg's SkipCutPart ends a cut at any % with parameters
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: A[B%C%(5,0)D]E\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "A[B%(5,0)D]E");
}

TEST(DeriveFragment, ProductionOnPercentPreventsTheMove)
{
    // "A production with %(par) as a predecessor will prevent the moving of the substring."
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: A[%(1)B]C\n"
                      "%(x) --> %(x+1)\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "A[%(2)B]C");
}

TEST(DeriveStochastic, SameSeedSameString)
{
    const char* src = R"(lsystem: 1
seed: 7
derivation length: 6
axiom: A
A --> AB : 1
A --> AC : 1
endlsystem
)";
    std::string a = derive_text(src);
    EXPECT_EQ(a, derive_text(src));
    EXPECT_EQ(a.size(), 7u);
}

// cpfg keeps each production's variables from its previous application: a block that
// skips its assignment sees the old value (corpus 06-phyllotaxis-ridley relies on it).
TEST(Derive, ProductionVariablesPersistBetweenApplications)
{
    const std::string source = "lsystem: 1\nderivation length: 3\naxiom: A(1)\n"
                               "A(n) : 1 { if (n == 1) { x = 5; } } --> B(x) A(n+1)\n"
                               "endlsystem\n";
    EXPECT_EQ(derive_text(source), "B(5)B(5)B(5)A(4)");
}

TEST(Derive, EachProductionHasItsOwnVariables)
{
    const std::string source = "lsystem: 1\nderivation length: 2\naxiom: A C\n"
                               "A : 1 { x = x + 1; } --> B(x) A\n"
                               "C : 1 { x = x + 10; } --> D(x) C\n"
                               "endlsystem\n";
    EXPECT_EQ(derive_text(source), "B(1)B(2)AD(10)D(20)C");
}

}  // namespace
}  // namespace cambium::lsys
