// SPDX-License-Identifier: Apache-2.0
// The cpp step: tab continuations, `#(` turtle lines, defines, missing preprocessor.
#include "lsys/preprocessor.h"

#include <sys/stat.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

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

TEST(LsysPreprocessor, FileWithoutDirectivesParsesAsCppWouldGiveIt)
{
    // Not run through cpp (the default, without -D): the same strings as through cpp
    // (named by its path, so that it runs), tab continuations and odd spacing included.
    const std::string source =
        "Lsystem: 1\nderivation length:   3\nAxiom: A(1)  B\n\n\n\n\n\n\n\n\n\n\n"
        "A(x) : x < 4 --> A(x+1) [+B]   \n\tB(x)\nB --> B-B\t\nendlsystem\n";
    LoadOptions through_cpp;
    through_cpp.preprocessor = "/usr/bin/cpp";
    if (!std::filesystem::exists(through_cpp.preprocessor))
        GTEST_SKIP() << "no /usr/bin/cpp";
    std::string direct = to_text(LSystem::from_source(source, "p.l").derive(),
                                 LSystem::from_source(source, "p.l").symbols());
    LSystem with_cpp = LSystem::from_source(source, "p.l", through_cpp);
    EXPECT_EQ(direct, to_text(with_cpp.derive(), with_cpp.symbols()));
    EXPECT_EQ(direct, "A(4)[+B]B(3)[+B-B]B(2)[+B-B-B-B]B(1)B-B-B-B-B-B-B-B");  // continued line
    // a syntax error names the same line either way
    std::string broken = "Lsystem: 1\n\n\nAxiom: A(\nendlsystem\n";
    std::string direct_error, cpp_error;
    try {
        LSystem::from_source(broken, "p.l");
    } catch (const Error& e) {
        direct_error = e.what();
    }
    try {
        LSystem::from_source(broken, "p.l", through_cpp);
    } catch (const Error& e) {
        cpp_error = e.what();
    }
    EXPECT_FALSE(direct_error.empty());
    EXPECT_EQ(direct_error, cpp_error);
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

namespace fs = std::filesystem;

/// An empty scratch folder for one test.
fs::path scratch(const std::string& name)
{
    fs::path dir = fs::temp_directory_path() / ("cambium_pp_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

/// The message of the Error `preprocess` throws ("" if none).
std::string preprocess_error(const std::string& source, const std::string& file,
                             const PreprocessOptions& options = {})
{
    try {
        preprocess(source, file, options);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// cpp's own diagnostics are relayed naming the model's file at its line, never a
// temporary path or <stdin>.
TEST(LsysPreprocessor, CppMessagesNameTheModelFile)
{
    std::string message = preprocess_error("#define A 1\n\n#error no good\n", "dir/m.l");
    EXPECT_NE(message.find("dir/m.l:3:2: error: #error no good"), std::string::npos) << message;
    EXPECT_EQ(message.find("<stdin>"), std::string::npos) << message;
    EXPECT_EQ(message.find(fs::temp_directory_path().string()), std::string::npos) << message;
}

// A macro that expands without bound hits the output limit with a message.
TEST(LsysPreprocessor, MacroBombHitsTheOutputLimit)
{
    std::string bomb = "#define A0 x x x x x x x x x x x x x x x x\n";
    for (int i = 1; i < 6; ++i)
        bomb += "#define A" + std::to_string(i) + " A" + std::to_string(i - 1) + " A" +
                std::to_string(i - 1) + " A" + std::to_string(i - 1) + " A" +
                std::to_string(i - 1) + "\n";
    for (int i = 0; i < 40; ++i)
        bomb += "A5\n";  // 40 x 16 x 4^5 words: about 1.3 MB
    PreprocessOptions options;
    options.max_output_bytes = 256u << 10;
    std::string message = preprocess_error(bomb, "bomb.l", options);
    EXPECT_NE(message.find("bomb.l: error: the preprocessed text grew past"), std::string::npos)
        << message;
    EXPECT_NE(message.find("without bound"), std::string::npos) << message;
}

// Reading /dev/zero, a FIFO or a folder never ends (or makes no sense): refused at the
// #include, before cpp runs.
TEST(LsysPreprocessor, IncludeOfDeviceOrFifoIsRefused)
{
    auto start = std::chrono::steady_clock::now();
    std::string message = preprocess_error("\n  #include \"/dev/zero\"\n", "z.l");
    EXPECT_NE(message.find("z.l:2:3: error: #include names /dev/zero, which is a device"),
              std::string::npos)
        << message;
    fs::path dir = scratch("fifo");
    ASSERT_EQ(::mkfifo((dir / "pipe.h").c_str(), 0600), 0);
    PreprocessOptions options;
    options.folder = dir;
    message = preprocess_error("#include \"pipe.h\"\n", "f.l", options);
    EXPECT_NE(message.find("f.l:1:1: error: #include names"), std::string::npos) << message;
    EXPECT_NE(message.find("pipe.h, which is a device, FIFO or folder"), std::string::npos)
        << message;
    // Also through an included file.
    std::ofstream(dir / "inner.h") << "#include <pipe.h>\n";
    message = preprocess_error("#include \"inner.h\"\n", "f.l", options);
    EXPECT_NE(message.find("inner.h:1:1: error: #include names"), std::string::npos) << message;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
}

// An include whose name is computed is not seen before cpp runs: cpp's memory and
// time limits stop it.
TEST(LsysPreprocessor, ComputedIncludeOfDeviceIsStoppedByLimits)
{
    PreprocessOptions options;
    options.max_seconds = 3;
    options.max_memory_bytes = 256u << 20;
    std::string message = preprocess_error("#define Z \"/dev/zero\"\n#include Z\n", "c.l", options);
    EXPECT_NE(message.find("c.l"), std::string::npos) << message;
    EXPECT_TRUE(message.find("memory") != std::string::npos ||
                message.find("stopped after 3 s") != std::string::npos)
        << message;
}

// `#include "../x"` is looked up from the model's folder, never from a temporary
// folder's parent (the system's temporary directory), where anyone may plant a file.
TEST(LsysPreprocessor, QuotedIncludesStartFromTheModelFolder)
{
    fs::path dir = scratch("hijack");
    fs::create_directories(dir / "model");
    std::ofstream(fs::temp_directory_path() / "cambium_planted.h") << "hijacked\n";
    std::ofstream(dir / "model" / "own.h") << "own_text\n";
    std::ofstream(dir / "shared.h") << "shared_text\n";
    PreprocessOptions options;
    options.folder = dir / "model";
    std::string out = preprocess("#include \"own.h\"\n#include \"../shared.h\"\n", "p.l", options);
    EXPECT_NE(out.find("own_text"), std::string::npos) << out;
    EXPECT_NE(out.find("shared_text"), std::string::npos) << out;
    std::string message = preprocess_error("#include \"../cambium_planted.h\"\n", "p.l", options);
    EXPECT_NE(message.find("p.l:1:10: fatal error: ../cambium_planted.h: No such file"),
              std::string::npos)
        << message;
    EXPECT_EQ(message.find("hijacked"), std::string::npos) << message;
    fs::remove(fs::temp_directory_path() / "cambium_planted.h");
}

// A model file reads nothing outside its model's folder (docs/security.md): with
// confine_to set, an #include of a file outside it (written out, through a link, from an
// included file, or computed by a macro) is an error, and none of its text comes back.
TEST(LsysPreprocessor, IncludesStayInTheConfinedFolder)
{
    constexpr auto npos = std::string::npos;
    fs::path dir = scratch("confined");
    fs::create_directories(dir / "model" / "sub");
    std::ofstream(dir / "secret.h") << "secret_text\n";
    std::ofstream(dir / "model" / "own.h") << "own_text\n";
    std::ofstream(dir / "model" / "sub" / "deeper.h") << "#include \"../own.h\"\n";
    std::ofstream(dir / "model" / "sneaky.h") << "#include \"../secret.h\"\n";
    fs::create_symlink(dir / "secret.h", dir / "model" / "link.h");
    PreprocessOptions options;
    options.folder = dir / "model";
    options.confine_to = dir / "model";
    std::string out = preprocess("#include \"own.h\"\n#include \"sub/deeper.h\"\n", "p.l", options);
    EXPECT_NE(out.find("own_text"), npos) << out;
    const std::string absolute = "\"" + (dir / "secret.h").string() + "\"";
    for (const std::string& include : {std::string("\"../secret.h\""), absolute, std::string("\"link.h\"")}) {
        std::string message = preprocess_error("\n#include " + include + "\n", "p.l", options);
        EXPECT_NE(message.find("p.l:2:1: error: #include names"), npos) << include << ": " << message;
        EXPECT_NE(message.find("lies outside the model's folder"), npos) << message;
        EXPECT_EQ(message.find("secret_text"), npos) << message;
    }
    std::string message = preprocess_error("#include \"sneaky.h\"\n", "p.l", options);
    EXPECT_NE(message.find("sneaky.h:1:1: error: #include names"), npos) << message;
    message = preprocess_error("#define S \"../secret.h\"\n#include S\n", "p.l", options);
    EXPECT_NE(message.find("p.l: error: the C preprocessor read ../secret.h, which lies outside"), npos)
        << message;
    EXPECT_EQ(message.find("secret_text"), npos) << message;
    options.confine_to.reset();  // --allow-file-access
    EXPECT_NE(preprocess("#include \"../secret.h\"\n", "p.l", options).find("secret_text"), npos);
}

// __has_include and `#pragma GCC dependency` look files up: a confined model could learn
// whether a file exists outside its folder, so they are refused where they stand.
TEST(LsysPreprocessor, FileProbesAreRefusedInTheConfinedFolder)
{
    constexpr auto npos = std::string::npos;
    fs::path dir = scratch("probes");
    fs::create_directories(dir / "model");
    std::ofstream(dir / "model" / "probe.h") << "\n#pragma GCC dependency \"/etc/passwd\"\n";
    PreprocessOptions options;
    options.folder = dir / "model";
    options.confine_to = dir / "model";
    const std::string has = "#if __has_include(\"/etc/passwd\")\nA\n#endif\nB\n";
    EXPECT_NE(preprocess_error("\n" + has, "p.l", options).find("p.l:2:5: error: '__has_include' would"), npos)
        << preprocess_error("\n" + has, "p.l", options);
    EXPECT_NE(preprocess_error("#if __has_include_next(<x>)\n#endif\n", "p.l", options)
                  .find("p.l:1:5: error: '__has_include_next'"), npos);
    EXPECT_NE(preprocess_error("#if __has_\\\ninclude(\"/etc/passwd\")\n#endif\n", "p.l", options)
                  .find("p.l:1:5: error: '__has_include'"), npos);
    EXPECT_NE(preprocess_error("#pragma GCC dependency \"/etc/passwd\"\n", "p.l", options)
                  .find("p.l:1:9: error: 'GCC dependency'"), npos);
    EXPECT_NE(preprocess_error("_Pragma(\"GCC dependency \\\"/etc/passwd\\\"\")\n", "p.l", options)
                  .find("'GCC dependency'"), npos);
    EXPECT_NE(preprocess_error("#include \"probe.h\"\n", "p.l", options).find("probe.h:2:9: error:"), npos);
    EXPECT_NE(preprocess_error("#define C(a, b) a ## b\n#if C(__has_, include)(\"/etc/passwd\")\n#endif\n",
                               "p.l", options)
                  .find("p.l:1:19: error: 'token pasting in a #define'"), npos);
    EXPECT_NE(preprocess_error("#define X\n %: define C(a, b) a%:%:b\n", "p.l", options)
                  .find("p.l:2:21: error:"), npos);
    options.confine_to.reset();  // --allow-file-access
    EXPECT_NE(preprocess(has, "p.l", options).find("A"), npos);
}

// cpp runs in the model's folder; included files are still named as the user reaches
// them (the folder they gave), in line markers and in cpp's messages.
TEST(LsysPreprocessor, IncludedFilesAreNamedFromTheUsersFolder)
{
    fs::path dir = scratch("names");
    std::ofstream(dir / "leaf.h") << "leaf_text\n";
    std::ofstream(dir / "bad.h") << "\n#error in bad\n";
    PreprocessOptions options;
    options.folder = dir;
    std::string main = (dir / "p.l").string();
    std::string out = preprocess("#include \"leaf.h\"\n", main, options);
    EXPECT_NE(out.find("\"" + (dir / "leaf.h").string() + "\""), std::string::npos) << out;
    EXPECT_NE(out.find("\"" + main + "\""), std::string::npos) << out;
    std::string message = preprocess_error("\n#include \"bad.h\"\n", main, options);
    EXPECT_NE(message.find("included from " + main + ":2"), std::string::npos) << message;
    EXPECT_NE(message.find((dir / "bad.h").string() + ":2:2: error: #error in bad"), std::string::npos)
        << message;
}

// System headers are not searched: a model has no business with them.
TEST(LsysPreprocessor, SystemHeadersAreNotSearched)
{
    std::string message = preprocess_error("#include <stdio.h>\n", "s.l");
    EXPECT_NE(message.find("s.l:1:10: fatal error: stdio.h: No such file"), std::string::npos)
        << message;
}

// cpp never reads cambium's standard input and no empty -I is passed: an empty
// include folder used to make cpp read its input from standard input.
TEST(LsysPreprocessor, EmptyIncludeFolderIsSkipped)
{
    PreprocessOptions options;
    options.include_dirs = {""};
    std::string out = preprocess("#define N 7\nA(N)\n", "e.l", options);
    EXPECT_NE(out.find("A(7)"), std::string::npos) << out;
}

// Nothing is left in the temporary directory, even after an error.
TEST(LsysPreprocessor, NoTemporaryFilesEvenAfterAnError)
{
    fs::path dir = scratch("tmpdir");
    const char* saved = std::getenv("TMPDIR");
    std::string saved_value = saved ? saved : "";
    ::setenv("TMPDIR", dir.c_str(), 1);
    std::string message = preprocess_error("#error stop\n", "t.l");
    std::string fine = preprocess("A\n", "t.l", {});
    if (saved)
        ::setenv("TMPDIR", saved_value.c_str(), 1);
    else
        ::unsetenv("TMPDIR");
    EXPECT_NE(message.find("t.l:1:2: error: #error stop"), std::string::npos) << message;
    EXPECT_TRUE(fs::is_empty(dir));
}

}  // namespace
}  // namespace cambium::lsys
