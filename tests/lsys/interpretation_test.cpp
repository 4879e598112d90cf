// SPDX-License-Identifier: Apache-2.0
// Homomorphism, object productions, queries, func() and @-commands at interpretation time.
#include "test_util.h"

#include <filesystem>
#include <fstream>
#include <set>

namespace cambium::lsys {
namespace {

std::string interpreted(const std::string& source, const LoadOptions& options = {})
{
    LSystem ls = LSystem::from_source(source, "test.l", options);
    return to_text(ls.interpretation_string(ls.derive()), ls.symbols());
}

TEST(Interpretation, HomomorphismDefaultsToDepthOne)
{
    EXPECT_EQ(interpreted(R"(lsystem: 1
axiom: A
homomorphism
A --> B
B --> C
endlsystem
)"),
              "B");
}

TEST(Interpretation, HomomorphismRecursesToItsMaximumDepth)
{
    // A --> AA applied 5 levels deep: 2^5 modules
    EXPECT_EQ(interpreted(R"(lsystem: 1
axiom: A
homomorphism
maximum depth: 5
A --> AA
endlsystem
)"),
              std::string(32, 'A'));
    EXPECT_EQ(interpreted(R"(lsystem: 1
axiom: A
homomorphism
maximum depth: 3
A --> B
B --> C
endlsystem
)"),
              "C");
}

/// The warnings loading, deriving and interpreting `source` reports, one a line.
std::string stderr_of(const std::string& source, const char* file_name)
{
    Diagnostics sink(Diagnostics::Output::quiet);
    ScopedDiagnostics install(sink);
    LSystem ls = LSystem::from_source(source, file_name);
    ls.interpretation_string(ls.derive());
    return sink.text();
}

TEST(Interpretation, WarningsSayWhenTheDepthStopsRewriting)
{
    const char* loud = R"(lsystem: 1
derivation length: 1
axiom: A
decomposition warnings
maximum depth: 2
A --> A
homomorphism: warnings
maximum depth: 2
A --> A
endlsystem
)";
    std::string said = stderr_of(loud, "loud.l");
    EXPECT_NE(said.find("maximum depth of the homomorphism reached for module 'A'"), std::string::npos)
        << said;
    EXPECT_NE(said.find("maximum depth (2) of the decomposition reached"), std::string::npos) << said;
    std::string quiet = loud;
    quiet.replace(quiet.find("decomposition warnings"), 22, "decomposition no warnings");
    quiet.replace(quiet.find("homomorphism: warnings"), 22, "homomorphism: no warnings");
    EXPECT_EQ(stderr_of(quiet, "quiet.l"), "");
}

TEST(Interpretation, HomomorphismDoesNotChangeTheDerivedString)
{
    LSystem ls = LSystem::from_source(R"(lsystem: 1
derivation length: 2
axiom: A(1)
A(x) --> A(x+1)
homomorphism
A(x) --> F(x*10)
endlsystem
)");
    ModuleString derived = ls.derive();
    EXPECT_EQ(to_text(derived, ls.symbols()), "A(3)");
    EXPECT_EQ(to_text(ls.interpretation_string(derived), ls.symbols()), "F(30)");
}

TEST(Interpretation, HomomorphismSeesTheGlobalsTheDerivationLeft)
{
    EXPECT_EQ(interpreted(R"(lsystem: 1
start: {g = 1;}
end: {g = 7;}
derivation length: 1
axiom: A
homomorphism
A --> F(g)
endlsystem
)"),
              "F(7)");
}

TEST(Interpretation, HomomorphismContextIsTheDerivedString)
{
    EXPECT_EQ(interpreted(R"(lsystem: 1
axiom: BAA
homomorphism
maximum depth: 2
B < A --> X
X --> Y
endlsystem
)"),
              "BYA");
}

TEST(Interpretation, SubLsystemsUseTheirOwnHomomorphism)
{
    EXPECT_EQ(interpreted(R"(lsystem: 1
axiom: A?(2)A$A
endlsystem
lsystem: 2
axiom: A
homomorphism
A --> X
endlsystem
)"),
              "A?(2)X$A");
}

TEST(Interpretation, ObjectProductionsExpandInlineAndOnRequest)
{
    LSystem ls = LSystem::from_source(R"(lsystem: 1
axiom: A(2)B
homomorphism
A(s) -o> F(s)+F(s*2)
B --> G
endlsystem
)");
    int a = ls.symbols().find("A"), b = ls.symbols().find("B");
    EXPECT_TRUE(ls.is_object_symbol(a));
    EXPECT_FALSE(ls.is_object_symbol(b));
    float two = 2;
    ModuleString object = ls.expand_object(ModuleRef{static_cast<SymbolId>(a), {&two, 1}});
    EXPECT_EQ(to_text(object, ls.symbols()), "F(2)+F(4)");
    EXPECT_EQ(to_text(ls.interpretation_string(ls.derive()), ls.symbols()), "F(2)+F(4)G");
}

TEST(Interpretation, StochasticHomomorphismIsReproducible)
{
    const char* source = R"(lsystem: 1
axiom: AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA
homomorphism
seed: 5
A --> B : 0.5
A --> C : 0.5
endlsystem
)";
    std::string first = interpreted(source), second = interpreted(source);
    EXPECT_EQ(first, second);
    EXPECT_EQ(first.size(), 64u);
    EXPECT_NE(first.find('B'), std::string::npos);
    EXPECT_NE(first.find('C'), std::string::npos);
    EXPECT_EQ(first.find('A'), std::string::npos);
}

