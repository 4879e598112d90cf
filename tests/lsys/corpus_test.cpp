// SPDX-License-Identifier: Apache-2.0
// Derives every corpus model that has an oracle string and compares with cpfg's output.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "base/diagnostics.h"
#include "lsys/lsystem.h"
#include "lsys/string_io.h"

namespace cambium::lsys {
namespace {

namespace fs = std::filesystem;

/// Models whose features we claim: their derived string must equal cpfg's exactly.
const std::set<std::string> supported_models = {
#include "corpus_supported.inc"
};

fs::path corpus_dir()
{
    const char* env = std::getenv("CAMBIUM_CORPUS");
    return env ? fs::path(env) : fs::path(CAMBIUM_CORPUS_DEFAULT);
}

std::string read_text(const fs::path& p)
{
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// The value of "lsystem": "..." inside model.json's command_parsed.
std::string lsystem_file_name(const fs::path& model_json)
{
    std::string json = read_text(model_json);
    std::size_t at = json.find("\"command_parsed\"");
    at = json.find("\"lsystem\"", at == std::string::npos ? 0 : at);
    if (at == std::string::npos)
        return "";
    std::size_t open = json.find('"', json.find(':', at) + 1);
    std::size_t close = json.find('"', open + 1);
    return json.substr(open + 1, close - open - 1);
}

std::string without_newlines(std::string s)
{
    std::erase(s, '\n');
    std::erase(s, '\r');
    return s;
}

struct Outcome {
    bool matched = false;
    std::string detail;
    bool homomorphism_compared = false;
};

Outcome derive_and_compare(const fs::path& model_dir, const fs::path& oracle)
{
    std::string lfile = lsystem_file_name(model_dir / "model.json");
    if (lfile.empty())
        return {false, "no lsystem in model.json"};
    try {
        set_warnings_enabled(false);
        // func() needs the view file's functions (geom): note its use and give 0
        bool uses_func = false;
        LoadOptions options;
        options.function = [&](int, double) {
            uses_func = true;
            return 0.0;
        };
        options.curve = [&](char, int, double) {
            uses_func = true;
            return 0.0;
        };
        LSystem ls = LSystem::load(model_dir / lfile, options);
        ModuleString derived = ls.derive();
        std::string ours = to_text(derived, ls.symbols());
        set_warnings_enabled(true);
        std::string raw_ref = read_text(oracle);
        std::string ref = without_newlines(raw_ref);
        if (ours == ref) {
            // the same modules: cpfg's text output must then agree byte for byte
            std::ostringstream text;
            write_string_text(derived, ls.symbols(), text);
            if (text.str() != raw_ref)
                return {false, "same modules, but write_string_text differs from cpfg's file"};
            // cpfg -h: the same string with the homomorphism applied
            fs::path homo = oracle.parent_path() / "string.homo.str";
            if (fs::exists(homo) && !uses_func) {
                set_warnings_enabled(false);
                std::string interpreted = to_text(ls.interpretation_string(derived), ls.symbols());
                set_warnings_enabled(true);
                if (uses_func)
                    return {true, ""};  // the homomorphism needs the view file's functions
                std::string homo_ref = without_newlines(read_text(homo));
                if (interpreted != homo_ref) {
                    std::size_t at = 0;
                    while (at < interpreted.size() && at < homo_ref.size() &&
                           interpreted[at] == homo_ref[at])
                        ++at;
                    return {false, "homomorphism differs at character " + std::to_string(at) +
                                       ": ours '" + interpreted.substr(at, 40) + "' cpfg '" +
                                       homo_ref.substr(at, 40) + "'"};
                }
                return {true, "", true};
            }
            return {true, ""};
        }
        std::size_t at = 0;
        while (at < ours.size() && at < ref.size() && ours[at] == ref[at])
            ++at;
        std::string needs = uses_func ? " [uses the view file's functions or curves]" : "";
        if (ls.has_queries())
            needs += " [has query modules: needs geom's query pass]";
        return {false, "differs at character " + std::to_string(at) + ": ours '" +
                           ours.substr(at, 40) + "' cpfg '" + ref.substr(at, 40) + "'" + needs};
    } catch (const std::exception& e) {
        set_warnings_enabled(true);
        return {false, e.what()};
    }
}

TEST(LsysCorpus, DeterministicModelsMatchCpfgStrings)
{
    fs::path corpus = corpus_dir();
    if (!fs::exists(corpus / "oracle"))
        GTEST_SKIP() << "corpus not found at " << corpus;
    int total = 0, matched = 0, homomorphisms = 0;
    for (const auto& entry : fs::recursive_directory_iterator(corpus / "oracle")) {
        if (entry.path().filename() != "string.str")
            continue;
        std::string id = fs::relative(entry.path().parent_path(), corpus / "oracle").string();
        Outcome o = derive_and_compare(corpus / "cpfg" / id, entry.path());
        ++total;
        matched += o.matched ? 1 : 0;
        homomorphisms += o.homomorphism_compared ? 1 : 0;
        if (!o.matched)
            std::printf("  mismatch %s: %s\n", id.c_str(), o.detail.substr(0, 300).c_str());
        if (supported_models.count(id)) {
            EXPECT_TRUE(o.matched) << id << ": " << o.detail;
        }
    }
    std::printf("%d of %d models match\n", matched, total);
    std::printf("%d of them also match cpfg -h (string.homo.str)\n", homomorphisms);
    EXPECT_GT(total, 0);
}

TEST(LsysCorpus, OracleStringsReadAndWrittenAgainAreUnchanged)
{
    fs::path corpus = corpus_dir();
    if (!fs::exists(corpus / "oracle"))
        GTEST_SKIP() << "corpus not found at " << corpus;
    int files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(corpus / "oracle")) {
        std::string name = entry.path().filename().string();
        if (name.size() < 4 || name.substr(name.size() - 4) != ".str")
            continue;
        SymbolTable symbols;
        ModuleString s = read_string_text(entry.path(), symbols);
        std::ostringstream text;
        write_string_text(s, symbols, text);
        EXPECT_EQ(text.str(), read_text(entry.path())) << entry.path();
        // and through the binary format
        std::stringstream binary;
        write_string_binary(s, symbols, binary, 3);
        int step = 0;
        ModuleString back = read_string_binary(binary, symbols, "binary", &step);
        EXPECT_EQ(step, 3);
        EXPECT_EQ(to_text(back, symbols), to_text(s, symbols)) << entry.path();
        ++files;
    }
    EXPECT_GT(files, 50);
}

}  // namespace
}  // namespace cambium::lsys
