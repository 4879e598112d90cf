// SPDX-License-Identifier: Apache-2.0
// cpfg's animation mode (-a): the string of the last frame of every corpus model whose
// oracle has one, and incremental derivation against fresh derivations frame by frame.
#include <gtest/gtest.h>

#include "app/pipeline.h"
#include "app/sequence.h"
#include "base/diagnostics.h"
#include "corpus_model.h"
#include "lsys/string_io.h"

namespace cambium::test {
namespace {

app::Options animated(const CorpusModel& model)
{
    app::Options options = model_options(model);
    options.shot.animate = true;
    return options;
}

TEST(AnimationConformance, LastFrameStringsMatchCpfg)
{
    compare_with_oracle("string.anim_last.str", {},
                        [](const CorpusModel& model, const std::string& reference) {
        app::Options options = animated(model);
        app::Model loaded = app::load_model(options);
        std::string last;
        app::derive_frames(loaded, app::animation_frames(loaded, options),
                           [&](const geom::AnimationFrame&, const lsys::ModuleString& s) {
            last = lsys::to_text(s, loaded.lsystem.symbols());
        });
        return string_difference(last, without_newlines(reference));
    });
}

/// Every frame's string, derived incrementally, equals a derivation from the axiom to
/// that frame's step: for the corpus models with an animation of several frames.
TEST(AnimationConformance, IncrementalDerivationEqualsFreshAtEveryFrame)
{
    auto corpus = corpus_dir();
    if (!corpus)
        GTEST_SKIP() << "corpus not found";
    set_warnings_enabled(false);
    int checked = 0;
    for (const CorpusModel& model : corpus_models(*corpus)) {
        if (model.environmental || !std::filesystem::exists(model.oracle / "string.anim_last.str"))
            continue;
        app::Options options = animated(model);
        app::Model loaded = app::load_model(options);
        std::vector<geom::AnimationFrame> frames = app::animation_frames(loaded, options);
        if (frames.size() > 200)
            frames.resize(200);  // long animations: their first 200 frames
        int compared = 0;
        app::derive_frames(loaded, frames, [&](const geom::AnimationFrame& f,
                                               const lsys::ModuleString& s) {
            // Fresh derivations of many frames cost their square: sample them.
            if (compared++ % 7 != 0 && &f != &frames.back())
                return;
            // derive() starts a Deriver of its own: the incremental one is unaffected
            lsys::ModuleString expected = loaded.lsystem.derive(f.number);
            EXPECT_EQ(lsys::to_text(s, loaded.lsystem.symbols()),
                      lsys::to_text(expected, loaded.lsystem.symbols()))
                << model.id << " frame " << f.number;
        });
        ++checked;
    }
    set_warnings_enabled(true);
    EXPECT_GT(checked, 5);
}

}  // namespace
}  // namespace cambium::test
