// SPDX-License-Identifier: Apache-2.0
#include "env/comm_spec.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "env/spec_values.h"
#include "geom/text_input.h"

namespace cambium::env {
namespace {

/// Longest format accepted: far beyond any real one, and a bound on what it prints.
constexpr std::size_t max_format_length = 200;

/// Checks that `text` holds only literal text, "%%" and floating-point conversions
/// ([flags][width][.precision] f e E g G a A), at most `most` of them; a model file's
/// format is never handed to printf otherwise.
TurtleFormat checked_format(const std::string& text, int most, const FileLoc& loc)
{
    if (text.size() > max_format_length)
        throw Error(loc, "format longer than " + std::to_string(max_format_length) + " characters");
    TurtleFormat f{text, 0};
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] != '%')
            continue;
        const std::size_t start = i++;
        if (i < text.size() && text[i] == '%')
            continue;
        while (i < text.size() && std::string_view("-+ #0").find(text[i]) != std::string_view::npos)
            ++i;
        auto digits = [&] {
            std::size_t n = 0;
            for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i)
                ++n;
            return n;
        };
        std::size_t width = digits(), precision = 0;
        if (i < text.size() && text[i] == '.') {
            ++i;
            precision = digits();
        }
        FileLoc at{loc.file, loc.line, loc.column + static_cast<int>(start)};
        if (width > 2 || precision > 2)
            throw Error(at, "a field width or precision of more than two digits");
        if (i >= text.size() || std::string_view("feEgGaA").find(text[i]) == std::string_view::npos)
            throw Error(at, "a turtle field's format may only convert numbers (%f %e %g %a)");
        if (++f.conversions > most)
            throw Error(at, "more conversions than the field has values (" + std::to_string(most) + ")");
    }
    return f;
}

bool yes(const std::string& value) { return value.rfind("yes", 0) == 0 || value.rfind("on", 0) == 0; }

}  // namespace

float through_g(float value)
{
    char text[64];
    std::snprintf(text, sizeof text, "%g", static_cast<double>(value));
    return static_cast<float>(std::atof(text));
}

int send_through_format(const TurtleFormat& format, const double* values, int count, float* out)
{
    char text[max_format_length * 2 + 4 * 400];
    double v[3] = {0, 0, 0};
    for (int k = 0; k < count && k < 3; ++k)
        v[k] = values[k];
    // the format was checked: only %f %e %g %a conversions, at most `count` of them
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
    std::snprintf(text, sizeof text, format.format.c_str(), v[0], v[1], v[2]);
#pragma GCC diagnostic pop
    const std::size_t prefix = std::min(format.format.find('%'), format.format.size());
    const char* body = std::string_view(text).size() >= prefix ? text + prefix : text;
    float read[3] = {0, 0, 0};
    int n = std::sscanf(body, "%f %f %f", &read[0], &read[1], &read[2]);
    n = std::max(0, std::min(n, count));
    for (int k = 0; k < n; ++k)
        out[k] = read[k];
    return n;
}

bool InterpretedModules::matches(std::string_view name, std::size_t params) const
{
    if (all)
        return true;
    for (const InterpretedModule& m : modules)
        if (m.name == name)
            return !m.params || static_cast<std::size_t>(*m.params) == params;
    return false;
}

