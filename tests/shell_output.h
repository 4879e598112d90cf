// SPDX-License-Identifier: Apache-2.0
// Runs a shell command line and collects what it prints: how the end-to-end tests run the
// cambium command as a user does.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace cambium::test {

/// What a command printed (stdout and stderr together) and its wait status (pclose's:
/// 0 for success).
struct CommandResult {
    int status = 0;
    std::string output;
};

/// Runs `command` with /bin/sh (in `folder` when given), its stderr merged into stdout.
inline CommandResult run_shell(const std::string& command, const std::filesystem::path& folder = {})
{
    std::string line = command + " 2>&1";
    if (!folder.empty())
        line = "cd '" + folder.string() + "' && " + line;
    CommandResult r;
    FILE* pipe = popen(line.c_str(), "r");
    if (!pipe)
        return {-1, "popen failed: " + line};
    std::array<char, 512> buffer{};
    while (fgets(buffer.data(), buffer.size(), pipe))
        r.output += buffer.data();
    r.status = pclose(pipe);
    return r;
}

}  // namespace cambium::test
