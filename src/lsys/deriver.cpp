// SPDX-License-Identifier: Apache-2.0
// Applies productions to a ModuleString step by step, as cpfg's generator does.
#include "lsys/deriver.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <new>
#include <utility>

#include "base/diagnostics.h"

namespace cambium::lsys {

namespace {

/// The largest `maximum depth:` accepted (decomposition passes; the homomorphism is cut
/// to max_homomorphism_depth).
constexpr long long max_depth_setting = 1'000'000;

/// The size a string of `size` reaches after a step that grows it by `growth`: a double,
/// compared with the memory budget before it becomes a size (converting a double past
/// SIZE_MAX is undefined)
double predicted(std::size_t size, double growth)
{
    return static_cast<double>(size) * growth * 1.01 + 64;
}

double growth(std::size_t before, std::size_t after)
{
    return before == 0 ? 1.0 : static_cast<double>(after) / static_cast<double>(before);
}

int symbol_or_none(const SymbolTable& symbols, std::string_view name)
{
    return symbols.find(name);
}

}  // namespace

Deriver::Deriver(const Program& program, DeriveLimits limits)
    : m_program(program), m_limits(limits)
{
    // module indices and parameter offsets are kept in 32 bits (no_parent is the largest)
    m_limits.max_modules = std::min<std::size_t>(m_limits.max_modules, 0xfffffffeu);
    m_limits.max_params = std::min<std::size_t>(m_limits.max_params, 0xffffffffu);
    const SymbolTable& symbols = program.symbols;
    m_bracket_open = symbol_or_none(symbols, "[");
    m_bracket_close = symbol_or_none(symbols, "]");
    m_cut = symbol_or_none(symbols, "%");
    m_conditional_cut = symbol_or_none(symbols, "@mc");
    m_sub_start = symbol_or_none(symbols, "?");
    m_sub_end = symbol_or_none(symbols, "$");
    m_equals = symbol_or_none(symbols, "=");
    for (const auto& ls : program.lsystems)
        for (const ProductionSet* set : {&ls.productions, &ls.decomposition})
            for (const auto& p : set->productions)
                m_needs_index |= !p.left_context.empty() || !p.right_context.empty();

    // Ignore tables: consider: ignores everything not listed
    for (const auto& ls : program.lsystems) {
        std::vector<char> ignored(symbols.size(), ls.has_consider ? 1 : 0);
        for (SymbolId s : ls.ignore)
            ignored[s] = 1;
        for (SymbolId s : ls.consider)
            ignored[s] = 0;
        m_ignored.push_back(std::move(ignored));
    }
    // Which symbols each L-system's productions and decomposition leave as they are
    // (every id a byte can hold has an entry, so a narrow string is looked up unchecked)
    for (const auto& ls : program.lsystems)
        for (bool decomposition : {false, true}) {
            std::vector<char> copied(std::max<std::size_t>(symbols.size(), 256), 0);
            for (std::size_t sym = 0; sym < symbols.size(); ++sym)
                copied[sym] = never_rewritten(decomposition ? ls.decomposition : ls.productions,
                                              static_cast<int>(sym), decomposition);
            m_copied.push_back(std::move(copied));
        }
    int frame = 0;
    for (const auto& ls : program.lsystems)
        for (const ProductionSet* set : {&ls.productions, &ls.decomposition, &ls.homomorphism})
            for (const auto& p : set->productions)
                frame = std::max(frame, p.frame_size);
    m_frame.assign(static_cast<std::size_t>(frame) + 1, 0.0);
    m_storage.assign(program.storage_size, 0.0);

    m_runtime.globals.assign(program.global_names.size(), 0.0);
    for (const auto& a : program.arrays)
        m_runtime.arrays.push_back(a.initial);
    m_runtime.strings = &program.strings;
    m_runtime.function = &m_limits.function;
    m_runtime.curve = &m_limits.curve;
    m_runtime.file_name = &program.file_name;
    m_runtime.allow_file_access = m_limits.allow_file_access;
    m_warning = [this](const std::string& message, int site) {
        warn(location(site), message + ", " + context());
    };
    m_runtime.warning = &m_warning;
    m_query_symbol.assign(symbols.size(), 0);
    // (and `%`, whose one-parameter modules the fragment pass maps back the same way, and
    // the communication modules ?E, whose answers the environmental step maps back)
    for (const char* name : {"?P", "?H", "?L", "?U", "?E", "%"})
        if (int id = symbols.find(name); id >= 0)
            m_query_symbol[static_cast<std::size_t>(id)] = 1;
    try {
        start();
    } catch (const EvaluationError& e) {
        fail(e);
    } catch (const std::bad_alloc&) {
        system_out_of_memory(m_string.memory_bytes(), m_string);
    }
}

void Deriver::start()
{
    const LSystemDefinition& main = m_program.lsystems.front();
    if (main.derivation_length) {
        in_block("'derivation length:'");
        m_runtime.derivation_length = static_cast<int>(
            setting(*main.derivation_length, main.derivation_length_loc, "the derivation length",
                    0, max_derivation_steps));
    }
    // The value of `seed:` is unused (below) but checked, as the homomorphism's: a number
    // out of a long's range is an error at its expression, not a silently accepted model.
    for (const LSystemDefinition& ls : m_program.lsystems)
        if (ls.seed) {
            in_block("'seed:'");
            setting(*ls.seed, ls.seed_loc, "the seed", LONG_MIN, LONG_MAX);
        }
    // seed: makes the L-system stochastic. The production choice draws from erand48 on
    // a state that starts at 0 and that cpfg (the build the corpus oracle comes from)
    // never seeds: RandomMoss (seed: 2454) matches cpfg only this way.
    m_stochastic.set_state(0);
    if (m_limits.seed) {
        // A scene's seed override: every stream starts from it instead (docs/scenes.md).
        m_stochastic.seed(mixed_seed(1, *m_limits.seed));
        m_runtime.function_random.seed(mixed_seed(2, *m_limits.seed));
        m_runtime.seed_override = m_limits.seed;
    }
    if (!m_limits.start)
        return;
    in_block("the Start block");
    evaluate(m_program.start_block, m_frame, m_runtime);
    // cpfg's derivation loop resets its animation flag after the Start block has run, so
    // a stop() there does not end the derivation
    m_runtime.stop_requested = false;
    in_block("the axiom");
    for (const auto& m : main.axiom)
        append_evaluated(m, m_string);
    // The axiom is not decomposed: manual 5.1.8 decomposes "after each simulation step",
    // so the first step rewrites the axiom as written (Ring, Lilac). A bad depth is
    // still reported here, before any step.
    if (!main.decomposition.productions.empty())
        decomposition_depth();
}

bool Deriver::is_query(int symbol) const
{
    return symbol >= 0 && static_cast<std::size_t>(symbol) < m_query_symbol.size() &&
           m_query_symbol[static_cast<std::size_t>(symbol)] != 0;
}

FileLoc Deriver::location(int site) const
{
    if (site >= 0 && static_cast<std::size_t>(site) < m_program.sites.size())
        return m_program.sites[static_cast<std::size_t>(site)];
    if (m_production)
        return m_production->loc;
    return FileLoc{m_program.file_name, 0, 0};
}

std::string Deriver::context() const
{
    if (m_production)
        return "in production '" + m_production->text + "'";
    return std::string("in ") + (m_block ? m_block : "the L-system");
}

void Deriver::fail(const EvaluationError& e) const
{
    FileLoc loc = location(e.site());
    std::string where = context();
    // a production that spans lines: say where it starts, too
    if (m_production && m_production->loc.line != loc.line && m_production->loc.line > 0)
        where += " (line " + std::to_string(m_production->loc.line) + ")";
    throw Error(loc, std::string(e.what()) + ", " + where);
}

int Deriver::lsystem_index(double id) const
{
    // compared as numbers: converting an arbitrary parameter to int is undefined
    for (std::size_t i = 0; i < m_program.lsystems.size(); ++i)
        if (static_cast<double>(m_program.lsystems[i].id) == std::trunc(id))
            return static_cast<int>(i);
    return -1;
}

void Deriver::set_runtime(const Runtime& runtime)
{
    m_runtime = runtime;
    m_runtime.function = &m_limits.function;
    m_runtime.curve = &m_limits.curve;
    m_runtime.file_name = &m_program.file_name;
    m_runtime.strings = &m_program.strings;
    m_runtime.warning = &m_warning;
    m_runtime.allow_file_access = m_limits.allow_file_access;
}

void Deriver::index(const ModuleString& s, Indexed& out, bool force) const
{
    out.string = &s;
    // Only context matching needs random access to parameters and bracket partners;
    // without context productions the arrays (8 bytes a module) are not built
    if (!m_needs_index && !force) {
        out.offsets.clear();
        out.partner.clear();
        return;
    }
    out.offsets.resize(s.size() + 1);
    out.partner.assign(s.size(), 0);
    std::vector<std::uint32_t> open;
    std::uint32_t offset = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        out.offsets[i] = offset;
        offset += static_cast<std::uint32_t>(s.param_count(i));
        int sym = s.symbol(i);
        if (sym == m_bracket_open) {
            open.push_back(static_cast<std::uint32_t>(i));
        } else if (sym == m_bracket_close && !open.empty()) {
            out.partner[i] = open.back();
            out.partner[open.back()] = static_cast<std::uint32_t>(i);
            open.pop_back();
        }
    }
    out.offsets[s.size()] = offset;
}