namespace {

/// `all`, or entries `M` / `M(n)` separated by blanks, commas or semicolons, read as vlab's
/// library reads them (cpfg and the program must agree on which ?E carry polygons): a
/// module is told by its one character, n is 0..6, a later entry for the same module
/// replaces an earlier one, and nothing after `all` counts.
InterpretedModules interpreted_modules(const std::string& value, const FileLoc& at)
{
    InterpretedModules result;
    std::size_t i = 0;
    auto separator = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == ';'; };
    while (i < value.size() && !result.all) {
        if (separator(value[i])) {
            ++i;
            continue;
        }
        std::size_t end = i;
        while (end < value.size() && !separator(value[end]))
            ++end;
        const std::string word = value.substr(i, end - i);
        const FileLoc loc{at.file, at.line, at.column + static_cast<int>(i)};
        i = end;
        if (word == "all") {
            result.all = true;
            result.modules.clear();
            continue;
        }
        const bool counted = word.size() == 4 && word[1] == '(' && word[3] == ')';
        if (word.size() != 1 && !counted)
            throw Error(loc, "interpreted modules: expected a one-character module M or M(n), found '" +
                                 word + "' (vlab's library tells modules apart by one character)");
        InterpretedModule m{word.substr(0, 1), std::nullopt};
        if (counted) {
            if (word[2] < '0' || word[2] > '6')
                throw Error(loc, "interpreted modules: the parameter count in '" + word +
                                     "' must be 0 to 6");
            m.params = word[2] - '0';
        }
        std::erase_if(result.modules, [&](const InterpretedModule& e) { return e.name == m.name; });
        result.modules.push_back(std::move(m));
    }
    return result;
}

}  // namespace

CommSpec read_comm_spec(const std::filesystem::path& file)
{
    CommSpec spec;
    spec.file = file;
    const std::string text = geom::read_text_file(file, "communication specification file");
    for (const auto& [number, line] : non_blank_lines(text)) {
        const std::size_t colon = line.find(':');
        const FileLoc loc{file.string(), number, 1};
        if (colon == std::string::npos)
            throw Error(loc, "expected 'command: value', found '" + line + "'");
        const std::string name = geom::normalize_command_name(line.substr(0, colon));
        // a format keeps its blanks; other values lose the leading ones
        const std::string raw = line.substr(colon + 1);
        const std::size_t first = std::min(raw.size(), raw.find_first_not_of(" \t"));
        const std::string value = raw.substr(first);
        const FileLoc at{file.string(), number, static_cast<int>(colon + 2 + first)};
        const FileLoc raw_at{file.string(), number, static_cast<int>(colon + 2)};
        if (name == "executable") {
            std::istringstream words(value);
            for (std::string w; words >> w;) {
                if (w == "-e" && !spec.executable.empty()) {
                    words >> w;  // cpfg's own `-e file`, which it adds when missing
                    continue;
                }
                spec.executable.push_back(w);
            }
            spec.executable_loc = at;
        } else if (name == "communication type") {
            std::istringstream words(value);
            words >> spec.communication_type;
            if (spec.communication_type != "pipes" && spec.communication_type != "sockets" &&
                spec.communication_type != "memory" && spec.communication_type != "files")
                throw Error(at, "communication type: expected pipes, sockets, memory or files, found '" +
                                    value + "'");
            // the chunk size, as atoi reads it; past a million it only costs memory
            std::string count;
            if (words >> count)
                spec.queries_per_chunk = static_cast<int>(
                    std::clamp(std::strtol(count.c_str(), nullptr, 10), 0L, 1'000'000L));
        } else if (name == "following module") {
            spec.following_module = yes(value);
        } else if (name == "verbose") {
            spec.verbose = yes(value);
        } else if (name == "interpreted modules") {
            spec.interpreted = interpreted_modules(value, at);
            spec.interpreted_loc = at;
        } else if (name == "turtle position" || name == "turtle heading" || name == "turtle left" ||
                   name == "turtle up") {
            TurtleFormat f = checked_format(raw, 3, raw_at);
            (name == "turtle position" ? spec.position
             : name == "turtle heading" ? spec.heading
             : name == "turtle left"    ? spec.left
                                        : spec.up) = f;
        } else if (name == "turtle line width" || name == "turtle scale factor") {
            TurtleFormat f = checked_format(raw, 1, raw_at);
            (name == "turtle line width" ? spec.line_width : spec.scale_factor) = f;
        } else {
            throw Error(loc, "unknown command '" + line.substr(0, colon) +
                                 "' in a communication specification file (manual 7.4.1)");
        }
    }
    if (spec.executable.empty())
        throw Error(FileLoc{file.string()}, "no 'executable:' line names the environmental program");
    return spec;
}

}  // namespace cambium::env
