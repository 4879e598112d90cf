// SPDX-License-Identifier: Apache-2.0
// Reading and writing L-system strings in cpfg's text (-str) and binary (-strb) formats.
#include "lsys/string_io.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <istream>
#include <ostream>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "base/diagnostics.h"
#include "base/input_file.h"
#include "lsys/lexer.h"

namespace cambium::lsys {

namespace {

constexpr std::string_view binary_header = "L-system string:";
constexpr std::size_t flush_bytes = 1 << 20;
constexpr std::size_t max_string_file_bytes = std::size_t{1} << 34;  // 16 GiB

/// Writes through a byte buffer so that a string of millions of modules is not written
/// one ostream call per character.
class BufferedWriter {
public:
    explicit BufferedWriter(std::ostream& out) : m_out(out) { m_buf.reserve(flush_bytes + 256); }
    ~BufferedWriter() { flush(); }
    void put(char c)
    {
        m_buf.push_back(c);
        if (m_buf.size() >= flush_bytes)
            flush();
    }
    void put(std::string_view s)
    {
        m_buf.append(s);
        if (m_buf.size() >= flush_bytes)
            flush();
    }
    void flush()
    {
        m_out.write(m_buf.data(), static_cast<std::streamsize>(m_buf.size()));
        m_buf.clear();
    }

private:
    std::ostream& m_out;
    std::string m_buf;
};

/// Modules as cpfg stores them: one character each, the parameters on the character
/// they follow. Grouped into this project's module names afterwards.
struct RawModules {
    std::vector<char> chars;
    std::vector<std::uint8_t> counts;
    std::vector<float> params;
};

/// Groups raw characters into names as the L-system lexer does ("@" with the command
/// letters after it, "~" with its surface letter, "?" with P H L U E) and interns them.
ModuleString group_modules(const RawModules& raw, SymbolTable& symbols)
{
    ModuleString out;
    out.reserve(raw.chars.size(), raw.params.size());
    std::array<int, 256> single;
    single.fill(-1);
    std::unordered_map<std::string, SymbolId> multi;
    auto intern = [&](const std::string& name) -> SymbolId {
        if (name.size() == 1) {
            int& id = single[static_cast<unsigned char>(name[0])];
            if (id < 0)
                id = symbols.intern(name);
            return static_cast<SymbolId>(id);
        }
        auto it = multi.find(name);
        if (it != multi.end())
            return it->second;
        return multi.emplace(name, symbols.intern(name)).first->second;
    };
    const std::size_t n = raw.chars.size();
    std::size_t offset = 0;
    std::string name;
    for (std::size_t i = 0; i < n;) {
        char c = raw.chars[i];
        std::size_t take = 1;
        bool bare = raw.counts[i] == 0;
        auto bare_at = [&](std::size_t k) { return k < n && raw.counts[k] == 0; };
        if (bare && c == '@' && i + 1 < n) {
            take = 2;
            if (bare_at(i + 1) && i + 2 < n &&
                continues_at_command(raw.chars[i + 1], raw.chars[i + 2]))
                take = 3;
        } else if (bare && c == '~' && i + 1 < n) {
            take = 2;
        } else if (bare && c == '?' && i + 1 < n &&
                   std::string_view("PHLUE").find(raw.chars[i + 1]) != std::string_view::npos) {
            take = 2;
        }
        name.assign(raw.chars.begin() + static_cast<std::ptrdiff_t>(i),
                    raw.chars.begin() + static_cast<std::ptrdiff_t>(i + take));
        std::size_t count = raw.counts[i + take - 1];
        out.append(intern(name), std::span<const float>(raw.params.data() + offset, count));
        offset += count;
        i += take;
    }
    return out;
}

void check_module_limit(const RawModules& raw, const StringReadLimits& limits,
                        const FileLoc& loc)
{
    if (raw.chars.size() > limits.max_modules)
        throw Error(loc, "the string has more than " + std::to_string(limits.max_modules) +
                             " modules");
}

std::string read_all(std::istream& in, std::string_view source)
{
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad())
        throw Error(FileLoc{std::string(source), 0, 0}, "cannot read the string file");
    return std::move(ss).str();
}

std::ifstream open_input(const std::filesystem::path& file)
{
    regular_file_size(file, "the string file", max_string_file_bytes);
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw Error(FileLoc{file.string(), 0, 0}, "cannot open the string file");
    return in;
}

/// Text parser state: position with line and column for messages.
class TextReader {
public:
    TextReader(std::string_view text, std::string_view source) : m_text(text), m_source(source) {}

