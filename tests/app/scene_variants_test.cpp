// SPDX-License-Identifier: Apache-2.0
// A scene's step counts of one model are prefixes of one derivation (docs/scenes.md):
// one run derives to the largest and hands out each smaller one on the way. Each variant
// must be what deriving it alone gives (strings, globals for the homomorphism, random
// streams, stop(), the End block), and the steps derived the largest count, not the sum.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "app/scene_assembly.h"
#include "app/scene_file.h"
#include "lsys/string_io.h"

using namespace cambium;
namespace fs = std::filesystem;

namespace {

/// A scratch folder for one test's models and scenes; removed at the end.
class Folder {
public:
    explicit Folder(const std::string& name)
        : m_dir(fs::temp_directory_path() /
                ("cambium_variants_" + name + "_" + std::to_string(::getpid())))
    {
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    ~Folder() { fs::remove_all(m_dir); }
    const fs::path& dir() const { return m_dir; }
    void write(const fs::path& file, const std::string& text) const
    {
        fs::create_directories((m_dir / file).parent_path());
        std::ofstream(m_dir / file, std::ios::binary) << text;
    }

private:
    fs::path m_dir;
};

const char* view = "angle factor: 8\ninitial line width: 0.1\nline style: cylinder\n";

/// A plant whose End block moves a global the homomorphism draws with and the next
/// steps read (run on a copy, it must leave the run's own globals alone), whose
/// EndEach block draws from ran() and whose productions are stochastic.
const char* stochastic_plant = R"(#define STOP 0
lsystem: 1
seed: 5
derivation length: 9
Start: { n = 0; w = 1; }
EndEach: { n = n + 1; r = ran(1); if (STOP > 0 && n == 4) { stop(STOP); } }
End: { n = n + 100; w = w + n * 0.01 + r; }
axiom: A(1)
A(x) --> F(x)[+(30)B(x*0.7)]/(137)A(x*0.9) : 1
A(x) --> F(x)[-(45)B(x*0.6)]\(90)A(x*0.95) : 1
A(x) --> F(x*ran(1))A(x) : 1
B(x) --> F(x)B(x*0.8)
homomorphism
B(x) --> F(x*w)@O(0.1*w)
endlsystem
)";

/// `stochastic_plant` whose EndEach calls stop(`stop`) after step 4.
std::string stopping_plant(int stop)
{
    std::string text = stochastic_plant;
    text.replace(text.find("#define STOP 0"), 14, "#define STOP " + std::to_string(stop));
    return text;
}

std::string text_of(const lsys::ModuleString& s, const lsys::SymbolTable& symbols)
{
    std::ostringstream out;
    lsys::write_string_text(s, symbols, out);
    return out.str();
}

/// One model's options as a scene's plant gets them (its seed too).
app::Options model_options(const fs::path& folder, std::optional<long> seed)
{
    app::Options o;
    o.lsystem = folder / "p.l";
    o.view = folder / "p.v";
    o.lsystem_seed = seed;
    return o;
}

/// Each step count's string (the homomorphism applied: what the turtle reads, and so
/// what the End block's globals change) from derive_variants, and from a derivation of
/// its own.
void expect_each_variant_as_derived_alone(const fs::path& folder,
                                          const std::vector<std::optional<int>>& steps,
                                          std::optional<long> seed, std::uint64_t largest)
{
    app::Options o = model_options(folder, seed);
    app::Model shared = app::load_model(o);
    std::vector<std::string> handed(steps.size()), turtle(steps.size());
    app::VariantRuns runs =
        app::derive_variants(shared, steps, [&](std::size_t k, const lsys::ModuleString& s) {
            handed[k] = text_of(s, shared.lsystem.symbols());
            turtle[k] = text_of(shared.lsystem.interpretation_string(s), shared.lsystem.symbols());
        });
    EXPECT_EQ(runs.runs, 1u);
    EXPECT_EQ(runs.steps, largest);
    for (std::size_t k = 0; k < steps.size(); ++k) {
        app::Model alone = app::load_model(o);
        app::Options ok = o;
        ok.steps = steps[k];
        lsys::ModuleString s = app::derive(alone, ok);
        EXPECT_EQ(handed[k], text_of(s, alone.lsystem.symbols())) << "variant " << k;
        EXPECT_EQ(turtle[k], text_of(alone.lsystem.interpretation_string(s), alone.lsystem.symbols()))
            << "variant " << k;
    }
}

}  // namespace

