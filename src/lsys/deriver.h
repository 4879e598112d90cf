// SPDX-License-Identifier: Apache-2.0
// Applies productions to a ModuleString step by step, as cpfg's generator does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "base/limits.h"
#include "lsys/inbetween.h"
#include "lsys/program.h"

namespace cambium::lsys {

struct DeriveLimits {
    std::size_t max_modules = 100'000'000;  ///< string growth limit
    /// Parameter values the string may hold: positions in it (the context index, the
    /// query pass's links) are 32-bit, so larger values are lowered to 2^32 - 1
    std::size_t max_params = 0xffffffffu;
    /// What the string being built and the one it is built from may take together
    /// (their modules and parameters, as allocated)
    std::uint64_t max_memory_bytes = default_max_memory_bytes();
    /// fopen may open files outside the model's folder
    bool allow_file_access = false;
    /// func(id, x) of the view file's function set; unset: 0 with one warning
    std::function<double(int, double)> function;
    /// curveX/Y/Z(id, t) ('x' 'y' 'z') and curveGAL(id) ('l') of the view file's curves
    std::function<double(char, int, double)> curve;
    /// false: neither the Start block nor the axiom (a Deriver for interpretation only)
    bool start = true;
    /// A scene's seed override of every random stream (LoadOptions::seed)
    std::optional<long> seed;
    /// Modules the decomposition's passes of one step may go through together: each pass
    /// reads the whole string, so a deep decomposition that keeps growing is quadratic
    /// (`A --> FA` at depth 10^6 is 5·10^11 modules, minutes; 2^32 take a few seconds).
    std::uint64_t max_decomposition_work = std::uint64_t{1} << 32;
};

/// A fragment start that the turtle pass reached before a step (manual 5.1.9 `%(par)`):
/// the one-parameter `%` module's index in the string and the index its turtle was
/// saved under (counted from 0 over the whole derivation run).
struct FragmentStart {
    std::uint32_t module = 0;
    std::uint32_t turtle = 0;
};

/// Where the parameters of one module of a string went in its homomorphism expansion:
/// the query pass answers ?P ?H ?L ?U there and copies the values back.
struct ParamLink {
    std::uint32_t from = 0;   ///< first parameter in the derived string
    std::uint32_t to = 0;     ///< first parameter in the expanded string
    std::uint32_t count = 0;
};

/// One derivation run: global variables, random generators and the current string.
/// A Deriver is created from a Program, runs the Start block and builds the axiom; each
/// step() rewrites the string once (then decomposes it); finish() runs the End block.
/// A failure while evaluating throws cambium::Error naming the file, the position and
/// the production or block that was running.
class Deriver {
public:
    Deriver(const Program& program, DeriveLimits limits = {});
    Deriver(const Deriver&) = delete;
    Deriver& operator=(const Deriver&) = delete;

    const ModuleString& string() const { return m_string; }
    int steps_done() const { return m_steps; }
    int derivation_length() const { return m_runtime.derivation_length; }
    /// stop() was called in a step (a call in the Start block does not count, as in cpfg)
    bool stop_requested() const { return m_runtime.stop_requested; }
    /// ... with an argument other than 1: the End block runs even though the derivation
    /// stopped early
    bool stop_runs_end() const { return m_runtime.stop_runs_end; }
    /// Forgets a stop() so that the next step() goes on (animate mode's stop(1)).
    void clear_stop() { m_runtime.stop_requested = m_runtime.stop_runs_end = false; }
    void step();
    void finish();
    /// Runs the End block on a copy of the globals and the block variables and returns
    /// the globals it leaves; the derivation's own state stays as before (a later step()
    /// goes on as if the End block had not run). Files the End block uses are shared
    /// with the derivation (OpenFiles), so a caller checks that it uses none.
    Runtime finish_on_copy();
    /// Frees the buffers a step reuses (the string the last step was built from, the
    /// context index): the next step() allocates them again.
    void release_buffers();
    /// The fragment starts of the current string, in string order, for the next step()
    /// (manual 5.1.9): that step derives each one's fragment (from after the `%(par)` to
    /// its branch's `]`, the next `%` with parameters or a sub-L-system's `$`) at the end
    /// of the new string behind `%(par, turtle)`, in this order, instead of in place.
    /// A one-parameter `%` not listed here stays in place.
    void mark_fragments(std::vector<FragmentStart> starts) { m_fragment_starts = std::move(starts); }
    /// Whether the `%` symbol exists (only then can a string hold fragment starts).
    bool has_cut_symbol() const { return m_cut >= 0; }
    /// Whether module i of `s` is a fragment start: `%` with exactly one parameter.
    bool is_fragment_start(const ModuleString& s, std::size_t i) const
    {
        return m_cut >= 0 && s.symbol(i) == static_cast<SymbolId>(m_cut) && s.param_count(i) == 1;
    }
    /// Records, from the next step on, which module of the previous string each module
    /// of the new one continues (lineage()). Off by default: it costs 4 bytes a module.
    void track_lineage(bool on) { m_track_lineage = on; }
    /// After a step with tracking on: for each module of string(), the index in the
    /// string before the step of the module it continues, or no_parent. A module
    /// continues another when it is that module copied (no production applied), or the
    /// first module with the predecessor's symbol in the successor of the production
    /// applied to it (F(x) --> F(x+1) G: the F); decomposition passes compose the same way.
    const std::vector<std::uint32_t>& lineage() const { return m_lineage; }
    /// Moves the current string out (the Deriver is spent afterwards).
    ModuleString take_string();
    /// The current string, for a query pass that fills ?P ?H ?L ?U parameters in place.
    ModuleString& mutable_string() { return m_string; }
    /// Global variables and arrays as the derivation left them.
    const Runtime& runtime() const { return m_runtime; }
    void set_runtime(const Runtime& runtime);

