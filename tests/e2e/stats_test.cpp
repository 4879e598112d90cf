// SPDX-License-Identifier: Apache-2.0
// --stats and --stats-json on a plant whose primitives are known, and string-only runs
// that interpret nothing.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {

/// F[+F]F: 3 cylinders; @O a sphere, @c a disc; a four-corner polygon: 2 triangles.
const char* known_plant =
    "lsystem: 1\nderivation length: 1\naxiom: A\n"
    "A --> F[+F]F@O(0.5)@c(0.5){.f.+f.+f.}\nendlsystem\n";

struct RunResult {
    fs::path dir;
    int status = 0;
    std::string output;
};

/// Runs cambium with `args` in r.dir, keeping its status and output in `r`.
void run_in_folder(RunResult& r, const std::string& args)
{
    std::string command = "cd '" + r.dir.string() + "' && " + CAMBIUM_EXE + " " + args +
                          " > out.txt 2>&1";
    r.status = std::system(command.c_str());
    std::ifstream in(r.dir / "out.txt");
    r.output.assign(std::istreambuf_iterator<char>(in), {});
}

/// Runs cambium on the known plant in a fresh folder with `args`, under the view file
/// `view`.
RunResult run_known_plant(const std::string& name, const std::string& args,
                          const std::string& view = "line style: cylinder\ninitial line width: 0.2\n")
{
    RunResult r;
    r.dir = fs::temp_directory_path() / ("cambium_stats_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(r.dir);
    fs::create_directories(r.dir);
    std::ofstream(r.dir / "p.l") << known_plant;
    std::ofstream(r.dir / "p.v") << view;
    run_in_folder(r, "p.l p.v " + args);
    return r;
}

nlohmann::json read_json(const fs::path& file)
{
    std::ifstream in(file);
    return nlohmann::json::parse(in);
}

/// The keys docs/architecture.md ("Statistics") documents.
void expect_documented_keys(const nlohmann::json& j)
{
    for (const char* key : {"interpreted", "rendered", "times_s", "primitives", "placed_primitives",
                            "instances", "prototypes", "memory_bytes", "bytes_per_primitive",
                            "render"})
        EXPECT_TRUE(j.contains(key)) << key;
    for (const char* key : {"load", "derive", "interpret", "assemble", "build", "first_pixel", "render"})
        EXPECT_TRUE(j["times_s"].contains(key)) << key;
    for (const char* group : {"primitives", "placed_primitives"})
        for (const char* key :
             {"cylinders", "lines", "curve_segments", "spheres", "discs", "triangles", "total"})
            EXPECT_TRUE(j[group].contains(key)) << group << "." << key;
    for (const char* key : {"embree", "embree_peak", "cambium", "scene_buffers", "render_buffers",
                            "embree_shared", "embree_unmonitored", "peak_process"})
        EXPECT_TRUE(j["memory_bytes"].contains(key)) << key;
    for (const char* key : {"embree", "cambium", "peak_process", "ratio_to_embree",
                            "ratio_to_embree_monitor", "ratio_to_embree_allocations"})
        EXPECT_TRUE(j["bytes_per_primitive"].contains(key)) << key;
    for (const char* key : {"width", "height", "samples", "rays", "background_only_samples",
                            "samples_per_s", "rays_per_s"})
        EXPECT_TRUE(j["render"].contains(key)) << key;
}

TEST(Stats, JsonCountsTheScenesPrimitivesAndTimesAddUp)
{
    RunResult r = run_known_plant("render", "-w 32 24 --spp 2 -o p.png --stats-json stats.json");
    ASSERT_EQ(r.status, 0) << r.output;
    nlohmann::json j = read_json(r.dir / "stats.json");
    expect_documented_keys(j);
    EXPECT_TRUE(j["interpreted"].get<bool>());
    EXPECT_TRUE(j["rendered"].get<bool>());
    const nlohmann::json& p = j["primitives"];
    EXPECT_EQ(p["cylinders"], 3);
    EXPECT_EQ(p["curve_segments"], 0);
    EXPECT_EQ(p["spheres"], 1);
    EXPECT_EQ(p["discs"], 1);
    EXPECT_EQ(p["triangles"], 2);
    EXPECT_EQ(p["total"], 7);
    EXPECT_EQ(j["placed_primitives"], p);  // no instances
    EXPECT_EQ(j["instances"], 0);

    const nlohmann::json& t = j["times_s"];
    double parts = 0;
    for (const char* key : {"load", "derive", "interpret", "build", "render"}) {
        EXPECT_GE(t[key].get<double>(), 0) << key;
        if (std::string(key) != "render")
            parts += t[key].get<double>();
    }
    EXPECT_GT(t["build"].get<double>(), 0);
    EXPECT_LE(parts, t["first_pixel"].get<double>());
    EXPECT_NEAR(t["assemble"].get<double>(),
                t["load"].get<double>() + t["derive"].get<double>() + t["interpret"].get<double>(),
                1e-9);

    const nlohmann::json& render = j["render"];
    EXPECT_EQ(render["samples"], 32 * 24 * 2);
    // Every sample traces its camera ray, except those of empty pixels (known to miss);
    // hits trace shadow and bounce rays too.
    EXPECT_GT(render["background_only_samples"].get<std::uint64_t>(), 0u);
    EXPECT_LT(render["background_only_samples"].get<std::uint64_t>(),
              render["samples"].get<std::uint64_t>());
    EXPECT_GT(render["rays"].get<std::uint64_t>() +
                  render["background_only_samples"].get<std::uint64_t>(),
              render["samples"].get<std::uint64_t>());
    EXPECT_GT(render["rays_per_s"].get<double>(), 0);

    const nlohmann::json& m = j["memory_bytes"];
    EXPECT_GT(m["embree"].get<std::uint64_t>(), 0);
    EXPECT_GE(m["embree_peak"].get<std::uint64_t>(), m["embree"].get<std::uint64_t>());
    // 3 cylinders, a sphere, a disc and 2 triangles: some hundreds of bytes of buffers.
    EXPECT_GT(m["cambium"].get<std::uint64_t>(), 100);
    EXPECT_LT(m["cambium"].get<std::uint64_t>(), 100'000);
    EXPECT_GT(m["peak_process"].get<std::uint64_t>(),
              m["embree"].get<std::uint64_t>() + m["cambium"].get<std::uint64_t>());

    // Cambium's memory is the Scene's buffers and the renderer's (the cylinders' caps);
    // of it, keys and indices Embree reads in place count as what Embree needs.
    auto bytes = [&](const char* key) { return double(m[key].get<std::uint64_t>()); };
    EXPECT_EQ(bytes("cambium"), bytes("scene_buffers") + bytes("render_buffers"));
    EXPECT_GT(bytes("render_buffers"), 0);
    EXPECT_GT(bytes("embree_shared"), 3 * 16);  // at least the cylinders' keys
    EXPECT_LT(bytes("embree_shared"), bytes("cambium"));
    const nlohmann::json& per = j["bytes_per_primitive"];
    // Embree's instance geometries, which its monitor does not see, count as Embree's.
    double embree = bytes("embree") + bytes("embree_unmonitored");
    EXPECT_NEAR(per["ratio_to_embree"].get<double>(),
                (embree + bytes("cambium")) / (embree + bytes("embree_shared")), 1e-9);
    EXPECT_NEAR(per["ratio_to_embree_monitor"].get<double>(),
                (bytes("embree") + bytes("cambium")) / (bytes("embree") + bytes("embree_shared")),
                1e-9);
    EXPECT_NEAR(per["ratio_to_embree_allocations"].get<double>(),
                (bytes("embree") + bytes("cambium")) / bytes("embree"), 1e-9);
}

TEST(Stats, PrintedBlockNamesEachFigure)
{
    RunResult r = run_known_plant("print", "-w 16 12 --spp 1 -o p.png --stats");
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* words : {"time to first pixel", "build", "7 (3 cylinders", "2 triangles",
                              "Embree", "Cambium", "peak process memory", "rays/s", "samples/s"})
        EXPECT_NE(r.output.find(words), std::string::npos) << words << " in\n" << r.output;
}

// Pixel-width lines are lines, not cylinders: under `line style: pixel` the three F, and
// under `render mode: wireframe` every edge of every primitive.
TEST(Stats, PixelWidthLinesAndWireframeEdgesCountAsLines)
{
    RunResult pixel = run_known_plant("pixel", "-w 16 12 --spp 1 -o p.png --stats-json stats.json",
                                      "line style: pixel\n");
    ASSERT_EQ(pixel.status, 0) << pixel.output;
    nlohmann::json p = read_json(pixel.dir / "stats.json")["primitives"];
    EXPECT_EQ(p["cylinders"], 0);
    EXPECT_EQ(p["lines"], 3);
    EXPECT_EQ(p["spheres"], 1);
    EXPECT_EQ(p["total"], 7);
    EXPECT_NE(pixel.output.find("interpreted 3 pixel-width lines"), std::string::npos)
        << pixel.output;

    RunResult wire = run_known_plant("wire", "-w 16 12 --spp 1 -o p.png --stats --stats-json stats.json",
                                     "line style: cylinder\nrender mode: wireframe\n");
    ASSERT_EQ(wire.status, 0) << wire.output;
    nlohmann::json w = read_json(wire.dir / "stats.json")["primitives"];
    EXPECT_EQ(w["cylinders"], 0);
    // at least the 8 sides of each cylinder's strip, and the two triangles' edges
    EXPECT_GT(w["lines"].get<std::uint64_t>(), 3 * 8 + 5);
    for (const char* key : {"curve_segments", "spheres", "discs", "triangles"})
        EXPECT_EQ(w[key], 0) << key;
    EXPECT_EQ(w["total"], w["lines"]);
    EXPECT_NE(wire.output.find("0 cylinders, " + std::to_string(w["lines"].get<std::uint64_t>()) +
                               " pixel-width lines"),
              std::string::npos)
        << wire.output;
}

TEST(Stats, StringOnlyRunInterpretsNothing)
{
    RunResult r = run_known_plant("str", "-str p.str -strb p.strb --stats-json stats.json");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(r.dir / "p.str"));
    EXPECT_TRUE(fs::exists(r.dir / "p.strb"));
    EXPECT_FALSE(fs::exists(r.dir / "p.png"));
    nlohmann::json j = read_json(r.dir / "stats.json");
    expect_documented_keys(j);
    EXPECT_FALSE(j["interpreted"].get<bool>());
    EXPECT_FALSE(j["rendered"].get<bool>());
    EXPECT_EQ(j["primitives"]["total"], 0);
    EXPECT_EQ(j["memory_bytes"]["cambium"], 0);
    EXPECT_TRUE(j["times_s"]["first_pixel"].is_null());
}

