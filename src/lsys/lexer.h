// SPDX-License-Identifier: Apache-2.0
// Tokens of the cpfg L-system language, lexed in cpfg's two modes (modules, expressions).
#pragma once

#include <string>
#include <string_view>

#include "base/diagnostics.h"

namespace cambium::lsys {

enum class TokenKind {
    End,       ///< end of input
    Eol,       ///< end of a line (not inside braces, not before a tab)
    Keyword,   ///< a section keyword such as "axiom:", text holds its canonical spelling
    Symbol,    ///< a module name (module mode)
    Star,      ///< '*' (module mode; in expressions it is Operator "*")
    Colon,     ///< ':'
    Yields,    ///< "-->"
    ObjectYields,  ///< "-o>"
    LeftSep,   ///< '<' (module mode)
    RightSep,  ///< '>' (module mode)
    LParen,
    RParen,
    Number,
    Name,
    String,
    Operator,  ///< any other expression punctuation, text holds it
};

struct Token {
    TokenKind kind = TokenKind::End;
    std::string text;
    double number = 0;
    FileLoc loc;
};

/// Whether `second` continues a two-letter turtle command after "@" and `first`
/// (@Gs, @Tx, @PS, @Dd...): cpfg's lexer and string reader group these characters.
bool continues_at_command(char first, char second);

/// Whether the lexer reads module names or expression tokens, as cpfg's lexer states do.
enum class LexMode { Module, Expression };

/// Reads preprocessed text (with cpp line markers) token by token. The parser chooses
/// the mode of every token; peeking does not consume.
class Lexer {
public:
    Lexer(std::string_view text, std::string file_name);

    Token next(LexMode mode);
    Token peek(LexMode mode);
    /// The rest of the current line, raw (for `lsystem:` labels), consuming it.
    std::string rest_of_line();
    FileLoc loc() const { return FileLoc{m_state.file, m_state.line, m_state.column}; }
    /// Error recovery: skips to the newline that ends the current line (its tab-continued
    /// lines and any open braces included), which is then read as an Eol token.
    void skip_rest_of_line();
    /// Whether the last token read ended a line (nothing of the next line read yet).
    bool at_line_start() const { return m_state.at_line_start; }
    /// The read position in the text, and the raw text between two positions (the
    /// source of a production, quoted in runtime errors).
    std::size_t offset() const { return m_state.pos; }
    std::string_view source(std::size_t from, std::size_t to) const
    {
        return m_text.substr(from, to > from ? to - from : 0);
    }

private:
    struct State {
        std::size_t pos = 0;
        int line = 1;
        int column = 1;
        std::string file;
        int brace_depth = 0;
        bool at_line_start = true;
    };

    char at(std::size_t offset = 0) const;
    void advance(std::size_t n = 1);
    bool skip_blanks();                 // returns true when an Eol token is due
    bool skip_line_marker();
    void skip_comment();
    Token lex(LexMode mode);
    bool lex_keyword(LexMode mode, Token& token);
    Token lex_symbol();
    Token lex_expression();
    Token lex_number();
    Token lex_string();
    Token make(TokenKind kind, std::string text, const FileLoc& loc) const;

    std::string_view m_text;
    State m_state;
};

}  // namespace cambium::lsys
