// SPDX-License-Identifier: Apache-2.0
// The one corpus model whose environment is a program of its own, CPFG-CelticKnot
// (`./obcheck`, whose source is not in the corpus), run as an external program through
// cpfg's pipe protocol: a stand-in written from FACTS-environment.md's description of
// obcheck (tests/env/test_program.cpp, started under the name obcheck) must give cpfg's
// string, 174 steps of answers later.
#include <gtest/gtest.h>

#include <filesystem>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "corpus_model.h"
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
    const std::string ours = lsys::to_text(app::derive(loaded, options), loaded.lsystem.symbols());
    EXPECT_EQ(string_difference(ours, without_newlines(read_text(found->oracle / "string.str"))), "");
    fs::remove_all(copy);
}

}  // namespace
}  // namespace cambium::test
