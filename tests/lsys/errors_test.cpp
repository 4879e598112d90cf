// SPDX-License-Identifier: Apache-2.0
// Runtime errors and warnings that name the production, stop(), and the query pass
// through the homomorphism.
#include <initializer_list>
#include <string>
#include <thread>

#include "test_util.h"

namespace cambium::lsys {
namespace {

using testing::derive_text;
using testing::load_error;

/// The message of the cambium::Error that deriving `source` throws ("" if none).
std::string derive_error(const std::string& source, std::optional<int> steps = std::nullopt)
{
    try {
        derive_text(source, steps);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

bool contains(const std::string& text, const std::string& part)
{
    return text.find(part) != std::string::npos;
}

/// Expects every one of `parts` in `text` (a message: file:line:col, what, where).
void expect_parts(const std::string& text, std::initializer_list<const char*> parts)
{
    for (const char* part : parts)
        EXPECT_TRUE(contains(text, part)) << "missing \"" << part << "\" in: " << text;
}

/// The warnings deriving `source` reports (collected by a sink of its own, one a line).
std::string derive_warnings(const std::string& source, std::string* derived = nullptr)
{
    Diagnostics sink(Diagnostics::Output::quiet);
    ScopedDiagnostics install(sink);
    std::string text = derive_text(source);
    if (derived)
        *derived = text;
    return sink.text();
}

// ---------------------------------------------------------------- arrays

const char* array_read = R"(lsystem: 1
define: { array a[3] = {5, 6, 7}; }
derivation length: 2
axiom: A(0)
A(x) --> A(x+3) B(a[x])
endlsystem
)";

TEST(RuntimeErrors, ArrayReadInRangeWorks)
{
    EXPECT_EQ(derive_text(array_read, 1), "A(3)B(5)");
}

TEST(RuntimeErrors, ArrayReadOutOfRangeNamesFileLineColumnAndProduction)
{
    // step 2 reads a[3] of a 3-element array; 'a' is column 19 of line 5
    std::string e = derive_error(array_read);
    expect_parts(e, {"test.l:5:19:", "in production 'A(x) --> A(x+3) B(a[x])'", "array 'a'",
                     "is 3, outside 0..2"});
}

TEST(RuntimeErrors, NegativeSubscriptInConditionIsAnError)
{
    std::string e = derive_error(R"(lsystem: 1
define: { array t[2][2]; }
derivation length: 1
axiom: A(-1)
A(x) : t[0][x] == 0 --> B
endlsystem
)");
    expect_parts(e, {"test.l:5:8:", "subscript 2 of array 't' is -1", "A(x) : t[0][x] == 0 --> B"});
}

TEST(RuntimeErrors, ArrayWriteOutOfRangeNamesTheBlock)
{
    std::string e = derive_error(R"(lsystem: 1
define: { array a[3]; }
Start: { i = 4; a[i] = 1; }
derivation length: 1
axiom: A
endlsystem
)");
    expect_parts(e, {"test.l:3:17:", "in the Start block", "is 4, outside 0..2"});
}

TEST(RuntimeErrors, ArrayWriteInPostBlockNamesProduction)
{
    std::string e = derive_error(R"(lsystem: 1
define: { array a[2]; }
derivation length: 3
axiom: A(0)
A(n) : * { a[n] = n; } --> A(n+1)
endlsystem
)");
    // n = 0 and 1 store; n = 2 fails in step 3
    expect_parts(e, {"test.l:5:12:", "in production 'A(n) : * { a[n] = n; } --> A(n+1)'"});
}

TEST(RuntimeErrors, WrongNumberOfSubscriptsIsAParseError)
{
    std::string e = load_error(R"(lsystem: 1
define: { array a[3]; }
axiom: A
A --> B(a[1][2])
endlsystem
)");
    expect_parts(e, {"test.l:4:9:", "1 dimension(s) but is used with 2 subscript(s)"});
    std::string none = load_error(R"(lsystem: 1
define: { array a[2][2]; }
axiom: A
A --> B(a)
endlsystem
)");
    expect_parts(none, {"test.l:4:9:", "used with 0 subscript(s)"});
}

TEST(RuntimeErrors, WrongArgumentCountAndTooManyParametersAreParseErrors)
{
    std::string arity = load_error("lsystem: 1\naxiom: A\nA --> B(sin(1, 2))\nendlsystem\n");
    expect_parts(arity, {"test.l:3:9:", "'sin' takes 1 argument(s), 2 given"});
    // a module holds at most 255 parameters (cpfg's limit is smaller still)
    std::string params = "1";
    for (int i = 1; i < 256; ++i)
        params += ",1";
    std::string many = load_error("lsystem: 1\naxiom: A\nA --> B C(" + params + ")\nendlsystem\n");
    expect_parts(many, {"test.l:3:9:", "too many parameters"});
}

// ---------------------------------------------------------------- arithmetic

TEST(RuntimeErrors, RemainderByZeroNamesProductionInHomomorphism)
{
    LSystem ls = LSystem::from_source(R"(lsystem: 1
derivation length: 1
axiom: A(7)
homomorphism
A(x) --> F(x % (x - 7))
endlsystem
)",
                                      "hom.l");
    ModuleString derived = ls.derive();
    try {
        ls.interpretation_string(derived);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        std::string m = e.what();
        expect_parts(m, {"hom.l:5:14:", "'%' with divisor 0",
                         "in production 'A(x) --> F(x % (x - 7))'"});
    }
}

TEST(RuntimeErrors, RemainderTruncatesAsCpfgDoes)
{
    // int % int: 7.9 % 3.2 is 7 % 3 = 1; -7 % 3 is -1 in C
    EXPECT_EQ(derive_text("lsystem: 1\nderivation length: 1\naxiom: A\nA --> B(7.9 % 3.2, -7 % 3)\n"
                          "endlsystem\n"),
              "B(1,-1)");
}

TEST(RuntimeWarnings, DivisionByZeroWarnsNamingProductionAndDividesByOne)
{
    std::string derived;
    std::string warnings = derive_warnings(R"(lsystem: 1
derivation length: 1
axiom: A(6)
A(x) --> B(x / (x - 6))
endlsystem
)",
                                           &derived);
    EXPECT_EQ(derived, "B(6)");  // cpfg divides by 1 instead of 0
    expect_parts(warnings, {"test.l:4:14:", "division by 0",
                            "in production 'A(x) --> B(x / (x - 6))'"});
}

// ---------------------------------------------------------------- names

TEST(RuntimeWarnings, UndefinedIdentifierWarnsOnceNamingProductionAndReadsZero)
{
    std::string derived;
    std::string warnings = derive_warnings(R"(lsystem: 1
derivation length: 1
axiom: A(2)
A(x) --> B(x + undefined_a) C(undefined_a)
endlsystem
)",
                                           &derived);
    EXPECT_EQ(derived, "B(2)C(0)");
    expect_parts(warnings, {"test.l:4:16:", "identifier 'undefined_a'",
                            "production 'A(x) --> B(x + undefined_a) C(undefined_a)'"});
    // once per name
    std::size_t first = warnings.find("identifier 'undefined_a'");
    EXPECT_EQ(warnings.find("identifier 'undefined_a'", first + 1), std::string::npos) << warnings;
}

