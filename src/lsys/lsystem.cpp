// SPDX-License-Identifier: Apache-2.0
// The public face of src/lsys: load a cpfg .l file, read its axiom, derive strings.
#include "lsys/lsystem.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "base/diagnostics.h"
#include "base/input_file.h"
#include "lsys/deriver.h"
#include "lsys/parser.h"
#include "lsys/preprocessor.h"
#include "lsys/program.h"

namespace cambium::lsys {

namespace {

std::unique_ptr<Program> compile(std::string_view source, const std::string& file_name,
                                 const PreprocessOptions& pp)
{
    std::string text = preprocess(source, file_name, pp);
    auto program = std::make_unique<Program>();
    parse_program(text, file_name, *program);
    return program;
}

bool uses_symbol(const Program& program, int symbol)
{
    if (symbol < 0)
        return false;
    auto in = [&](const std::vector<ModuleTemplate>& modules) {
        for (const auto& m : modules)
            if (m.symbol == symbol)
                return true;
        return false;
    };
    for (const auto& ls : program.lsystems) {
        if (in(ls.axiom))
            return true;
        for (const ProductionSet* set : {&ls.productions, &ls.decomposition, &ls.homomorphism})
            for (const auto& p : set->productions)
                if (in(p.successor))
                    return true;
    }
    return false;
}

}  // namespace

LSystem::LSystem(std::unique_ptr<Program> program, LoadOptions options)
    : m_program(std::move(program)), m_options(std::move(options))
{
    const SymbolTable& symbols = m_program->symbols;
    for (const char* name : {"?P", "?H", "?L", "?U"})
        m_has_queries |= uses_symbol(*m_program, symbols.find(name));
    for (const auto& ls : m_program->lsystems)
        m_has_homomorphism |= !ls.homomorphism.productions.empty();
    m_has_communication = uses_symbol(*m_program, symbols.find("?E"));
    if (m_has_communication && !m_options.environment)
        warn(FileLoc{m_program->file_name, 0, 0},
             "the L-system uses ?E communication modules, but no environment is connected "
             "(-e file.e); they stay in the string with their parameters unchanged");
}
LSystem::LSystem(LSystem&&) noexcept = default;
LSystem& LSystem::operator=(LSystem&&) noexcept = default;
LSystem::~LSystem() = default;

LSystem LSystem::load(const std::filesystem::path& file, const LoadOptions& options)
{
    PreprocessOptions pp;
    pp.defines = options.defines;
    pp.preprocessor = options.preprocessor;
    pp.folder = file.parent_path();
    if (!options.allow_file_access)
        pp.confine_to = std::filesystem::weakly_canonical(std::filesystem::absolute(pp.folder.empty() ? "." : pp.folder));
    std::string source = read_file(file, "the L-system file", pp.max_input_bytes);
    return LSystem(compile(source, file.string(), pp), options);
}

LSystem LSystem::from_source(std::string_view source, std::string_view file_name,
                             const LoadOptions& options)
{
    PreprocessOptions pp;
    pp.defines = options.defines;
    pp.preprocessor = options.preprocessor;
    if (!options.allow_file_access)
        pp.confine_to = std::filesystem::current_path();  // where cpp runs
    return LSystem(compile(source, std::string(file_name), pp), options);
}

LSystem LSystem::from_preprocessed(std::string_view text, std::string_view file_name,
                                   const LoadOptions& options)
{
    auto program = std::make_unique<Program>();
    parse_program(text, std::string(file_name), *program);
    return LSystem(std::move(program), options);
}

const SymbolTable& LSystem::symbols() const { return m_program->symbols; }
SymbolTable& LSystem::symbols() { return m_program->symbols; }
const Program& LSystem::program() const { return *m_program; }

namespace {

DeriveLimits limits_of(const LoadOptions& options)
{
    DeriveLimits limits;
    limits.max_modules = options.max_modules;
    limits.max_memory_bytes = options.max_memory_bytes;
    limits.allow_file_access = options.allow_file_access;
    limits.function = options.function;
    limits.curve = options.curve;
    limits.seed = options.seed;
    return limits;
}

}  // namespace

int LSystem::derivation_length() const
{
    Deriver deriver(*m_program, limits_of(m_options));
    return deriver.derivation_length();
}

ModuleString LSystem::axiom() const
{
    Deriver deriver(*m_program, limits_of(m_options));
    return deriver.string();
}

bool LSystem::has_queries() const { return m_has_queries; }

bool LSystem::end_block_uses_files() const
{
    for (const Instr& in : m_program->end_block.instrs) {
        if (in.op == Op::FilePrint || in.op == Op::FileScan)
            return true;
        if (in.op == Op::Call) {
            const auto f = static_cast<Function>(in.arg);
            if (f == Function::Fopen || f == Function::Fclose || f == Function::Fflush)
                return true;
        }
    }
    return false;
}

ModuleString LSystem::derive(std::optional<int> steps) const
{
    Derivation derivation = start();
    int n = steps.value_or(derivation.derivation_length());
    derivation.advance(n);
    bool stopped_early = derivation.stopped() && derivation.steps_done() < n;
    if (!stopped_early || derivation.stop_runs_end())
        derivation.finish();
    return derivation.take_string();
}

ModuleString LSystem::derive_with_ages(std::optional<int> steps,
                                       std::vector<std::uint16_t>& ages) const
{
    constexpr std::uint16_t oldest = 0xfffe;
    Derivation derivation = start();
    derivation.track_lineage();
    ages.assign(derivation.string().size(), 0);
    int n = steps.value_or(derivation.derivation_length());
    // one step at a time: each advance's lineage is that step's
    for (int k = 0; k < n && !derivation.stopped(); ++k) {
        derivation.advance(1);
        const std::vector<std::uint32_t>& lineage = derivation.lineage();
        const auto step = static_cast<std::uint16_t>(std::min(derivation.steps_done(), int(oldest)));
        std::vector<std::uint16_t> next(lineage.size());
        for (std::size_t i = 0; i < lineage.size(); ++i)
            next[i] = lineage[i] == no_parent || lineage[i] >= ages.size() ? step : ages[lineage[i]];
        ages = std::move(next);
    }
    bool stopped_early = derivation.stopped() && derivation.steps_done() < n;
    if (!stopped_early || derivation.stop_runs_end())
        derivation.finish();
    ModuleString out = derivation.take_string();
    ages.resize(out.size(), oldest);
    return out;
}

Derivation LSystem::start() const
{
    auto deriver = std::make_unique<Deriver>(*m_program, limits_of(m_options));
    if (m_options.on_step)
        m_options.on_step(0, deriver->string());
    m_last_runtime = std::make_shared<Runtime>(deriver->runtime());
    return Derivation(*this, std::move(deriver));
}

Derivation::Derivation(const LSystem& lsystem, std::unique_ptr<Deriver> deriver)
    : m_lsystem(&lsystem), m_deriver(std::move(deriver))
{
    if (lsystem.m_has_communication && lsystem.m_options.environment)
        m_environment = lsystem.m_options.environment();
}
Derivation::Derivation(Derivation&&) noexcept = default;
Derivation& Derivation::operator=(Derivation&&) noexcept = default;
Derivation::~Derivation() = default;

void Derivation::track_lineage()
{
    m_track_lineage = true;
    m_deriver->track_lineage(true);
}

void Derivation::advance(int steps)
{
    const LoadOptions& options = m_lsystem->m_options;
    if (m_track_lineage) {  // no step yet: every module continues itself
        m_lineage.resize(m_deriver->string().size());
        for (std::size_t k = 0; k < m_lineage.size(); ++k)
            m_lineage[k] = static_cast<std::uint32_t>(k);
    }
    for (int i = 0; i < steps && !m_deriver->stop_requested(); ++i) {
        // cpfg (with its default "environment display" off) answers queries while
        // interpreting the string before each step, not after the last one
        if (m_lsystem->m_has_queries && options.query)
            m_lsystem->run_query(*m_deriver);
        if (m_environment)
            m_lsystem->run_environment(*m_deriver, m_environment);
        if (m_deriver->has_cut_symbol())
            m_saved_turtles += m_lsystem->run_fragment_pass(*m_deriver, m_saved_turtles);
        m_deriver->step();
        if (m_track_lineage) {
            std::vector<std::uint32_t> step = m_deriver->lineage();
            for (std::uint32_t& parent : step)
                parent = parent == no_parent ? no_parent : m_lineage[parent];
            m_lineage = std::move(step);
        }
        if (options.on_step)
            options.on_step(m_deriver->steps_done(), m_deriver->string());
        if (m_go_on_after_stop_one && m_deriver->stop_requested() && !m_deriver->stop_runs_end())
            m_deriver->clear_stop();
    }
    m_lsystem->m_last_runtime = std::make_shared<Runtime>(m_deriver->runtime());
}

void Derivation::finish()
{
    if (m_finished)
        return;
    m_finished = true;
    m_deriver->finish();
    m_lsystem->m_last_runtime = std::make_shared<Runtime>(m_deriver->runtime());
}

void Derivation::finish_on_copy()
{
    m_lsystem->m_last_runtime = std::make_shared<Runtime>(m_deriver->finish_on_copy());
}

void Derivation::release_buffers() { m_deriver->release_buffers(); }

const ModuleString& Derivation::string() const { return m_deriver->string(); }
int Derivation::steps_done() const { return m_deriver->steps_done(); }
int Derivation::derivation_length() const { return m_deriver->derivation_length(); }
bool Derivation::stopped() const { return m_deriver->stop_requested(); }
bool Derivation::stop_runs_end() const { return m_deriver->stop_runs_end(); }
void Derivation::go_on_after_stop_one() { m_go_on_after_stop_one = true; }
ModuleString Derivation::take_string() { return m_deriver->take_string(); }

void LSystem::run_query(Deriver& deriver) const
{
    turtle_pass(deriver, [&](const TurtleString& s) { m_options.query(s.modules); });
}

void LSystem::run_environment(Deriver& deriver,
                              const std::function<void(const TurtleString&, int)>& pass) const
{
    const int step = deriver.steps_done();
    turtle_pass(deriver, [&](const TurtleString& s) { pass(s, step); });
}

void LSystem::turtle_pass(Deriver& deriver,
                          const std::function<void(const TurtleString&)>& pass) const
{
    ModuleString& s = deriver.mutable_string();
    auto changed_count = [&] {
        return Error(FileLoc{m_program->file_name, 0, 0},
                     "internal: a turtle pass changed the number of parameters");
    };
    if (!m_has_homomorphism && m_program->split_commands.empty()) {
        pass(TurtleString{s, s, {}});
        return;
    }
    if (!m_has_homomorphism) {
        // '@' has no parameters, so the joined string holds the same values in the same order
        std::vector<std::uint32_t> origins;
        ModuleString joined = join_at_commands(s, &origins);
        pass(TurtleString{joined, s, origins});
        if (joined.param_total() != s.param_total())
            throw changed_count();
        std::copy_n(joined.param_data(), joined.param_total(), s.mutable_params().data());
        return;
    }
    // cpfg interprets the string with the homomorphism applied, with the derivation's own
    // variables; the modules the homomorphism keeps in place take their values back
    ModuleString expanded;
    std::vector<ParamLink> links;
    std::vector<std::uint32_t> origins;
    deriver.apply_homomorphism(s, expanded, &links, false, &origins);
    ModuleString joined = joined_at_commands(std::move(expanded), &origins);
    std::size_t total = joined.param_total();
    pass(TurtleString{joined, s, origins});
    if (joined.param_total() != total)
        throw changed_count();
    float* params = s.mutable_params().data();
    for (const ParamLink& link : links)
        std::copy_n(joined.param_data() + link.to, link.count, params + link.from);
}

std::uint32_t LSystem::run_fragment_pass(Deriver& deriver, std::uint32_t first_turtle) const
{
    const ModuleString& s = deriver.string();
    // the first parameter of each fragment start, in string order
    std::vector<std::uint32_t> starts, start_offsets;
    for (std::size_t i = 0, offset = 0; i < s.size(); offset += s.param_count(i), ++i)
        if (deriver.is_fragment_start(s, i)) {
            starts.push_back(static_cast<std::uint32_t>(i));
            start_offsets.push_back(static_cast<std::uint32_t>(offset));
        }
    if (starts.empty())
        return 0;
    auto too_many = [&] {
        return Error(FileLoc{m_program->file_name, 0, 0},
                     "more than " + std::to_string(m_options.max_saved_turtles) +
                         " fragment starts %(par) in one derivation (each saves a turtle, "
                         "manual 5.1.9)");
    };
    std::vector<FragmentStart> marks;
    if (!m_options.fragment_pass) {
        if (starts.size() > m_options.max_saved_turtles - first_turtle)
            throw too_many();
        for (std::size_t k = 0; k < starts.size(); ++k)
            marks.push_back(FragmentStart{starts[k], first_turtle + static_cast<std::uint32_t>(k)});
        deriver.mark_fragments(std::move(marks));
        return static_cast<std::uint32_t>(starts.size());
    }
    // The turtle reads the string with the homomorphism applied and @-commands joined;
    // a fragment start it reaches is found again in the derived string by its parameter
    std::vector<std::uint32_t> reached;
    std::vector<std::uint32_t> reached_offsets;  // in the derived string
    auto offsets_of = [](const ModuleString& t, const std::vector<std::uint32_t>& modules) {
        std::vector<std::uint32_t> out;
        std::size_t m = 0, offset = 0;
        for (std::size_t i = 0; i < t.size() && m < modules.size(); offset += t.param_count(i), ++i)
            if (i == modules[m]) {
                out.push_back(static_cast<std::uint32_t>(offset));
                ++m;
            }
        return out;
    };
    if (!m_has_homomorphism && m_program->split_commands.empty()) {
        reached = m_options.fragment_pass(s, first_turtle);
        reached_offsets = offsets_of(s, reached);
    } else if (!m_has_homomorphism) {
        ModuleString joined = join_at_commands(s);
        reached = m_options.fragment_pass(joined, first_turtle);
        reached_offsets = offsets_of(joined, reached);  // joining keeps parameters in order
    } else {
        ModuleString expanded;
        std::vector<ParamLink> links;
        deriver.apply_homomorphism(s, expanded, &links);
        ModuleString joined = join_at_commands(expanded);
        reached = m_options.fragment_pass(joined, first_turtle);
        // a `%(par)` the homomorphism wrote saves a turtle, but has no fragment to move
        for (std::uint32_t to : offsets_of(joined, reached)) {
            std::uint32_t from = UINT32_MAX;
            for (const ParamLink& link : links)
                if (link.to == to && link.count == 1)
                    from = link.from;
            reached_offsets.push_back(from);
        }
    }
    if (reached.size() > m_options.max_saved_turtles - first_turtle)
        throw too_many();
    for (std::size_t k = 0; k < reached_offsets.size(); ++k) {
        auto at = std::lower_bound(start_offsets.begin(), start_offsets.end(), reached_offsets[k]);
        if (at != start_offsets.end() && *at == reached_offsets[k])
            marks.push_back(FragmentStart{starts[static_cast<std::size_t>(at - start_offsets.begin())],
                                          first_turtle + static_cast<std::uint32_t>(k)});
    }
    std::sort(marks.begin(), marks.end(),
              [](const FragmentStart& a, const FragmentStart& b) { return a.module < b.module; });
    deriver.mark_fragments(std::move(marks));
    return static_cast<std::uint32_t>(reached.size());
}

ModuleString LSystem::joined_at_commands(ModuleString s, std::vector<std::uint32_t>* origins) const
{
    if (m_program->split_commands.empty())
        return s;  // moved out, not copied
    return join_at_commands(s, origins);
}

ModuleString LSystem::join_at_commands(const ModuleString& s, std::vector<std::uint32_t>* origins) const
{
    const auto& commands = m_program->split_commands;
    if (commands.empty())
        return s;
    std::vector<std::uint32_t> joined_origins;
    auto origin = [&](std::size_t i) {
        return origins && !origins->empty() ? (*origins)[i] : static_cast<std::uint32_t>(i);
    };
    SymbolId at = commands.front().parts.front();
    ModuleString out;
    out.reserve(s.size(), s.param_total());
    std::size_t offset = 0;
    for (std::size_t i = 0; i < s.size();) {
        const SplitCommand* best = nullptr;
        if (s.symbol(i) == at && s.param_count(i) == 0) {
            for (const auto& c : commands) {
                std::size_t n = c.parts.size();
                if (i + n > s.size() || (best && best->parts.size() >= n))
                    continue;
                bool ok = true;
                for (std::size_t k = 1; k < n && ok; ++k)
                    ok = s.symbol(i + k) == c.parts[k] && (k + 1 == n || s.param_count(i + k) == 0);
                if (ok)
                    best = &c;
            }
        }
        if (origins)
            joined_origins.push_back(origin(i));
        if (best) {
            std::size_t last = i + best->parts.size() - 1;
            out.append(best->joined,
                       std::span<const float>(s.param_data() + offset, s.param_count(last)));
            offset += s.param_count(last);
            i = last + 1;
        } else {
            out.append(s.symbol(i), std::span<const float>(s.param_data() + offset, s.param_count(i)));
            offset += s.param_count(i);
            ++i;
        }
    }
    if (origins)
        *origins = std::move(joined_origins);
    return out;
}

ModuleString LSystem::interpretation_string(const ModuleString& derived, ObjectHandling objects,
                                           std::vector<std::uint32_t>& origins) const
{
    DeriveLimits limits = limits_of(m_options);
    limits.start = m_last_runtime == nullptr;  // else the Start block gives the globals
    Deriver deriver(*m_program, limits);
    if (m_last_runtime)
        deriver.set_runtime(*m_last_runtime);
    ModuleString out;
    origins.clear();
    deriver.apply_homomorphism(derived, out, nullptr, objects == ObjectHandling::keep, &origins);
    ModuleString joined = joined_at_commands(std::move(out), &origins);
    if (origins.empty())  // the identity
        for (std::size_t i = 0; i < joined.size(); ++i)
            origins.push_back(static_cast<std::uint32_t>(i));
    return joined;
}

ModuleString LSystem::interpretation_string(const ModuleString& derived,
                                           ObjectHandling objects) const
{
    DeriveLimits limits = limits_of(m_options);
    limits.start = m_last_runtime == nullptr;  // else the Start block gives the globals
    Deriver deriver(*m_program, limits);
    if (m_last_runtime)
        deriver.set_runtime(*m_last_runtime);
    ModuleString out;
    deriver.apply_homomorphism(derived, out, nullptr, objects == ObjectHandling::keep);
    return joined_at_commands(std::move(out));
}

bool LSystem::is_object_symbol(int symbol) const
{
    for (const auto& ls : m_program->lsystems)
        for (const auto& p : ls.homomorphism.productions)
            if (is_instanceable_object(p) && p.predecessor.front().symbol == symbol)
                return true;
    return false;
}

ModuleString LSystem::expand_object(ModuleRef module) const
{
    ModuleString one;
    one.append(module.symbol, module.params);
    return interpretation_string(one);
}

}  // namespace cambium::lsys
