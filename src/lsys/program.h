// SPDX-License-Identifier: Apache-2.0
// A parsed and compiled L-system file: L-systems, productions, global blocks, arrays.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "lsys/expression.h"
#include "lsys/module_string.h"

namespace cambium::lsys {

/// A module of a predecessor or context: its symbol and the frame slots its formal
/// parameters bind to.
struct FormalModule {
    SymbolId symbol = 0;
    std::vector<int> param_slots;
    FileLoc loc;
};

/// A module of a successor or axiom: its symbol and one compiled expression per parameter.
struct ModuleTemplate {
    SymbolId symbol = 0;
    std::vector<Code> params;
};

/// A successor parameter that is not a constant: where it goes in the successor's
/// parameters and the expression (successor[module].params[param]) that computes it.
struct ComputedParam {
    std::uint32_t index = 0;
    std::uint32_t module = 0;
    std::uint32_t param = 0;
};

/// lc < pred > rc : {pre} condition {post} --> successor : probability
struct Production {
    std::vector<FormalModule> left_context;   ///< in reading order
    std::vector<FormalModule> predecessor;    ///< the strict predecessor
    std::vector<FormalModule> right_context;
    Code pre_block;                           ///< {alpha}
    std::optional<Code> condition;            ///< none: '*' or absent
    Code post_block;                          ///< {beta}
    std::vector<ModuleTemplate> successor;
    /// The successor with its constant parameters filled in (build_successor_prototype):
    /// applying the production copies it and evaluates only `computed_params` into it.
    ModuleString successor_prototype;
    std::vector<ComputedParam> computed_params;  ///< in the successor's order
    std::optional<Code> probability;          ///< stochastic productions only
    bool object_production = false;           ///< '-o>'
    int frame_size = 0;                       ///< formal parameters + local variables
    /// Where this production's variables live between applications (Program::storage_size):
    /// cpfg keeps each production's variables from its previous application.
    std::size_t storage = 0;
    FileLoc loc;
    std::string text;                         ///< its source on one line, for messages
};

/// Builds p.successor_prototype and p.computed_params from p.successor.
void build_successor_prototype(Production& p);

/// An object production geom may instance: -o> with one predecessor module and no
/// context, so the module alone decides its expansion.
inline bool is_instanceable_object(const Production& p)
{
    return p.object_production && p.predecessor.size() == 1 && p.left_context.empty() &&
           p.right_context.empty();
}

/// Productions of one section with their lookup by first predecessor symbol.
struct ProductionSet {
    std::vector<Production> productions;
    std::vector<std::vector<std::uint32_t>> by_symbol;  ///< indexed by SymbolId
    std::optional<Code> max_depth;
    std::optional<Code> seed;
    FileLoc max_depth_loc, seed_loc;  ///< where their expressions start
    bool warnings = false;

    /// Rebuilds by_symbol for `symbol_count` symbols.
    void index(std::size_t symbol_count);
    const std::vector<std::uint32_t>* candidates(SymbolId symbol) const
    {
        return symbol < by_symbol.size() && !by_symbol[symbol].empty() ? &by_symbol[symbol]
                                                                      : nullptr;
    }
};

/// One `lsystem: N ... endlsystem` block.
struct LSystemDefinition {
    int id = 0;
    std::string label;
    FileLoc loc;
    std::optional<Code> seed;
    std::optional<Code> derivation_length;
    FileLoc seed_loc, derivation_length_loc;  ///< where their expressions start
    std::vector<SymbolId> ignore;
    std::vector<SymbolId> consider;
    bool has_consider = false;
    /// `ring lsystem`: contexts wrap around the ends of the string (a closed ring of
    /// cells, as cpfg's Ring example).
    bool ring = false;
    std::vector<ModuleTemplate> axiom;
    ProductionSet productions;
    ProductionSet decomposition;
    ProductionSet homomorphism;
};

/// A declared array and its initial values.
struct ArrayDefinition {
    std::string name;
    ArrayValues initial;
};

/// An @-command ("@o", "@Gs") that cpfg's productions rewrite letter by letter: cpfg
/// stores its string one character per module, so `o(r) --> o(r+1)` rewrites the 'o' of
/// "@o(0.2)". Such commands are derived as '@' plus one module per letter (the
/// parameters on the last) and joined back for interpretation.
struct SplitCommand {
    SymbolId joined = 0;
    std::vector<SymbolId> parts;  ///< '@' first
};

/// The whole compiled file.
struct Program {
    SymbolTable symbols;
    std::vector<LSystemDefinition> lsystems;  ///< the first is the main L-system
    Code start_block, end_block, start_each_block, end_each_block;
    std::vector<std::string> global_names;
    std::vector<ArrayDefinition> arrays;
    std::vector<std::string> strings;
    std::string file_name;
    std::vector<SplitCommand> split_commands;
    /// Source positions of the instructions that can fail at run time (Instr::value)
    std::vector<FileLoc> sites;
    /// Sum of the productions' frame sizes: the persistent variables of all productions
    std::size_t storage_size = 0;
};

}  // namespace cambium::lsys