TEST(RuntimeWarnings, DefinedNamesDoNotWarn)
{
    // formals, locals assigned in the pre-condition block, and globals from Start
    std::string derived;
    std::string warnings = derive_warnings(R"(lsystem: 1
Start: { g = 10; }
derivation length: 1
axiom: A(2)
A(x) : { y = x * g; } y > 0 --> B(y, g)
endlsystem
)",
                                           &derived);
    EXPECT_EQ(derived, "B(20,10)");
    EXPECT_FALSE(contains(warnings, "identifier")) << warnings;
}

TEST(RuntimeWarnings, UndefinedIdentifierInBlockNamesTheBlock)
{
    std::string warnings = derive_warnings(R"(lsystem: 1
EndEach: { k = never_set_b + 1; }
derivation length: 1
axiom: A
endlsystem
)");
    expect_parts(warnings, {"test.l:2:16:", "identifier 'never_set_b'", "in the EndEach block"});
}

TEST(RuntimeErrors, FileFunctionFailureNamesProduction)
{
    std::string e = derive_error(R"(lsystem: 1
derivation length: 1
axiom: A
A --> B(fclose(3))
endlsystem
)");
    expect_parts(e, {"test.l:4:9:", "file index 3 does not name a file opened with fopen",
                     "in production 'A --> B(fclose(3))'"});
}

