// SPDX-License-Identifier: Apache-2.0
// Reading cpfg's small text formats: bounded file reads, comment removal, value tokens.
#include "geom/text_input.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>

namespace cambium::geom {

std::string read_text_file(const std::filesystem::path& file, const char* what)
{
    return read_file(file, what, max_text_file_bytes);
}

std::vector<SourceLine> split_lines_without_comments(std::string_view text)
{
    std::vector<SourceLine> lines;
    std::string current;
    int number = 1;
    bool in_block = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        char c = text[i];
        if (c == '\n') {
            lines.push_back({number++, current});
            current.clear();
            continue;
        }
        if (in_block) {
            if (c == '*' && i + 1 < text.size() && text[i + 1] == '/') {
                in_block = false;
                current += "  ";
                ++i;
            } else {
                current += ' ';
            }
        } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
            in_block = true;
            current += "  ";
            ++i;
        } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
            while (i + 1 < text.size() && text[i + 1] != '\n')
                ++i;
        } else {
            current += c;
        }
    }
    if (!current.empty())
        lines.push_back({number, current});
    return lines;
}

std::string normalize_command_name(std::string_view name)
{
    std::string out;
    bool space = false;
    for (char c : name) {
        if (std::isspace(static_cast<unsigned char>(c))) {
            space = !out.empty();
            continue;
        }
        if (space)
            out += ' ';
        space = false;
        out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    return out;
}

ValueReader::ValueReader(std::string_view line, std::size_t start, FileLoc line_loc)
    : m_line(line), m_pos(start), m_loc(std::move(line_loc))
{
}

void ValueReader::skip_separators()
{
    while (m_pos < m_line.size() &&
           (std::isspace(static_cast<unsigned char>(m_line[m_pos])) || m_line[m_pos] == ','))
        ++m_pos;
}

bool ValueReader::at_end()
{
    skip_separators();
    return m_pos >= m_line.size();
}

FileLoc ValueReader::loc()
{
    skip_separators();
    FileLoc l = m_loc;
    l.column = static_cast<int>(m_pos) + 1;
    return l;
}

Error ValueReader::error(const std::string& message) { return Error(loc(), message); }

double ValueReader::number()
{
    if (at_end())
        throw error("expected a number");
    std::string token;
    std::size_t end = m_pos;
    while (end < m_line.size() && !std::isspace(static_cast<unsigned char>(m_line[end])) &&
           m_line[end] != ',')
        ++end;
    token = std::string(m_line.substr(m_pos, end - m_pos));
    char* stop = nullptr;
    errno = 0;
    double value = std::strtod(token.c_str(), &stop);
    if (stop == token.c_str() || errno == ERANGE || !std::isfinite(value))
        throw error("expected a number, found '" + token + "'");
    // "0.5abc": consume only the numeric prefix and let the next read complain.
    m_pos += static_cast<std::size_t>(stop - token.c_str());
    return value;
}

int ValueReader::integer()
{
    FileLoc where = loc();
    double value = number();
    if (value != std::floor(value) || std::fabs(value) > 1e9)
        throw Error(where, "expected an integer");
    return static_cast<int>(value);
}

std::string ValueReader::word(const char* what)
{
    if (at_end())
        throw error(std::string("expected ") + what);
    std::string out;
    while (m_pos < m_line.size()) {
        char c = m_line[m_pos];
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-' &&
            c != '%')
            break;
        out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        ++m_pos;
    }
    if (out.empty())
        throw error(std::string("expected ") + what);
    return out;
}

bool ValueReader::on_off()
{
    FileLoc where = loc();
    std::string found = word("on or off");
    if (found == "on")
        return true;
    if (found == "off")
        return false;
    throw Error(where, "expected 'on' or 'off', found '" + found + "'");
}

std::string ValueReader::name(const char* what)
{
    if (at_end())
        throw error(std::string("expected ") + what);
    std::size_t start = m_pos;
    while (m_pos < m_line.size() && !std::isspace(static_cast<unsigned char>(m_line[m_pos])) &&
           m_line[m_pos] != ',')
        ++m_pos;
    return std::string(m_line.substr(start, m_pos - start));
}

std::string ValueReader::rest()
{
    while (m_pos < m_line.size() && std::isspace(static_cast<unsigned char>(m_line[m_pos])))
        ++m_pos;
    std::string_view text = m_line.substr(std::min(m_pos, m_line.size()));
    m_pos = m_line.size();
    std::size_t last = text.find_last_not_of(" \t\r");
    return std::string(last == std::string_view::npos ? std::string_view() : text.substr(0, last + 1));
}

char ValueReader::subcommand(const char* what)
{
    if (at_end() || !std::isalpha(static_cast<unsigned char>(m_line[m_pos])))
        throw error(std::string("expected ") + what);
    char c = static_cast<char>(std::toupper(static_cast<unsigned char>(m_line[m_pos++])));
    if (m_pos < m_line.size() && m_line[m_pos] == ':')
        ++m_pos;
    return c;
}

void ValueReader::expect_label(const std::string& label)
{
    FileLoc where = loc();
    std::string found = at_end() ? std::string() : word(("'" + label + ":'").c_str());
    if (found != label)
        throw Error(where, "expected '" + label + ":'");
    if (m_pos < m_line.size() && m_line[m_pos] == ':')
        ++m_pos;
}

}  // namespace cambium::geom