void Deriver::step()
{
    try {
        step_located();
    } catch (const EvaluationError& e) {
        fail(e);
    } catch (const std::bad_alloc&) {
        // the budget is checked as the string grows; this is the system running out first
        system_out_of_memory(m_string.memory_bytes() + m_next.memory_bytes(), m_next);
    }
}

void Deriver::step_located()
{
    in_block("the StartEach block");
    evaluate(m_program.start_each_block, m_frame, m_runtime);
    index(m_string, m_indexed);
    m_next.clear();
    // Reserve what the last step's growth predicts, so the new string is not
    // reallocated (and briefly held twice) while it is built
    // (not past the memory budget: the prediction may be wrong, the budget is not)
    double modules_ahead = predicted(m_string.size(), m_module_growth);
    double params_ahead = predicted(m_string.param_total(), m_param_growth);
    if (modules_ahead * 3 + params_ahead * 4 + static_cast<double>(m_string.memory_bytes()) <
        static_cast<double>(m_limits.max_memory_bytes))
        m_next.reserve(static_cast<std::size_t>(modules_ahead),
                       static_cast<std::size_t>(params_ahead));
    std::size_t modules = m_string.size(), params = m_string.param_total();
    rewrite(m_indexed, m_next, false);
    compose_lineage(true);
    m_module_growth = growth(modules, m_next.size());
    m_param_growth = growth(params, m_next.param_total());
    std::swap(m_string, m_next);
    decompose();
    in_block("the EndEach block");
    evaluate(m_program.end_each_block, m_frame, m_runtime);
    ++m_steps;
}

