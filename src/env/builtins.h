// SPDX-License-Identifier: Apache-2.0
// Cambium's own versions of vlab's environmental programs (docs/environment.md): they
// compute what the programs compute, from the same quantised messages, without a process.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "env/environment.h"

namespace cambium::env {

/// vlab's honda81: collision of points (or spheres) ranked by vigor.
std::unique_ptr<Environment> make_honda81(const std::vector<std::string>& args, const Context& context);
/// vlab's ecosystem: competition of circles (disks) for space.
std::unique_ptr<Environment> make_ecosystem(const std::vector<std::string>& args, const Context& context);
/// vlab's chiba: light reaching leaf balls from sources or the sky.
std::unique_ptr<Environment> make_chiba(const std::vector<std::string>& args, const Context& context);
/// vlab's clover: light from above through leaf disks, on a grid read from an image.
std::unique_ptr<Environment> make_clover(const std::vector<std::string>& args, const Context& context);

/// The built-in named by an executable's file name ("honda81", "./chiba"), made from the
/// program's arguments (the `-e file` pair already removed); nullptr when there is none.
std::unique_ptr<Environment> make_builtin(const std::string& program,
                                          const std::vector<std::string>& args,
                                          const Context& context);

}  // namespace cambium::env