TEST(RuntimeErrors, ContinuationLineSaysWhereTheProductionStarts)
{
    std::string e = derive_error("lsystem: 1\ndefine: { array a[1]; }\nderivation length: 1\n"
                                 "axiom: A\nA --> B\n\tC(a[2])\nendlsystem\n");
    expect_parts(e, {"test.l:6:4:", "in production 'A --> B C(a[2])' (line 5)"});
}

// ---------------------------------------------------------------- stop()

std::string counting(const std::string& end_each)
{
    return "lsystem: 1\nStart: { n = 0; }\nEndEach: { n = n + 1; " + end_each +
           " }\nderivation length: 10\naxiom: A(1)\nA(x) --> A(x*2) B(x)\nendlsystem\n";
}

TEST(Stop, StopEndsTheDerivationAfterItsStep)
{
    std::string stopped = derive_text(counting("if (n == 3) { stop(0); }"));
    std::string three = derive_text(counting(""), 3);
    EXPECT_EQ(stopped, three);
    EXPECT_EQ(three, "A(8)B(4)B(2)B(1)");
}

TEST(Stop, StopWithoutArgumentAndStopOneAlsoEndTheDerivation)
{
    // stop() is stop(0); cpfg's batch derivation loop breaks on stop(1) (RUN) as well
    EXPECT_EQ(derive_text(counting("if (n == 2) { stop(); }")), derive_text(counting(""), 2));
    EXPECT_EQ(derive_text(counting("if (n == 2) { stop(1); }")), derive_text(counting(""), 2));
}

TEST(Stop, InAnimateModeStopOneOnlyDrawsAndTheDerivationGoesOn)
{
    // cpfg's animate mode: stop(1) draws the string and the simulation continues, stop(0)
    // ends it (manual 5.1); an advance past a stop(1) reaches all its steps
    LSystem one = LSystem::from_source(counting("if (n == 2) { stop(1); }"), "stop.l");
    Derivation animated = one.start();
    animated.go_on_after_stop_one();
    animated.advance(4);
    EXPECT_EQ(animated.steps_done(), 4);
    EXPECT_FALSE(animated.stopped());
    EXPECT_EQ(to_text(animated.string(), one.symbols()), derive_text(counting(""), 4));

    LSystem zero = LSystem::from_source(counting("if (n == 2) { stop(0); }"), "stop.l");
    Derivation ended = zero.start();
    ended.go_on_after_stop_one();
    ended.advance(4);
    EXPECT_EQ(ended.steps_done(), 2);
    EXPECT_TRUE(ended.stopped());
}

/// A model that calls stop(`argument`) in step 2 of 5 and whose End block sets a
/// global that the homomorphism shows.
std::string end_block_after_stop(const std::string& argument)
{
    LSystem ls = LSystem::from_source("lsystem: 1\nStart: { done = 1; }\nEnd: { done = 7; }\n"
                                      "derivation length: 5\naxiom: A(0)\n"
                                      "A(x) : x == 1 { stop(" + argument + "); } --> A(x+1)\n"
                                      "A(x) --> A(x+1)\nhomomorphism\nA(x) --> A(x) D(done)\n"
                                      "endlsystem\n",
                                      "stop.l");
    return to_text(ls.interpretation_string(ls.derive()), ls.symbols());
}

TEST(Stop, EndBlockRunsAfterStopZeroButNotAfterStopOne)
{
    EXPECT_EQ(end_block_after_stop("0"), "A(2)D(7)");
    EXPECT_EQ(end_block_after_stop("1"), "A(2)D(1)");
}

TEST(Stop, StopInAProductionAndEndBlockStillRuns)
{
    LSystem ls = LSystem::from_source(R"(lsystem: 1
End: { done = 7; }
derivation length: 10
axiom: A(0)
A(x) : x == 4 { stop(2); } --> A(x+1)
A(x) --> A(x+1)
homomorphism
A(x) --> A(x) D(done)
endlsystem
)",
                                      "stop.l");
    ModuleString derived = ls.derive();
    EXPECT_EQ(to_text(derived, ls.symbols()), "A(5)");
    EXPECT_EQ(to_text(ls.interpretation_string(derived), ls.symbols()), "A(5)D(7)");
}

TEST(Stop, StopInStartBlockIsIgnored)
{
    // cpfg resets its animation flag when the derivation loop starts
    EXPECT_EQ(derive_text("lsystem: 1\nStart: { stop(0); }\nderivation length: 3\naxiom: A\n"
                          "A --> AA\nendlsystem\n"),
              "AAAAAAAA");
}