ModuleString Deriver::take_string()
{
    m_next = ModuleString();
    return std::move(m_string);
}

void Deriver::finish()
{
    in_block("the End block");
    try {
        evaluate(m_program.end_block, m_frame, m_runtime);
    } catch (const EvaluationError& e) {
        fail(e);
    }
}

Runtime Deriver::finish_on_copy()
{
    Runtime saved = m_runtime;
    std::vector<double> frame = m_frame;
    try {
        finish();
    } catch (...) {
        m_runtime = std::move(saved);
        m_frame = std::move(frame);
        throw;
    }
    Runtime after = std::exchange(m_runtime, std::move(saved));
    m_frame = std::move(frame);
    return after;
}

void Deriver::release_buffers()
{
    m_next = ModuleString();
    m_indexed = Indexed{};
}

void Deriver::decompose()
{
    const ProductionSet& set = m_program.lsystems.front().decomposition;
    if (set.productions.empty())
        return;
    int depth = decomposition_depth();
    std::size_t applied = 0;
    std::uint64_t work = 0;
    for (int pass = 0; pass < depth; ++pass) {
        work += m_string.size();
        if (work > m_limits.max_decomposition_work)
            throw Error(set.max_depth_loc,
                        "the decomposition went through " + std::to_string(work) +
                            " modules in " + std::to_string(pass + 1) + " passes of one step (maximum depth " +
                            std::to_string(depth) + "), more than the " +
                            std::to_string(m_limits.max_decomposition_work) +
                            " a step may take; lower the maximum depth");
        index(m_string, m_indexed);
        m_next.clear();
        applied = rewrite(m_indexed, m_next, true);
        compose_lineage(false);
        std::swap(m_string, m_next);
        if (applied == 0)
            break;
    }
    // `warnings` after the section keyword: say when the depth cut decomposition short
    if (applied > 0 && set.warnings && depth > 0) {
        index(m_string, m_indexed);
        // The probe is written into m_next, whose capacity the budget check counts (a
        // string of its own would be held beside m_next's capacity, unseen by it).
        m_next.clear();
        Runtime saved = m_runtime;  // probing must not run blocks for real
        Rand48 saved_random = m_stochastic;
        if (rewrite(m_indexed, m_next, true) > 0)
            warn(set.productions.front().loc,
                 "maximum depth (" + std::to_string(depth) + ") of the decomposition reached");
        m_next.clear();
        m_runtime = saved;
        m_stochastic = saved_random;
    }
}

int Deriver::decomposition_depth()
{
    const ProductionSet& set = m_program.lsystems.front().decomposition;
    in_block("the decomposition's 'maximum depth:'");
    return set.max_depth ? static_cast<int>(setting(*set.max_depth, set.max_depth_loc,
                                                    "the decomposition's maximum depth", 0,
                                                    max_depth_setting))
                         : 1;
}

void Deriver::compose_lineage(bool first)
{
    if (!m_track_lineage)
        return;
    if (first) {
        m_lineage.swap(m_pass_lineage);
        return;
    }
    for (std::uint32_t& parent : m_pass_lineage)
        parent = parent == no_parent ? no_parent : m_lineage[parent];
    m_lineage.swap(m_pass_lineage);
}

std::size_t Deriver::rewrite(const Indexed& src, ModuleString& dst, bool decomposition)
{
    const ModuleString& s = *src.string;
    m_source = &s;
    m_pass_lineage.clear();
    m_lsystem_stack.assign(1, 0);
    if (decomposition || m_fragment_starts.empty())
        return rewrite_range(src, dst, decomposition, 0, s.size(), 0, nullptr);
    // Fragmentation (manual 5.1.9): the marked `%(par)` and their fragments are left out
    // in place; after the end of the string, each fragment is derived behind
    // `%(par, turtle)`, in string order, as cpfg's Derive goes on past the end.
    std::vector<Fragment> fragments;
    m_next_mark = 0;
    std::size_t applied = rewrite_range(src, dst, false, 0, s.size(), 0, &fragments);
    m_fragment_starts.clear();
    for (const Fragment& f : fragments) {
        float head[2] = {f.parameter, static_cast<float>(f.turtle)};
        dst.append(static_cast<SymbolId>(m_cut), std::span<const float>(head, 2));
        if (m_track_lineage)
            m_pass_lineage.push_back(static_cast<std::uint32_t>(f.begin - 1));
        applied += rewrite_range(src, dst, false, f.begin, f.end, f.offset, nullptr);
    }
    return applied;
}

