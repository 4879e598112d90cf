// SPDX-License-Identifier: Apache-2.0
// The public face of src/lsys: load a cpfg .l file, read its axiom, derive strings.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/limits.h"
#include "lsys/inbetween.h"
#include "lsys/module_string.h"

namespace cambium::lsys {

struct Program;
struct Runtime;
class Deriver;

/// The string a turtle pass reads (the homomorphism applied, split @-commands joined) and
/// the derived string it was made from: module i of `modules` came from module
/// origins[i] of `derived` (one derived module may give many, or none). `origins` is
/// empty when the two strings are alike module for module.
struct TurtleString {
    ModuleString& modules;
    const ModuleString& derived;
    std::span<const std::uint32_t> origins;

    /// The derived module that module i came from.
    std::size_t origin(std::size_t i) const { return origins.empty() ? i : origins[i]; }
};

struct LoadOptions {
    std::vector<std::string> defines;      ///< extra -D NAME[=VALUE] for the preprocessor
    std::string preprocessor = "cpp";      ///< the system C preprocessor
    std::size_t max_modules = 100'000'000; ///< derivation fails past this string length
    /// derivation fails when its strings take more (--max-memory; base/limits.h)
    std::uint64_t max_memory_bytes = default_max_memory_bytes();
    /// fopen may open, and #include may read, files outside the model's folder (--allow-file-access)
    bool allow_file_access = false;
    /// func(id, x): the view file's function set (geom's FunctionSet::evaluate, which
    /// owns the clamping). Unset: func() evaluates to 0 with one warning.
    std::function<double(int id, double x)> function;
    /// curveX(id, t), curveY, curveZ and curveGAL(id) on the view file's curves (geom):
    /// `which` is 'x', 'y', 'z', or 'l' for the curve's length (t is then 0).
    /// Unset: they evaluate to 0 with one warning.
    std::function<double(char which, int id, double t)> curve;
    /// The interpretation pass that fills the parameters of ?P ?H ?L ?U from the turtle
    /// (geom). Called, when the program has query modules, before every derivation step
    /// (on the axiom, ..., on the string of step n-1; not after the last step), as cpfg
    /// does with its default "environment display" off. It gets the string with the homomorphism
    /// applied (as cpfg interprets it; the answers of query modules the homomorphism
    /// leaves as they are go back into the derived string) and @-commands joined (as
    /// interpretation_string() would join them), and may change parameter values only,
    /// not modules or parameter counts.
    std::function<void(ModuleString&)> query;
    /// The environmental step of an open L-system (manual 7, from the app's environment).
    /// Each derivation run calls `environment()` once, when it starts, for a pass of its
    /// own (an environment keeps state from pass to pass, as cpfg's program does, and two
    /// runs must not share it). The run calls that pass, when the program has
    /// communication modules ?E, before every derivation step (after `query`, at the same
    /// points), with the string as the turtle reads it (as `query` gets it) and cpfg's
    /// step counter (0 for the axiom's pass), and the derived string with each module's
    /// origin in it. It may change parameter values only; those of the ?E modules the
    /// homomorphism leaves in place go back into the derived string, the others (made by
    /// the homomorphism) are dropped.
    std::function<std::function<void(const TurtleString&, int step)>()> environment;
    /// Fragmentation's turtle pass (manual 5.1.9 `%(par)`), from geom. Called before every
    /// step whose string holds a one-parameter `%` (after `query`), with the string as the
    /// turtle reads it (as `query` gets it) and the index of the first turtle this pass
    /// saves (0 at the start of each derivation run, so a new run starts afresh). It
    /// interprets the string, restoring the saved turtle at each `%(par, index)`; at each
    /// one-parameter `%` it reaches it saves the turtle under the next index and returns
    /// those modules' indices in the string it got, in the order reached. It must not
    /// save more than `max_saved_turtles` in a run (a cambium::Error). Unset: every
    /// one-parameter `%` starts a fragment, numbered in string order.
    std::function<std::vector<std::uint32_t>(const ModuleString&, std::uint32_t first_turtle)>
        fragment_pass;
    /// The most turtles fragment starts may save in one derivation run (each is drawn
    /// with one; geom's turtle takes 824 bytes, so 82 MB at most): past it, derivation
    /// fails naming the .l file.
    std::uint32_t max_saved_turtles = 100'000;
    /// A scene's seed override (docs/scenes.md): every random stream of the derivation
    /// (stochastic productions, ran() and its kin, the homomorphism's) starts from it,
    /// and srand(x) seeds with x mixed with it.
    std::optional<long> seed;
    /// Called with the axiom (step 0) and after every step (cpfg's -V output).
    std::function<void(int step, const ModuleString&)> on_step;
};

/// What interpretation_string does with object productions (-o>).
enum class ObjectHandling { expand, keep };

class LSystem;

/// A derivation that advances step by step, as cpfg's animation mode derives: each
/// frame continues from the previous one's string (never re-derived from the axiom).
/// Made by LSystem::start(); it refers to its LSystem, which must outlive it. Every
/// advance() leaves its globals where LSystem::interpretation_string() reads them.
class Derivation {
public:
    Derivation(Derivation&&) noexcept;
    Derivation& operator=(Derivation&&) noexcept;
    ~Derivation();

