// SPDX-License-Identifier: Apache-2.0
#include "env/environmental_step.h"

#include <cstdio>
#include <unordered_map>

#include "env/builtins.h"
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
    auto linear = [&](const geom::Vec3& v) {
        return geom::Vec3{m[0] * v.x + m[3] * v.y + m[6] * v.z, m[1] * v.x + m[4] * v.y + m[7] * v.z,
                          m[2] * v.x + m[5] * v.y + m[8] * v.z};
    };
    const geom::Vec3 p = linear(t.position);
    t.position = {p.x + m[9], p.y + m[10], p.z + m[11]};
    for (geom::Vec3* v : {&t.heading, &t.left, &t.up})
        *v = geom::normalize(linear(*v));
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
                        "chiba, clover); a model file starts a program only with "
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

std::vector<Query> EnvironmentalStep::queries_of(const lsys::ModuleString& string,
                                                 const lsys::SymbolTable& symbols,
                                                 const geom::ViewFile& view, int communication,
                                                 std::vector<std::size_t>& offsets) const
{
    const std::vector<geom::TurtleAtModule> turtles =
        geom::collect_communication_turtles(string, symbols, view);
    // parameter offsets of every module (the turtle reports module indices)
    std::vector<std::size_t> offset_of(string.size() + 1, 0);
    for (std::size_t i = 0; i < string.size(); ++i)
        offset_of[i + 1] = offset_of[i] + string.param_count(i);
    std::vector<Query> queries;
    queries.reserve(turtles.size());
    offsets.clear();
    const std::size_t first = turtles.empty() ? 0 : turtles.front().module;
    for (geom::TurtleAtModule t : turtles) {
        if (static_cast<int>(string.symbol(t.module)) != communication)
            continue;
        if (m_connection.placement)
            place(t, *m_connection.placement);
        Query q;
        // cpfg's addresses count from the pass's first ?E; a module count serves the same
        // purpose (programs echo them back) and keeps string order
        q.address = t.module - first;
        q.module = sent_module(string, t.module, offset_of[t.module], symbols);
        if (m_spec.following_module && t.module + 1 < string.size())
            q.following = sent_module(string, t.module + 1, offset_of[t.module + 1], symbols);
        q.position = sent_vector(m_spec.position, t.position);
        q.heading = sent_vector(m_spec.heading, t.heading);
        q.left = sent_vector(m_spec.left, t.left);
        q.up = sent_vector(m_spec.up, t.up);
        q.line_width = sent_scalar(m_spec.line_width, t.line_width);
        q.scale_factor = sent_scalar(m_spec.scale_factor, t.scale);
        queries.push_back(std::move(q));
        offsets.push_back(offset_of[t.module]);
    }
    return queries;
}

void EnvironmentalStep::run(lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                            const geom::ViewFile& view, int step)
{
    const int communication = symbols.find("?E");
    if (communication < 0)
        return;
    bool any = false;
    for (std::size_t i = 0; i < string.size() && !any; ++i)
        any = static_cast<int>(string.symbol(i)) == communication;
    if (!any) {
        m_environment->idle(step);  // cpfg sends nothing: the environment never sees this step
        return;
    }

    std::vector<std::size_t> offsets;
    const std::vector<Query> queries = queries_of(string, symbols, view, communication, offsets);
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