void Deriver::record_lineage(const ModuleString& s, const ModuleString& dst, std::size_t i,
                             std::size_t first_new, bool copied)
{
    // Lineage: modules i .. i + n copied are their own continuations; of a successor, the
    // first module with the predecessor's symbol continues it and the others are new.
    if (!m_track_lineage)
        return;
    bool continued = false;
    for (std::size_t k = first_new; k < dst.size(); ++k) {
        bool same = copied || (!continued && dst.symbol(k) == s.symbol(i));
        continued = continued || same;
        m_pass_lineage.push_back(same ? static_cast<std::uint32_t>(copied ? i + (k - first_new) : i)
                                      : no_parent);
    }
}

std::size_t Deriver::rewrite_range(const Indexed& src, ModuleString& dst, bool decomposition,
                                   std::size_t begin, std::size_t end, std::size_t offset,
                                   std::vector<Fragment>* fragments)
{
    const ModuleString& s = *src.string;
    auto record = [&](std::size_t i, std::size_t first_new, bool copied) {
        record_lineage(s, dst, i, first_new, copied);
    };
    // whether module i is the next marked fragment start (marks of modules a production
    // or a cut took are passed over)
    auto marked = [&](std::size_t i) {
        while (m_next_mark < m_fragment_starts.size() && m_fragment_starts[m_next_mark].module < i)
            ++m_next_mark;
        return m_next_mark < m_fragment_starts.size() && m_fragment_starts[m_next_mark].module == i;
    };
    std::size_t applied = 0;
    // offset: the first parameter of module i
    for (std::size_t i = begin; i < end;) {
        const LSystemDefinition& ls =
            m_program.lsystems[static_cast<std::size_t>(m_lsystem_stack.back())];
        const ProductionSet& set = decomposition ? ls.decomposition : ls.productions;
        bool stochastic = ls.seed && !decomposition;
        // Copy a run of modules that nothing can rewrite in one go
        const std::vector<char>& copied =
            m_copied[2 * static_cast<std::size_t>(m_lsystem_stack.back()) + (decomposition ? 1 : 0)];
        std::size_t run = std::min(run_end(s, i, copied), end);
        if (run > i) {
            if (stochastic)
                for (std::size_t k = i; k < run; ++k)
                    m_stochastic.next_double();  // cpfg draws for every module
            std::size_t first_new = dst.size();
            std::size_t run_params = 0;
            const std::uint8_t* counts = s.count_data();
            for (std::size_t k = i; k < run; ++k)
                run_params += counts[k];
            dst.append_range(s, i, run, offset, run_params);
            record(i, first_new, true);
            offset += run_params;
            i = run;
            check_size(dst);
            continue;
        }
        int sym = s.symbol(i);
        std::size_t consumed = 1;
        std::size_t first_new = dst.size();
        if (apply_first_match(set, ls, src, i, offset, dst, consumed)) {
            ++applied;
            record(i, first_new, false);
        } else if (!decomposition && cuts(s, i, offset)) {
            consumed = fragment_end(s, i, end) - i;
        } else if (fragments && is_fragment_start(s, i) && marked(i)) {
            // a marked fragment start: left out here, its fragment derived at the end
            std::size_t stop = fragment_end(s, i, end);
            fragments->push_back(Fragment{i + 1, stop, offset + 1, s.param_data()[offset],
                                          m_fragment_starts[m_next_mark++].turtle});
            consumed = stop - i;
        } else {
            dst.append(s.symbol(i),
                       std::span<const float>(s.param_data() + offset, s.param_count(i)));
            record(i, first_new, true);
        }
        // Sub-L-system switching: ?(id) enters, $ returns
        if (sym == m_sub_start && s.param_count(i) > 0) {
            int idx = lsystem_index(s.param_data()[offset]);
            m_lsystem_stack.push_back(idx >= 0 ? idx : m_lsystem_stack.back());
        } else if (sym == m_sub_end && m_lsystem_stack.size() > 1) {
            m_lsystem_stack.pop_back();
        }
        for (std::size_t k = 0; k < consumed; ++k)
            offset += s.param_count(i + k);
        i += consumed;
        check_size(dst);
    }
    return applied;
}

std::size_t Deriver::run_end(const ModuleString& s, std::size_t i,
                             const std::vector<char>& copied)
{
    std::size_t n = s.size();
    if (const std::uint8_t* symbols = s.narrow_symbol_data()) {
        while (i < n && copied[symbols[i]])
            ++i;
        return i;
    }
    while (i < n && s.symbol(i) < copied.size() && copied[s.symbol(i)])
        ++i;
    return i;
}

bool Deriver::never_rewritten(const ProductionSet& set, int sym, bool decomposition) const
{
    return !set.candidates(static_cast<SymbolId>(sym)) && sym != m_sub_start &&
           sym != m_sub_end && (decomposition || (sym != m_cut && sym != m_conditional_cut));
}

bool Deriver::cuts(const ModuleString& s, std::size_t i, std::size_t offset) const
{
    int sym = s.symbol(i);
    // %(par) marks a fragment (moved by rewrite, not cut); @mc(flag) cuts
    // only when its flag is 1
    if (sym == m_cut)
        return s.param_count(i) == 0;
    return sym == m_conditional_cut && s.param_count(i) > 0 && s.param_data()[offset] == 1.0f;
}