    RawModules read(const StringReadLimits& limits)
    {
        RawModules raw;
        for (;;) {
            skip_blanks();
            if (m_pos >= m_text.size())
                break;
            char c = m_text[m_pos];
            // ',' and ')' are modules (turtle commands); '(' only opens parameters
            if (c == '(')
                fail("unexpected '(' where a module name is expected");
            advance();
            raw.chars.push_back(c);
            raw.counts.push_back(static_cast<std::uint8_t>(read_params(raw.params)));
            if ((raw.chars.size() & 0xffff) == 0)
                check_module_limit(raw, limits, loc());
        }
        check_module_limit(raw, limits, loc());
        return raw;
    }

private:
    [[noreturn]] void fail(const std::string& message) const { throw Error(loc(), message); }
    FileLoc loc() const { return FileLoc{std::string(m_source), m_line, m_column}; }
    void advance()
    {
        if (m_text[m_pos] == '\n') {
            ++m_line;
            m_column = 1;
        } else {
            ++m_column;
        }
        ++m_pos;
    }
    void skip_blanks()
    {
        while (m_pos < m_text.size() && std::strchr(" \t\r\n\f\v", m_text[m_pos]) &&
               m_text[m_pos] != '\0')
            advance();
    }
    /// Reads "(v1,v2,...)" when it follows; returns the number of values.
    std::size_t read_params(std::vector<float>& params)
    {
        skip_blanks();
        if (m_pos >= m_text.size() || m_text[m_pos] != '(')
            return 0;
        advance();
        skip_blanks();
        if (m_pos < m_text.size() && m_text[m_pos] == ')') {
            advance();
            return 0;
        }
        std::size_t count = 0;
        for (;;) {
            skip_blanks();
            if (count == ModuleString::max_params)
                fail("a module has more than 255 parameters");
            params.push_back(read_number());
            ++count;
            skip_blanks();
            if (m_pos >= m_text.size())
                fail("the string ends inside a module's parameters; expected ')'");
            char sep = m_text[m_pos];
            advance();
            if (sep == ')')
                return count;
            if (sep != ',')
                fail(std::string("expected ',' or ')' after a parameter, found '") + sep + "'");
        }
    }
    float read_number()
    {
        std::size_t start = m_pos;
        if (m_pos < m_text.size() && m_text[m_pos] == '+')
            ++start;  // from_chars does not take a leading '+'
        float value = 0;
        const char* first = m_text.data() + start;
        const char* last = m_text.data() + m_text.size();
        auto [end, ec] = std::from_chars(first, last, value);
        if (ec == std::errc::invalid_argument || end == first)
            fail("expected a number as a module parameter");
        // out of float range: keep what cpfg's %f scanning gives (infinity or 0)
        while (m_pos < static_cast<std::size_t>(end - m_text.data()))
            advance();
        return value;
    }

    std::string_view m_text;
    std::string_view m_source;
    std::size_t m_pos = 0;
    int m_line = 1, m_column = 1;
};

/// Parses cpfg's binary string bytes (after the header line).
RawModules parse_binary_bytes(std::string_view bytes, std::string_view source,
                              const StringReadLimits& limits)
{
    RawModules raw;
    const FileLoc loc{std::string(source), 0, 0};
    std::size_t p = 0;
    while (p < bytes.size()) {
        char c = bytes[p++];
        if (c == '\0')
            break;
        std::size_t count = 0;
        if (p < bytes.size() && bytes[p] == '(') {
            ++p;
            for (;;) {
                if (p + sizeof(float) + 1 > bytes.size())
                    throw Error(loc, "the binary string ends inside a module's parameters");
                if (count == ModuleString::max_params)
                    throw Error(loc, "a module has more than 255 parameters");
                float v;
                std::memcpy(&v, bytes.data() + p, sizeof v);
                raw.params.push_back(v);
                ++count;
                p += sizeof(float);
                char sep = bytes[p++];
                if (sep == ')')
                    break;
                if (sep != ',')
                    throw Error(loc, "malformed binary string: expected ',' or ')' at byte " +
                                         std::to_string(p - 1));
            }
        }
        raw.chars.push_back(c);
        raw.counts.push_back(static_cast<std::uint8_t>(count));
        if ((raw.chars.size() & 0xffff) == 0)
            check_module_limit(raw, limits, loc);
    }
    check_module_limit(raw, limits, loc);
    return raw;
}

}  // namespace

