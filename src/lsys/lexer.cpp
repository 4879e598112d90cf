// SPDX-License-Identifier: Apache-2.0
// Tokens of the cpfg L-system language, lexed in cpfg's two modes (modules, expressions).
#include "lsys/lexer.h"

#include <array>
#include <cctype>
#include <cstdlib>
#include <span>

namespace cambium::lsys {

namespace {

/// Section keywords, recognised in either mode as cpfg's lexer does (longest match wins
/// over a one-character module name). A space in the pattern is optional; letters match
/// in either case.
constexpr std::array<std::string_view, 18> keywords = {
    "derivation length:", "maximum depth:", "start each:", "end each:", "ring lsystem",
    "homomorphism:", "decomposition:", "homomorphism", "decomposition", "no warnings",
    "endlsystem", "lsystem:", "consider:", "ignore:", "axiom:", "define:", "start:", "end:",
};
constexpr std::array<std::string_view, 2> late_keywords = {"seed:", "warnings"};

bool is_name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; }
bool is_name_char(char c)
{
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}
bool is_digit(char c) { return c >= '0' && c <= '9'; }

/// The canonical keyword spelling without its optional ':' ("homomorphism:" -> "homomorphism").
std::string canonical(std::string_view keyword)
{
    if (keyword == "homomorphism:" || keyword == "decomposition:")
        keyword.remove_suffix(1);
    return std::string(keyword);
}

}  // namespace

bool continues_at_command(char first, char second)
{
    std::string_view set;
    switch (first) {
    case 'G': set = "sectr"; break;
    case 'T': set = "sxfpid"; break;
    case 'P': set = "SCD"; break;
    case 'D': set = "dies"; break;
    case 'm': set = "c"; break;  // @mc, the conditional cut
    default: return false;
    }
    return second != '\0' && set.find(second) != std::string_view::npos;
}

Lexer::Lexer(std::string_view text, std::string file_name) : m_text(text)
{
    m_state.file = std::move(file_name);
}

char Lexer::at(std::size_t offset) const
{
    std::size_t p = m_state.pos + offset;
    return p < m_text.size() ? m_text[p] : '\0';
}

void Lexer::advance(std::size_t n)
{
    for (std::size_t i = 0; i < n && m_state.pos < m_text.size(); ++i) {
        if (m_text[m_state.pos] == '\n') {
            ++m_state.line;
            m_state.column = 1;
            m_state.at_line_start = true;
        } else {
            ++m_state.column;
            m_state.at_line_start = false;
        }
        ++m_state.pos;
    }
}

Token Lexer::make(TokenKind kind, std::string text, const FileLoc& loc) const
{
    Token t;
    t.kind = kind;
    t.text = std::move(text);
    t.loc = loc;
    return t;
}

bool Lexer::skip_line_marker()
{
    // "# 12 "file" flags" or "#line 12 "file"", written by cpp
    std::size_t p = m_state.pos + 1;
    if (m_text.compare(p, 5, "line ") == 0)
        p += 5;
    else if (at(1) == ' ')
        p += 1;
    else
        return false;
    if (p >= m_text.size() || !is_digit(m_text[p]))
        return false;
    std::size_t eol = m_text.find('\n', p);
    std::string_view line = m_text.substr(p, eol == std::string_view::npos ? eol : eol - p);
    // (a line number past int's range, which cpp never writes, counts as unknown)
    long long marked = std::strtoll(std::string(line).c_str(), nullptr, 10);
    int number = marked > 0 && marked <= 1'000'000'000 ? static_cast<int>(marked) : 0;
    std::size_t open = line.find('"');
    std::size_t close = line.rfind('"');
    if (open != std::string_view::npos && close > open)
        m_state.file = std::string(line.substr(open + 1, close - open - 1));
    m_state.pos = eol == std::string_view::npos ? m_text.size() : eol + 1;
    m_state.line = number;
    m_state.column = 1;
    m_state.at_line_start = true;
    return true;
}

