// SPDX-License-Identifier: Apache-2.0
// User-facing diagnostics: source locations, errors that name them, and warnings.
#include "base/diagnostics.h"

#include <atomic>
#include <cstdio>
#include <mutex>
#include <set>

namespace cambium {

std::string FileLoc::to_string() const
{
    std::string s = file;
    if (line > 0) {
        s += ":" + std::to_string(line);
        if (column > 0)
            s += ":" + std::to_string(column);
    }
    return s;
}

namespace {
std::string located(const FileLoc& loc, const char* kind, const std::string& message)
{
    std::string where = loc.to_string();
    return (where.empty() ? std::string() : where + ": ") + kind + ": " + message;
}

std::atomic<bool> g_warnings_enabled{true};
}  // namespace

Error::Error(const std::string& message) : std::runtime_error("error: " + message) {}

Error::Error(const FileLoc& loc, const std::string& message)
    : std::runtime_error(located(loc, "error", message)), m_loc(loc)
{
}

void warn(const FileLoc& loc, const std::string& message)
{
    if (!g_warnings_enabled)
        return;
    static std::mutex mutex;
    static std::set<std::string> said;
    std::string text = located(loc, "warning", message);
    std::lock_guard lock(mutex);
    if (said.insert(text).second)
        std::fprintf(stderr, "%s\n", text.c_str());
}

void warn(const std::string& message) { warn(FileLoc{}, message); }

void set_warnings_enabled(bool enabled) { g_warnings_enabled = enabled; }

}  // namespace cambium
