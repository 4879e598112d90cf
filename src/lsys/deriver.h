// SPDX-License-Identifier: Apache-2.0
// Applies productions to a ModuleString step by step, as cpfg's generator does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "lsys/program.h"

namespace cambium::lsys {

struct DeriveLimits {
    std::size_t max_modules = 100'000'000;  ///< string growth limit
    /// func(id, x) of the view file's function set; unset: 0 with one warning
    std::function<double(int, double)> function;
    /// curveX/Y/Z(id, t) ('x' 'y' 'z') and curveGAL(id) ('l') of the view file's curves
    std::function<double(char, int, double)> curve;
    /// false: neither the Start block nor the axiom (a Deriver for interpretation only)
    bool start = true;
};

/// One derivation run: global variables, random generators and the current string.
/// A Deriver is created from a Program, runs the Start block and builds the axiom; each
/// step() rewrites the string once (then decomposes it); finish() runs the End block.
class Deriver {
public:
    Deriver(const Program& program, DeriveLimits limits = {});

    const ModuleString& string() const { return m_string; }
    int steps_done() const { return m_steps; }
    int derivation_length() const { return m_runtime.derivation_length; }
    bool stop_requested() const { return m_runtime.stop_requested; }
    void step();
    void finish();
    /// Moves the current string out (the Deriver is spent afterwards).
    ModuleString take_string();
    /// The current string, for a query pass that fills ?P ?H ?L ?U parameters in place.
    ModuleString& mutable_string() { return m_string; }
    /// Global variables and arrays as the derivation left them.
    const Runtime& runtime() const { return m_runtime; }
    void set_runtime(const Runtime& runtime);

    /// `in` with the homomorphism productions applied (recursively to each set's
    /// maximum depth, with its seed: and warnings), for interpretation. Object
    /// productions (-o>) are expanded like the others.
    void apply_homomorphism(const ModuleString& in, ModuleString& out);

private:
    /// A string with the lookup tables context matching needs.
    struct Indexed {
        const ModuleString* string = nullptr;
        std::vector<std::uint32_t> offsets;   ///< first parameter of each module
        std::vector<std::uint32_t> partner;   ///< matching bracket of each '[' / ']'
    };
    void index(const ModuleString& s, Indexed& out, bool force = false) const;
    std::size_t rewrite(const Indexed& src, ModuleString& dst, bool decomposition);
    bool apply_first_match(const ProductionSet& set, const LSystemDefinition& ls,
                           const Indexed& src, std::size_t i, std::size_t offset,
                           ModuleString& dst, std::size_t& consumed);
    bool is_plain(const ProductionSet& set, int sym, bool decomposition) const;
    const Production* find_homomorphism(const ProductionSet& set, const LSystemDefinition& ls,
                                        const ModuleString& s, std::size_t k,
                                        std::size_t offset, const Indexed& ctx,
                                        std::size_t left, std::size_t right);
    void homomorphism_module(const ProductionSet& set, const LSystemDefinition& ls,
                             const ModuleString& s, std::size_t& k, std::size_t& offset,
                             const Indexed& ctx, std::size_t left, std::size_t right,
                             int depth, int max_depth, ModuleString& out);
    bool match_at(const Production& p, const LSystemDefinition& ls, const ModuleString& s,
                  std::size_t k, std::size_t offset, const Indexed& ctx, std::size_t left,
                  std::size_t right);
    bool apply_stochastic(const ProductionSet& set, const LSystemDefinition& ls,
                          const Indexed& src, std::size_t i, std::size_t offset,
                          ModuleString& dst, std::size_t& consumed);
    void run_post_block(const Production& p);
    std::size_t branch_end(const Indexed& src, std::size_t k) const;
    bool match(const Production& p, const LSystemDefinition& ls, const Indexed& src,
               std::size_t i, std::size_t offset);
    bool match_left(const Production& p, const std::vector<char>& ignored, const Indexed& src,
                    std::size_t i);
    bool match_right(const Production& p, const std::vector<char>& ignored, const Indexed& src,
                     std::size_t i);
    bool bind(const FormalModule& f, const ModuleString& s, std::size_t k, std::size_t offset);
    bool condition_holds(const Production& p);
    void produce(const Production& p, ModuleString& dst);
    void append_evaluated(const ModuleTemplate& m, ModuleString& dst);
    std::size_t cut_end(const ModuleString& s, std::size_t i) const;
    void decompose();
    void check_size(const ModuleString& s) const;
    int lsystem_index(double id) const;

    const Program& m_program;
    DeriveLimits m_limits;
    Runtime m_runtime;
    Rand48 m_stochastic;
    ModuleString m_string, m_next;
    Indexed m_indexed;
    std::vector<double> m_frame;
    std::vector<std::vector<char>> m_ignored;  ///< per L-system, by symbol
    std::vector<int> m_lsystem_stack;
    std::vector<std::uint32_t> m_matches;     ///< stochastic candidates
    std::vector<float> m_match_probs;         ///< their probabilities
    std::vector<double> m_match_frames;       ///< their bound variables, concatenated
    int m_steps = 0;
    bool m_needs_index = false;          ///< some production has a context
    double m_module_growth = 1.0, m_param_growth = 1.0;  ///< last step's, for reserve()
    int m_bracket_open = -1, m_bracket_close = -1, m_cut = -1, m_sub_start = -1, m_sub_end = -1;
    int m_equals = -1;
    std::vector<ModuleString> m_homomorphism_stack;  ///< successor buffers, by depth
    Rand48 m_homomorphism_random;
};

}  // namespace cambium::lsys