void Lexer::skip_comment()
{
    advance(2);
    while (m_state.pos < m_text.size() && !(at() == '*' && at(1) == '/'))
        advance();
    advance(2);
}

bool Lexer::skip_blanks()
{
    while (m_state.pos < m_text.size()) {
        char c = at();
        if (m_state.at_line_start && c == '#' && skip_line_marker())
            continue;
        if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            advance();
        } else if (c == '/' && at(1) == '*') {
            skip_comment();
        } else if (c == '\n') {
            if (at(1) != '\t' && m_state.brace_depth == 0)
                return true;  // the Eol token is produced at the newline
            advance();
        } else {
            return false;
        }
    }
    return false;
}

bool Lexer::lex_keyword(LexMode mode, Token& token)
{
    if (!is_name_start(at()))
        return false;
    auto try_match = [&](std::string_view kw) -> std::size_t {
        std::size_t p = m_state.pos;
        for (char k : kw) {
            if (k == ' ') {
                if (p < m_text.size() && m_text[p] == ' ')
                    ++p;
                continue;
            }
            if (p >= m_text.size() ||
                std::tolower(static_cast<unsigned char>(m_text[p])) != k)
                return 0;
            ++p;
        }
        return p - m_state.pos;
    };
    std::size_t name_len = 0;
    while (is_name_char(at(name_len)))
        ++name_len;
    for (auto list : {std::span<const std::string_view>(keywords),
                      std::span<const std::string_view>(late_keywords)}) {
        for (std::string_view kw : list) {
            std::size_t len = try_match(kw);
            if (len == 0)
                continue;
            bool ends_with_colon = kw.back() == ':';
            if (mode == LexMode::Expression && !ends_with_colon && len < name_len)
                continue;  // a longer identifier, not the keyword
            token = make(TokenKind::Keyword, canonical(kw), loc());
            advance(len);
            return true;
        }
    }
    return false;
}

Token Lexer::lex_symbol()
{
    FileLoc where = loc();
    char c = at();
    std::size_t len = 1;
    if (c == '@') {
        // cpfg reads modules one character at a time and skips blanks, so "@ Tx" is
        // the command @Tx: drop the blanks after '@'
        std::size_t gap = 1;
        while (at(gap) == ' ' || at(gap) == '\t')
            ++gap;
        if (at(gap) != '\0' && at(gap) != '\n') {
            std::size_t name_len = continues_at_command(at(gap), at(gap + 1)) ? 2 : 1;
            std::string name(1, '@');
            name.append(m_text.substr(m_state.pos + gap, name_len));
            advance(gap + name_len);
            return make(TokenKind::Symbol, std::move(name), where);
        }
    }
    else if (c == '~' && at(1) != '\0' && at(1) != '\n')
        len = 2;
    else if (c == '?' && std::string_view("PHLUE").find(at(1)) != std::string_view::npos &&
             at(1) != '\0')
        len = 2;
    std::string name(m_text.substr(m_state.pos, len));
    advance(len);
    return make(TokenKind::Symbol, std::move(name), where);
}

Token Lexer::lex_number()
{
    FileLoc where = loc();
    std::size_t len = 0;
    while (is_digit(at(len)))
        ++len;
    if (at(len) == '.') {
        ++len;
        while (is_digit(at(len)))
            ++len;
    }
    if ((at(len) == 'e' || at(len) == 'E') &&
        (is_digit(at(len + 1)) ||
         ((at(len + 1) == '+' || at(len + 1) == '-') && is_digit(at(len + 2))))) {
        len += 2;
        while (is_digit(at(len)))
            ++len;
    }
    Token t = make(TokenKind::Number, std::string(m_text.substr(m_state.pos, len)), where);
    t.number = std::strtod(t.text.c_str(), nullptr);
    advance(len);
    return t;
}

