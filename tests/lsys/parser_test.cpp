// SPDX-License-Identifier: Apache-2.0
// Parser and lexer behaviour: module names, sections, and located error messages.
#include <utility>
#include <vector>

#include "lsys/program.h"
#include "test_util.h"

namespace cambium::lsys {
namespace {

using testing::derive_text;
using testing::load_error;

TEST(LsysParser, ReportsColumnOfMissingArrow)
{
    std::string e = load_error("lsystem: 1\naxiom: A\nA(x) B\nendlsystem\n");
    EXPECT_NE(e.find("test.l:3:7: error: expected '-->', found end of line"), std::string::npos)
        << e;
}

TEST(LsysParser, ReportsLineOfBadExpression)
{
    std::string e = load_error("lsystem: 1\n\naxiom: A(1)\nA(x) --> B(x*)\nendlsystem\n");
    EXPECT_NE(e.find("test.l:4:14: error: expected an expression, found ')'"),
              std::string::npos)
        << e;
}

TEST(LsysParser, ReportsMissingEndlsystem)
{
    std::string e = load_error("lsystem: 1\naxiom: A\nA --> B\n");
    EXPECT_NE(e.find("test.l:4:1: error: expected a production or 'endlsystem', found end of file"),
              std::string::npos)
        << e;
}

TEST(LsysParser, ReportsUnknownFunction)
{
    std::string e = load_error("lsystem: 1\naxiom: A(frob(2))\nendlsystem\n");
    EXPECT_NE(e.find("test.l:2:10: error: unknown function 'frob'"), std::string::npos) << e;
}

TEST(LsysParser, LineNumbersSurviveMacrosAndComments)
{
    std::string e = load_error(
        "#define X 3\n/* a\n comment */\nlsystem: 1\naxiom: A(X)\nA --> B(\nendlsystem\n");
    EXPECT_NE(e.find("test.l:6:"), std::string::npos) << e;
}

TEST(LsysParser, RejectsDeepExpressionNesting)
{
    std::string deep(500, '(');
    std::string src = "lsystem: 1\naxiom: A(" + deep + "1" + std::string(500, ')') +
                      ")\nendlsystem\n";
    EXPECT_NE(load_error(src).find("nested too deeply"), std::string::npos);
}

TEST(LsysParser, AtCommandsTildeAndQueryModulesAreSingleModules)
{
    LSystem ls = LSystem::from_source(
        "lsystem: 1\naxiom: @Gs@GcF(1)@O(2)~l(3)?P(0,0)@v@oZG\nendlsystem\n");
    ModuleString s = ls.axiom();
    std::vector<std::string> names;
    s.for_each([&](ModuleRef m) { names.emplace_back(ls.symbols().name(m.symbol)); });
    EXPECT_EQ(names, (std::vector<std::string>{"@Gs", "@Gc", "F", "@O", "~l", "?P", "@v", "@o",
                                               "Z", "G"}));
}

TEST(LsysParser, KeywordSpellingsOfTheCorpus)
{
    const char* src = "Lsystem: 1\nDerivation Length: 1\nAxiom: A\nA --> B\nendLsystem\n";
    EXPECT_EQ(derive_text(src), "B");
}

TEST(LsysParser, StarContextsAndConditions)
{
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: A\n* < A > * : * --> B\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "B");
}

TEST(LsysParser, TabContinuesProductionOnNextLine)
{
    const char* src = "lsystem: 1\nderivation length: 1\naxiom: A\nA --> B\n\tC\n\tD\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "BCD");
}

TEST(LsysParser, LineWithoutTabEndsProduction)
{
    std::string e = load_error("lsystem: 1\naxiom: A\nA --> B\n C\nendlsystem\n");
    EXPECT_NE(e.find("test.l:4:3: error: expected '-->'"), std::string::npos) << e;
}

TEST(LsysParser, ParsesMultipleLsystemsAndSections)
{
    LSystem ls = LSystem::from_source(R"(lsystem: 1
axiom: A
A --> B
homomorphism: no warnings
maximum depth: 3
B --> F
endlsystem
lsystem: 2
axiom: C
endlsystem
)");
    const Program& p = ls.program();
    ASSERT_EQ(p.lsystems.size(), 2u);
    EXPECT_EQ(p.lsystems[1].id, 2);
    EXPECT_EQ(p.lsystems[0].homomorphism.productions.size(), 1u);
    EXPECT_TRUE(p.lsystems[0].homomorphism.max_depth.has_value());
}

TEST(LsysParser, StochasticProbabilityParsed)
{
    LSystem ls = LSystem::from_source("lsystem: 1\nseed: 3\naxiom: A\nA --> B : 0.3\nA --> C : 0.7\nendlsystem\n");
    ASSERT_EQ(ls.program().lsystems[0].productions.productions.size(), 2u);
    EXPECT_TRUE(ls.program().lsystems[0].productions.productions[1].probability.has_value());
}

TEST(LsysParser, SubLsystemSwitchesProductionSets)
{
    const char* src = R"(lsystem: 1
derivation length: 1
axiom: A?(2)A$A
A --> X
endlsystem
lsystem: 2
axiom: A
A --> Y
endlsystem
)";
    EXPECT_EQ(derive_text(src), "X?(2)Y$X");
}

