// SPDX-License-Identifier: Apache-2.0
// Material transparency as cpfg's window draws it (manual 9.4): the L-system's objects
// opaque, unless --material-transparency asks for rayshade's reading.
#include <gtest/gtest.h>

#include <algorithm>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "corpus_model.h"

namespace cambium::test {
namespace {

float most_transparent(const CorpusModel& model, std::vector<std::string> extra)
{
    CorpusModel m = model;
    m.command.insert(m.command.begin(), extra.begin(), extra.end());
    app::Options options = model_options(m);
    set_warnings_enabled(false);
    app::Model loaded = app::load_model(options);
    geom::Scene scene = app::interpret(loaded, app::derive(loaded, options), options);
    set_warnings_enabled(true);
    float most = 0;
    for (const geom::Material& mat : scene.materials)
        most = std::max(most, mat.transparency);
    return most;
}

// Lilac's petals have transparency 153/255 in materials.mat.
TEST(MaterialConformance, LilacIsOpaqueAsInCpfgsWindowUnlessAsked)
{
    auto corpus = corpus_dir();
    if (!corpus)
        GTEST_SKIP() << "corpus not found";
    for (const CorpusModel& model : corpus_models(*corpus)) {
        if (model.id != "10-manuals/11-CPFG/Lilac")
            continue;
        EXPECT_EQ(most_transparent(model, {}), 0.0f);
        EXPECT_FLOAT_EQ(most_transparent(model, {"--material-transparency"}), 153 / 255.0f);
        return;
    }
    GTEST_SKIP() << "Lilac not in the corpus";
}

}  // namespace
}  // namespace cambium::test