void write_string_text(const ModuleString& string, const SymbolTable& symbols, std::ostream& out)
{
    std::vector<std::string_view> names(symbols.size());
    std::size_t longest = 0;
    for (std::size_t id = 0; id < names.size(); ++id) {
        names[id] = symbols.name(static_cast<SymbolId>(id));
        longest = std::max(longest, names[id].size());
    }
    // Written straight into a block; the most one module can add (a line break before
    // each name character, parentheses, numbers and commas) is left free before each.
    const std::size_t module_room =
        2 * longest + 2 + ModuleString::max_params * (max_parameter_chars + 1);
    std::vector<char> block(flush_bytes + module_room);
    char* const first = block.data();
    char* const flush_at = first + flush_bytes;
    char* to = first;
    auto flush = [&] {
        out.write(first, to - first);
        to = first;
    };
    int on_line = 0;
    const float* values = string.param_data();
    const std::uint8_t* counts = string.count_data();
    for (std::size_t i = 0, n = string.size(); i < n; ++i) {
        if (to >= flush_at)
            flush();
        for (char c : names[string.symbol(i)]) {
            if (on_line >= 70) {
                on_line = 0;
                *to++ = '\n';
            }
            *to++ = c;
            ++on_line;
        }
        std::size_t count = counts[i];
        if (count == 0)
            continue;
        *to++ = '(';
        for (std::size_t k = 0; k < count; ++k) {
            char* number = to;
            to = format_parameter(to, values[k]);
            on_line += static_cast<int>(to - number);
            *to++ = ',';  // cpfg does not count the commas
        }
        to[-1] = ')';
        on_line += 2;  // the parentheses
        values += count;
    }
    *to++ = '\n';
    flush();
}

void write_string_binary(const ModuleString& string, const SymbolTable& symbols,
                         std::ostream& out, int step)
{
    // the byte count comes first, so measure before writing
    std::size_t bytes = 0;
    string.for_each([&](ModuleRef m) {
        bytes += symbols.name(m.symbol).size();
        if (!m.params.empty())
            bytes += 1 + m.params.size() * (sizeof(float) + 1);
    });
    BufferedWriter w(out);
    w.put(binary_header);
    w.put(std::to_string(bytes) + " " + std::to_string(step) + "\n");
    string.for_each([&](ModuleRef m) {
        w.put(symbols.name(m.symbol));
        if (m.params.empty())
            return;
        w.put('(');
        for (std::size_t i = 0; i < m.params.size(); ++i) {
            char b[sizeof(float)];
            std::memcpy(b, &m.params[i], sizeof b);
            w.put(std::string_view(b, sizeof b));
            w.put(i + 1 == m.params.size() ? ')' : ',');
        }
    });
}

ModuleString read_string_text(std::istream& in, SymbolTable& symbols, std::string_view source,
                              const StringReadLimits& limits)
{
    std::string text = read_all(in, source);
    RawModules raw = TextReader(text, source).read(limits);
    return group_modules(raw, symbols);
}

ModuleString read_string_text(const std::filesystem::path& file, SymbolTable& symbols,
                              const StringReadLimits& limits)
{
    std::ifstream in = open_input(file);
    return read_string_text(in, symbols, file.string(), limits);
}

