// SPDX-License-Identifier: Apache-2.0
// The environmental step's cost (docs/environment.md): a string of N communication modules
// `[+(a) f(r) ?E(vigor)]`, each at its own point of a disc, sent to the built-in honda81.
// Prints one JSON line per N: the turtle pass alone, the whole step (turtle pass,
// messages, honda81, answers written back), and the process's peak memory.
//
// Usage: environment [N ...]   (default 100000 1000000)
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "env/environmental_step.h"
#include "geom/query.h"

namespace {

using namespace cambium;

double peak_mib()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

template <class F>
double seconds(F&& f)
{
    auto start = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// N branches from the origin, each ending in a ?E: a disc of radius sqrt(N) / 4 holding
/// about 16 points per unit square (golden-angle spiral), so honda81's radius 0.1 finds few.
lsys::ModuleString disc_of_queries(std::size_t n, lsys::SymbolTable& symbols)
{
    const lsys::SymbolId push = symbols.intern("["), pop = symbols.intern("]"),
                         turn = symbols.intern("+"), move = symbols.intern("f"),
                         query = symbols.intern("?E");
    lsys::ModuleString s;
    for (std::size_t i = 0; i < n; ++i) {
        const float angle = static_cast<float>(std::fmod(137.50776 * static_cast<double>(i), 360.0));
        const float radius = static_cast<float>(std::sqrt(static_cast<double>(i)) / 4.0);
        const float vigor = static_cast<float>(i % 7);
        s.append(push);
        s.append(turn, std::span<const float>(&angle, 1));
        s.append(move, std::span<const float>(&radius, 1));
        s.append(query, std::span<const float>(&vigor, 1));
        s.append(pop);
    }
    return s;
}

}  // namespace

int main(int argc, char** argv)
{
    std::vector<std::size_t> sizes;
    for (int i = 1; i < argc; ++i)
        sizes.push_back(static_cast<std::size_t>(std::strtoull(argv[i], nullptr, 10)));
    if (sizes.empty())
        sizes = {100'000, 1'000'000};

    namespace fs = std::filesystem;
    const fs::path folder = fs::temp_directory_path() / "cambium_environment_bench";
    fs::create_directories(folder);
    std::ofstream(folder / "density.spec") << "radius: 0.1\n3d case: on\n";
    std::ofstream(folder / "plant.e") << "executable: honda81 density.spec\n"
                                         "turtle position:P:%.4f %.4f %.0f\n";
    std::ofstream(folder / "plant.v") << "angle increment: 90\n";
    const geom::ViewFile view = geom::read_view_file(folder / "plant.v");
    env::Context context;
    context.folder = folder;
    const env::CommSpec spec = env::read_comm_spec(folder / "plant.e");

    for (std::size_t n : sizes) {
        lsys::SymbolTable symbols;
        lsys::ModuleString string = disc_of_queries(n, symbols);
        double turtle_s = seconds([&] { geom::collect_communication_turtles(string, symbols, view); });
        env::EnvironmentalStep step(spec, env::connect(spec, context));
        double step_s = seconds([&] { step.run(string, symbols, view, 1); });
        std::printf("{\"benchmark\": \"environment_step\", \"builtin\": \"honda81\", \"queries\": %zu, "
                    "\"modules\": %zu, \"turtle_pass_s\": %.4f, \"step_s\": %.4f, "
                    "\"step_over_turtle_pass\": %.2f, \"peak_memory_mib\": %.1f}\n",
                    n, string.size(), turtle_s, step_s, step_s / turtle_s, peak_mib());
    }
    fs::remove_all(folder);
    return 0;
}