    /// Derives up to `steps` more steps (the query pass before each, as derive() does),
    /// past the derivation length if asked. stop() called in a step ends the advance
    /// after that step; stopped() then stays true.
    void advance(int steps);
    /// Runs the End block once (later calls do nothing).
    void finish();
    /// For a string handed out on the way to a later step (a scene's plant variants of
    /// one model share one derivation run, docs/scenes.md): runs the End block on a copy
    /// of the globals, which LSystem::interpretation_string() then reads, while the
    /// derivation goes on from its state before the block, as if it had not run. Only
    /// for programs whose End block uses no file (LSystem::end_block_uses_files()).
    void finish_on_copy();
    /// Frees the buffers only the next advance() needs (the string the last step was
    /// built from, the context index), so that the string alone is held while it is
    /// interpreted; the next step allocates them again.
    void release_buffers();
    const ModuleString& string() const;
    /// Steps derived since the axiom.
    int steps_done() const;
    /// The derivation length the Start block left (the file's, unless it sets one).
    int derivation_length() const;
    /// stop() was called in a step.
    bool stopped() const;
    /// ... with an argument other than 1: the End block runs anyway (cpfg).
    bool stop_runs_end() const;
    /// Animate mode: from now on stop(1) does not end an advance(), as in cpfg's animate
    /// mode, where it only draws the string and the simulation goes on (manual 5.1);
    /// stop(n) with n other than 1 still ends it.
    void go_on_after_stop_one();
    /// Moves the string out; the Derivation is spent afterwards.
    ModuleString take_string();
    /// Records lineage from the next advance() on (Deriver::track_lineage).
    void track_lineage();
    /// After advance() with lineage tracked: for each module of string(), the index of
    /// the module it continues in the string before that advance() (through every step
    /// it made), or no_parent for a module that appeared (Deriver::lineage()).
    const std::vector<std::uint32_t>& lineage() const { return m_lineage; }

private:
    friend class LSystem;
    Derivation(const LSystem& lsystem, std::unique_ptr<Deriver> deriver);
    const LSystem* m_lsystem;
    std::unique_ptr<Deriver> m_deriver;
    bool m_finished = false;
    bool m_track_lineage = false;
    bool m_go_on_after_stop_one = false;
    std::uint32_t m_saved_turtles = 0;  ///< by fragment starts in this run (manual 5.1.9)
    std::function<void(const TurtleString&, int step)> m_environment;  ///< this run's (manual 7)
    std::vector<std::uint32_t> m_lineage;
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
    /// Compiles text that is already preprocessed (cpp's output, line markers allowed):
    /// no preprocessor runs. For the fuzz targets and tools that preprocess themselves.
    static LSystem from_preprocessed(std::string_view text, std::string_view file_name,
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
    /// Derives `steps` steps from the axiom (default: derivation_length()). stop()
    /// called in a step ends the derivation after that step (its EndEach block
    /// included), as cpfg's batch derivation does; the End block then runs for stop(n)
    /// with n != 1 and not for stop(1). stop() in the Start block is ignored. Failures
    /// (array subscript out of range, '%' by 0, file functions) throw cambium::Error
    /// naming file:line:col and the production or block.
    ModuleString derive(std::optional<int> steps = std::nullopt) const;
    /// derive(), and for each module of its string the step at which the module appeared
    /// (0: the axiom's; a module continues its parent as Derivation::lineage() says),
    /// at most 0xfffe: the ages provenance reports (docs/architecture.md). The lineage
    /// costs 4 bytes a module more while deriving.
    ModuleString derive_with_ages(std::optional<int> steps, std::vector<std::uint16_t>& ages) const;
    /// A derivation at the axiom (Start block run), to advance step by step.
    Derivation start() const;
    /// The compiled program (productions, decomposition, homomorphism, globals).
    const Program& program() const;

    /// Whether an axiom or successor holds ?P ?H ?L or ?U (then LoadOptions::query runs).
    bool has_queries() const;
    /// Whether the End block calls fopen, fclose, fflush, fprintf or fscanf (its files
    /// are the derivation's own: it cannot run on a copy, Derivation::finish_on_copy()).
    bool end_block_uses_files() const;
    /// The string the turtle interprets: `derived` with the homomorphism applied
    /// (recursively to each set's `maximum depth:`, default 1; its `seed:` makes it
    /// stochastic; `warnings` reports reaching the depth), object productions (-o>)
    /// expanded inline, and @-commands that derivation kept as one-character modules
    /// (see docs: cpfg's one-character string) joined back into their turtle names.
    /// Global variables are those the last derive() left (else after the Start block).
    /// Not thread-safe with derive() on the same LSystem.
    /// With ObjectHandling::keep, modules an instanceable object production applies to
    /// stay unexpanded: geom instances them through is_object_symbol/expand_object.
    ModuleString interpretation_string(const ModuleString& derived,
                                       ObjectHandling objects = ObjectHandling::expand) const;
    /// The same, and in `origins` for each of its modules the index in `derived` of the
    /// module whose successor it is (as TurtleString::origins).
    ModuleString interpretation_string(const ModuleString& derived, ObjectHandling objects,
                                       std::vector<std::uint32_t>& origins) const;
    /// Whether `symbol` is the predecessor of an object production (-o>, one module, no
    /// context) in a homomorphism: geom may instance its expansion instead of repeating it.
    bool is_object_symbol(int symbol) const;
    /// The homomorphism successor of one module (context-free, recursively to the
    /// maximum depth), @-commands joined: the geometry of one instance of an object.
    ModuleString expand_object(ModuleRef module) const;

private:
    friend class Derivation;
    explicit LSystem(std::unique_ptr<Program> program, LoadOptions options);
    void run_query(Deriver& deriver) const;
    void run_environment(Deriver& deriver,
                         const std::function<void(const TurtleString&, int)>& pass) const;
    /// Calls `pass` on the string as the turtle reads it (homomorphism applied,
    /// @-commands joined), then copies the parameters of the query and communication
    /// modules that string keeps in place back into the derived string.
    void turtle_pass(Deriver& deriver, const std::function<void(const TurtleString&)>& pass) const;
    /// Marks the fragment starts of the deriver's string for its next step; returns the
    /// turtles saved (numbered from `first_turtle`).
    std::uint32_t run_fragment_pass(Deriver& deriver, std::uint32_t first_turtle) const;
    /// The string with split @-commands joined. With `origins` (each module's origin, or
    /// empty for the identity), they are carried to the joined string's modules.
    ModuleString join_at_commands(const ModuleString& s, std::vector<std::uint32_t>* origins = nullptr) const;
    /// join_at_commands of a string the caller gives up: the string itself when there is
    /// no split command (no copy)
    ModuleString joined_at_commands(ModuleString s, std::vector<std::uint32_t>* origins = nullptr) const;

    std::unique_ptr<Program> m_program;
    LoadOptions m_options;
    /// Globals and arrays after the last derive(), for interpretation_string()
    mutable std::shared_ptr<Runtime> m_last_runtime;
    bool m_has_queries = false;
    bool m_has_communication = false;
    bool m_has_homomorphism = false;
};

}  // namespace cambium::lsys
