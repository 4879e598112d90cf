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
};

Outcome derive_and_compare(const fs::path& model_dir, const fs::path& oracle)
{
    std::string lfile = lsystem_file_name(model_dir / "model.json");
    if (lfile.empty())
        return {false, "no lsystem in model.json"};
    try {
        set_warnings_enabled(false);
        LSystem ls = LSystem::load(model_dir / lfile);
        std::string ours = to_text(ls.derive(), ls.symbols());
        set_warnings_enabled(true);
        std::string ref = without_newlines(read_text(oracle));
        if (ours == ref)
            return {true, ""};
        std::size_t at = 0;
        while (at < ours.size() && at < ref.size() && ours[at] == ref[at])
            ++at;
        return {false, "differs at character " + std::to_string(at) + ": ours '" +
                           ours.substr(at, 40) + "' cpfg '" + ref.substr(at, 40) + "'"};
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
    int total = 0, matched = 0;
    for (const auto& entry : fs::recursive_directory_iterator(corpus / "oracle")) {
        if (entry.path().filename() != "string.str")
            continue;
        std::string id = fs::relative(entry.path().parent_path(), corpus / "oracle").string();
        Outcome o = derive_and_compare(corpus / "cpfg" / id, entry.path());
        ++total;
        matched += o.matched ? 1 : 0;
        if (!o.matched)
            std::printf("  mismatch %s: %s\n", id.c_str(), o.detail.substr(0, 300).c_str());
        if (supported_models.count(id)) {
            EXPECT_TRUE(o.matched) << id << ": " << o.detail;
        }
    }
    std::printf("%d of %d models match\n", matched, total);
    EXPECT_GT(total, 0);
}

}  // namespace
}  // namespace cambium::lsys
