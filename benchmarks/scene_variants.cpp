// SPDX-License-Identifier: Apache-2.0
// A scene's plant variants of one model (docs/scenes.md "How plants are combined"): N
// step counts S/N, 2S/N, ..., S of one model, each derived from the axiom (as each variant
// alone would be) against one derivation to S that hands out the others on the way (what
// assemble_scene does). Prints one JSON line per model: the steps derived and the time
// of each way, with the interpretation of every variant included in both, and the
// process's peak memory after all.
//
//   build/benchmarks/scene_variants [--variants N] [--steps S]
//
// Models: `counter`, one module counted up (each step costs the same: the sum of the
// step counts is (N + 1) / 2 times the largest), and `shoot`, a stem that grows a node
// with a leaf each step (a step costs its string's length: the sum, about N / 3 times).
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "app/scene_assembly.h"
#include "app/scene_file.h"

namespace {

namespace fs = std::filesystem;
namespace app = cambium::app;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t)
{
    return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Model {
    const char* name;
    const char* lsystem;
};

const Model models[] = {
    {"counter", "lsystem: 1\nderivation length: 1\naxiom: F(1)A(0)\n"
                "A(n) --> A(n + 1)\n"
                "homomorphism\nA(n) --> [+(90)F(n * 1e-6)]\nendlsystem\n"},
    {"shoot", "lsystem: 1\nderivation length: 1\naxiom: A(0)\n"
              "A(n) --> F(1)[+(40)L(n)]/(137.5)A(n + 1)\n"
              "homomorphism\nL(n) --> F(0.5)@O(0.2)\nendlsystem\n"},
};

}  // namespace

int main(int argc, char** argv)
{
    int variants = 10, largest = 0;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (std::strcmp(argv[i], "--variants") == 0)
            variants = std::atoi(argv[i + 1]);
        else if (std::strcmp(argv[i], "--steps") == 0)
            largest = std::atoi(argv[i + 1]);
    }
    if (variants < 1 || variants > 100 || largest < 0) {
        std::fprintf(stderr, "usage: scene_variants [--variants 1..100] [--steps S]\n");
        return 2;
    }
    const fs::path dir = fs::temp_directory_path() /
                         ("cambium_scene_variants_" + std::to_string(::getpid()));
    try {
        for (const Model& m : models) {
            // a counter's steps are cheap, a shoot's cost its length
            const int s = largest > 0 ? largest : (std::strcmp(m.name, "counter") == 0 ? 1'000'000 : 20'000);
            fs::create_directories(dir / m.name);
            std::ofstream(dir / m.name / "p.l") << m.lsystem;
            std::ofstream(dir / m.name / "p.v") << "angle factor: 8\ninitial line width: 0.1\n";
            std::vector<std::optional<int>> steps;
            std::string list;
            for (int k = 1; k <= variants; ++k) {
                const int n = int(std::int64_t(s) * k / variants);
                steps.emplace_back(n);
                list += (k > 1 ? ", " : "") + std::to_string(n);
            }
            // each variant from the axiom: derive_variants of one step count each
            app::Options o;
            o.lsystem = dir / m.name / "p.l";
            o.view = dir / m.name / "p.v";
            app::Model model = app::load_model(o);
            std::uint64_t separate_steps = 0;
            std::size_t primitives = 0;
            auto t = Clock::now();
            for (const std::optional<int>& n : steps)
                separate_steps +=
                    app::derive_variants(model, {n}, [&](std::size_t, const auto& string) {
                        primitives += app::interpret(model, string, o).geometry.lines.segment_count();
                    }).steps;
            const double separate_s = seconds_since(t);
            // the scene: one entry, all step counts, one placement each
            std::string placements;
            for (int k = 0; k < variants; ++k)
                placements += (k ? ", " : "") + std::string("{\"translate\": [") +
                              std::to_string(10 * k) + ", 0, 0]}";
            std::ofstream(dir / "scene.json")
                << "{\"plants\": [{\"model\": \"" << m.name
                << "\", \"command\": \"cpfg p.l p.v\", \"steps\": [" << list
                << "], \"placements\": [" << placements << "]}]}";
            app::SceneFile file = app::read_scene_file(dir / "scene.json", app::Options{});
            t = Clock::now();
            app::AssemblyReport report;
            cambium::geom::Scene scene = app::assemble_scene(file, app::Options{}, {}, &report);
            const double shared_s = seconds_since(t);
            std::size_t scene_primitives = 0;
            for (const auto& p : scene.prototypes)
                scene_primitives += p.geometry.lines.segment_count();
            struct rusage usage {};
            getrusage(RUSAGE_SELF, &usage);
            std::printf("{\"model\": \"%s\", \"variants\": %d, \"largest_steps\": %d, "
                        "\"separate\": {\"steps\": %llu, \"seconds\": %.3f}, "
                        "\"one_derivation\": {\"steps\": %llu, \"derivations\": %zu, "
                        "\"seconds\": %.3f, \"load_s\": %.3f, \"derive_s\": %.3f, \"interpret_s\": %.3f}, "
                        "\"speedup\": %.2f, \"segments\": [%zu, %zu], \"peak_rss_mb\": %.1f}\n",
                        m.name, variants, s, static_cast<unsigned long long>(separate_steps),
                        separate_s, static_cast<unsigned long long>(report.derivation_steps),
                        report.derivations, shared_s, report.load_s, report.derive_s, report.interpret_s,
                        separate_s / shared_s, primitives, scene_primitives,
                        double(usage.ru_maxrss) / 1024.0);
            std::fflush(stdout);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "scene_variants: %s\n", e.what());
        fs::remove_all(dir);
        return 1;
    }
    fs::remove_all(dir);
    return 0;
}
