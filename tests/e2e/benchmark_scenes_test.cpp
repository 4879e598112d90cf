// SPDX-License-Identifier: Apache-2.0
// The large-scene benchmark suite's files (benchmarks/scenes/, docs/benchmarks.md): the
// scene files hold what the suite promises, and every plant derives and interprets into
// the primitives it is meant to have. The suite itself runs outside ctest (run.sh).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "app/command_line.h"
#include "app/pipeline.h"
#include "base/diagnostics.h"

namespace fs = std::filesystem;

namespace cambium::test {
namespace {

const fs::path suite = fs::path(CAMBIUM_SOURCE_DIR) / "benchmarks" / "scenes";

/// Loads, derives (`steps`, or the file's derivation length) and interprets a model.
geom::Scene interpret_model(const fs::path& folder, std::optional<int> steps = {})
{
    std::vector<std::string> args;
    for (const auto& e : fs::directory_iterator(folder))
        if (e.path().extension() == ".l")
            args.push_back((folder / e.path().filename()).string());
    EXPECT_EQ(args.size(), 1u) << folder;
    args.push_back(fs::path(args[0]).replace_extension(".v").string());
    args.insert(args.end(), {"-M", (folder / "plants.mat").string(), "-q"});
    if (steps)
        args.insert(args.end(), {"--steps", std::to_string(*steps)});
    std::optional<app::Options> options = app::parse_command_line(args);
    app::Model model = app::load_model(*options);
    return app::interpret(model, app::derive(model, *options), *options);
}

struct SceneSummary {
    std::size_t plants = 0;
    std::set<std::string> models;
};

/// Counts a scene file's plants (explicit placements and scatter counts) and models.
SceneSummary summarise(const fs::path& file)
{
    std::ifstream in(file);
    nlohmann::json j = nlohmann::json::parse(in);
    SceneSummary s;
    for (const nlohmann::json& plant : j.at("plants")) {
        std::string model = plant.at("model").get<std::string>();
        EXPECT_TRUE(fs::is_directory(file.parent_path() / model)) << model;
        s.models.insert(model);
        const nlohmann::json& placements = plant.at("placements");
        s.plants += placements.is_array() ? placements.size()
                                          : placements.at("scatter").at("count").get<std::size_t>();
    }
    return s;
}

TEST(BenchmarkScenes, MeadowHasTenThousandPlantsOfSeveralHerbs)
{
    SceneSummary s = summarise(suite / "meadow.json");
    EXPECT_GE(s.plants, 10'000u);
    EXPECT_GE(s.models.size(), 3u);
}

TEST(BenchmarkScenes, ForestHasAThousandTreesOfFiveSpecies)
{
    SceneSummary s = summarise(suite / "forest.json");
    EXPECT_GE(s.plants, 1'000u);
    EXPECT_GE(s.models.size(), 5u);
}

TEST(BenchmarkScenes, EveryPlantOfTheScenesHasWoodOrStemsAndLeaves)
{
    Diagnostics quiet(Diagnostics::Output::quiet);
    ScopedDiagnostics install(quiet);
    for (const char* scene : {"meadow.json", "forest.json"}) {
        for (const std::string& model : summarise(suite / scene).models) {
            geom::Scene s = interpret_model(suite / model);
            const geom::Geometry& g = s.geometry;
            // Leaves are polygons (triangles) or, for clover, discs.
            EXPECT_GT(g.mesh.size() + g.discs.size(), 0u) << model;
            if (model != "models/grass") {
                EXPECT_GT(g.lines.segment_count(), 0u) << model;
            }
        }
    }
}

TEST(BenchmarkScenes, BigTreeHasTheSegmentCountItsCommentPromisesAtASmallScale)
{
    // At 6 of its 14 steps the tree has (3^6 - 1) / 2 internodes plus its trunk: the
    // branching that, at full depth, gives (3^13 - 1) / 2 + 7 * 3^13 = 11 957 422 segments.
    geom::Scene s = interpret_model(suite / "models" / "tree10m", 6);
    EXPECT_EQ(s.geometry.lines.segment_count(), 1u + (729u - 1u) / 2u);
}

}  // namespace
}  // namespace cambium::test
