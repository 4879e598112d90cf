// SPDX-License-Identifier: Apache-2.0
// The communication specification file (`.e`, manual 7.4.1): which program answers the
// ?E modules and what the plant sends it.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"

namespace cambium::env {

/// A printf format for one turtle field (`turtle position:P:%.4f %.4f %.0f`): literal
/// text and at most `most` floating-point conversions (checked when read).
struct TurtleFormat {
    std::string format;
    int conversions = 0;
};

/// One entry of `interpreted modules:`: a module name, with or without a parameter count.
struct InterpretedModule {
    std::string name;                 ///< as Cambium spells modules ("F", "@O", "~l")
    std::optional<int> params;        ///< M(n): only with n parameters (0..6)

    bool operator==(const InterpretedModule&) const = default;
};

/// The modules whose interpretation is sent (as GLS polygons) after the ?E they follow.
struct InterpretedModules {
    bool all = false;                        ///< `all`
    std::vector<InterpretedModule> modules;  ///< otherwise these

    bool any() const { return all || !modules.empty(); }
    /// Whether a module of this name and parameter count is sent with its polygons.
    bool matches(std::string_view name, std::size_t params) const;
};

struct CommSpec {
    std::filesystem::path file;            ///< the .e file, for messages
    std::vector<std::string> executable;   ///< program and its arguments, `-e file` removed
    FileLoc executable_loc;
    std::string communication_type = "pipes";  ///< pipes, sockets, memory or files
    /// The number after the type (`pipes 500`): ?E modules per chunk of a pass; 0 when
    /// absent or not positive (cpfg then sends 100 per chunk through pipes).
    int queries_per_chunk = 0;
    bool following_module = true;          ///< cpfg's default, whatever the manual says
    std::optional<TurtleFormat> position, heading, left, up, line_width, scale_factor;
    /// `interpreted modules:` (manual 7.4.1): whose polygons go with the ?E they follow.
    InterpretedModules interpreted;
    FileLoc interpreted_loc;               ///< its line, for messages
    bool verbose = false;
};

/// Reads a `.e` file. Errors name the file, line and column: unknown commands, a format
/// with a conversion other than %f %e %g %a (or more of them than the field has values),
/// a missing `executable:`.
CommSpec read_comm_spec(const std::filesystem::path& file);

/// `format` applied to the field's values as cpfg prints it, then read back as an
/// environmental program reads it: the format's literal prefix skipped, then
/// sscanf("%f %f %f"). Returns the values read and their count.
int send_through_format(const TurtleFormat& format, const double* values, int count, float* out);

/// A number as the protocol carries parameters: printed with "%g", read back with atof.
float through_g(float value);

}  // namespace cambium::env