TEST(Stats, ViewVolumeRunInterpretsButRendersNothing)
{
    RunResult r = run_known_plant("vv", "-vv p.vv --stats-json stats.json");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(r.dir / "p.vv"));
    nlohmann::json j = read_json(r.dir / "stats.json");
    EXPECT_TRUE(j["interpreted"].get<bool>());
    EXPECT_FALSE(j["rendered"].get<bool>());
    EXPECT_EQ(j["render"]["rays"], 0);
}

TEST(Stats, SceneFileCountsPrototypesOnceAndPlacedCopiesPerInstance)
{
    RunResult r = run_known_plant("scene", "--version");  // makes the folder and the plant
    std::ofstream(r.dir / "field.json") << R"({
  "plants": [{"model": ".", "command": "cpfg p.l p.v",
              "placements": [{"translate": [0, 0, 0]}, {"translate": [3, 0, 0]},
                             {"translate": [6, 0, 0]}]}],
  "camera": {"eye": [3, 2, 12], "look_at": [3, 1, 0], "width": 24, "height": 16},
  "render": {"spp": 1}
})";
    std::string command = "cd '" + r.dir.string() + "' && " + CAMBIUM_EXE +
                          " field.json -o f.png --stats-json stats.json > out.txt 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0);
    nlohmann::json j = read_json(r.dir / "stats.json");
    expect_documented_keys(j);
    EXPECT_EQ(j["instances"], 3);
    EXPECT_EQ(j["prototypes"], 1);
    // The known plant once, and three placed copies of it.
    EXPECT_EQ(j["primitives"]["total"], 7);
    EXPECT_EQ(j["placed_primitives"]["total"], 21);
    EXPECT_EQ(j["placed_primitives"]["cylinders"], 9);
    const nlohmann::json& t = j["times_s"];
    EXPECT_LE(t["assemble"].get<double>() + t["build"].get<double>(), t["first_pixel"].get<double>());
    EXPECT_EQ(j["render"]["samples"], 24 * 16);
}

