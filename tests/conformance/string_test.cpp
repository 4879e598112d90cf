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

TEST(StringConformance, CorpusStringsMatchCpfg)
{
    compare_with_oracle("string.str", known_string_differences,
                        [](const CorpusModel& model, const std::string& reference) {
        std::string ref = without_newlines(reference);
        app::Options options = model_options(model);
        app::Model loaded = app::load_model(options);
        std::string ours = lsys::to_text(app::derive(loaded, options), loaded.lsystem.symbols());
        return string_difference(ours, ref);
    });
}

}  // namespace
}  // namespace cambium::test