TEST(SceneVariants, EachStepCountIsTheStringDerivedAlone)
{
    Folder f("strings");
    f.write("m/p.l", stochastic_plant);
    f.write("m/p.v", view);
    f.write("stop1/p.l", stopping_plant(1));
    f.write("stop1/p.v", view);
    f.write("stop2/p.l", stopping_plant(2));
    f.write("stop2/p.v", view);
    // in any order, with the derivation length (9) among them; seeded or not
    const std::vector<std::optional<int>> steps{7, 2, std::nullopt, 0, 5, 12};
    expect_each_variant_as_derived_alone(f.dir() / "m", steps, std::nullopt, 12);
    expect_each_variant_as_derived_alone(f.dir() / "m", steps, 77, 12);
    // stop(1) after step 4 ends the derivation there without the End block (but with it
    // for the variant of 4 steps); stop(2) with it: the run stops after 4 steps
    expect_each_variant_as_derived_alone(f.dir() / "stop1", steps, 3, 4);
    expect_each_variant_as_derived_alone(f.dir() / "stop2", steps, std::nullopt, 4);
}

TEST(SceneVariants, AnEndBlockWithFilesDerivesEachStepCountAlone)
{
    Folder f("files");
    std::string text = stochastic_plant;
    text.replace(text.find("End: {"), 6,
                 "End: { f = fopen(\"log.txt\", \"w\"); fprintf(f, \"%d\\n\", n); fclose(f);");
    f.write("m/p.l", text);
    f.write("m/p.v", view);
    app::Model model = app::load_model(model_options(f.dir() / "m", std::nullopt));
    ASSERT_TRUE(model.lsystem.end_block_uses_files());
    app::VariantRuns runs = app::derive_variants(model, {3, 6}, [](std::size_t, const auto&) {});
    EXPECT_EQ(runs.runs, 2u);
    EXPECT_EQ(runs.steps, 9u);
}

namespace {

/// A variant's geometry as placed in the scene: its primitives, exactly.
struct Variant {
    std::vector<geom::Float4> keys, points, spheres;
    std::size_t triangles = 0;
    bool operator==(const Variant&) const = default;
};

std::ostream& operator<<(std::ostream& out, const Variant& v)
{
    return out << v.keys.size() << " line keys, " << v.points.size() << " curve points, "
               << v.spheres.size() << " spheres, " << v.triangles << " triangles";
}

/// A scene of one entry of `model` with `steps` and `count` placements (placement i gets
/// variant i): each variant's geometry, by placement, and the report.
std::vector<Variant> scene_variants(const Folder& f, const std::string& model,
                                    const std::string& steps, std::size_t count,
                                    app::AssemblyReport& report)
{
    std::string placements;
    for (std::size_t i = 0; i < count; ++i)
        placements += (i ? ", " : "") + std::string("{\"translate\": [") +
                      std::to_string(100 * i) + ", 0, 0]}";
    f.write("scene.json", R"({"plants": [{"model": ")" + model +
                              R"(", "command": "cpfg p.l p.v", "seed": 11, )" + steps +
                              R"("placements": [)" + placements + "]}]}");
    app::SceneFile file = app::read_scene_file(f.dir() / "scene.json", app::Options{});
    app::AssemblyOptions flat{app::OrganPlacement::flatten, false};
    geom::Scene scene = app::assemble_scene(file, app::Options{}, flat, &report);
    std::vector<Variant> out(count);
    for (std::size_t i = 0; i < count; ++i) {
        const geom::Instance& inst = scene.instances.at(i);
        const geom::Geometry& g = scene.prototypes.at(inst.prototype).geometry;
        out[i] = {g.lines.keys, g.curves.points, g.spheres.centres, g.mesh.size()};
    }
    return out;
}

}  // namespace

TEST(SceneVariants, OneDerivationGivesTheGeometryOfSeparateOnes)
{
    Folder f("geometry");
    f.write("m/p.l", stochastic_plant);
    f.write("m/p.v", view);
    f.write("stop1/p.l", stopping_plant(1));
    f.write("stop1/p.v", view);
    for (const std::string model : {"m", "stop1"}) {
        const std::vector<int> counts{14, 3, 9, 6};
        app::AssemblyReport together;
        std::vector<Variant> shared =
            scene_variants(f, model, "\"steps\": [14, 3, 9, 6], ", 4, together);
        // one derivation to the largest step count (stop(1) ends it after step 4): the
        // steps derived are not the sum of the step counts
        EXPECT_EQ(together.derivations, 1u);
        EXPECT_EQ(together.variants, 4u);
        EXPECT_EQ(together.derivation_steps, model == "m" ? 14u : 4u);
        std::uint64_t sum = 0;
        for (std::size_t i = 0; i < counts.size(); ++i) {
            const int steps = counts[i];
            app::AssemblyReport alone;
            Variant v = scene_variants(f, model, "\"steps\": " + std::to_string(steps) + ", ", 1,
                                       alone)
                            .front();
            sum += alone.derivation_steps;
            EXPECT_EQ(shared[i], v) << model << ", " << steps << " steps";
        }
        if (model == "m") {
            EXPECT_EQ(sum, 32u);
            EXPECT_NE(shared[0], shared[1]);  // the variants are plants of their own
        }
    }
}
