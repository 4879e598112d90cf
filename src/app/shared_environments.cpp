// SPDX-License-Identifier: Apache-2.0
#include "app/shared_environments.h"

#include <cstdio>
#include <map>
#include <memory>

#include "base/confinement.h"
#include "env/comm_spec.h"
#include "geom/text_input.h"

namespace cambium::app {
namespace {

namespace fs = std::filesystem;

/// The options a plant's environment is connected with: the command line's, the
/// plant's model files.
Options environment_options(const Options& options, const ScenePlant& plant)
{
    Options o = options;
    o.lsystem = plant.model.lsystem;
    o.view = plant.model.view;
    o.environment_file = plant.model.environment_file;
    o.quiet = true;  // the scene says once which environment its plants share
    return o;
}

/// What makes two plants' environments one: the program's name, its arguments, and the
/// text of those that name files in the model's folder (two species with one density.spec).
std::string environment_identity(const env::CommSpec& spec, const fs::path& folder)
{
    std::string id = fs::path(spec.executable.front()).filename().string();
    for (std::size_t k = 1; k < spec.executable.size(); ++k) {
        const fs::path file = folder / spec.executable[k];
        std::error_code ec;
        const bool inside = lies_within(file, folder) && fs::is_regular_file(file, ec);
        id += '\n' + (inside ? geom::read_text_file(file, "specification file") : spec.executable[k]);
    }
    return id;
}

}  // namespace

SeatedPlants seat_open_plants(const SceneFile& file, const Options& options)
{
    SeatedPlants out;
    struct Shared {
        std::vector<std::size_t> plants;  ///< indices into out.plants
        env::Connection connection;
    };
    std::map<std::string, Shared> shared;
    for (const ScenePlant& p : file.plants) {
        if (!p.model.environment_file) {
            out.plants.push_back(p);
            out.seats.emplace_back();
            continue;
        }
        const Options o = environment_options(options, p);
        Shared* seat = nullptr;
        try {
            const env::CommSpec spec = env::read_comm_spec(*p.model.environment_file);
            auto [it, added] = shared.try_emplace(environment_identity(spec, model_folder(o)));
            if (added)
                it->second.connection = model_environment(o, spec);
            seat = &it->second;
        } catch (const Error& e) {
            throw Error(file.file.string() + ": " + p.path + " (" + p.command + "): " + e.what());
        }
        for (std::size_t i = 0; i < p.placements.size(); ++i) {
            ScenePlant one = p;
            one.path = p.path + ".placements[" + std::to_string(i) + "]";
            one.placements = {p.placements[i]};
            one.steps = {p.steps[i % p.steps.size()]};
            seat->plants.push_back(out.plants.size());
            out.plants.push_back(std::move(one));
            out.seats.emplace_back();
        }
        if (out.plants.size() > max_open_plants + file.plants.size())
            throw Error(file.file.string() + ": more than " + std::to_string(max_open_plants) +
                        " placed plants of open L-systems (each derives in a thread of its own)");
    }
    for (auto& [id, s] : shared) {
        if (s.plants.size() > max_open_plants)
            throw Error(file.file.string() + ": more than " + std::to_string(max_open_plants) +
                        " placed plants of open L-systems (each derives in a thread of its own)");
        auto environment = std::make_shared<env::SharedEnvironment>(s.connection.make(), s.plants.size());
        for (std::size_t k = 0; k < s.plants.size(); ++k) {
            const std::size_t plant = s.plants[k];
            out.seats[plant] = EnvironmentSeat{environment, k, out.plants[plant].placements.front()};
        }
        if (!options.quiet)
            std::fprintf(stderr, "environment: %s, shared by %zu placed plants\n",
                         s.connection.description.c_str(), s.plants.size());
        out.any = true;
    }
    return out;
}

}  // namespace cambium::app