/// A growing plant: step n has n copies of the known plant's 7 primitives.
RunResult run_growing_plant(const std::string& name, const std::string& args)
{
    RunResult r = run_known_plant(name, "--version");  // makes the folder
    std::ofstream(r.dir / "g.l") << "lsystem: 1\nderivation length: 3\naxiom: A\n"
                                    "A --> F[+F]F@O(0.5)@c(0.5){.f.+f.+f.}A\nendlsystem\n";
    run_in_folder(r, "g.l p.v " + args);
    return r;
}

/// The sum of one per-frame figure.
double frame_sum(const nlohmann::json& j, const char* time)
{
    double sum = 0;
    for (const nlohmann::json& f : j["frames"])
        sum += f["times_s"][time].get<double>();
    return sum;
}

TEST(Stats, AnimationReportsEveryFrameAndTotalsThatAddUp)
{
    RunResult r = run_growing_plant("anim", "-a -w 16 12 --spp 2 -o g%02d.png --stats-json s.json");
    ASSERT_EQ(r.status, 0) << r.output;
    nlohmann::json j = read_json(r.dir / "s.json");
    expect_documented_keys(j);
    EXPECT_TRUE(j["sequence"].get<bool>());
    EXPECT_EQ(j["sequence_frames"], 3);
    ASSERT_EQ(j["frames"].size(), 3u);
    std::uint64_t peak_so_far = 0;
    for (int k = 0; k < 3; ++k) {
        const nlohmann::json& f = j["frames"][std::size_t(k)];
        EXPECT_EQ(f["number"], k + 1);
        EXPECT_EQ(f["placed_primitives"], 7 * (k + 1));  // the plant grows a copy a step
        EXPECT_EQ(f["samples"], 16 * 12 * 2);
        EXPECT_GT(f["rays"].get<std::uint64_t>() + f["background_only_samples"].get<std::uint64_t>(),
                  f["samples"].get<std::uint64_t>());
        for (const char* key : {"derive", "interpret", "build", "render"})
            EXPECT_GE(f["times_s"][key].get<double>(), 0) << key;
        EXPECT_GT(f["times_s"]["build"].get<double>(), 0);  // a new scene each frame
        std::uint64_t peak = f["peak_process_bytes"].get<std::uint64_t>();
        EXPECT_GE(peak, peak_so_far);  // a high-water mark
        peak_so_far = peak;
    }
    // The totals are the frames' sums; the counts are the largest frame's.
    const nlohmann::json& t = j["times_s"];
    for (const char* key : {"derive", "interpret", "build", "render"})
        EXPECT_NEAR(t[key].get<double>(), frame_sum(j, key), 1e-9) << key;
    EXPECT_EQ(j["render"]["samples"], 3 * 16 * 12 * 2);
    EXPECT_EQ(j["primitives"]["total"], 21);
    EXPECT_GE(j["memory_bytes"]["peak_process"].get<std::uint64_t>(), peak_so_far);
    EXPECT_LE(t["load"].get<double>() + j["frames"][0]["times_s"]["build"].get<double>(),
              t["first_pixel"].get<double>());
}

