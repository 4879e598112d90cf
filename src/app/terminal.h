// SPDX-License-Identifier: Apache-2.0
// The command's terminal: the render's progress line on stderr, and Ctrl-C.
#pragma once

#include <atomic>
#include <string>

#include "render/render.h"

namespace cambium::app {

/// The progress line: "render  42%  elapsed 0:12  remaining 0:17" (hours when needed).
std::string format_progress(double fraction, double elapsed_s);

/// Draws a view's progress (RenderSettings::progress) as one line on stderr, redrawn in
/// place and ended when the view finishes.
void draw_progress_line(const render::RenderProgress& progress);

/// Installs a SIGINT handler that sets the returned flag (pass it as
/// RenderSettings::cancel); a second Ctrl-C kills the process as usual. Idempotent.
const std::atomic<bool>* install_interrupt_handler();

}  // namespace cambium::app
