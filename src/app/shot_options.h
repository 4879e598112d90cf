// SPDX-License-Identifier: Apache-2.0
// The command-line options of sequences and of the camera (ShotOptions).
#pragma once

#include <CLI/CLI.hpp>

#include <array>

#include "app/command_line.h"

namespace cambium::app {

/// Declares --turntable, --turntable-elevation, --orbit, --zoom, --fit, --fov,
/// --perspective, --parallel, --frames and --resume on `cli`.
void add_shot_options(CLI::App& cli, ShotOptions& shot);

/// Checks their combinations after parsing; throws cambium::Error.
void check_shot_options(const Options& options);

/// The colour of --background #rrggbb or R,G,B (display values in 0..1).
std::array<float, 3> background_colour(const std::string& text);

/// The first and last frame number of --frames A-B (A alone: that frame only).
std::pair<int, int> frame_range(const std::string& text);

}  // namespace cambium::app
