// SPDX-License-Identifier: Apache-2.0
// An empty scratch folder per test, under the system's temporary directory.
#pragma once

#include <filesystem>
#include <string>

namespace cambium::testing {

inline std::filesystem::path scratch(const std::string& name)
{
    std::filesystem::path dir = std::filesystem::temp_directory_path() / ("cambium_base_" + name);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace cambium::testing
