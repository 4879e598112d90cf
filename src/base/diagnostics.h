// SPDX-License-Identifier: Apache-2.0
// User-facing diagnostics: source locations, errors that name them, and warnings collected
// by an injectable sink.
#pragma once

#include <cstddef>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace cambium {

/// A position in a user's input file (1-based line and column; 0 = unknown).
struct FileLoc {
    std::string file;
    int line = 0;
    int column = 0;

    /// "file:line:col", "file:line" or "file", as much as is known.
    std::string to_string() const;
};

/// An error in user input or in the environment that ends the command.
/// what() is the complete message, e.g. "plant.l:12:7: error: expected '-->'".
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message);
    Error(const FileLoc& loc, const std::string& message);

    const FileLoc& loc() const { return m_loc; }

private:
    FileLoc m_loc;
};

enum class Severity { warning, error };

/// One message: what, where, how bad.
struct Diagnostic {
    Severity severity = Severity::warning;
    FileLoc loc;
    std::string message;

    /// "loc: warning: message", as printed.
    std::string to_string() const;
};

/// Where the diagnostics of one run (a load, a render, a command) go: kept in order, each
/// distinct text once per sink (a second run with its own sink hears the same warning
/// again), and warnings printed to stderr as they come unless quiet. Errors are kept but
/// not printed: they reach the user in the Error that ends the run (see ErrorList).
/// Thread-safe.
/// A library user or a test makes one, installs it with ScopedDiagnostics, and reads
/// collected() or count() afterwards.
class Diagnostics {
public:
    enum class Output { print, quiet };
    explicit Diagnostics(Output output = Output::print) : m_output(output) {}

    void report(Severity severity, const FileLoc& loc, const std::string& message);

    /// Every distinct diagnostic so far, in order.
    std::vector<Diagnostic> collected() const;
    std::size_t count(Severity severity) const;
    /// Every collected diagnostic's to_string(), one a line.
    std::string text() const;
    void set_output(Output output);

private:
    mutable std::mutex m_mutex;
    Output m_output;
    std::set<std::string> m_said;
    std::vector<Diagnostic> m_list;
};

/// Installs `sink` as where warn() reports while it lives, then restores what was there.
/// Reach::this_thread (the default) is for tests and libraries that may run several loads
/// at once: only warn() calls made on this thread go to the sink. Reach::process also
/// takes every thread that has no sink of its own (worker threads): for a command, whose
/// run is the whole process. Without any installed sink, warn() goes to a process-wide
/// default that prints to stderr (each text once per process).
class ScopedDiagnostics {
public:
    enum class Reach { this_thread, process };
    explicit ScopedDiagnostics(Diagnostics& sink, Reach reach = Reach::this_thread);
    ~ScopedDiagnostics();
    ScopedDiagnostics(const ScopedDiagnostics&) = delete;
    ScopedDiagnostics& operator=(const ScopedDiagnostics&) = delete;

private:
    Reach m_reach;
    Diagnostics* m_previous;
};

/// Reports "loc: warning: message" to the installed sink (see ScopedDiagnostics).
void warn(const FileLoc& loc, const std::string& message);
void warn(const std::string& message);

/// The errors of one input file, so that a reader can go on after an error (at the next
/// production, the next line) and report several before failing. Each added error goes
/// to the installed sink (Severity::error, with its location); finish() then throws one
/// Error: the error itself when there was one, else "FILE: error: N errors:" followed by
/// each, one a line. The `limit`-th error throws at once (a file of garbage stops early).
class ErrorList {
public:
    static constexpr std::size_t default_limit = 20;
    explicit ErrorList(std::string file, std::size_t limit = default_limit);

    void add(const Error& error);
    std::size_t size() const { return m_errors.size(); }
    /// Throws when any error was added; returns otherwise.
    void finish() const;

private:
    [[noreturn]] void throw_summary(const std::string& note) const;

    std::string m_file;
    std::size_t m_limit;
    std::vector<Error> m_errors;
};

/// Silences (drops what would reach it) or restores the process-wide default sink; an
/// installed sink is not affected.
void set_warnings_enabled(bool enabled);

}  // namespace cambium
