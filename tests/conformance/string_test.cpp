// SPDX-License-Identifier: Apache-2.0
// Every corpus model with a reference string, derived through the whole pipeline (with
// the view file's functions, curves and the turtle's query pass, as the command does)
// and compared module by module with the original cpfg's -str output.
#include <gtest/gtest.h>

#include <set>

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
    compare_with_oracle("string.str", known_string_differences,
                        [](const CorpusModel& model, const std::string& reference) {
        std::string ref = without_newlines(reference);
        app::Options options = model_options(model);
        app::Model loaded = app::load_model(options);
        std::string ours = lsys::to_text(app::derive(loaded, options), loaded.lsystem.symbols());
        if (ours == ref)
            return std::string();
        std::size_t at = 0;
        while (at < ours.size() && at < ref.size() && ours[at] == ref[at])
            ++at;
        return "at character " + std::to_string(at) + ": ours '" + ours.substr(at, 40) +
               "' cpfg '" + ref.substr(at, 40) + "'";
    });
}

}  // namespace
}  // namespace cambium::test
