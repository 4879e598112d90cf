// SPDX-License-Identifier: Apache-2.0
// A one-file model written to a temporary folder for the pipeline tests.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "app/command_line.h"

namespace cambium::testing {

/// Writes `lsystem` as plant.l beside a plant.v of cylinders 0.2 wide in the folder
/// cambium_<name> of the temporary directory; the options name both.
inline app::Options write_model(const std::string& name, const std::string& lsystem)
{
    namespace fs = std::filesystem;
    fs::path dir = fs::temp_directory_path() / ("cambium_" + name);
    fs::create_directories(dir);
    std::ofstream(dir / "plant.l") << lsystem;
    std::ofstream(dir / "plant.v") << "line style: cylinder\ninitial line width: 0.2\n";
    app::Options options;
    options.lsystem = dir / "plant.l";
    options.view = dir / "plant.v";
    return options;
}

}  // namespace cambium::testing
