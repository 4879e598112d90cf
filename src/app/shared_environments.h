// SPDX-License-Identifier: Apache-2.0
// A scene file's open L-systems (plants whose command has `-e`) in shared environments:
// a field of plants that compete for space or light (docs/environment.md).
#pragma once

#include <optional>
#include <vector>

#include "app/pipeline.h"
#include "app/scene_file.h"

namespace cambium::app {

/// The scene's plants, each open one split into one plant per placement (each placed
/// plant grows as its neighbours let it, so none is an instance of another), with their
/// seats: plants whose `.e` files name the same environment (the same program and
/// arguments, specification files of the same text) share one, seeing every plant's ?E
/// in world coordinates.
struct SeatedPlants {
    std::vector<ScenePlant> plants;
    std::vector<std::optional<EnvironmentSeat>> seats;  ///< per plant; none for closed ones
    bool any = false;                                    ///< some plant is open
};

/// At most this many open plants in one scene: each derives in a thread of its own.
inline constexpr std::size_t max_open_plants = 1000;

/// Seats the open plants of `file`. Throws cambium::Error naming the scene file: a `.e`
/// file that cannot be read or connected, more than max_open_plants open plants.
SeatedPlants seat_open_plants(const SceneFile& file, const Options& options);

}  // namespace cambium::app