std::size_t Deriver::fragment_end(const ModuleString& s, std::size_t i, std::size_t end) const
{
    // cpfg's SkipCutPart: to the ']' that closes the current branch, the '$' that closes
    // the current sub-L-system, the next '%' with parameters (at any depth), or the end
    int depth = 0, sub_depth = 0;
    for (std::size_t k = i + 1; k < end; ++k) {
        int sym = s.symbol(k);
        if (sym == m_bracket_open)
            ++depth;
        else if (sym == m_bracket_close && depth-- == 0)
            return k;
        else if (sym == m_sub_start && s.param_count(k) > 0)
            ++sub_depth;
        else if (sym == m_sub_end && sub_depth-- == 0)
            return k;
        else if (sym == m_cut && s.param_count(k) > 0)
            return k;
    }
    return end;
}

void Deriver::check_size(const ModuleString& s) const
{
    if (s.size() > m_limits.max_modules)
        throw Error(FileLoc{m_program.file_name, 0, 0},
                    "the string grew past " + std::to_string(m_limits.max_modules) +
                        " modules in " + phase() +
                        "; reduce the derivation length or raise the limit");
    if (s.param_total() > m_limits.max_params)
        throw Error(FileLoc{m_program.file_name, 0, 0},
                    "the string grew past " + std::to_string(m_limits.max_params) +
                        " parameter values in " + phase() + "; reduce the derivation length");
    // What a step holds at once: the string it builds from, its context index and the
    // string being built, at its next peak (when a full array grows, its old block and
    // the new one, a quarter larger, are held at once)
    std::size_t bytes = s.peak_bytes() +
                        (m_source && m_source != &s ? m_source->memory_bytes() : 0) +
                        (m_indexed.offsets.capacity() + m_indexed.partner.capacity()) *
                            sizeof(std::uint32_t);
    if (bytes > m_limits.max_memory_bytes)
        out_of_memory(bytes, s);
}

std::string Deriver::phase() const
{
    return m_in_homomorphism ? std::string("the homomorphism")
                             : "step " + std::to_string(m_steps + 1);
}

void Deriver::out_of_memory(std::size_t bytes, const ModuleString& s) const
{
    throw Error(FileLoc{m_program.file_name, 0, 0},
                "the derivation needs " + byte_size_text(bytes) + " in " + phase() +
                    ", more than the memory budget of " +
                    byte_size_text(m_limits.max_memory_bytes) + " (--max-memory); the string " +
                    "has " + std::to_string(s.size()) + " modules with " +
                    std::to_string(s.param_total()) +
                    " parameters so far; reduce the derivation length or raise --max-memory");
}

void Deriver::system_out_of_memory(std::size_t bytes, const ModuleString& s) const
{
    // Within the budget (or it would have been reported as such): the system refused.
    throw Error(FileLoc{m_program.file_name, 0, 0},
                "the system refused memory in " + phase() + " with " + byte_size_text(bytes) +
                    " held by the strings, within the memory budget of " +
                    byte_size_text(m_limits.max_memory_bytes) + " (--max-memory); the string " +
                    "has " + std::to_string(s.size()) + " modules with " +
                    std::to_string(s.param_total()) +
                    " parameters so far; reduce the derivation length or --max-memory");
}

long long Deriver::setting(const Code& code, const FileLoc& loc, const std::string& what,
                           long long lo, long long hi)
{
    double value = evaluate(code, m_frame, m_runtime);
    if (std::optional<long long> whole = truncated_in(value, lo, hi))
        return *whole;
    throw Error(loc, what + " is " + number_text(value) + "; it must be a number from " +
                         std::to_string(lo) + " to " + std::to_string(hi));
}

bool Deriver::apply_first_match(const ProductionSet& set, const LSystemDefinition& ls,
                                const Indexed& src, std::size_t i, std::size_t offset,
                                ModuleString& dst, std::size_t& consumed)
{
    if (ls.seed && &set == &ls.productions)
        return apply_stochastic(set, ls, src, i, offset, dst, consumed);
    const auto* candidates = set.candidates(src.string->symbol(i));
    if (!candidates)
        return false;
    for (std::uint32_t index : *candidates) {
        const Production& p = set.productions[index];
        if (match(p, ls, src, i, offset) && condition_holds(p)) {
            run_post_block(p);
            produce(p, dst);
            consumed = p.predecessor.size();
            return true;
        }
    }
    return false;
}

bool Deriver::apply_stochastic(const ProductionSet& set, const LSystemDefinition& ls,
                               const Indexed& src, std::size_t i, std::size_t offset,
                               ModuleString& dst, std::size_t& consumed)
{
    // cpfg collects every applicable production with its probability, summed in
    // single precision, then draws once per module, even where nothing applies
    m_matches.clear();
    m_match_probs.clear();
    float total = 0;
    if (const auto* candidates = set.candidates(src.string->symbol(i))) {
        for (std::uint32_t index : *candidates) {
            const Production& p = set.productions[index];
            if (!match(p, ls, src, i, offset) || !condition_holds(p))
                continue;
            float prob = p.probability
                             ? static_cast<float>(evaluate(*p.probability, m_frame, m_runtime))
                             : 1.0f;
            total += prob;
            m_matches.push_back(index);
            m_match_probs.push_back(prob);
        }
    }
    auto scaled = static_cast<float>(total * m_stochastic.next_double());
    for (std::size_t k = 0; k < m_matches.size(); ++k) {
        const Production& p = set.productions[m_matches[k]];
        scaled -= m_match_probs[k];
        if (scaled <= 0) {
            use_frame_of(p);  // its variables as its match left them
            in_production(p);
            run_post_block(p);
            produce(p, dst);
            consumed = p.predecessor.size();
            return true;
        }
    }
    return false;
}

