// SPDX-License-Identifier: Apache-2.0
// The environmental step (manual 7.1): a turtle pass over the string that sends every
// ?E module to the environment and writes the answers back into their parameters.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <memory>
#include <string>

#include "env/comm_spec.h"
#include "env/environment.h"
#include "env/external_program.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"
#include "lsys/module_string.h"

namespace cambium::env {

/// The environment a `.e` file names, made anew for each derivation run.
struct Connection {
    std::function<std::unique_ptr<Environment>()> make;
    std::string description;  ///< "honda81 (built in)": for the line that says which
    /// Where the plant stands (a 3x4 column-major transform, as a scene's placements):
    /// the turtle's position and frame are sent in those world coordinates.
    std::optional<std::array<float, 12>> placement;
};

/// Whether, and how, a `.e` file may start a program of its own.
struct ProgramPermission {
    bool allowed = false;  ///< --allow-environment-program
    ExternalLimits limits;
};

/// Connects a `.e` file: Cambium's built-in of the executable's name (honda81,
/// ecosystem, chiba, clover), made once here so that its specification file's errors
/// come before any work; any other program runs as an external program when the
/// permission allows it (each derivation run starts its own), else it is an Error
/// naming the program, the `.e` line and the option.
Connection connect(const CommSpec& spec, const Context& context,
                   const ProgramPermission& programs = {});

/// One derivation run's environmental steps, with the run's own environment.
class EnvironmentalStep {
public:
    EnvironmentalStep(CommSpec spec, Connection connection);

    /// One pass over `string` (as the turtle reads it, with the derived string it came
    /// from) at cpfg's step counter `step`. A string without ?E sends nothing.
    void run(const lsys::TurtleString& string, const lsys::SymbolTable& symbols,
             const geom::ViewFile& view, int step);
    /// The same for a string without a homomorphism: the turtle reads it as derived.
    void run(lsys::ModuleString& string, const lsys::SymbolTable& symbols,
             const geom::ViewFile& view, int step)
    {
        run(lsys::TurtleString{string, string, {}}, symbols, view, step);
    }

    /// Passes that sent something, and the ?E modules sent, since construction.
    std::size_t passes() const { return m_passes; }
    std::size_t queries() const { return m_queries; }

private:
    std::vector<Query> queries_of(const lsys::TurtleString& string, const lsys::SymbolTable& symbols,
                                  const geom::ViewFile& view, int communication,
                                  std::vector<std::size_t>& modules) const;

    CommSpec m_spec;
    Connection m_connection;
    std::unique_ptr<Environment> m_environment;
    std::size_t m_passes = 0, m_queries = 0;
};

}  // namespace cambium::env
