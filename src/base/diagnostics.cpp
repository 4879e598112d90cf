// SPDX-License-Identifier: Apache-2.0
// User-facing diagnostics: source locations, errors that name them, and warnings collected
// by an injectable sink.
#include "base/diagnostics.h"

#include <atomic>
#include <cstdio>
#include <utility>

namespace cambium {

std::string FileLoc::to_string() const
{
    // Appended piece by piece: `":" + std::to_string(n)` trips GCC 12's false
    // -Wrestrict on the inlined insert (GCC bug 105329).
    std::string s = file;
    if (line > 0) {
        s.push_back(':');
        s.append(std::to_string(line));
        if (column > 0) {
            s.push_back(':');
            s.append(std::to_string(column));
        }
    }
    return s;
}

namespace {

std::string located(const FileLoc& loc, const char* kind, const std::string& message)
{
    std::string where = loc.to_string();
    return (where.empty() ? std::string() : where + ": ") + kind + ": " + message;
}

/// The sink of warn() calls on threads with none installed: stderr, once per process.
Diagnostics& process_default()
{
    static Diagnostics sink;
    return sink;
}

std::atomic<Diagnostics*> g_process{nullptr};  ///< Reach::process installs (null: default)
thread_local Diagnostics* t_current = nullptr;  ///< Reach::this_thread installs
std::atomic<bool> g_default_enabled{true};      ///< set_warnings_enabled

/// Where warn() goes now; null when that is the silenced default.
Diagnostics* current_sink()
{
    if (t_current)
        return t_current;
    if (Diagnostics* process = g_process.load())
        return process;
    return g_default_enabled ? &process_default() : nullptr;
}

}  // namespace

Error::Error(const std::string& message) : std::runtime_error("error: " + message) {}

Error::Error(const FileLoc& loc, const std::string& message)
    : std::runtime_error(located(loc, "error", message)), m_loc(loc)
{
}

std::string Diagnostic::to_string() const
{
    return located(loc, severity == Severity::error ? "error" : "warning", message);
}

void Diagnostics::report(Severity severity, const FileLoc& loc, const std::string& message)
{
    Diagnostic d{severity, loc, message};
    std::string text = d.to_string();
    std::lock_guard lock(m_mutex);
    if (!m_said.insert(text).second)
        return;
    m_list.push_back(std::move(d));
    if (m_output == Output::print && severity == Severity::warning)
        std::fprintf(stderr, "%s\n", text.c_str());
}

std::vector<Diagnostic> Diagnostics::collected() const
{
    std::lock_guard lock(m_mutex);
    return m_list;
}

std::size_t Diagnostics::count(Severity severity) const
{
    std::lock_guard lock(m_mutex);
    std::size_t n = 0;
    for (const Diagnostic& d : m_list)
        n += d.severity == severity ? 1 : 0;
    return n;
}

std::string Diagnostics::text() const
{
    std::string out;
    for (const Diagnostic& d : collected())
        out += d.to_string() + "\n";
    return out;
}

void Diagnostics::set_output(Output output)
{
    std::lock_guard lock(m_mutex);
    m_output = output;
}

ScopedDiagnostics::ScopedDiagnostics(Diagnostics& sink, Reach reach) : m_reach(reach)
{
    if (reach == Reach::process) {
        m_previous = g_process.exchange(&sink);
    } else {
        m_previous = t_current;
        t_current = &sink;
    }
}

ScopedDiagnostics::~ScopedDiagnostics()
{
    if (m_reach == Reach::process)
        g_process.store(m_previous);
    else
        t_current = m_previous;
}

void warn(const FileLoc& loc, const std::string& message)
{
    if (Diagnostics* sink = current_sink())
        sink->report(Severity::warning, loc, message);
}

void warn(const std::string& message) { warn(FileLoc{}, message); }

ErrorList::ErrorList(std::string file, std::size_t limit) : m_file(std::move(file)), m_limit(limit) {}

void ErrorList::add(const Error& error)
{
    if (m_errors.size() >= m_limit)  // the summary itself, on its way out
        throw_summary(" (stopped after " + std::to_string(m_limit) + ")");
    if (Diagnostics* sink = current_sink()) {
        // the message without its "loc: error: " prefix, which to_string() writes again
        std::string text = error.what();
        std::string prefix = located(error.loc(), "error", "");
        sink->report(Severity::error, error.loc(), text.starts_with(prefix) ? text.substr(prefix.size()) : text);
    }
    m_errors.push_back(error);
    if (m_errors.size() >= m_limit)
        throw_summary(" (stopped after " + std::to_string(m_limit) + ")");
}

void ErrorList::finish() const
{
    if (m_errors.size() == 1)
        throw m_errors.front();
    if (!m_errors.empty())
        throw_summary("");
}

void ErrorList::throw_summary(const std::string& note) const
{
    std::string message = std::to_string(m_errors.size()) + " errors" + note + ":";
    for (const Error& e : m_errors) {
        message.push_back('\n');
        message.append(e.what());
    }
    throw Error(FileLoc{m_file, 0, 0}, message);
}

// A silenced default drops warnings instead of remembering them, so a warning first met
// while silenced is still printed the next time once warnings are back on.
void set_warnings_enabled(bool enabled) { g_default_enabled = enabled; }

}  // namespace cambium