// ---------------------------------------------------------------- queries

/// Derives `source` with a query pass that writes into each ?P the index of the
/// module in the string the pass was given, and the string's length.
std::string derive_with_positions(const std::string& source)
{
    LoadOptions options;
    LSystem* self = nullptr;
    options.query = [&self](ModuleString& s) {
        int query = self->symbols().find("?P");
        std::size_t first = 0;
        for (std::size_t i = 0; i < s.size(); first += s.param_count(i), ++i)
            if (s.symbol(i) == query && s.param_count(i) == 2) {
                auto params = s.mutable_params();
                params[first] = static_cast<float>(i);
                params[first + 1] = static_cast<float>(s.size());
            }
    };
    LSystem ls = LSystem::from_source(source, "q.l", options);
    self = &ls;
    return to_text(ls.derive(), ls.symbols());
}

/// One step of "A ?P(v) B" with `homomorphism` (productions, or "" for none).
std::string query_model(const std::string& values, const std::string& homomorphism)
{
    return "lsystem: 1\nderivation length: 1\naxiom: A ?P(" + values + ") B\nA --> A\n" +
           (homomorphism.empty() ? "" : "homomorphism\n" + homomorphism + "\n") + "endlsystem\n";
}

TEST(QueryPass, AnswersComeFromTheStringWithHomomorphismApplied)
{
    // derived: A ?P B; interpreted: F F F ?P B, where ?P is module 3 of 5
    EXPECT_EQ(derive_with_positions(query_model("0,0", "A --> F F F")), "A?P(3,5)B");
}

TEST(QueryPass, WithoutHomomorphismTheDerivedStringIsQueried)
{
    EXPECT_EQ(derive_with_positions(query_model("0,0", "")), "A?P(1,3)B");
}

TEST(QueryPass, QueryRewrittenByHomomorphismKeepsItsValues)
{
    // the homomorphism replaces ?P itself: no module of the expansion answers for it
    EXPECT_EQ(derive_with_positions(query_model("9,9", "?P(x, y) --> F ?P(x, y) F")),
              "A?P(9,9)B");
}

}  // namespace
}  // namespace cambium::lsys

// ---------------------------------------------------------------- diagnostics sinks

namespace cambium::lsys {
namespace {

const char* division_by_zero = R"(lsystem: 1
derivation length: 1
axiom: A(6)
A(x) --> B(x / (x - 6))
endlsystem
)";

TEST(DiagnosticsSink, EachRunHearsItsOwnWarnings)
{
    // Deduplication is per sink (per run): a second run is told again.
    for (int run = 0; run < 2; ++run) {
        Diagnostics sink(Diagnostics::Output::quiet);
        ScopedDiagnostics install(sink);
        derive_text(division_by_zero);
        ASSERT_EQ(sink.count(Severity::warning), 1u) << "run " << run << ": " << sink.text();
        const Diagnostic d = sink.collected().at(0);
        EXPECT_EQ(d.loc.file, "test.l");
        EXPECT_EQ(d.loc.line, 4);
        EXPECT_EQ(d.loc.column, 14);
        EXPECT_TRUE(contains(d.message, "division by 0")) << d.message;
    }
}

TEST(DiagnosticsSink, InnerSinkTakesWarningsThenTheOuterOneAgain)
{
    Diagnostics outer(Diagnostics::Output::quiet), inner(Diagnostics::Output::quiet);
    ScopedDiagnostics install_outer(outer);
    {
        ScopedDiagnostics install_inner(inner);
        warn(FileLoc{"a.l", 1, 2}, "first");
        warn(FileLoc{"a.l", 1, 2}, "first");  // the same text: once
    }
    warn("second");
    EXPECT_EQ(inner.text(), "a.l:1:2: warning: first\n");
    EXPECT_EQ(outer.text(), "warning: second\n");
}

TEST(DiagnosticsSink, OtherThreadsKeepTheirOwnSink)
{
    Diagnostics mine(Diagnostics::Output::quiet), theirs(Diagnostics::Output::quiet);
    ScopedDiagnostics install(mine);
    std::thread other([&] {
        ScopedDiagnostics install_theirs(theirs);
        warn("from the other thread");
    });
    other.join();
    warn("from this thread");
    EXPECT_EQ(mine.text(), "warning: from this thread\n");
    EXPECT_EQ(theirs.text(), "warning: from the other thread\n");
}

}  // namespace
}  // namespace cambium::lsys
