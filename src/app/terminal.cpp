// SPDX-License-Identifier: Apache-2.0
#include "app/terminal.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <mutex>

namespace cambium::app {

namespace {

std::atomic<bool> interrupted{false};

extern "C" void on_interrupt(int) { interrupted.store(true); }

/// "m:ss", or "h:mm:ss" from an hour on.
std::string clock_time(double seconds)
{
    long s = std::lround(std::max(0.0, seconds));
    char buffer[32];
    if (s >= 3600)
        std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else
        std::snprintf(buffer, sizeof buffer, "%ld:%02ld", s / 60, s % 60);
    return buffer;
}

}  // namespace

std::string format_progress(double fraction, double elapsed_s)
{
    fraction = std::clamp(fraction, 0.0, 1.0);
    std::string line = "render " + std::to_string(int(std::floor(fraction * 100))) + "%  elapsed " +
                       clock_time(elapsed_s) + "  remaining ";
    if (fraction <= 0)
        return line + "?";
    return line + clock_time(elapsed_s * (1 - fraction) / fraction);
}

void draw_progress_line(const render::RenderProgress& progress)
{
    std::fprintf(stderr, "\r%s   ", format_progress(progress.fraction, progress.elapsed_s).c_str());
    std::fflush(stderr);
    if (progress.finished)
        std::fputc('\n', stderr);
}

const std::atomic<bool>* install_interrupt_handler()
{
    static std::once_flag once;
    std::call_once(once, [] {
        struct sigaction action {};
        action.sa_handler = &on_interrupt;
        sigemptyset(&action.sa_mask);
        // The second Ctrl-C finds the default action again and ends the process.
        action.sa_flags = SA_RESETHAND;
        sigaction(SIGINT, &action, nullptr);
    });
    return &interrupted;
}

}  // namespace cambium::app
