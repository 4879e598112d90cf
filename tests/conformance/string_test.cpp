// SPDX-License-Identifier: Apache-2.0
// Every corpus model with a reference string, derived through the whole pipeline (with
// the view file's functions, curves and the turtle's query pass, as the command does)
// and compared module by module with the original cpfg's -str output.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "corpus_model.h"

namespace cambium::test {
namespace {

/// Models whose string differs from cpfg's for a reason docs/deviations.md gives.
const std::set<std::string> known_string_differences = {
#include "string_known.inc"
};

std::string without_newlines(std::string s)
{
    std::erase(s, '\n');
    std::erase(s, '\r');
    return s;
}

TEST(StringConformance, CorpusStringsMatchCpfg)
{
    auto corpus = corpus_dir();
    if (!corpus)
        GTEST_SKIP() << "corpus not found";
    int total = 0, matched = 0;
    set_warnings_enabled(false);
    for (const CorpusModel& model : corpus_models(*corpus)) {
        auto reference = model.oracle / "string.str";
        if (!std::filesystem::exists(reference))
            continue;
        ++total;
        std::string detail;
        bool ok = false;
        try {
            std::ifstream in(reference, std::ios::binary);
            std::ostringstream text;
            text << in.rdbuf();
            std::string ref = without_newlines(text.str());
            app::Options options = model_options(model);
            app::Model loaded = app::load_model(options);
            std::string ours = lsys::to_text(app::derive(loaded, options), loaded.lsystem.symbols());
            ok = ours == ref;
            if (!ok) {
                std::size_t at = 0;
                while (at < ours.size() && at < ref.size() && ours[at] == ref[at])
                    ++at;
                detail = "differs at character " + std::to_string(at) + ": ours '" +
                         ours.substr(at, 40) + "' cpfg '" + ref.substr(at, 40) + "'";
            }
        } catch (const std::exception& e) {
            detail = e.what();
        }
        matched += ok ? 1 : 0;
        if (!ok)
            std::printf("  string differs %s: %s\n", model.id.c_str(), detail.c_str());
        if (!known_string_differences.count(model.id)) {
            EXPECT_TRUE(ok) << model.id << ": " << detail;
        }
    }
    set_warnings_enabled(true);
    std::printf("%d of %d models match\n", matched, total);
    EXPECT_GT(total, 0);
}

}  // namespace
}  // namespace cambium::test
