// SPDX-License-Identifier: Apache-2.0
// The public face of src/lsys: load a cpfg .l file, read its axiom, derive strings.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lsys/module_string.h"

namespace cambium::lsys {

struct Program;

struct LoadOptions {
    std::vector<std::string> defines;      ///< extra -D NAME[=VALUE] for the preprocessor
    std::string preprocessor = "cpp";      ///< the system C preprocessor
    std::size_t max_modules = 100'000'000; ///< derivation fails past this string length
};

/// A parsed and compiled .l file.
class LSystem {
public:
    /// Reads, preprocesses (with -I the file's folder) and compiles `file`.
    /// Throws cambium::Error naming file:line:col on any problem.
    static LSystem load(const std::filesystem::path& file, const LoadOptions& = {});
    /// Compiles source text (still preprocessed); for tests.
    static LSystem from_source(std::string_view source, std::string_view file_name = "<string>",
                               const LoadOptions& = {});

    LSystem(LSystem&&) noexcept;
    LSystem& operator=(LSystem&&) noexcept;
    ~LSystem();

    /// Every module name in the program is interned here.
    const SymbolTable& symbols() const;
    /// Geom interns the turtle symbols it needs here (lookups by name).
    SymbolTable& symbols();
    /// The main L-system's derivation length (0 when not given).
    int derivation_length() const;
    /// The main L-system's axiom, its parameters evaluated after the Start block.
    ModuleString axiom() const;
    /// Derives `steps` steps from the axiom (default: derivation_length()).
    ModuleString derive(std::optional<int> steps = std::nullopt) const;
    /// The compiled program (productions, decomposition, homomorphism, globals).
    const Program& program() const;

private:
    explicit LSystem(std::unique_ptr<Program> program, LoadOptions options);
    std::unique_ptr<Program> m_program;
    LoadOptions m_options;
};

}  // namespace cambium::lsys