    /// `in` with the homomorphism productions applied (recursively to each set's
    /// maximum depth, with its seed: and warnings), for interpretation. With
    /// `keep_objects`, a module that an object production (-o>, one module, no
    /// context) applies to stays as it is, for geom to instance; otherwise objects are
    /// expanded like the others. With `query_links`, says where each ?P ?H ?L ?U module
    /// of `in` that the homomorphism leaves as it is went. With `origins`, origins[k] is
    /// the module of `in` whose successor module k of `out` is part of.
    void apply_homomorphism(const ModuleString& in, ModuleString& out,
                            std::vector<ParamLink>* query_links = nullptr,
                            bool keep_objects = false,
                            std::vector<std::uint32_t>* origins = nullptr);

private:
    void start();
    void step_located();
    void homomorphism_located(const ModuleString& in, ModuleString& out,
                              std::vector<ParamLink>* query_links,
                              std::vector<std::uint32_t>* origins);
    /// What is being evaluated, for messages: a production, else a block
    void in_block(const char* block)
    {
        m_production = nullptr;
        m_block = block;
    }
    void in_production(const Production& p) { m_production = &p; }
    FileLoc location(int site) const;
    std::string context() const;
    [[noreturn]] void fail(const EvaluationError& e) const;
    bool is_query(int symbol) const;