Token Lexer::lex_string()
{
    FileLoc where = loc();
    advance();
    std::string value;
    while (m_state.pos < m_text.size() && at() != '"' && at() != '\n') {
        char c = at();
        if (c == '\\' && at(1) != '\0') {
            char e = at(1);
            value += e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e;
            advance(2);
            continue;
        }
        value += c;
        advance();
    }
    if (at() == '"')
        advance();
    return make(TokenKind::String, std::move(value), where);
}

Token Lexer::lex_expression()
{
    FileLoc where = loc();
    char c = at();
    if (is_digit(c) || (c == '.' && is_digit(at(1))))
        return lex_number();
    if (is_name_start(c)) {
        std::size_t len = 0;
        while (is_name_char(at(len)))
            ++len;
        Token t = make(TokenKind::Name, std::string(m_text.substr(m_state.pos, len)), where);
        advance(len);
        return t;
    }
    if (c == '"')
        return lex_string();
    static constexpr std::array<std::string_view, 8> two = {"<>", "!=", "==", "<=",
                                                            ">=", "&&", "||", "=="};
    for (std::string_view op : two) {
        if (m_text.compare(m_state.pos, 2, op) == 0) {
            advance(2);
            return make(TokenKind::Operator, op == "<>" ? "!=" : std::string(op), where);
        }
    }
    advance();
    switch (c) {
    case ':': return make(TokenKind::Colon, ":", where);
    case '(': return make(TokenKind::LParen, "(", where);
    case ')': return make(TokenKind::RParen, ")", where);
    case '{': ++m_state.brace_depth; break;
    case '}': m_state.brace_depth = m_state.brace_depth > 0 ? m_state.brace_depth - 1 : 0; break;
    default: break;
    }
    return make(TokenKind::Operator, std::string(1, c), where);
}

Token Lexer::lex(LexMode mode)
{
    // cpfg's expression lexer drops characters it has no rule for, such as a stray '\'
    // left by a `\\` line continuation in a macro
    while (true) {
        bool eol = skip_blanks();
        if (eol || mode != LexMode::Expression || at() != '\\')
            break;
        advance();
    }
    if (skip_blanks()) {
        Token t = make(TokenKind::Eol, "end of line", loc());
        advance();
        return t;
    }
    if (m_state.pos >= m_text.size())
        return make(TokenKind::End, "end of file", loc());
    FileLoc where = loc();
    if (m_text.compare(m_state.pos, 3, "-->") == 0) {
        advance(3);
        return make(TokenKind::Yields, "-->", where);
    }
    if (m_text.compare(m_state.pos, 3, "-o>") == 0) {
        advance(3);
        return make(TokenKind::ObjectYields, "-o>", where);
    }
    Token keyword;
    if (lex_keyword(mode, keyword))
        return keyword;
    if (mode == LexMode::Expression)
        return lex_expression();
    TokenKind kind = TokenKind::Symbol;
    switch (at()) {
    case '*': kind = TokenKind::Star; break;
    case ':': kind = TokenKind::Colon; break;
    case '<': kind = TokenKind::LeftSep; break;
    case '>': kind = TokenKind::RightSep; break;
    case '(': kind = TokenKind::LParen; break;
    case ')': kind = TokenKind::RParen; break;
    default: return lex_symbol();
    }
    Token t = make(kind, std::string(1, at()), where);
    advance();
    return t;
}

Token Lexer::next(LexMode mode) { return lex(mode); }

Token Lexer::peek(LexMode mode)
{
    State saved = m_state;
    Token t = lex(mode);
    m_state = std::move(saved);
    return t;
}

void Lexer::skip_rest_of_line()
{
    m_state.brace_depth = 0;
    while (m_state.pos < m_text.size() && !(at() == '\n' && at(1) != '\t'))
        advance();
}

std::string Lexer::rest_of_line()
{
    std::string out;
    while (m_state.pos < m_text.size() && at() != '\n') {
        out += at();
        advance();
    }
    return out;
}

}  // namespace cambium::lsys
