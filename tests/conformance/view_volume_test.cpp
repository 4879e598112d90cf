// SPDX-License-Identifier: Apache-2.0
// The bounding box of every corpus model's interpreted geometry against the original
// cpfg's view-volume file (-vv), within 1e-3 of the box diagonal.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "corpus_model.h"
#include "geom/view_volume.h"

namespace cambium::test {
namespace {

/// Models whose box differs from cpfg's for a reason docs/deviations.md gives.
const std::set<std::string> known_differences = {
#include "view_volume_known.inc"
};

std::string read_text(const std::filesystem::path& p)
{
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// The largest corner difference, as a fraction of the reference box's diagonal.
double box_error(const geom::Bounds3& ours, const geom::Bounds3& ref)
{
    double diagonal = geom::length(ref.extent());
    double worst = 0;
    for (int axis = 0; axis < 3; ++axis)
        worst = std::max({worst, std::fabs(ours.lo[axis] - ref.lo[axis]),
                          std::fabs(ours.hi[axis] - ref.hi[axis])});
    return diagonal > 0 ? worst / diagonal : worst;
}

TEST(ViewVolumeConformance, CorpusBoxesMatchCpfg)
{
    auto corpus = corpus_dir();
    if (!corpus)
        GTEST_SKIP() << "corpus not found";
    int total = 0, matched = 0;
    set_warnings_enabled(false);
    for (const CorpusModel& model : corpus_models(*corpus)) {
        auto vv = model.oracle / "view.vv";
        if (!std::filesystem::exists(vv))
            continue;
        ++total;
        std::string detail;
        bool ok = false;
        try {
            geom::Bounds3 ref = geom::parse_view_volume(read_text(vv), vv.string());
            app::Options options = model_options(model);
            app::Model loaded = app::load_model(options);
            geom::Scene scene = app::interpret(loaded, app::derive(loaded, options), options);
            geom::Bounds3 ours = scene.view.box.value_or(scene.bounds);  // as cpfg's -vv
            double error = box_error(ours, ref);
            ok = error <= 1e-3;
            detail = "ours " + geom::format_view_volume(ours) + " cpfg " +
                     geom::format_view_volume(ref) + " error " + std::to_string(error);
        } catch (const std::exception& e) {
            detail = e.what();
        }
        matched += ok ? 1 : 0;
        if (!ok)
            std::printf("  box differs %s: %s\n", model.id.c_str(), detail.c_str());
        if (!known_differences.count(model.id)) {
            EXPECT_TRUE(ok) << model.id << ": " << detail;
        }
    }
    set_warnings_enabled(true);
    std::printf("%d of %d models match\n", matched, total);
    EXPECT_GT(total, 0);
}

}  // namespace
}  // namespace cambium::test