    /// A string with the lookup tables context matching needs.
    struct Indexed {
        const ModuleString* string = nullptr;
        std::vector<std::uint32_t> offsets;   ///< first parameter of each module
        std::vector<std::uint32_t> partner;   ///< matching bracket of each '[' / ']'
    };
    void index(const ModuleString& s, Indexed& out, bool force = false) const;
    std::size_t rewrite(const Indexed& src, ModuleString& dst, bool decomposition);
    /// Rewrites modules [begin, end) of src (parameters from `offset`) onto dst; with
    /// `fragments`, the marked fragment starts met are skipped with their fragment and
    /// recorded there. Returns the productions applied.
    struct Fragment {
        std::size_t begin, end, offset;  ///< its modules (after the `%`) and first parameter
        float parameter;
        std::uint32_t turtle;
    };
    std::size_t rewrite_range(const Indexed& src, ModuleString& dst, bool decomposition,
                              std::size_t begin, std::size_t end, std::size_t offset,
                              std::vector<Fragment>* fragments);
    void record_lineage(const ModuleString& s, const ModuleString& dst, std::size_t i,
                        std::size_t first_new, bool copied);
    /// Where a cut or a fragment that starts at module i ends (cpfg's SkipCutPart): the
    /// ']' that closes its branch, the '$' that closes its sub-L-system, the next '%' with
    /// parameters, or `end`.
    std::size_t fragment_end(const ModuleString& s, std::size_t i, std::size_t end) const;
    /// A context search may not step onto a `%` with parameters (manual 5.1.9) unless the
    /// context names `%` itself.
    /// (even when `%` is ignored).
    bool context_barrier(const ModuleString& s, std::size_t k, const FormalModule& f) const
    {
        return fragment_mark(s, k) && f.symbol != static_cast<SymbolId>(m_cut);
    }
    bool fragment_mark(const ModuleString& s, std::size_t k) const
    {
        return m_cut >= 0 && s.symbol(k) == static_cast<SymbolId>(m_cut) && s.param_count(k) > 0;
    }
    std::vector<FragmentStart> m_fragment_starts;  ///< for the next step (mark_fragments)
    std::size_t m_next_mark = 0;                   ///< the next one rewrite_range may meet
    bool apply_first_match(const ProductionSet& set, const LSystemDefinition& ls,
                           const Indexed& src, std::size_t i, std::size_t offset,
                           ModuleString& dst, std::size_t& consumed);
    /// Whether no production of `set` can rewrite `sym` (runs of such modules are copied
    /// in bulk).
    bool never_rewritten(const ProductionSet& set, int sym, bool decomposition) const;
    /// never_rewritten for each symbol: by L-system, then productions (0) or
    /// decomposition (1)
    std::vector<std::vector<char>> m_copied;
    /// The end of the run of modules from `i` on that `copied` says are copied as they are.
    static std::size_t run_end(const ModuleString& s, std::size_t i,
                               const std::vector<char>& copied);
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
    void decompose();
    /// the decomposition's `maximum depth:` (1 without one), range-checked
    int decomposition_depth();
    void check_size(const ModuleString& s) const;
    [[noreturn]] void out_of_memory(std::size_t bytes, const ModuleString& building) const;
    /// std::bad_alloc within the budget: the system refused the memory
    [[noreturn]] void system_out_of_memory(std::size_t bytes, const ModuleString& building) const;
    std::string phase() const;
    long long setting(const Code& code, const FileLoc& loc, const std::string& what,
                      long long lo, long long hi);
    int lsystem_index(double id) const;

    const Program& m_program;
    DeriveLimits m_limits;
    Runtime m_runtime;
    Rand48 m_stochastic;
    ModuleString m_string, m_next;
    Indexed m_indexed;
    const ModuleString* m_source = nullptr;  ///< the string being rewritten, for check_size
    std::vector<double> m_frame;
    /// Every production's variables between applications (Production::storage); the
    /// frame holds those of m_frame_owner and goes back there when another takes it.
    std::vector<double> m_storage;
    const Production* m_frame_owner = nullptr;
    void use_frame_of(const Production& p);
    std::vector<std::vector<char>> m_ignored;  ///< per L-system, by symbol
    std::vector<int> m_lsystem_stack;
    std::vector<std::uint32_t> m_matches;     ///< stochastic candidates
    std::vector<float> m_match_probs;         ///< their probabilities
    int m_steps = 0;
    bool m_track_lineage = false;
    std::vector<std::uint32_t> m_lineage;       ///< of the last step (track_lineage)
    std::vector<std::uint32_t> m_pass_lineage;  ///< of the last rewrite() pass
    /// Composes the last rewrite() pass onto m_lineage (or starts it with `first`).
    void compose_lineage(bool first);
    bool m_needs_index = false;          ///< some production has a context
    bool m_keep_objects = false;         ///< apply_homomorphism leaves objects as they are
    bool m_in_homomorphism = false;      ///< apply_homomorphism is running (for messages)
    double m_module_growth = 1.0, m_param_growth = 1.0;  ///< last step's, for reserve()
    int m_bracket_open = -1, m_bracket_close = -1, m_cut = -1, m_sub_start = -1, m_sub_end = -1;
    int m_equals = -1;
    int m_conditional_cut = -1;  ///< @mc
    /// Whether module i (parameters from offset) cuts its branch while rewriting: a `%`
    /// without parameters, or `@mc(1)` (manual 5.1.9).
    bool cuts(const ModuleString& s, std::size_t i, std::size_t offset) const;
    /// The L-system being matched is a `ring lsystem`: contexts wrap around once.
    bool m_ring = false;
    std::vector<ModuleString> m_homomorphism_stack;  ///< successor buffers, by depth
    Rand48 m_homomorphism_random;
    std::vector<char> m_query_symbol;                ///< by symbol: ?P ?H ?L ?U
    const Production* m_production = nullptr;        ///< being evaluated, if any
    const char* m_block = nullptr;                   ///< else the block being run
    std::function<void(const std::string&, int)> m_warning;  ///< Runtime::warning
};

}  // namespace cambium::lsys
