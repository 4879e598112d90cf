// SPDX-License-Identifier: Apache-2.0
// From a scene file to one geom::Scene: each distinct plant variant loaded, derived and
// interpreted once (in parallel), then placed by instances (docs/scenes.md,
// docs/architecture.md "Scenes of many plants").
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "app/command_line.h"
#include "app/pipeline.h"
#include "app/scene_file.h"
#include "geom/scene.h"

namespace cambium::app {

/// How a plant's own instances (`-o>` objects, predefined surfaces) reach Embree's one
/// instance level when the plant itself is instanced.
enum class OrganPlacement {
    /// Per plant variant, whichever of the two takes less memory (the default; the
    /// measurements are in docs/architecture.md): flatten once a variant is placed
    /// about as many times as its organs have primitives each.
    automatic,
    /// Each organ instance becomes a top-level instance, its transform composed with
    /// each placement of the plant.
    compose,
    /// The organs are drawn into the plant's prototype, which is then instanced.
    flatten,
};

struct AssemblyOptions {
    OrganPlacement organs = OrganPlacement::automatic;
    /// Draw every placed plant into the scene's own geometry, no instances at all
    /// (tests compare it with the instanced scene; it costs memory per copy).
    bool inline_plants = false;
};

/// What assembling took (for --stats and the tests).
struct AssemblyReport {
    std::size_t models_loaded = 0;   ///< distinct (model, command, seed)
    /// Derivation runs from the axiom: one per model loaded, each handing out the
    /// strings of the model's step counts on the way to the largest
    std::size_t derivations = 0;
    std::size_t variants = 0;        ///< distinct (model, command, seed, steps)
    std::uint64_t derivation_steps = 0;  ///< steps derived, all runs together
    std::size_t plant_instances = 0; ///< placements of plants
    std::size_t organ_instances = 0; ///< top-level instances of organs (compose)
    double load_s = 0, derive_s = 0, interpret_s = 0;  ///< summed over threads
    double wall_s = 0;
};

/// The scene of `file`: its plants placed on its ground, seen by its camera, lit by its
/// lights. `options` are the command line's with the scene's settings applied
/// (apply_scene_settings): they give the plants' limits (--max-memory, --max-modules,
/// --allow-system-calls ...). Errors name the scene file and the plant's JSON path.
geom::Scene assemble_scene(const SceneFile& file, const Options& options,
                           const AssemblyOptions& how = {}, AssemblyReport* report = nullptr);

/// What derive_variants did.
struct VariantRuns {
    std::size_t runs = 0;      ///< derivation runs from the axiom
    std::uint64_t steps = 0;   ///< steps derived, all runs together
};

/// The derived strings of `model` after each of `steps` (nullopt: the derivation length
/// the Start block leaves), each what derive() gives for it, from one derivation run to
/// the largest: `each(k, string)` gets the string of steps[k] as the run reaches it (the
/// fewest steps first), while the model's globals are those that derivation would leave,
/// for interpret(); the string is the run's own, gone once `each` returns. Derived from
/// the axiom for each step count instead when the End block uses files
/// (lsys::LSystem::end_block_uses_files()). Throws what derive() throws.
VariantRuns derive_variants(const Model& model, const std::vector<std::optional<int>>& steps,
                            const std::function<void(std::size_t, const lsys::ModuleString&)>& each);

/// Applies the scene file's camera size, render settings, sky and environment to
/// `options`, except where the command line gave them (Options::given).
void apply_scene_settings(const SceneFile& file, Options& options);

}  // namespace cambium::app
