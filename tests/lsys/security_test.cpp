// SPDX-License-Identifier: Apache-2.0
// Hostile L-system files (docs/security.md): printf formats, file access
// outside the model's folder, deep nesting, out-of-range numbers, the memory budget.
// Each asserts the exact diagnostic: file, line, column and message.
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "base/limits.h"
#include "lsys/deriver.h"
#include "lsys/expression.h"
#include "test_util.h"

namespace cambium::lsys {
namespace {

namespace fs = std::filesystem;
using testing::derive_text;
using testing::load_error;

/// The message of the cambium::Error that loading and deriving `source` (named
/// `file`) throws, "" if none.
std::string derive_error(const std::string& source, const std::string& file = "test.l",
                         const LoadOptions& options = {})
{
    try {
        LSystem ls = LSystem::from_source(source, file, options);
        ls.interpretation_string(ls.derive());
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

/// An L-system whose Start block is `start` (line 2).
std::string with_start(const std::string& start)
{
    return "lsystem: 1\nStart: {" + start + "}\naxiom: A\nendlsystem\n";
}

/// What deriving `source` prints on standard output.
std::string printed(const std::string& source)
{
    ::testing::internal::CaptureStdout();
    derive_text(source);
    return ::testing::internal::GetCapturedStdout();
}

// ---------------------------------------------------------------- printf formats

const char* const allowed_conversions =
    "only %[flags][width][.precision](e E f F g G d i c), %lf and %% are";

TEST(FormatStrings, StringConversionIsALoadErrorAtItsColumn)
{
    // a crash once: %s read a pointer from a double. '%' is column 17.
    EXPECT_EQ(load_error(with_start(R"(printf("%s%s\n", 1);)")),
              std::string("test.l:2:17: error: printf format: conversion '%s' is not allowed; ") +
                  allowed_conversions);
}

TEST(FormatStrings, EveryConversionOutsideTheAllowedSetIsRefused)
{
    // %n writes memory, %p prints an address, * takes a width from the arguments,
    // length modifiers change what is read
    // (the message quotes the conversion up to the character that is not allowed)
    for (const auto& [conversion, quoted] : std::vector<std::pair<std::string, std::string>>{
             {"%n", "%n"},     {"%p", "%p"},   {"%x", "%x"},     {"%u", "%u"},
             {"%o", "%o"},     {"%a", "%a"},   {"%*d", "%*"},    {"%.*f", "%.*"},
             {"%hd", "%h"},    {"%lld", "%ll"}, {"%Lf", "%L"},   {"%ld", "%ld"},
             {"%lc", "%lc"},   {"%zd", "%z"},  {"%5%", "%5%"},   {"%$d", "%$"},
             {"%1$f", "%1$"}}) {
        std::string e = load_error(with_start("printf(\"ab" + conversion + "\", 1);"));
        EXPECT_EQ(e, "test.l:2:19: error: printf format: conversion '" + quoted +
                         "' is not allowed; " + allowed_conversions)
            << conversion;
    }
}

TEST(FormatStrings, ColumnCountsEscapesAsWritten)
{
    // "a\t\"%s": the '%' is the 4th character of the value, the 6th after the quote
    EXPECT_EQ(load_error(with_start(R"(printf("a\t\"%s");)")).substr(0, 19),
              "test.l:2:22: error:");
}

TEST(FormatStrings, AFormatEndingInsideAConversionIsRefused)
{
    EXPECT_EQ(load_error(with_start(R"(printf("100%");)")),
              "test.l:2:20: error: printf format: the format ends inside a conversion");
    EXPECT_EQ(load_error(with_start(R"(printf("%5.2");)")),
              "test.l:2:17: error: printf format: the format ends inside a conversion");
}

TEST(FormatStrings, WidthAndPrecisionAreBounded)
{
    EXPECT_EQ(load_error(with_start(R"(printf("%100f", 1);)")),
              "test.l:2:17: error: printf format: width and precision may have at most 2 digits");
    EXPECT_EQ(load_error(with_start(R"(printf("%.999999999f", 1);)")),
              "test.l:2:17: error: printf format: width and precision may have at most 2 digits");
}

TEST(FormatStrings, ValuesMustMatchConversions)
{
    EXPECT_EQ(load_error(with_start(R"(printf("%f %f\n", 1);)")),
              "test.l:2:16: error: printf format has 2 conversion(s) but 1 value(s) to print");
    EXPECT_EQ(load_error(with_start(R"(printf("%f%%\n", 1, 2);)")),
              "test.l:2:16: error: printf format has 1 conversion(s) but 2 value(s) to print");
}

TEST(FormatStrings, FprintfAndFscanfFormatsAreCheckedToo)
{
    EXPECT_EQ(load_error(with_start(R"(f = fopen("x", "w"); fprintf(f, "%n", 1);)")),
              std::string("test.l:2:42: error: fprintf format: conversion '%n' is not allowed; ") +
                  allowed_conversions);
    EXPECT_EQ(load_error(with_start(R"(f = fopen("x", "r"); fscanf(f, "%s", x);)")),
              "test.l:2:41: error: fscanf format: conversion '%s' is not allowed; only "
              "%[width][l](d i e E f F g G) are");
    EXPECT_EQ(load_error(with_start(R"(f = fopen("x", "r"); fscanf(f, "%f %f", x);)")),
              "test.l:2:40: error: fscanf format has 2 conversion(s) but 1 variable(s) to read "
              "into");
}

TEST(FormatStrings, AllowedConversionsPrintAsC)
{
    // the corpus writes %lf, %.lf, %3f and %.0f; %d saturates instead of overflowing
    EXPECT_EQ(printed(with_start(
                  R"(printf("[%5.2f|%-4d|%c|%%|%lf|%.lf|%3f|%e|%G|%+i|%d]\n", 3.14159, 42, 65, 1.5, 2.5, 1, 1234.5, 0.00001, 7, 1e30);)")),
              "[ 3.14|42  |A|%|1.500000|2|1.000000|1.234500e+03|1E-05|+7|2147483647]\n");
}

TEST(FormatStrings, CheckFormatCountsConversions)
{
    FormatCheck check = check_format("%g and %5.1e, 100%%");
    EXPECT_TRUE(check.problem.empty());
    EXPECT_EQ(check.conversions, 2);
    check = check_format("ok %d then %s", false);
    EXPECT_EQ(check.at, 11u);
    EXPECT_EQ(check_format("%lf %3d", true).conversions, 2);
}

// ---------------------------------------------------------------- file access

/// A model folder `model` inside a fresh folder, and a file beside the model folder.
struct ModelFolder {
    fs::path root, model, outside;
    ModelFolder()
    {
        root = fs::temp_directory_path() /
               ("cambium-security-" + std::to_string(::getpid()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(root);
        model = root / "model";
        fs::create_directories(model / "data");
        outside = root / "outside.txt";
    }
    ~ModelFolder() { fs::remove_all(root); }
    std::string l_file() const { return (model / "plant.l").string(); }
    /// The model folder as fopen's messages name it (canonical)
    std::string folder() const { return fs::canonical(model).string(); }
};

std::string read_file(const fs::path& path)
{
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(FileAccess, WritingAndReadingInsideTheModelFolderWorks)
{
    ModelFolder m;
    std::string source = with_start(
        R"(f = fopen("data/out.txt", "w"); fprintf(f, "%g %g\n", 2.5, 7); fclose(f); )"
        R"(f = fopen("./data/../data/out.txt", "r"); n = fscanf(f, "%f %f", x, y); fclose(f); )"
        R"(printf("%g %g %g\n", n, x, y);)");
    ::testing::internal::CaptureStdout();
    EXPECT_EQ(derive_error(source, m.l_file()), "");
    EXPECT_EQ(::testing::internal::GetCapturedStdout(), "2 2.5 7\n");
    EXPECT_EQ(read_file(m.model / "data/out.txt"), "2.5 7\n");
}

TEST(FileAccess, DotDotOutOfTheModelFolderIsRefusedAndWritesNothing)
{
    ModelFolder m;
    std::string e = derive_error(with_start(R"(f = fopen("data/../../outside.txt", "w");)"),
                                 m.l_file());
    EXPECT_EQ(e, m.l_file() + ":2:13: error: fopen(\"data/../../outside.txt\"): '" +
                     fs::weakly_canonical(m.outside).string() +
                     "' is outside the model's folder '" + m.folder() +
                     "'; an L-system opens files only there and below (--allow-file-access "
                     "lifts this), in the Start block");
    EXPECT_FALSE(fs::exists(m.outside));
}

TEST(FileAccess, AbsolutePathsOutsideAreRefused)
{
    ModelFolder m;
    for (std::string path : {m.outside.string(), std::string("/etc/passwd"),
                             std::string("/dev/zero")}) {
        std::string e = derive_error(with_start("f = fopen(\"" + path + "\", \"r\");"),
                                     m.l_file());
        EXPECT_EQ(e.rfind(m.l_file() + ":2:13: error: fopen(\"" + path + "\"): '", 0), 0u)
            << e;
        EXPECT_NE(e.find("' is outside the model's folder '" + m.folder() + "'"),
                  std::string::npos)
            << e;
    }
}

TEST(FileAccess, SymbolicLinksPointingOutsideAreRefused)
{
    ModelFolder m;
    std::ofstream(m.outside) << "secret\n";
    fs::create_symlink(m.outside, m.model / "link.txt");
    fs::create_symlink(m.root / "not-yet.txt", m.model / "dangling.txt");
    fs::create_directory_symlink(m.root, m.model / "up");
    for (std::string name : {"link.txt", "dangling.txt", "up/outside.txt"}) {
        std::string e = derive_error(with_start("f = fopen(\"" + name + "\", \"w\");"),
                                     m.l_file());
        EXPECT_EQ(e.rfind(m.l_file() + ":2:13: error: fopen(\"" + name + "\"): '", 0), 0u)
            << e;
        EXPECT_NE(e.find("is outside the model's folder"), std::string::npos) << e;
    }
    EXPECT_EQ(read_file(m.outside), "secret\n");
    EXPECT_FALSE(fs::exists(m.root / "not-yet.txt"));
}

// A hard link in the model's folder shares its data with a file outside: writing through
// it (or truncating it) would change that file, so a file to write must have one name.
TEST(FileAccess, HardLinksAreNotWritten)
{
    ModelFolder m;
    std::ofstream(m.outside) << "secret\n";
    ASSERT_EQ(::link(m.outside.c_str(), (m.model / "shared.txt").c_str()), 0);
    for (std::string mode : {"w", "a"}) {
        std::string e = derive_error(with_start("f = fopen(\"shared.txt\", \"" + mode + "\"); fprintf(f, \"x\");"),
                                     m.l_file());
        EXPECT_NE(e.find("has 2 hard links, so writing it could change a file outside"), std::string::npos) << e;
    }
    EXPECT_EQ(read_file(m.outside), "secret\n");
    // reading it is harmless, and a file of one name is written as before
    EXPECT_EQ(derive_error(with_start(R"(f = fopen("shared.txt", "r"); fclose(f);)"), m.l_file()), "");
    std::ofstream(m.model / "own.txt") << "old text\n";
    EXPECT_EQ(derive_error(with_start(R"(f = fopen("own.txt", "w"); fprintf(f, "new\n"); fclose(f);)"), m.l_file()), "");
    EXPECT_EQ(read_file(m.model / "own.txt"), "new\n");
}

TEST(FileAccess, FifosAndFoldersInsideAreNotOpened)
{
    ModelFolder m;
    ASSERT_EQ(::mkfifo((m.model / "pipe").c_str(), 0600), 0);
    // opening a FIFO for reading would wait for a writer forever
    EXPECT_EQ(derive_error(with_start(R"(f = fopen("pipe", "r");)"), m.l_file()),
              m.l_file() + ":2:13: error: fopen: '" + m.folder() +
                  "/pipe' is not a regular file, in the Start block");
    std::string e = derive_error(with_start(R"(f = fopen("data", "r");)"), m.l_file());
    EXPECT_EQ(e, m.l_file() + ":2:13: error: fopen: '" + m.folder() +
                     "/data' is not a regular file, in the Start block");
}

TEST(FileAccess, AllowFileAccessLiftsTheConfinement)
{
    ModelFolder m;
    LoadOptions options;
    options.allow_file_access = true;
    std::string source =
        with_start(R"(f = fopen("../outside.txt", "w"); fprintf(f, "%d\n", 5); fclose(f);)");
    EXPECT_EQ(derive_error(source, m.l_file(), options), "");
    EXPECT_EQ(read_file(m.outside), "5\n");
}

// ---------------------------------------------------------------- nesting

/// `n` copies of `text`.
std::string repeat(const std::string& text, int n)
{
    std::string out;
    for (int i = 0; i < n; ++i)
        out += text;
    return out;
}

constexpr int deep = 50'000;

/// An L-system whose only production is `A --> B(expression)` (line 4, the expression
/// from column 9).
std::string with_parameter(const std::string& expression)
{
    return "lsystem: 1\nderivation length: 1\naxiom: A\nA --> B(" + expression + ")\nendlsystem\n";
}

TEST(Nesting, ConditionalChainsInTheThenBranchStopAtTheLimit)
{
    // "1?" repeated: the 200th '?' is column 9 + 2*199 + 1 = 408; the error names the
    // operand after it (the expression itself is level 1, each then-branch one more)
    std::string e = load_error(with_parameter(repeat("1?", deep) + "1" + repeat(":0", deep)));
    EXPECT_EQ(e, "test.l:4:409: error: conditional expression nested too deeply (more than "
                 "200 levels)");
}

TEST(Nesting, ConditionalChainsInTheElseBranchNeedNoStack)
{
    // a ? b : c ? d : ... is a loop, not a recursion: any length works
    EXPECT_EQ(derive_text(with_parameter(repeat("0?1:", deep) + "7")), "B(7)");
    EXPECT_EQ(derive_text(with_parameter("0?1:1?2:3")), "B(2)");
    EXPECT_EQ(derive_text(with_parameter("1?0?5:6:7")), "B(6)");
}

TEST(Nesting, CallsSubscriptsParenthesesAndUnaryOperatorsShareTheLimit)
{
    // the expression's own level and 199 inside it fit; one more is refused
    EXPECT_EQ(derive_text(with_parameter(repeat("fabs(", 198) + "-3" + repeat(")", 198))),
              "B(3)");
    for (const auto& [open, close] : {std::pair<std::string, std::string>{"sin(", ")"},
                                      {"(", ")"},
                                      {"- ", ""},
                                      {"!", ""},
                                      {"a[", "]"}}) {
        std::string source = "lsystem: 1\ndefine: { array a[1]; }\naxiom: A\nA --> B(" +
                             repeat(open, deep) + "0" + repeat(close, deep) + ")\nendlsystem\n";
        std::string e = load_error(source);
        EXPECT_EQ(e.substr(0, e.find(": error:")).substr(0, 9), "test.l:4:") << open;
        EXPECT_NE(e.find("error: expression nested too deeply (more than 200 levels)"),
                  std::string::npos)
            << open << ": " << e.substr(0, 200);
    }
}

TEST(Nesting, BlocksStopAtTheLimit)
{
    // the Start block is level 1; "if(1){" is 6 characters from column 9, so the '{'
    // of the 200th is at 9 + 6 * 199 + 5 = 1208
    std::string source = "lsystem: 1\nStart: {" + repeat("if(1){", deep) +
                         repeat("}", deep) + "}\naxiom: A\nendlsystem\n";
    EXPECT_EQ(load_error(source),
              "test.l:2:1208: error: block nested too deeply (more than 200 levels)");
    std::string loops = "lsystem: 1\nStart: {" + repeat("while(0){", deep) + repeat("}", deep) +
                        "}\naxiom: A\nendlsystem\n";
    EXPECT_NE(load_error(loops).find("error: block nested too deeply"), std::string::npos);
}

TEST(Nesting, HomomorphismDepthIsCutWithAWarning)
{
    std::string source = "lsystem: 1\naxiom: A(0)\nhomomorphism: warnings\nmaximum depth: 5000\n"
             "A(n) --> A(n+1)\nendlsystem\n";
    LSystem ls = LSystem::from_source(source, "test.l");
    ::testing::internal::CaptureStderr();
    std::string text = to_text(ls.interpretation_string(ls.derive()), ls.symbols());
    std::string warnings = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(text, "A(1000)");
    EXPECT_NE(warnings.find("homomorphism maximum depth 5000 is more than 1000; using 1000"),
              std::string::npos)
        << warnings;
}

// ---------------------------------------------------------------- numbers

TEST(NumericSettings, DerivationLengthOutOfRangeIsAnErrorAtItsExpression)
{
    EXPECT_EQ(derive_error("lsystem: 1\nderivation length: 1e30\naxiom: A\nendlsystem\n"),
              "test.l:2:20: error: the derivation length is 1e+30; it must be a number from 0 "
              "to 1000000");
    EXPECT_EQ(derive_error("lsystem: 1\nderivation length: -3\naxiom: A\nendlsystem\n"),
              "test.l:2:20: error: the derivation length is -3; it must be a number from 0 to "
              "1000000");
    EXPECT_EQ(derive_error("lsystem: 1\nderivation length: sqrt(-1)\naxiom: A\nendlsystem\n")
                  .substr(0, 44),
              "test.l:2:20: error: the derivation length is");
}

TEST(NumericSettings, MaximumDepthOutOfRangeIsAnErrorAtItsExpression)
{
    for (const char* section : {"decomposition", "homomorphism"}) {
        for (const char* depth : {"1e30", "-2"}) {
            std::string source = std::string("lsystem: 1\naxiom: A\n") + section +
                                 "\nmaximum depth: " + depth + "\nA --> B\nendlsystem\n";
            EXPECT_EQ(derive_error(source), std::string("test.l:4:16: error: the ") + section +
                                                "'s maximum depth is " +
                                                (depth[0] == '1' ? "1e+30" : "-2") +
                                                "; it must be a number from 0 to 1000000");
        }
    }
}

TEST(NumericSettings, HomomorphismSeedOutOfRangeIsAnError)
{
    std::string e = derive_error(
        "lsystem: 1\naxiom: A\nhomomorphism\nseed: 1e300\nA --> B\nendlsystem\n");
    EXPECT_EQ(e.substr(0, 60), "test.l:4:7: error: the homomorphism's seed is 1e+300; it mus");
}

// The value is unused (cpfg never seeds) but a model's seed must still be a long
TEST(NumericSettings, LsystemSeedOutOfRangeIsAnError)
{
    EXPECT_EQ(derive_error("lsystem: 1\nseed: 1e30\naxiom: A\nA --> B\nendlsystem\n").substr(0, 48),
              "test.l:2:7: error: the seed is 1e+30; it must be");
    EXPECT_EQ(derive_error("lsystem: 1\nseed: -1e300\naxiom: A\nA --> B\nendlsystem\n").substr(0, 49),
              "test.l:2:7: error: the seed is -1e+300; it must b");
}

TEST(NumericSettings, FunctionArgumentsOutOfRangeAreErrorsNamingTheBlock)
{
    EXPECT_EQ(derive_error(with_start("SetDerivationLength(1e30);")),
              "test.l:2:9: error: SetDerivationLength() is 1e+30; it must be from 0 to 1000000 "
              "steps, in the Start block");
    EXPECT_EQ(derive_error(with_start("srand(-1e300);")),
              "test.l:2:9: error: srand(): the seed -1e+300 is not a number within +-9.2e18, in "
              "the Start block");
    EXPECT_EQ(derive_error(with_start("x = biran(1e30, 0.5);")),
              "test.l:2:13: error: biran(1e+30, p): the number of trials must be at most 1e+08, "
              "in the Start block");
}

// ---------------------------------------------------------------- loops

TEST(Loops, ALoopThatNeverEndsIsAnErrorAtItsKeyword)
{
    // `while (1) {}` would hang the renderer; 'while' is column 9, 'do' column 16
    EXPECT_EQ(derive_error(with_start("while (1) {}")),
              "test.l:2:9: error: a loop repeated more than 100000000 times (a loop that never "
              "ends?), in the Start block");
    EXPECT_EQ(derive_error(with_start("x = 0; do { x = x + 1; } while (x > 0);")),
              "test.l:2:16: error: a loop repeated more than 100000000 times (a loop that never "
              "ends?), in the Start block");
}

TEST(Loops, LongFiniteLoopsRunToTheirEnd)
{
    EXPECT_EQ(printed(with_start("i = 0; while (i < 100000) { i = i + 1; } printf(\"%g\\n\", i);")),
              "100000\n");
}

TEST(NumericSettings, ArrayDimensionOutOfRangeIsALoadError)
{
    EXPECT_EQ(load_error("lsystem: 1\ndefine: { array a[1e30]; }\naxiom: A\nendlsystem\n"),
              "test.l:2:19: error: array 'a' has dimension 1e+30; dimensions go from 1 to "
              "16777216");
    EXPECT_EQ(load_error("lsystem: 1\ndefine: { array a[2][sqrt(-1)]; }\naxiom: A\nendlsystem\n")
                  .substr(0, 47),
              "test.l:2:22: error: array 'a' has dimension -na");
}

TEST(NumericSettings, HugeIdsNameNothingWithoutUndefinedConversions)
{
    // a sub-L-system id and a label past int's range: no such L-system, no crash
    EXPECT_EQ(derive_text("lsystem: 99999999999999999999\nderivation length: 1\naxiom: "
                          "?(1e30)A$\nA --> B\nendlsystem\n"),
              "?(1e+30)B$");
    EXPECT_EQ(truncated_in(2147483647.9, 0, 2147483647), 2147483647);
    EXPECT_EQ(truncated_in(9.3e18, 0, LLONG_MAX), std::nullopt);
    EXPECT_EQ(truncated_in(9223372036854775808.0, LLONG_MIN, LLONG_MAX), std::nullopt);
    EXPECT_EQ(truncated_in(-0.5, 0, 1), 0);
}

// ---------------------------------------------------------------- memory budget

/// A module with 200 parameters that doubles every step.
std::string doubling_model(int steps)
{
    std::string formal, actual;
    for (int i = 0; i < 200; ++i) {
        formal += (i ? ",p" : "p") + std::to_string(i);
        actual += (i ? ",1" : "1");
    }
    return "lsystem: 1\nderivation length: " + std::to_string(steps) + "\naxiom: A(" + actual +
           ")\nA(" + formal + ") --> A(" + formal + ")A(" + formal + ")\nendlsystem\n";
}

TEST(MemoryBudget, DerivationStopsAtTheBudgetNamingTheStep)
{
    // step n builds 2^n modules of 802 bytes (symbol, count, 200 floats) from 2^(n-1):
    // 1203 * 2^n bytes when done, past 1 MiB in step 10 (2^10 = 1024 > 871)
    LoadOptions options;
    options.max_memory_bytes = 1 << 20;
    std::string e = derive_error(doubling_model(40), "test.l", options);
    EXPECT_EQ(e.rfind("test.l: error: the derivation needs ", 0), 0u) << e;
    EXPECT_NE(e.find(" in step 10, more than the memory budget of 1.0 MiB (--max-memory); the "
                     "string has "),
              std::string::npos)
        << e;
    EXPECT_NE(e.find(" parameters so far; reduce the derivation length or raise --max-memory"),
              std::string::npos)
        << e;
}

TEST(MemoryBudget, ModelsWithinTheBudgetDeriveAsBefore)
{
    LoadOptions options;
    options.max_memory_bytes = 1 << 20;
    LSystem ls = LSystem::from_source(doubling_model(6), "test.l", options);
    EXPECT_EQ(ls.derive().size(), 64u);
}

// Positions in a string are 32-bit: a limit on its parameter values (2^32 - 1 at most)
// stops the derivation with a message, checked here with a small limit.
TEST(MemoryBudget, ParameterValuesPastTheLimitStopTheDerivation)
{
    LSystem ls = LSystem::from_source(doubling_model(40), "test.l");
    DeriveLimits limits;
    limits.max_params = 10000;  // step 5 holds 32 x 200 values, step 6 64 x 200
    Deriver deriver(ls.program(), limits);
    std::string e;
    try {
        for (int step = 0; step < 40; ++step)
            deriver.step();
    } catch (const Error& error) {
        e = error.what();
    }
    EXPECT_EQ(e, "test.l: error: the string grew past 10000 parameter values in step 6; "
                 "reduce the derivation length");
    DeriveLimits past;
    past.max_params = std::size_t{1} << 40;  // lowered to what 32-bit positions hold
    Deriver within(ls.program(), past);
    for (int step = 0; step < 8; ++step)
        within.step();
    EXPECT_EQ(within.string().param_total(), std::size_t{200} << 8);
}

// Each decomposition pass reads the whole string: a deep decomposition that keeps
// growing is quadratic, so the modules its passes go through in one step are bounded
// (here 10^4: `A --> FA` passes over 1, 2, 3 ... modules, past 10^4 at pass 141).
TEST(DecompositionWork, DeepGrowingDecompositionStopsAtItsMaximumDepthLine)
{
    LSystem ls = LSystem::from_source("Lsystem: 1\nderivation length: 1\nAxiom: A\n"
                                      "decomposition\nmaximum depth: 1000000\nA --> FA\nendlsystem\n",
                                      "deep.l");
    DeriveLimits limits;
    limits.max_decomposition_work = 10000;
    Deriver deriver(ls.program(), limits);
    std::string e;
    try {
        deriver.step();
    } catch (const Error& error) {
        e = error.what();
    }
    EXPECT_EQ(e, "deep.l:5:16: error: the decomposition went through 10011 modules in 141 passes of "
                 "one step (maximum depth 1000000), more than the 10000 a step may take; lower the "
                 "maximum depth");
    // a depth whose passes stay within the bound derives as before
    DeriveLimits roomy;
    roomy.max_decomposition_work = 10000;
    LSystem shallow = LSystem::from_source("Lsystem: 1\nderivation length: 1\nAxiom: A\n"
                                           "decomposition\nmaximum depth: 100\nA --> FA\nendlsystem\n",
                                           "shallow.l");
    Deriver within(shallow.program(), roomy);
    within.step();
    EXPECT_EQ(within.string().size(), 101u);
}

// The system refusing memory within the budget (here an address-space limit makes
// mmap and mremap fail) is an error naming the file and the step, and it does not claim
// that the budget was exceeded.
TEST(MemoryBudget, MemoryTheSystemRefusesIsReportedAsSuch)
{
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer reserves its shadow memory past any address-space limit";
#else
    std::fflush(nullptr);
    pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        // the child: 48 MiB more address space than it has now, a budget far above that
        long pages = 0;
        if (std::FILE* statm = std::fopen("/proc/self/statm", "r")) {
            if (std::fscanf(statm, "%ld", &pages) != 1)
                pages = 0;
            std::fclose(statm);
        }
        rlimit limit{};
        limit.rlim_cur = limit.rlim_max =
            static_cast<rlim_t>(pages) * static_cast<rlim_t>(sysconf(_SC_PAGESIZE)) + (48u << 20);
        if (pages == 0 || setrlimit(RLIMIT_AS, &limit) != 0)
            _exit(3);
        LoadOptions options;
        options.max_memory_bytes = std::uint64_t{1} << 40;
        std::string e = derive_error(doubling_model(40), "test.l", options);
        bool named = e.rfind("test.l: error: the system refused memory in step ", 0) == 0;
        bool honest = e.find("within the memory budget of 1.0 TiB (--max-memory)") !=
                          std::string::npos &&
                      e.find("more than the memory budget") == std::string::npos;
        if (!named || !honest)
            std::fprintf(stderr, "message: %s\n", e.c_str());
        _exit(named && honest ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 0) << "3: no address-space limit could be set";
#endif
}

TEST(MemoryBudget, ByteSizesParseWithBinarySuffixes)
{
    EXPECT_EQ(parse_byte_size("8G"), std::uint64_t{8} << 30);
    EXPECT_EQ(parse_byte_size("512m"), std::uint64_t{512} << 20);
    EXPECT_EQ(parse_byte_size("1.5GiB"), std::uint64_t{3} << 29);
    EXPECT_EQ(parse_byte_size("64KB"), std::uint64_t{64} << 10);
    EXPECT_EQ(parse_byte_size("100000"), 100000u);
    for (const char* bad : {"", "G", "-1G", "0", "8X", "1e30", "nan", "inf", "8 G"})
        EXPECT_EQ(parse_byte_size(bad), std::nullopt) << bad;
    EXPECT_EQ(byte_size_text(512), "512 bytes");
    EXPECT_EQ(byte_size_text(std::uint64_t{3} << 29), "1.5 GiB");
    EXPECT_GE(default_max_memory_bytes(), std::uint64_t{1} << 20);
}

}  // namespace
}  // namespace cambium::lsys
