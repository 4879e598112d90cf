// SPDX-License-Identifier: Apache-2.0
// The one corpus model whose environment is a program of its own, CPFG-CelticKnot
// (`./obcheck`, whose source is not in the corpus), run as an external program through
// cpfg's pipe protocol: a stand-in written from FACTS-environment.md's description of
// obcheck (tests/env/test_program.cpp, started under the name obcheck) must give cpfg's
// string, 174 steps of answers later, cpfg's box and cpfg's picture.
#include <gtest/gtest.h>

#include <filesystem>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "corpus_model.h"
#include "image_compare.h"
#include "geom/view_volume.h"
#include "lsys/string_io.h"

namespace cambium::test {
namespace {

namespace fs = std::filesystem;

TEST(ExternalProgramConformance, CelticKnotWithAnObcheckStandInMatchesCpfg)
{
    auto corpus = corpus_dir();
    if (!corpus)
        GTEST_SKIP() << "corpus not found";
    const std::string id = "10-manuals/20-EnviroPgms/CPFG-CelticKnot";
    std::optional<CorpusModel> found;
    for (const CorpusModel& m : corpus_models(*corpus))
        if (m.id == id)
            found = m;
    if (!found || !fs::exists(found->oracle / "string.str"))
        GTEST_SKIP() << id << " or its oracle not found";
    // a writable copy of the model folder, with the stand-in as its ./obcheck
    CorpusModel model = *found;
    const fs::path copy = fs::temp_directory_path() / "cambium_celtic_knot";
    fs::remove_all(copy);
    fs::copy(model.folder, copy, fs::copy_options::recursive);
    fs::permissions(copy, fs::perms::owner_all, fs::perm_options::add);
    fs::copy_file(CAMBIUM_TEST_PROGRAM, copy / "obcheck");
    model.folder = copy;

    app::Options options = model_options(model);
    options.allow_environment_program = true;
    Diagnostics quiet(Diagnostics::Output::quiet);
    ScopedDiagnostics scope(quiet);
    app::Model loaded = app::load_model(options);
    const lsys::ModuleString derived = app::derive(loaded, options);
    const std::string ours = lsys::to_text(derived, loaded.lsystem.symbols());
    EXPECT_EQ(string_difference(ours, without_newlines(read_text(found->oracle / "string.str"))), "");
    // the box, within 1e-3 of its diagonal as the view-volume conformance test asks
    const geom::Bounds3 box = app::view_volume(loaded, derived, options);
    const geom::Bounds3 ref =
        geom::parse_view_volume(read_text(found->oracle / "view.vv"), (found->oracle / "view.vv").string());
    const double tolerance = 1e-3 * geom::length(ref.extent());
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_NEAR(box.lo[axis], ref.lo[axis], tolerance) << "axis " << axis;
        EXPECT_NEAR(box.hi[axis], ref.hi[axis], tolerance) << "axis " << axis;
    }
    // the picture, as the image conformance test judges the other models'
    const PlantImage picture = render_for_comparison(options);
    const ImageAgreement a = compare_images(picture, read_cpfg_image((found->oracle / "image.png").string(), picture.background));
    EXPECT_TRUE(a.silhouettes_agree()) << a.describe();
    // the frame's red-orange bars: the lighting model (docs/deviations.md, CPFG-CelticKnot)
    EXPECT_FALSE(a.colours_agree()) << "the colours match now: say so in docs/deviations.md";
    fs::remove_all(copy);
}

}  // namespace
}  // namespace cambium::test