/// Three independent errors: a missing arrow, a bad expression, an unknown header item's
/// value; each is reported to the sink at its position and the Error lists all three.
TEST(LsysParser, ReportsSeveralErrorsWithTheirPositions)
{
    Diagnostics sink(Diagnostics::Output::quiet);
    ScopedDiagnostics install(sink);
    std::string e = load_error("lsystem: 1\n"
                               "derivation length: 2 +\n"
                               "axiom: A(1)\n"
                               "A(x) B\n"
                               "B --> C\n"
                               "C(x) --> D(x*)\n"
                               "D --> E\n"
                               "endlsystem\n");
    EXPECT_EQ(e.rfind("test.l: error: 3 errors:", 0), 0u) << e;
    std::vector<Diagnostic> errors = sink.collected();
    ASSERT_EQ(sink.count(Severity::error), 3u) << sink.text();
    std::vector<std::pair<int, int>> at;
    for (const Diagnostic& d : errors)
        if (d.severity == Severity::error)
            at.emplace_back(d.loc.line, d.loc.column);
    EXPECT_EQ(at, (std::vector<std::pair<int, int>>{{2, 23}, {4, 7}, {6, 14}}));
    for (const char* part : {"test.l:2:23: error: expected an expression", "test.l:4:7: error: expected '-->'",
                             "test.l:6:14: error: expected an expression, found ')'"})
        EXPECT_NE(e.find(part), std::string::npos) << part << " missing in: " << e;
}

/// The productions between and after the errors are parsed: a file whose only fault is
/// one production still says that one error alone, as before.
TEST(LsysParser, OneErrorIsThrownAsItIs)
{
    std::string e = load_error("lsystem: 1\naxiom: A\nA(x) B\nB --> C\nendlsystem\n");
    EXPECT_EQ(e.rfind("test.l:3:7: error: expected '-->', found end of line", 0), 0u) << e;
}

/// A file of garbage stops at the cap, not after a line per error.
TEST(LsysParser, ErrorsAreCappedAtTwenty)
{
    std::string source = "lsystem: 1\naxiom: A\n";
    for (int i = 0; i < 30; ++i)
        source += "A(x) B" + std::to_string(i) + "\n";
    source += "endlsystem\n";
    std::string e = load_error(source);
    EXPECT_EQ(e.rfind("test.l: error: 20 errors (stopped after 20):", 0), 0u) << e;
    EXPECT_NE(e.find("test.l:22:"), std::string::npos) << e;
    EXPECT_EQ(e.find("test.l:23:"), std::string::npos) << e;
}

}  // namespace
}  // namespace cambium::lsys

namespace cambium::lsys {
namespace {

TEST(LsysParser, ExpressionStatementStartingWithAVariableIsEvaluatedAndDropped)
{
    // cpfg accepts `x - 1;` as a statement (04-paintbrush writes `roll - roll/L0;`):
    // the value is dropped and x is unchanged.
    std::string text = testing::derive_text(
        "lsystem: 1\nderivation length: 1\naxiom: A(4)\n"
        "A(x) : { y = x; y - 1; y + x * 2; } --> B(y)\nendlsystem\n");
    EXPECT_EQ(text, "B(4)");
}

TEST(LsysParser, StatementOfAVariableAloneStillNeedsASemicolon)
{
    std::string e = load_error(
        "lsystem: 1\naxiom: A(4)\nA(x) : { y = x; y } --> B(y)\nendlsystem\n");
    EXPECT_NE(e.find("test.l:3:"), std::string::npos) << e;
}

}  // namespace
}  // namespace cambium::lsys
