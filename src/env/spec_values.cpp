// SPDX-License-Identifier: Apache-2.0
#include "env/spec_values.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace cambium::env {

std::vector<std::string> value_tokens(const SpecLine& line)
{
    std::vector<std::string> tokens;
    const std::string& v = line.value;
    for (std::size_t i = 0; i < v.size();) {
        std::size_t end = v.find_first_of(" \t,;:x", i);
        if (end == std::string::npos)
            end = v.size();
        if (end > i)
            tokens.push_back(v.substr(i, end - i));
        i = end + 1;
    }
    return tokens;
}

std::vector<double> numbers_value(const SpecLine& line, std::size_t count)
{
    const std::vector<std::string> tokens = value_tokens(line);
    std::vector<double> numbers;
    for (std::size_t k = 0; k < count; ++k) {
        const char* text = k < tokens.size() ? tokens[k].c_str() : "";
        char* end = nullptr;
        const double v = std::strtod(text, &end);
        if (end == text || !std::isfinite(v))
            throw Error(line.loc, line.keyword + ": expected " + std::to_string(count) +
                                      (count == 1 ? " number" : " numbers") + ", found '" +
                                      line.value + "'");
        numbers.push_back(v);
    }
    return numbers;
}

double number_value(const SpecLine& line) { return numbers_value(line, 1)[0]; }

std::vector<double> leading_numbers(const SpecLine& line, std::size_t at_most)
{
    return numbers_value(line, std::min(at_most, value_tokens(line).size()));
}

std::vector<std::pair<int, std::string>> non_blank_lines(const std::string& text)
{
    std::vector<std::pair<int, std::string>> lines;
    std::istringstream in(text);
    int number = 0;
    for (std::string line; std::getline(in, line);) {
        ++number;
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        if (line.find_first_not_of(" \t") != std::string::npos)
            lines.emplace_back(number, std::move(line));
    }
    return lines;
}

bool switch_value(const SpecLine& line, std::initializer_list<const char*> words)
{
    const std::vector<std::string> tokens = value_tokens(line);
    if (tokens.empty())
        return false;
    for (const char* w : words)
        if (tokens[0] == w)
            return true;
    return false;
}

std::string spec_argument(const std::string& program, const std::vector<std::string>& args)
{
    for (const std::string& a : args)
        if (!a.empty() && a[0] != '-')
            return a;
    throw Error(program + ": no specification file among the program's arguments in the .e file");
}

}  // namespace cambium::env
