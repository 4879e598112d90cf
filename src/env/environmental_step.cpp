// SPDX-License-Identifier: Apache-2.0
#include "env/environmental_step.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <unordered_map>

#include "env/builtins.h"
#include "base/limits.h"
#include "geom/gls_polygons.h"
#include "geom/primitives.h"
#include "geom/query.h"

namespace cambium::env {
namespace {

SentModule sent_module(const lsys::ModuleString& string, std::size_t i, std::size_t offset,
                       const lsys::SymbolTable& symbols)
{
    SentModule m{std::string(symbols.name(string.symbol(i))), {}};
    const std::size_t n = string.param_count(i);
    m.params.reserve(n);
    for (std::size_t k = 0; k < n; ++k)
        m.params.push_back(through_g(string.param_data()[offset + k]));
    return m;
}

SentVector sent_vector(const std::optional<TurtleFormat>& format, const geom::Vec3& v)
{
    SentVector s;
    if (format) {
        const double values[3] = {v.x, v.y, v.z};
        s.count = send_through_format(*format, values, 3, s.values.data());
    }
    return s;
}

SentVector sent_scalar(const std::optional<TurtleFormat>& format, double v)
{
    SentVector s;
    if (format)
        s.count = send_through_format(*format, &v, 1, s.values.data());
    return s;
}

/// The turtle in the world of a placed plant: position moved, frame turned (unit length).
void place(geom::TurtleAtModule& t, const std::array<float, 12>& m)
{
    const geom::Affine3x4 placement(m);
    t.position = placement.apply(t.position);
    for (geom::Vec3* v : {&t.heading, &t.left, &t.up})
        *v = geom::normalize(placement.linear(*v));
}

}  // namespace

Connection connect(const CommSpec& spec, const Context& context, const ProgramPermission& programs)
{
    const std::string& program = spec.executable.front();
    const std::vector<std::string> args(spec.executable.begin() + 1, spec.executable.end());
    const std::string name = std::filesystem::path(program).filename().string();
    Connection c;
    if (make_builtin(program, args, context)) {
        c.make = [program, args, context] { return make_builtin(program, args, context); };
        c.description = name + " (built in: no program is started)";
        return c;
    }
    if (!programs.allowed)
        throw Error(spec.executable_loc,
                    "the environmental program '" + program +
                        "' is not one of Cambium's built-in environments (honda81, ecosystem, "
                        "chiba, clover, QuasiMC); a model file starts a program only with "
                        "--allow-environment-program");
    c.make = [spec, context, limits = programs.limits] {
        return make_external_program(spec, context, limits);
    };
    c.description = program + " (an external program, started in " + context.folder.string() + ")";
    return c;
}

EnvironmentalStep::EnvironmentalStep(CommSpec spec, Connection connection)
    : m_spec(std::move(spec)), m_connection(std::move(connection)), m_environment(m_connection.make())
{
}

namespace {

/// Parameter offsets of every module of `string` (and one past the last).
std::vector<std::size_t> parameter_offsets(const lsys::ModuleString& string)
{
    std::vector<std::size_t> offsets(string.size() + 1, 0);
    for (std::size_t i = 0; i < string.size(); ++i)
        offsets[i + 1] = offsets[i] + string.param_count(i);
    return offsets;
}

/// The modules the turtle reads for the module after the ?E at `i`: the whole
/// homomorphism successor of the derived module that follows it, or, for a ?E the
/// homomorphism made, the next module of its successor.
geom::ModuleRange following_range(const lsys::TurtleString& s, std::size_t i)
{
    const std::size_t n = s.modules.size();
    if (i + 1 >= n)
        return {n, n};
    std::size_t end = i + 2;
    if (s.origin(i + 1) != s.origin(i))
        while (end < n && s.origin(end) == s.origin(i + 1))
            ++end;
    return {i + 1, end};
}

/// What the polygons of one pass may take as text: a program reads them line by line,
/// and a pass keeps them all until it is sent.
constexpr std::size_t max_geometry_bytes = std::size_t{1} << 28;

}  // namespace

std::vector<Query> EnvironmentalStep::queries_of(const lsys::TurtleString& pass,
                                                 const lsys::SymbolTable& symbols,
                                                 const geom::ViewFile& view, int communication,
                                                 std::vector<std::size_t>& offsets) const
{
    const lsys::ModuleString& string = pass.modules;
    // the ?E modules and, with `interpreted modules:`, the modules whose polygons go with them
    std::vector<std::size_t> communicating;
    for (std::size_t i = 0; i < string.size(); ++i)
        if (static_cast<int>(string.symbol(i)) == communication)
            communicating.push_back(i);
    std::vector<geom::ModuleRange> ranges;
    std::vector<std::size_t> range_of(communicating.size(), SIZE_MAX);
    // vlab's library expects polygons only with the following module, and, with `all`,
    // even after a ?E that ends the string (an empty block)
    if (m_spec.interpreted.any() && m_spec.following_module)
        for (std::size_t k = 0; k < communicating.size(); ++k) {
            const std::size_t i = communicating[k];
            const std::size_t after = pass.origin(i) + 1;
            const bool derived_after = i + 1 < string.size() && pass.origin(i + 1) != pass.origin(i);
            // the module named in `interpreted modules:` is the derived string's (manual 7.4.1)
            const lsys::ModuleString& named = derived_after ? pass.derived : string;
            const std::size_t x = derived_after ? after : i + 1;
            if (x < named.size() ? m_spec.interpreted.matches(symbols.name(named.symbol(x)),
                                                               named.param_count(x))
                                 : m_spec.interpreted.all) {
                range_of[k] = ranges.size();
                ranges.push_back(following_range(pass, i));
            }
        }
    std::vector<std::vector<geom::GlsPolygon>> polygons;
    const std::vector<geom::TurtleAtModule> turtles = geom::collect_communication_turtles(
        string, symbols, view, ranges, ranges.empty() ? nullptr : &polygons);
    const std::vector<std::size_t> offset_of = parameter_offsets(string);
    const std::vector<std::size_t> derived_offset_of =
        pass.origins.empty() ? std::vector<std::size_t>{} : parameter_offsets(pass.derived);
    std::vector<Query> queries;
    queries.reserve(turtles.size());
    offsets.clear();
    const std::size_t first = turtles.empty() ? 0 : turtles.front().module;
    std::size_t geometry_bytes = 0;
    for (std::size_t k = 0; k < turtles.size(); ++k) {
        geom::TurtleAtModule t = turtles[k];
        if (static_cast<int>(string.symbol(t.module)) != communication)
            continue;
        if (m_connection.placement)
            place(t, *m_connection.placement);
        Query q;
        // cpfg's addresses count from the pass's first ?E; a module count serves the same
        // purpose (programs echo them back) and keeps string order
        q.address = t.module - first;
        q.module = sent_module(string, t.module, offset_of[t.module], symbols);
        const std::size_t i = t.module;
        q.organ = pass.origin(i) + 1;
        if (m_spec.following_module && i + 1 < string.size()) {
            // the module after the ?E in the derived string, before the homomorphism
            if (!pass.origins.empty() && pass.origin(i + 1) != pass.origin(i))
                q.following = sent_module(pass.derived, pass.origin(i) + 1,
                                          derived_offset_of[pass.origin(i) + 1], symbols);
            else
                q.following = sent_module(string, i + 1, offset_of[i + 1], symbols);
        }
        q.position = sent_vector(m_spec.position, t.position);
        q.heading = sent_vector(m_spec.heading, t.heading);
        q.left = sent_vector(m_spec.left, t.left);
        q.up = sent_vector(m_spec.up, t.up);
        q.line_width = sent_scalar(m_spec.line_width, t.line_width);
        q.scale_factor = sent_scalar(m_spec.scale_factor, t.scale);
        const auto c = std::lower_bound(communicating.begin(), communicating.end(), i);
        if (c != communicating.end() && *c == i && range_of[c - communicating.begin()] != SIZE_MAX) {
            q.geometry.emplace();
            for (geom::GlsPolygon& p : polygons[range_of[c - communicating.begin()]]) {
                if (m_connection.placement)
                    for (geom::Vec3& v : p)
                        v = geom::Affine3x4(*m_connection.placement).apply(v);
                q.geometry->push_back(geom::gls_polygon_statement(p));
                geometry_bytes += q.geometry->back().size() + 1;
            }
            if (geometry_bytes > max_geometry_bytes)
                throw Error(m_spec.interpreted_loc,
                            "the polygons of the modules after ?E take more than " +
                                byte_size_text(max_geometry_bytes) +
                                " in one environmental pass (interpreted modules:); name fewer modules");
        }
        queries.push_back(std::move(q));
        offsets.push_back(offset_of[t.module]);
    }
    return queries;
}

void EnvironmentalStep::run(const lsys::TurtleString& pass, const lsys::SymbolTable& symbols,
                            const geom::ViewFile& view, int step)
{
    lsys::ModuleString& string = pass.modules;
    const int communication = symbols.find("?E");
    if (communication < 0)
        return;
    m_environment->observe(PassPlant{pass, symbols, view, 0,
                                     m_connection.placement ? &*m_connection.placement : nullptr});
    bool any = false;
    for (std::size_t i = 0; i < string.size() && !any; ++i)
        any = static_cast<int>(string.symbol(i)) == communication;
    if (!any) {
        m_environment->idle(step);  // cpfg sends nothing: the environment never sees this step
        return;
    }

    std::vector<std::size_t> offsets;
    const std::vector<Query> queries = queries_of(pass, symbols, view, communication, offsets);
    std::unordered_map<std::uint64_t, std::size_t> sent;
    sent.reserve(queries.size());
    for (std::size_t k = 0; k < queries.size(); ++k)
        sent.emplace(queries[k].address, k);
    const std::vector<Reply> replies = m_environment->pass(queries, step);
    ++m_passes;
    m_queries += queries.size();
    if (m_spec.verbose)
        std::fprintf(stderr, "environment: step %d: %zu ?E sent, %zu answers\n", step, queries.size(),
                     replies.size());

    float* params = string.mutable_params().data();
    for (const Reply& r : replies) {
        auto it = sent.find(r.address);
        if (it == sent.end())
            continue;  // cpfg ignores an answer to an address it did not send
        const Query& q = queries[it->second];
        for (std::size_t k = 0; k < r.params.size() && k < q.module.params.size(); ++k)
            if (r.params[k])
                params[offsets[it->second] + k] = through_g(*r.params[k]);
    }
}

}  // namespace cambium::env
