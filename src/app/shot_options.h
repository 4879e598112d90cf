// SPDX-License-Identifier: Apache-2.0
// The command-line options of sequences and of the camera (ShotOptions).
#pragma once

#include <CLI/CLI.hpp>

#include <array>
#include <string>
#include <vector>

#include "app/command_line.h"

namespace cambium::app {

/// Declares --turntable, --turntable-elevation, --orbit, --zoom, --fit, --fov,
/// --perspective, --parallel, --frames and --resume on `cli`.
void add_shot_options(CLI::App& cli, ShotOptions& shot);

/// Takes `--ground`, `--ground=VALUE` and `--ground VALUE` out of `args` (CLI11 cannot
/// tell an optional value from the L-system file): the next word is its value only if
/// it is a colour (#rrggbb, R,G,B) or an image file name (.png .jpg .exr ...).
std::vector<std::string> take_ground_option(const std::vector<std::string>& args,
                                            ShotOptions& shot);

/// Whether --ground's value names a texture rather than a colour.
bool is_ground_texture(const std::string& value);

/// Checks their combinations after parsing; throws cambium::Error.
void check_shot_options(const Options& options);

/// The colour of --background (or `option`) #rrggbb or R,G,B (display values in 0..1).
std::array<float, 3> background_colour(const std::string& text,
                                       const char* option = "--background");

/// The first and last frame number of --frames A-B (A alone: that frame only).
std::pair<int, int> frame_range(const std::string& text);

}  // namespace cambium::app