TEST(Stats, TurntableBuildsOnceAndCountsOnlyTheSelectedFrames)
{
    RunResult r = run_known_plant(
        "turn", "--turntable 4 --frames 2-3 -w 16 12 --spp 1 -o t%02d.png --stats --stats-json s.json");
    ASSERT_EQ(r.status, 0) << r.output;
    nlohmann::json j = read_json(r.dir / "s.json");
    EXPECT_EQ(j["sequence_frames"], 4);
    ASSERT_EQ(j["frames"].size(), 2u);
    EXPECT_EQ(j["frames"][0]["number"], 2);
    EXPECT_EQ(j["frames"][1]["number"], 3);
    // One scene, one BVH: the first view pays for the build.
    EXPECT_GT(j["frames"][0]["times_s"]["build"].get<double>(), 0);
    EXPECT_EQ(j["frames"][1]["times_s"]["build"].get<double>(), 0);
    EXPECT_EQ(j["frames"][1]["placed_primitives"], 7);
    EXPECT_EQ(j["render"]["samples"], 2 * 16 * 12);
    for (const char* words : {"sequence of 4 frames, 2 rendered here", "slowest frame",
                              "time to first pixel", "peak process memory"})
        EXPECT_NE(r.output.find(words), std::string::npos) << words << " in\n" << r.output;
}

TEST(Stats, ViewVolumeAloneMatchesTheOneWrittenBesideAnImage)
{
    // -vv without an image walks the turtle without building geometry.
    RunResult r = run_growing_plant("vvwalk", "-vv alone.vv");
    ASSERT_EQ(r.status, 0) << r.output;
    RunResult with_image = run_growing_plant("vvimage", "-vv beside.vv -w 8 8 --spp 1 -o g.png");
    ASSERT_EQ(with_image.status, 0) << with_image.output;
    auto text = [](const fs::path& f) {
        std::ifstream in(f);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_FALSE(text(r.dir / "alone.vv").empty());
    EXPECT_EQ(text(r.dir / "alone.vv"), text(with_image.dir / "beside.vv"));
}

}  // namespace