void Deriver::use_frame_of(const Production& p)
{
    if (m_frame_owner == &p)
        return;
    if (m_frame_owner)
        std::copy_n(m_frame.begin(), m_frame_owner->frame_size,
                    m_storage.begin() + static_cast<std::ptrdiff_t>(m_frame_owner->storage));
    std::copy_n(m_storage.begin() + static_cast<std::ptrdiff_t>(p.storage), p.frame_size,
                m_frame.begin());
    m_frame_owner = &p;
}

bool Deriver::bind(const FormalModule& f, const ModuleString& s, std::size_t k,
                  std::size_t offset)
{
    if (s.symbol(k) != f.symbol || s.param_count(k) != f.param_slots.size())
        return false;
    const float* params = s.param_data() + offset;
    for (std::size_t j = 0; j < f.param_slots.size(); ++j)
        m_frame[static_cast<std::size_t>(f.param_slots[j])] = params[j];
    return true;
}

bool Deriver::match(const Production& p, const LSystemDefinition& ls, const Indexed& src,
                    std::size_t i, std::size_t offset)
{
    // The string matched is the one context is read from (indexed whenever some
    // production has context).
    return match_at(p, ls, *src.string, i, offset, src, i, i + p.predecessor.size());
}

bool Deriver::match_left(const Production& p, const std::vector<char>& ignored,
                         const Indexed& src, std::size_t i)
{
    const ModuleString& s = *src.string;
    std::size_t k = i;
    bool wrapped = false;
    for (auto f = p.left_context.rbegin(); f != p.left_context.rend(); ++f) {
        for (;;) {
            if (k == 0) {
                if (!m_ring || wrapped)
                    return false;
                wrapped = true;  // a ring: the string's last module precedes its first
                k = s.size();
            }
            --k;
            int sym = s.symbol(k);
            if (sym == m_bracket_close)
                k = src.partner[k];  // skip a whole branch to the left
            else if (sym == m_bracket_open ||
                     (sym < static_cast<int>(ignored.size()) && ignored[static_cast<std::size_t>(sym)] &&
                      !fragment_mark(s, k)))
                continue;            // into the parent branch, or ignored
            else
                break;
        }
        if (context_barrier(s, k, *f) || !bind(*f, s, k, src.offsets[k]))
            return false;
    }
    return true;
}

bool Deriver::match_right(const Production& p, const std::vector<char>& ignored,
                          const Indexed& src, std::size_t i)
{
    // cpfg's RconDiff: '=' jumps to the end of the current branch; every other context
    // module matches literally after skipping ignored modules and, unless the context
    // names '[', whole lateral branches. Ignoring comes first, so a '[' that consider:
    // leaves out is stepped into rather than skipped.
    const ModuleString& s = *src.string;
    std::size_t k = i;
    bool wrapped = false;
    for (const FormalModule& f : p.right_context) {
        if (f.symbol == m_equals) {
            k = branch_end(src, k);
            continue;
        }
        for (;;) {
            if (k >= s.size()) {
                if (!m_ring || wrapped || s.size() == 0)
                    return false;
                wrapped = true;  // a ring: the first module follows the last
                k = 0;
            }
            int sym = s.symbol(k);
            if (sym < static_cast<int>(ignored.size()) && ignored[static_cast<std::size_t>(sym)] &&
                !fragment_mark(s, k))
                ++k;
            else if (sym == m_bracket_open && f.symbol != m_bracket_open)
                k = src.partner[k] > k ? src.partner[k] + 1 : s.size();
            else
                break;
        }
        if (context_barrier(s, k, f) || !bind(f, s, k, src.offsets[k]))
            return false;
        ++k;
    }
    return true;
}

std::size_t Deriver::branch_end(const Indexed& src, std::size_t k) const
{
    const ModuleString& s = *src.string;
    for (; k < s.size(); ++k) {
        int sym = s.symbol(k);
        if (sym == m_bracket_close)
            return k;
        if (sym == m_bracket_open) {
            if (src.partner[k] <= k)
                return s.size();
            k = src.partner[k];
        }
    }
    return s.size();
}

bool Deriver::condition_holds(const Production& p)
{
    in_production(p);
    std::span<double> frame(m_frame);
    if (!p.pre_block.empty())
        evaluate(p.pre_block, frame, m_runtime);
    return !p.condition || evaluate(*p.condition, frame, m_runtime) != 0;
}

void Deriver::run_post_block(const Production& p)
{
    in_production(p);
    if (!p.post_block.empty())
        evaluate(p.post_block, std::span<double>(m_frame), m_runtime);
}

void Deriver::produce(const Production& p, ModuleString& dst)
{
    in_production(p);
    std::size_t first = dst.param_total();
    dst.append(p.successor_prototype);
    if (p.computed_params.empty())
        return;
    // Evaluated straight into the string (expressions never read it; a failure ends the
    // step, whose string is unfinished anyway), in the successor's order.
    float* values = dst.mutable_params().data() + first;
    for (const ComputedParam& c : p.computed_params)
        values[c.index] = static_cast<float>(
            evaluate(p.successor[c.module].params[c.param], m_frame, m_runtime));
}