TEST(Interpretation, FuncCallsTheProvidedFunctionSet)
{
    const char* source = R"(lsystem: 1
derivation length: 1
axiom: A
A --> F(func(2, 0.5))
endlsystem
)";
    LoadOptions options;
    options.function = [](int id, double x) { return id * 10 + x; };
    LSystem with = LSystem::from_source(source, "test.l", options);
    EXPECT_EQ(to_text(with.derive(), with.symbols()), "F(20.5)");
    options.curve = [](char which, int id, double t) { return which == 'l' ? id * 100 : id + t; };
    LSystem curves = LSystem::from_source(
        "lsystem: 1\nderivation length: 1\naxiom: A\nA --> F(curveX(1,0.5))G(curveGAL(2))\n"
        "endlsystem\n",
        "test.l", options);
    EXPECT_EQ(to_text(curves.derive(), curves.symbols()), "F(1.5)G(200)");
    Diagnostics sink(Diagnostics::Output::quiet);
    {
        ScopedDiagnostics install(sink);
        EXPECT_EQ(testing::derive_text(source), "F(0)");  // unset: 0, and one warning
    }
    EXPECT_EQ(sink.count(Severity::warning), 1u) << sink.text();
}

TEST(Interpretation, QueryPassRunsBeforeEveryStepNotAfterTheLast)
{
    const char* source = R"(lsystem: 1
derivation length: 3
axiom: C(0)?P(0)
C(n) > ?P(x) --> C(x)
endlsystem
)";
    int calls = 0;
    LoadOptions options;
    options.query = [&](ModuleString& s) {
        ++calls;
        for (auto c = s.begin(); !c.at_end(); c.next())
            if ((*c).params.size() == 1 && (*c).symbol != s.symbol(0))
                s.mutable_params()[c.param_offset()] = static_cast<float>(calls);
    };
    std::vector<int> steps;
    options.on_step = [&](int step, const ModuleString&) { steps.push_back(step); };
    LSystem ls = LSystem::from_source(source, "test.l", options);
    EXPECT_TRUE(ls.has_queries());
    // C reads the answer of the pass before its step: 1, 2, 3; as in cpfg (whose
    // "environment display" is off by default) no pass follows the last step
    EXPECT_EQ(to_text(ls.derive(), ls.symbols()), "C(3)?P(3)");
    EXPECT_EQ(calls, 3);
    EXPECT_EQ(steps, (std::vector<int>{0, 1, 2, 3}));
}

TEST(Interpretation, NoQueryPassWithoutQueryModules)
{
    int calls = 0;
    LoadOptions options;
    options.query = [&](ModuleString&) { ++calls; };
    LSystem ls = LSystem::from_source("lsystem: 1\nderivation length: 2\naxiom: A\nA --> AB\nendlsystem\n",
                                      "test.l", options);
    EXPECT_FALSE(ls.has_queries());
    ls.derive();
    EXPECT_EQ(calls, 0);
}

