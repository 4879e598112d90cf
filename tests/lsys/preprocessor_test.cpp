// SPDX-License-Identifier: Apache-2.0
// The cpp step: tab continuations, `#(` turtle lines, defines, missing preprocessor.
#include "lsys/preprocessor.h"
#include "test_util.h"

namespace cambium::lsys {
namespace {

using testing::derive_text;

TEST(LsysPreprocessor, KeepsLeadingTab)
{
    std::string out = preprocess("#define N 2\nA --> B(N)\n\tC(N)\n", "p.l", {});
    EXPECT_NE(out.find("A --> B(2)\n\tC(2)"), std::string::npos) << out;
}

TEST(LsysPreprocessor, KeepsHashParenTurtleLines)
{
    std::string out = preprocess("#define W 4\nA --> B\n\t#(W)F\n  #(1)G\n", "p.l", {});
    EXPECT_NE(out.find("\t#(4)F"), std::string::npos) << out;
    EXPECT_NE(out.find("#(1)G"), std::string::npos) << out;
}

TEST(LsysPreprocessor, HashParenLineDerives)
{
    const char* src = "#define W 4\nlsystem: 1\nderivation length: 1\naxiom: A\nA --> B\n\t#(W)F\nendlsystem\n";
    EXPECT_EQ(derive_text(src), "B#(4)F");
}

TEST(LsysPreprocessor, LineMarkersNameTheOriginalFile)
{
    std::string out = preprocess("#define A 1\n\nx\n", "dir/plant.l", {});
    EXPECT_NE(out.find("\"dir/plant.l\""), std::string::npos) << out;
    EXPECT_EQ(out.find("input.l"), std::string::npos) << out;
}

TEST(LsysPreprocessor, DefinesFromOptions)
{
    LoadOptions options;
    options.defines = {"STEPS=3"};
    LSystem ls = LSystem::from_source(
        "lsystem: 1\nderivation length: STEPS\naxiom: A\nendlsystem\n", "d.l", options);
    EXPECT_EQ(ls.derivation_length(), 3);
}

TEST(LsysPreprocessor, MissingPreprocessorIsClearError)
{
    LoadOptions options;
    options.preprocessor = "/nonexistent/cpp-cambium";
    try {
        LSystem::from_source("lsystem: 1\naxiom: A\nendlsystem\n", "m.l", options);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("was not found"), std::string::npos) << e.what();
    }
}

TEST(LsysPreprocessor, PreprocessorErrorIsReported)
{
    try {
        LSystem::from_source("#include \"missing-file.h\"\n", "e.l");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("e.l"), std::string::npos) << e.what();
    }
}

TEST(LsysPreprocessor, RefusesHugeInput)
{
    PreprocessOptions options;
    options.max_input_bytes = 10;
    EXPECT_THROW(preprocess("lsystem: 1\naxiom: A\n", "big.l", options), Error);
}

}  // namespace
}  // namespace cambium::lsys