void Deriver::append_evaluated(const ModuleTemplate& m, ModuleString& dst)
{
    float* values = dst.append_module(m.symbol, m.params.size());
    for (std::size_t j = 0; j < m.params.size(); ++j)
        values[j] = static_cast<float>(evaluate(m.params[j], m_frame, m_runtime));
}


// ---------------------------------------------------------------- homomorphism

namespace {

/// Homomorphism productions apply recursively, one stack frame per level: deeper
/// `maximum depth:` values are cut here with a warning.
constexpr int max_homomorphism_depth = 1000;

ParamLink make_link(std::size_t from, std::size_t to, std::size_t count)
{
    return ParamLink{static_cast<std::uint32_t>(from), static_cast<std::uint32_t>(to),
                     static_cast<std::uint32_t>(count)};
}

}  // namespace

void Deriver::apply_homomorphism(const ModuleString& in, ModuleString& out,
                                 std::vector<ParamLink>* query_links, bool keep_objects,
                                 std::vector<std::uint32_t>* origins)
{
    m_keep_objects = keep_objects;
    m_in_homomorphism = true;
    m_source = &in;
    try {
        homomorphism_located(in, out, query_links, origins);
    } catch (const EvaluationError& e) {
        m_keep_objects = m_in_homomorphism = false;
        fail(e);
    } catch (const std::bad_alloc&) {
        system_out_of_memory(in.memory_bytes() + out.memory_bytes(), out);
    }
    m_keep_objects = m_in_homomorphism = false;
    m_source = nullptr;
}

void Deriver::homomorphism_located(const ModuleString& in, ModuleString& out,
                                   std::vector<ParamLink>* query_links,
                                   std::vector<std::uint32_t>* origins)
{
    out.clear();
    if (query_links)
        query_links->clear();
    if (origins)
        origins->clear();
    bool any = false, contexts = false;
    for (const auto& ls : m_program.lsystems) {
        any |= !ls.homomorphism.productions.empty();
        for (const auto& p : ls.homomorphism.productions)
            contexts |= !p.left_context.empty() || !p.right_context.empty();
    }
    if (!any) {
        if (query_links)
            for (std::size_t i = 0, offset = 0; i < in.size(); offset += in.param_count(i), ++i)
                if (is_query(in.symbol(i)))
                    query_links->push_back(make_link(offset, offset, in.param_count(i)));
        out.append(in);
        if (origins)
            for (std::size_t i = 0; i < in.size(); ++i)
                origins->push_back(static_cast<std::uint32_t>(i));
        return;
    }
    Indexed ctx;
    index(in, ctx, contexts);
    // Each pass starts the homomorphism's own random stream afresh from its seed:
    const ProductionSet& main_set = m_program.lsystems.front().homomorphism;
    in_block("the homomorphism's 'seed:' or 'maximum depth:'");
    long homomorphism_seed =
        main_set.seed ? static_cast<long>(setting(*main_set.seed, main_set.seed_loc,
                                                  "the homomorphism's seed", LONG_MIN, LONG_MAX))
                      : 0;
    m_homomorphism_random.seed(m_limits.seed ? mixed_seed(homomorphism_seed, *m_limits.seed)
                                             : homomorphism_seed);
    std::vector<int> depth_of(m_program.lsystems.size(), 1);
    for (std::size_t l = 0; l < m_program.lsystems.size(); ++l) {
        const ProductionSet& set = m_program.lsystems[l].homomorphism;
        if (set.max_depth)
            depth_of[l] = static_cast<int>(setting(*set.max_depth, set.max_depth_loc,
                                                   "the homomorphism's maximum depth", 0,
                                                   max_depth_setting));
        if (depth_of[l] > max_homomorphism_depth) {
            warn(set.productions.empty() ? FileLoc{m_program.file_name, 0, 0}
                                         : set.productions.front().loc,
                 "homomorphism maximum depth " + std::to_string(depth_of[l]) +
                     " is more than " + std::to_string(max_homomorphism_depth) +
                     "; using " + std::to_string(max_homomorphism_depth));
            depth_of[l] = max_homomorphism_depth;
        }
    }
    m_homomorphism_stack.resize(static_cast<std::size_t>(
        *std::max_element(depth_of.begin(), depth_of.end()) + 1));
    m_lsystem_stack.assign(1, 0);
    std::size_t offset = 0;
    for (std::size_t i = 0; i < in.size();) {
        std::size_t l = static_cast<std::size_t>(m_lsystem_stack.back());
        const LSystemDefinition& ls = m_program.lsystems[l];
        int sym = in.symbol(i);
        std::size_t first = i, first_offset = offset;
        if (ls.homomorphism.candidates(static_cast<SymbolId>(sym)) && depth_of[l] > 0) {
            std::size_t before = out.size(), before_params = out.param_total();
            homomorphism_module(ls.homomorphism, ls, in, i, offset, ctx, i, i + 1, 0,
                                depth_of[l], out);
            // a query module that no production rewrote is answered in place
            if (query_links && is_query(sym) && i == first + 1 && out.size() == before + 1 &&
                out.symbol(before) == sym && out.param_count(before) == in.param_count(first))
                query_links->push_back(
                    make_link(first_offset, before_params, in.param_count(first)));
        } else {
            if (query_links && is_query(sym))
                query_links->push_back(make_link(offset, out.param_total(), in.param_count(i)));
            out.append(static_cast<SymbolId>(sym),
                       std::span<const float>(in.param_data() + offset, in.param_count(i)));
            offset += in.param_count(i);
            ++i;
        }
        if (origins)
            origins->resize(out.size(), static_cast<std::uint32_t>(first));
        check_size(out);
        // sub-L-system switching follows the original string, as in derivation
        for (std::size_t k = first, o = first_offset; k < i; o += in.param_count(k), ++k) {
            int s = in.symbol(k);
            if (s == m_sub_start && in.param_count(k) > 0) {
                int idx = lsystem_index(in.param_data()[o]);
                m_lsystem_stack.push_back(idx >= 0 ? idx : m_lsystem_stack.back());
            } else if (s == m_sub_end && m_lsystem_stack.size() > 1) {
                m_lsystem_stack.pop_back();
            }
        }
    }
}