TEST(Interpretation, CommunicationModulesStayInTheString)
{
    Diagnostics sink(Diagnostics::Output::quiet);
    {
        ScopedDiagnostics install(sink);
        EXPECT_EQ(testing::derive_text("lsystem: 1\nderivation length: 1\naxiom: A?E(1,2)\n"
                                       "A > ?E(x,y) --> B(x+y)\nendlsystem\n"),
                  "B(3)?E(1,2)");
    }
    // No environmental program is connected: said once.
    EXPECT_EQ(sink.count(Severity::warning), 1u) << sink.text();
}

TEST(Interpretation, AtCommandLettersAreRewrittenAsCpfgDoes)
{
    // cpfg stores "@o(1)" as '@' and 'o(1)': the production on o applies to it
    LSystem ls = LSystem::from_source(R"(lsystem: 1
derivation length: 2
axiom: F@o(1)@Gs
o(r) --> o(r+0.5)
endlsystem
)");
    ModuleString derived = ls.derive();
    EXPECT_EQ(to_text(derived, ls.symbols()), "F@o(2)@Gs");
    EXPECT_EQ(derived.size(), 4u);  // F, @, o(2), @Gs
    ModuleString shown = ls.interpretation_string(derived);
    ASSERT_EQ(shown.size(), 3u);
    EXPECT_EQ(ls.symbols().name(shown.symbol(1)), "@o");
    EXPECT_EQ(shown.param_data()[0], 2.0f);
    EXPECT_EQ(ls.symbols().name(shown.symbol(2)), "@Gs");
}

TEST(Interpretation, IgnoredAtCommandLettersAreIgnoredInContext)
{
    // ignore: @o lists the characters '@' and 'o' (cpfg reads it character by character)
    EXPECT_EQ(testing::derive_text(R"(lsystem: 1
derivation length: 1
ignore: @o
axiom: B@o(1)A
o(r) --> o(r)
B < A --> X
endlsystem
)"),
              "B@o(1)X");
}

}  // namespace
}  // namespace cambium::lsys

namespace cambium::lsys {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name)
{
    fs::path dir = fs::temp_directory_path() / ("cambium_lsys_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string derive_file(const fs::path& file, const std::string& source)
{
    {
        std::ofstream out(file);
        out << source;
    }
    LSystem ls = LSystem::load(file);
    return to_text(ls.derive(), ls.symbols());
}

TEST(FileFunctions, WriteThenReadBackBesideTheModel)
{
    fs::path dir = fresh_dir("files");
    std::string result = derive_file(dir / "plant.l", R"(lsystem: 1
start: {f = fopen("out.txt", "w"); fprintf(f, "%g %g\n", 1.5, 2); fflush(f); fclose(f);
        g = fopen("out.txt", "r"); n = fscanf(g, "%f %lf", &a, &b); fclose(g);}
derivation length: 1
axiom: X
X --> A(a)B(b)N(n)
endlsystem
)");
    EXPECT_EQ(result, "A(1.5)B(2)N(2)");
    std::ifstream in(dir / "out.txt");
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "1.5 2");
    fs::remove_all(dir);
}

TEST(FileFunctions, ScanStopsAtTheFirstMismatchAndKeepsOldValues)
{
    fs::path dir = fresh_dir("scan");
    {
        std::ofstream out(dir / "in.txt");
        out << "x= 4 y= z";
    }
    std::string result = derive_file(dir / "plant.l", R"(lsystem: 1
start: {a = 9; b = 9; g = fopen("in.txt", "r"); n = fscanf(g, "x= %f y= %f", &a, &b);}
derivation length: 1
axiom: X
X --> A(a)B(b)N(n)
endlsystem
)");
    EXPECT_EQ(result, "A(4)B(9)N(1)");
    fs::remove_all(dir);
}

TEST(FileFunctions, MisuseIsAnErrorNamingTheFile)
{
    fs::path dir = fresh_dir("misuse");
    auto error = [&](const std::string& start) {
        try {
            derive_file(dir / "bad.l", "lsystem: 1\nstart: {" + start +
                                           "}\naxiom: X\nendlsystem\n");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(error("f = fopen(\"a.txt\", \"q\");").find("bad.l"), std::string::npos);
    EXPECT_NE(error("fprintf(3, \"%g\", 1);").find("file index 3"), std::string::npos);
    EXPECT_NE(error("f = fopen(\"missing.txt\", \"r\");").find("cannot open"), std::string::npos);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace cambium::lsys
