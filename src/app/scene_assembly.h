// SPDX-License-Identifier: Apache-2.0
// From a scene file to one geom::Scene: each distinct plant variant loaded, derived and
// interpreted once (in parallel), then placed by instances (docs/scenes.md,
// docs/architecture.md "Scenes of many plants").
#pragma once

#include <cstddef>

#include "app/command_line.h"
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
    std::size_t derivations = 0;     ///< distinct (model, command, seed, steps)
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

/// Applies the scene file's camera size, render settings, sky and environment to
/// `options`, except where the command line gave them (Options::given).
void apply_scene_settings(const SceneFile& file, Options& options);

}  // namespace cambium::app
