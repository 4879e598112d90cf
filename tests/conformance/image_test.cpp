// SPDX-License-Identifier: Apache-2.0
// Every corpus model's render against cpfg's window image (the oracle's image.png), as a
// modeller would compare them: the silhouettes agree within 2 px and the colours agree.
// Renders are small in samples (2 per pixel) so the whole corpus takes seconds.
#include <gtest/gtest.h>

#include <optional>
#include <set>

#include "base/diagnostics.h"
#include "corpus_model.h"
#include "image_compare.h"

namespace cambium::test {
namespace {

/// Models whose silhouette or colours differ from cpfg's window for a reason
/// docs/deviations.md gives: {id, what} with what "silhouette" or "colour". A listed
/// check must still fail (take the entry off when it passes); the other check must pass.
const std::set<std::pair<std::string, std::string>> known_differences = {
#include "image_known.inc"
};

TEST(ImageConformance, CorpusPicturesMatchCpfgsWindow)
{
    int matched = 0;
    std::optional<int> total = for_each_oracle_model("image.png", [&](const CorpusModel& model,
                                                                      const std::filesystem::path& reference) {
        // a model that cannot be rendered differs in both respects, and says why
        bool silhouette = false, colour = false;
        std::string described;
        try {
            PlantImage ours = render_for_comparison(model_options(model));
            ImageAgreement a = compare_images(ours, read_cpfg_image(reference.string(), ours.background));
            silhouette = a.silhouettes_agree();
            colour = a.colours_agree();
            described = a.describe();
        } catch (const Error& e) {
            described = std::string("error: ") + e.what();
        }
        std::printf("  %-60s %s\n", model.id.c_str(), described.c_str());
        matched += silhouette && colour;
        for (auto [what, agrees] : {std::pair{"silhouette", silhouette}, std::pair{"colour", colour}}) {
            bool known = known_differences.count({model.id, what}) != 0;
            if (known)
                EXPECT_FALSE(agrees) << model.id << ": the " << what << " matches now: take it off image_known.inc";
            else
                EXPECT_TRUE(agrees) << model.id << ": the " << what << " differs from cpfg's: " << described;
        }
    });
    if (!total)
        GTEST_SKIP() << "corpus not found";
    std::printf("%d of %d models match cpfg's window\n", matched, *total);
    EXPECT_GT(*total, 0);
}

}  // namespace
}  // namespace cambium::test
