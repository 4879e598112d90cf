// SPDX-License-Identifier: Apache-2.0
// The `cambium` command line: cpfg's options that make sense offline, plus modern ones.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace cambium::app {

/// A colormap (-m[n]) or material file (-M[n]) for colour-table block n.
struct ColourFile {
    int block = 1;
    bool materials = false;
    std::filesystem::path file;
};

struct Options {
    std::filesystem::path lsystem, view;
    std::optional<std::filesystem::path> animation;
    std::vector<ColourFile> colour_files;
    int colour_block = 1;  ///< -c n
    int width = 640, height = 480;
    std::vector<std::filesystem::path> outputs;
    int samples_per_pixel = 64;
    int max_depth = 6;
    int threads = 0;
    std::uint64_t seed = 0;
    bool quiet = false;
};

/// Parses argv. Returns nullopt after printing help (exit 0); throws cambium::Error
/// on a malformed command line.
std::optional<Options> parse_command_line(int argc, char** argv);

}  // namespace cambium::app
