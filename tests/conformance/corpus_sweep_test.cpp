// SPDX-License-Identifier: Apache-2.0
// Every self-contained corpus model goes through the whole pipeline without an error,
// a small render of it shows the plant inside the frame, and skipping the pixels no
// primitive reaches (render::ScreenMask) changes no pixel of it.
#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "corpus_model.h"
#include "render/render.h"

namespace cambium::test {
namespace {

/// Models the original cpfg draws nothing for (its oracle image.png is the background):
/// an exercise whose L-system is left as `?` placeholders.
const std::set<std::string> drawn_empty_by_cpfg = {
    "11-CPFG/01-Introduction/02-snowflake-exercise",
};

/// Fraction of the image's pixels the geometry covers (alpha is coverage).
double coverage(const render::Image& image)
{
    double sum = 0;
    for (std::size_t i = 3; i < image.rgba.size(); i += 4)
        sum += image.rgba[i];
    return sum / (static_cast<double>(image.width) * image.height);
}

TEST(CorpusSweep, EverySelfContainedModelRendersInFrame)
{
    auto corpus = corpus_dir();
    if (!corpus)
        GTEST_SKIP() << "corpus not found";
    int models = 0, skipping = 0;
    set_warnings_enabled(false);
    for (const CorpusModel& model : corpus_models(*corpus)) {
        if (model.environmental)
            continue;
        ++models;
        try {
            app::Options options = model_options(model);
            options.max_modules = 5'000'000;  // the sweep's memory bound
            app::Model loaded = app::load_model(options);
            geom::Scene scene = app::interpret(loaded, app::derive(loaded, options), options);
            render::RenderSettings settings;
            settings.width = 64;
            settings.height = 48;
            settings.samples_per_pixel = 1;
            settings.max_depth = 1;
            render::RenderReport report;
            render::Image image = render::render(scene, settings, &report);
            double covered = coverage(image);
            // Pixels the screen mask skips show exactly what their traced rays show.
            settings.skip_empty_pixels = false;
            render::Image traced = render::render(scene, settings);
            EXPECT_TRUE(image.rgba == traced.rgba) << model.id << ": skipping empty pixels changed the image";
            skipping += report.background_only_samples > 0 ? 1 : 0;
            // Something of the plant is in the frame, and it is not all over the frame
            // (which would mean a camera inside the geometry).
            if (!drawn_empty_by_cpfg.count(model.id)) {
                EXPECT_GT(covered, 0.0) << model.id << ": nothing visible";
            }
            EXPECT_LT(covered, 0.98) << model.id << ": the frame is all plant";
        } catch (const std::exception& e) {
            ADD_FAILURE() << model.id << ": " << e.what();
        }
    }
    set_warnings_enabled(true);
    std::printf("%d self-contained models swept\n", models);
    EXPECT_GE(models, 79);
    // Most plants leave some of their frame empty.
    EXPECT_GE(skipping, models / 2);
}

}  // namespace
}  // namespace cambium::test