bool Deriver::match_at(const Production& p, const LSystemDefinition& ls, const ModuleString& s,
                       std::size_t k, std::size_t offset, const Indexed& ctx, std::size_t left,
                       std::size_t right)
{
    if (k + p.predecessor.size() > s.size())
        return false;
    in_production(p);
    use_frame_of(p);
    for (std::size_t j = 0; j < p.predecessor.size(); ++j) {
        if (!bind(p.predecessor[j], s, k + j, offset))
            return false;
        offset += s.param_count(k + j);
    }
    if (p.left_context.empty() && p.right_context.empty())
        return true;
    if (ctx.offsets.empty())
        return false;  // no original string to take context from (an object expansion)
    const auto& ignored = m_ignored[static_cast<std::size_t>(&ls - m_program.lsystems.data())];
    m_ring = ls.ring;
    return match_left(p, ignored, ctx, left) && match_right(p, ignored, ctx, right);
}

const Production* Deriver::find_homomorphism(const ProductionSet& set,
                                             const LSystemDefinition& ls,
                                             const ModuleString& s, std::size_t k,
                                             std::size_t offset, const Indexed& ctx,
                                             std::size_t left, std::size_t right)
{
    const auto* candidates = set.candidates(s.symbol(k));
    if (!candidates)
        return nullptr;
    if (!set.seed) {
        for (std::uint32_t index : *candidates) {
            const Production& p = set.productions[index];
            if (match_at(p, ls, s, k, offset, ctx, left, right) && condition_holds(p))
                return &p;
        }
        return nullptr;
    }
    // seed: makes the homomorphism stochastic: choose among the applicable productions
    // by their probabilities, drawing from the homomorphism's own generator
    std::vector<const Production*> applicable;
    std::vector<float> probs;
    float total = 0;
    for (std::uint32_t index : *candidates) {
        const Production& p = set.productions[index];
        if (!match_at(p, ls, s, k, offset, ctx, left, right) || !condition_holds(p))
            continue;
        float prob = p.probability ? static_cast<float>(evaluate(*p.probability, m_frame, m_runtime))
                                   : 1.0f;
        total += prob;
        applicable.push_back(&p);
        probs.push_back(prob);
    }
    auto scaled = static_cast<float>(total * m_homomorphism_random.next_double());
    for (std::size_t j = 0; j < applicable.size(); ++j) {
        scaled -= probs[j];
        if (scaled <= 0) {
            use_frame_of(*applicable[j]);
            in_production(*applicable[j]);
            return applicable[j];
        }
    }
    return nullptr;
}

void Deriver::homomorphism_module(const ProductionSet& set, const LSystemDefinition& ls,
                                  const ModuleString& s, std::size_t& k, std::size_t& offset,
                                  const Indexed& ctx, std::size_t left, std::size_t right,
                                  int depth, int max_depth, ModuleString& out)
{
    auto copy_one = [&] {
        out.append(s.symbol(k), std::span<const float>(s.param_data() + offset, s.param_count(k)));
        offset += s.param_count(k);
        ++k;
    };
    const Production* p = find_homomorphism(set, ls, s, k, offset, ctx, left, right);
    if (!p) {
        copy_one();
        return;
    }
    if (depth >= max_depth) {
        if (set.warnings)
            warn(p->loc, "maximum depth of the homomorphism reached for module '" +
                             std::string(m_program.symbols.name(s.symbol(k))) + "'");
        copy_one();
        return;
    }
    if (m_keep_objects && is_instanceable_object(*p)) {
        copy_one();
        return;
    }
    run_post_block(*p);
    ModuleString& successor = m_homomorphism_stack[static_cast<std::size_t>(depth)];
    successor.clear();
    produce(*p, successor);
    for (std::size_t j = 0; j < p->predecessor.size(); ++j)
        offset += s.param_count(k + j);
    k += p->predecessor.size();
    std::size_t sk = 0, soffset = 0;
    while (sk < successor.size()) {
        homomorphism_module(set, ls, successor, sk, soffset, ctx, left, right, depth + 1,
                            max_depth, out);
        check_size(out);
    }
}

}  // namespace cambium::lsys