ModuleString read_string_binary(std::istream& in, SymbolTable& symbols, std::string_view source,
                                int* step, const StringReadLimits& limits)
{
    const FileLoc loc{std::string(source), 0, 0};
    std::string data = read_all(in, source);
    if (data.compare(0, binary_header.size(), binary_header) != 0)
        throw Error(loc, "not a cpfg binary string: it does not start with '" +
                             std::string(binary_header) + "'");
    std::size_t eol = data.find('\n', binary_header.size());
    if (eol == std::string::npos || eol - binary_header.size() > 64)
        throw Error(loc, "malformed binary string header");
    std::string line = data.substr(binary_header.size(), eol - binary_header.size());
    unsigned long long length = 0;
    int stored_step = 0;
    if (std::sscanf(line.c_str(), "%llu %d", &length, &stored_step) < 1)
        throw Error(loc, "malformed binary string header: no length");
    std::string_view body(data);
    body.remove_prefix(eol + 1);
    if (length > body.size())
        throw Error(loc, "the binary string is truncated: the header says " +
                             std::to_string(length) + " bytes, the file holds " +
                             std::to_string(body.size()));
    if (step)
        *step = stored_step;
    RawModules raw = parse_binary_bytes(body.substr(0, length), source, limits);
    return group_modules(raw, symbols);
}

ModuleString read_string_binary(const std::filesystem::path& file, SymbolTable& symbols,
                                int* step, const StringReadLimits& limits)
{
    std::ifstream in = open_input(file);
    return read_string_binary(in, symbols, file.string(), step, limits);
}

namespace {

/// The extent of the conversion starting at pattern[at] == '%' (flags, width,
/// precision, conversion letter), or throws.
std::size_t conversion_end(std::string_view pattern, std::size_t at, bool& is_integer)
{
    std::size_t j = at + 1;
    while (j < pattern.size() && std::string_view("-+ #0").find(pattern[j]) != std::string_view::npos)
        ++j;
    std::size_t digits = 0;
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9')
        ++j, ++digits;
    if (j < pattern.size() && pattern[j] == '.') {
        ++j;
        while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9')
            ++j, ++digits;
    }
    if (j >= pattern.size())
        throw Error("output name '" + std::string(pattern) + "' ends inside a '%' conversion");
    if (digits > 2)
        throw Error("output name '" + std::string(pattern) + "': field width too large");
    char c = pattern[j];
    is_integer = std::string_view("diouxX").find(c) != std::string_view::npos;
    if (c == '%' && j == at + 1)
        return j;
    if (!is_integer)
        throw Error("output name '" + std::string(pattern) + "': '%" + std::string(1, c) +
                    "' is not allowed; use one integer conversion such as %03d for the frame "
                    "number (and %% for a literal '%')");
    return j;
}

int count_conversions(std::string_view pattern)
{
    int conversions = 0;
    for (std::size_t i = 0; i < pattern.size(); ++i) {
        if (pattern[i] != '%')
            continue;
        bool is_integer = false;
        i = conversion_end(pattern, i, is_integer);
        conversions += is_integer ? 1 : 0;
    }
    if (conversions > 1)
        throw Error("output name '" + std::string(pattern) +
                    "' has more than one conversion; at most one (the frame number) is allowed");
    return conversions;
}

}  // namespace

bool is_frame_pattern(std::string_view pattern) { return count_conversions(pattern) == 1; }

std::string format_frame_name(std::string_view pattern, int frame)
{
    count_conversions(pattern);  // validates
    std::string out;
    for (std::size_t i = 0; i < pattern.size(); ++i) {
        if (pattern[i] != '%') {
            out += pattern[i];
            continue;
        }
        bool is_integer = false;
        std::size_t end = conversion_end(pattern, i, is_integer);
        if (!is_integer) {
            out += '%';
        } else {
            std::string spec(pattern.substr(i, end - i + 1));
            char buf[128];
            int n = std::snprintf(buf, sizeof buf, spec.c_str(), frame);
            if (n > 0)
                out.append(buf, static_cast<std::size_t>(std::min(n, static_cast<int>(sizeof buf) - 1)));
        }
        i = end;
    }
    return out;
}

}  // namespace cambium::lsys
