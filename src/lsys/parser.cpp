// SPDX-License-Identifier: Apache-2.0
// Recursive-descent parser of preprocessed cpfg L-system text into a compiled Program.
#include "lsys/parser.h"

#include <array>
#include <cstdlib>
#include <functional>
#include <optional>
#include <set>
#include <utility>

#include "lsys/lexer.h"

namespace cambium::lsys {

namespace {

/// How deep expressions (parentheses, calls, subscripts, unary operators, conditional
/// expressions in a then-branch) may nest, and, counted apart, blocks. The parser
/// recurses once (a dozen frames at most) per level, so this bounds its stack use
/// whatever the input; cpfg's models nest a few levels.
constexpr int max_nesting = 200;
constexpr int max_stack = 250;

/// Appends instructions to a Code and tracks the evaluation stack depth.
class Emitter {
public:
    explicit Emitter(Code& code) : m_code(code) {}
    std::size_t emit(Op op, int effect, std::int32_t arg = 0, std::uint8_t arg2 = 0,
                     double value = 0)
    {
        m_code.instrs.push_back(Instr{op, arg2, arg, value});
        m_depth += effect;
        if (m_depth > m_code.max_stack)
            m_code.max_stack = m_depth;
        return m_code.instrs.size() - 1;
    }
    std::int32_t here() const { return static_cast<std::int32_t>(m_code.instrs.size()); }
    void patch(std::size_t at, std::int32_t target) { m_code.instrs[at].arg = target; }
    int depth() const { return m_depth; }

private:
    Code& m_code;
    int m_depth = 0;
};

/// Where a name lives: the production frame, the globals, or an array.
struct VariableRef {
    enum Kind { Local, Global, Array } kind;
    int index;
};

/// Names visible while compiling one production or one global block.
struct Scope {
    bool global = false;
    std::vector<std::pair<std::string, int>> locals;
    int next_slot = 0;
    /// Names read before any definition, warned about once the production is parsed
    std::vector<std::pair<std::string, FileLoc>> undefined;

    int local_slot(const std::string& name)
    {
        for (const auto& [n, slot] : locals)
            if (n == name)
                return slot;
        locals.emplace_back(name, next_slot);
        return next_slot++;
    }
};

Scope global_scope()
{
    Scope s;
    s.global = true;
    return s;
}

class Parser {
public:
    Parser(std::string_view text, const std::string& file_name, Program& program)
        : m_lexer(text, file_name), m_program(program), m_errors(file_name)
    {
    }
    void parse_file();

private:
    // --- tokens ---
    Token next(LexMode mode) { return m_lexer.next(mode); }
    Token peek(LexMode mode) { return m_lexer.peek(mode); }
    [[noreturn]] void fail(const Token& at, const std::string& expected);
    Token expect(LexMode mode, TokenKind kind, const char* what);
    void expect_operator(const char* op);
    bool accept_operator(const char* op);
    bool at_keyword(const char* keyword);
    void expect_eol(const char* after);
    void skip_blank_lines();
    /// After an error in a production or a one-line item that began at `start`: on to
    /// the next line (at least one line on), with no scope open.
    void recover(std::size_t start);

    // --- L-system structure (Appendix A) ---
    void parse_lsystem();
    void parse_label(LSystemDefinition& ls);
    bool parse_item(LSystemDefinition& ls);
    void parse_characters(std::vector<SymbolId>& out);
    void parse_define_block();
    void parse_array_definition();
    Code parse_global_block();
    void parse_axiom(LSystemDefinition& ls);
    void parse_decomposition(LSystemDefinition& ls);
    void parse_homomorphism(LSystemDefinition& ls);
    void parse_warning_flag(ProductionSet& set);
    void parse_productions(ProductionSet& set);
    void parse_production(ProductionSet& set);
    void parse_predecessor(Production& p);
    std::vector<FormalModule> parse_formal_modules(bool allow_star);
    FormalModule parse_formal_module(const Token& symbol);
    void parse_conditional(Production& p);
    void parse_successor(Production& p);
    std::vector<ModuleTemplate> parse_modules(bool stop_at_colon);
    ModuleTemplate parse_module(const Token& symbol);

    // --- statements ---
    void parse_block(Emitter& e);
    void parse_statement(Emitter& e);
    void parse_if(Emitter& e);
    void parse_while(Emitter& e);
    void parse_do(Emitter& e);
    void parse_assignment_or_expression(Emitter& e);

    // --- expressions, by precedence ---
    Code compile_expression();
    void parse_expression(Emitter& e);
    void parse_ternary(Emitter& e);
    void parse_or(Emitter& e);
    void parse_and(Emitter& e);
    void parse_equality(Emitter& e);
    void parse_relational(Emitter& e);
    void parse_additive(Emitter& e);
    void parse_multiplicative(Emitter& e);
    void parse_power(Emitter& e);
    void parse_unary(Emitter& e);
    void parse_primary(Emitter& e);
    void parse_call(Emitter& e, const Token& name);
    void parse_file_call(Emitter& e, const Token& name);
    void check_format_literal(const std::string& function, const Token& format,
                              std::string_view raw, int values) const;
    int parse_indices(Emitter& e);
    void emit_load(Emitter& e, const Token& name);
    void check_subscripts(const Token& name, const VariableRef& ref, int n) const;
    std::optional<VariableRef> lookup(const std::string& name) const;
    VariableRef resolve(const Token& name, bool reading);
    void warn_undefined(const std::string& name, const FileLoc& loc, const std::string& where);
    double site(const FileLoc& loc);
    double constant_expression();

    /// One level of a recursive construct while it lives (`depth`: m_nesting for
    /// expressions, m_block_nesting for blocks; `what` names it): max_nesting levels
    /// at most, else an error at the token that would open one more.
    class Level {
    public:
        Level(Parser& parser, int& depth, const char* what) : m_depth(depth)
        {
            if (depth >= max_nesting)
                throw Error(parser.peek(LexMode::Expression).loc,
                            std::string(what) + " nested too deeply (more than " +
                                std::to_string(max_nesting) + " levels)");
            ++depth;
        }
        Level(const Level&) = delete;
        Level& operator=(const Level&) = delete;
        ~Level() { --m_depth; }

    private:
        int& m_depth;
    };

    Lexer m_lexer;
    Program& m_program;
    Scope* m_scope = nullptr;
    std::string m_context;             ///< the global block or header item being compiled
    std::set<std::string> m_warned;    ///< undefined names already reported
    int m_nesting = 0;        ///< expressions being parsed inside each other
    int m_block_nesting = 0;  ///< blocks being parsed inside each other
    ErrorList m_errors;       ///< errors recovered from, thrown together at the end
};

/// The source of a production on one line: line markers and comments dropped, blanks
/// collapsed, long ones shortened.
std::string one_line(std::string_view raw)
{
    std::string out;
    bool line_start = true, blank = false;
    for (std::size_t i = 0; i < raw.size(); ++i) {
        char c = raw[i];
        if (line_start && c == '#') {  // a cpp line marker
            while (i < raw.size() && raw[i] != '\n')
                ++i;
            continue;
        }
        if (c == '/' && i + 1 < raw.size() && raw[i + 1] == '*') {
            std::size_t end = raw.find("*/", i + 2);
            i = end == std::string_view::npos ? raw.size() : end + 1;
            blank = true;
            continue;
        }
        if (c == '/' && i + 1 < raw.size() && raw[i + 1] == '/') {
            while (i + 1 < raw.size() && raw[i + 1] != '\n')
                ++i;
            continue;
        }
        line_start = c == '\n';
        if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
            blank = true;
            continue;
        }
        if (blank && !out.empty())
            out += ' ';
        blank = false;
        out += c;
    }
    constexpr std::size_t max_length = 90;
    if (out.size() > max_length)
        out = out.substr(0, max_length - 3) + "...";
    return out;
}

// ---------------------------------------------------------------- tokens

std::string describe(const Token& t)
{
    switch (t.kind) {
    case TokenKind::End: return "end of file";
    case TokenKind::Eol: return "end of line";
    default: return "'" + t.text + "'";
    }
}

void Parser::fail(const Token& at, const std::string& expected)
{
    throw Error(at.loc, "expected " + expected + ", found " + describe(at));
}

Token Parser::expect(LexMode mode, TokenKind kind, const char* what)
{
    Token t = next(mode);
    if (t.kind != kind)
        fail(t, what);
    return t;
}

void Parser::expect_operator(const char* op)
{
    Token t = next(LexMode::Expression);
    if (t.text != op || t.kind == TokenKind::String)
        fail(t, std::string("'") + op + "'");
}

bool Parser::accept_operator(const char* op)
{
    Token t = peek(LexMode::Expression);
    if (t.kind != TokenKind::Operator || t.text != op)
        return false;
    next(LexMode::Expression);
    return true;
}

bool Parser::at_keyword(const char* keyword)
{
    Token t = peek(LexMode::Module);
    return t.kind == TokenKind::Keyword && t.text == keyword;
}

void Parser::expect_eol(const char* after)
{
    Token t = next(LexMode::Expression);
    if (t.kind != TokenKind::Eol && t.kind != TokenKind::End)
        fail(t, std::string("end of line after ") + after);
}

void Parser::skip_blank_lines()
{
    while (peek(LexMode::Module).kind == TokenKind::Eol)
        next(LexMode::Module);
}

// ---------------------------------------------------------------- structure

void Parser::recover(std::size_t start)
{
    m_scope = nullptr;
    if (m_lexer.offset() == start || !m_lexer.at_line_start())
        m_lexer.skip_rest_of_line();
}

void Parser::parse_file()
{
    try {
        skip_blank_lines();
        while (peek(LexMode::Module).kind != TokenKind::End) {
            parse_lsystem();
            skip_blank_lines();
        }
    } catch (const Error& e) {
        m_errors.add(e);  // one the parser cannot go on after
    }
    m_errors.finish();
    if (m_program.lsystems.empty())
        throw Error(FileLoc{m_program.file_name, 0, 0}, "no 'lsystem:' found");
}

void Parser::parse_lsystem()
{
    Token label = next(LexMode::Module);
    if (label.kind != TokenKind::Keyword || label.text != "lsystem:")
        fail(label, "'lsystem:'");
    LSystemDefinition ls;
    ls.loc = label.loc;
    parse_label(ls);
    for (bool more = true; more;) {
        std::size_t start = m_lexer.offset();
        Token item;
        try {
            item = peek(LexMode::Module);
            more = parse_item(ls);
        } catch (const Error& e) {
            // blocks ({...} over several lines) are not recovered from
            static const std::set<std::string> blocks = {"define:", "start:", "end:", "start each:",
                                                         "end each:"};
            if (item.kind == TokenKind::Keyword && blocks.contains(item.text))
                throw;
            m_errors.add(e);
            recover(start);
        }
    }
    std::size_t axiom_start = m_lexer.offset();
    try {
        parse_axiom(ls);
    } catch (const Error& e) {
        m_errors.add(e);
        recover(axiom_start);
    }
    parse_productions(ls.productions);
    if (at_keyword("decomposition"))
        parse_decomposition(ls);
    if (at_keyword("homomorphism"))
        parse_homomorphism(ls);
    Token end = next(LexMode::Module);
    if (end.kind != TokenKind::Keyword || end.text != "endlsystem")
        fail(end, "a production or 'endlsystem'");
    m_program.lsystems.push_back(std::move(ls));
}

void Parser::parse_label(LSystemDefinition& ls)
{
    std::string text = m_lexer.rest_of_line();
    std::size_t first = text.find_first_not_of(" \t");
    ls.label = first == std::string::npos ? "" : text.substr(first);
    // the label's leading number is the id ?(id) names; beyond int it names nothing
    long long id = std::strtoll(ls.label.c_str(), nullptr, 10);
    ls.id = id >= -2147483647 && id <= 2147483647 ? static_cast<int>(id) : 0;
}

bool Parser::parse_item(LSystemDefinition& ls)
{
    Token t = next(LexMode::Module);
    if (t.kind == TokenKind::Eol)
        return true;
    if (t.kind != TokenKind::Keyword)
        fail(t, "a header item or 'axiom:'");
    if (t.text == "axiom:")
        return false;
    if (t.text == "seed:" || t.text == "derivation length:") {
        Scope scope = global_scope();
        m_scope = &scope;
        m_context = "'" + t.text + "'";
        (t.text == "seed:" ? ls.seed_loc : ls.derivation_length_loc) =
            peek(LexMode::Expression).loc;
        (t.text == "seed:" ? ls.seed : ls.derivation_length) = compile_expression();
        m_scope = nullptr;
        expect_eol(t.text.c_str());
    } else if (t.text == "ignore:") {
        parse_characters(ls.ignore);
    } else if (t.text == "consider:") {
        ls.has_consider = true;
        parse_characters(ls.consider);
    } else if (t.text == "define:") {
        parse_define_block();
    } else if (t.text == "start:" || t.text == "end:" || t.text == "start each:" ||
               t.text == "end each:") {
        m_context = t.text == "start:"        ? "the Start block"
                    : t.text == "end:"        ? "the End block"
                    : t.text == "start each:" ? "the StartEach block"
                                              : "the EndEach block";
        Code block = parse_global_block();
        Code& target = t.text == "start:"        ? m_program.start_block
                       : t.text == "end:"        ? m_program.end_block
                       : t.text == "start each:" ? m_program.start_each_block
                                                 : m_program.end_each_block;
        target.instrs.insert(target.instrs.end(), block.instrs.begin(), block.instrs.end());
        target.max_stack = std::max(target.max_stack, block.max_stack);
    } else if (t.text == "ring lsystem") {
        ls.ring = true;
    } else {
        fail(t, "a header item or 'axiom:'");
    }
    return true;
}

void Parser::parse_characters(std::vector<SymbolId>& out)
{
    for (Token t = next(LexMode::Module); t.kind != TokenKind::Eol && t.kind != TokenKind::End;
         t = next(LexMode::Module))
        out.push_back(m_program.symbols.intern(t.text));
}

Code Parser::parse_global_block()
{
    Scope scope = global_scope();
    m_scope = &scope;
    Code code;
    Emitter e(code);
    parse_block(e);
    m_scope = nullptr;
    expect_eol("a block");
    return code;
}

void Parser::parse_define_block()
{
    expect_operator("{");
    while (!accept_operator("}")) {
        Token t = next(LexMode::Expression);
        if (t.kind != TokenKind::Name || t.text != "array")
            fail(t, "'array' or '}'");
        do
            parse_array_definition();
        while (accept_operator(","));
        expect_operator(";");
    }
    expect_eol("'define:'");
}

void Parser::parse_array_definition()
{
    Token name = expect(LexMode::Expression, TokenKind::Name, "an array name");
    ArrayDefinition def;
    def.name = name.text;
    def.initial.name = name.text;
    std::size_t total = 1;
    while (accept_operator("[")) {
        FileLoc dim_loc = peek(LexMode::Expression).loc;
        double size = constant_expression();
        std::optional<long long> whole = truncated_in(size, 1, 1 << 24);
        if (!whole)
            throw Error(dim_loc, "array '" + name.text + "' has dimension " + number_text(size) +
                                     "; dimensions go from 1 to " + std::to_string(1 << 24));
        int dim = static_cast<int>(*whole);
        def.initial.dims.push_back(dim);
        total *= static_cast<std::size_t>(dim);
        expect_operator("]");
    }
    if (total > (std::size_t{1} << 26))
        throw Error(name.loc, "array '" + name.text + "' is too large");
    def.initial.values.assign(total, 0.0);
    if (accept_operator("=")) {
        expect_operator("{");
        std::size_t i = 0;
        do {
            double v = constant_expression();
            if (i < total)
                def.initial.values[i] = v;
            ++i;
        } while (accept_operator(","));
        expect_operator("}");
    }
    m_program.arrays.push_back(std::move(def));
}

double Parser::constant_expression()
{
    Scope scope = global_scope();
    Scope* saved = m_scope;
    m_scope = &scope;
    std::string saved_context = std::exchange(m_context, "an array definition");
    Code code = compile_expression();
    m_context = std::move(saved_context);
    m_scope = saved;
    Runtime rt;
    rt.globals.assign(m_program.global_names.size(), 0.0);
    for (const auto& a : m_program.arrays)
        rt.arrays.push_back(a.initial);
    rt.strings = &m_program.strings;
    rt.file_name = &m_program.file_name;  // fopen's folder: the model's
    try {
        return evaluate(code, {}, rt);
    } catch (const EvaluationError& e) {
        throw Error(e.site() >= 0 ? m_program.sites[static_cast<std::size_t>(e.site())]
                                  : m_lexer.loc(),
                    e.what());
    }
}

void Parser::parse_axiom(LSystemDefinition& ls)
{
    Scope scope = global_scope();
    m_scope = &scope;
    m_context = "the axiom";
    ls.axiom = parse_modules(false);
    m_scope = nullptr;
}

void Parser::parse_warning_flag(ProductionSet& set)
{
    if (peek(LexMode::Module).kind == TokenKind::Colon)
        next(LexMode::Module);
    Token t = peek(LexMode::Module);
    if (t.kind == TokenKind::Keyword && (t.text == "warnings" || t.text == "no warnings")) {
        set.warnings = t.text == "warnings";
        next(LexMode::Module);
    }
    expect_eol("the section keyword");
}

void Parser::parse_decomposition(LSystemDefinition& ls)
{
    next(LexMode::Module);
    parse_warning_flag(ls.decomposition);
    skip_blank_lines();
    if (at_keyword("maximum depth:")) {
        next(LexMode::Module);
        m_context = "the decomposition's 'maximum depth:'";
        ls.decomposition.max_depth_loc = peek(LexMode::Expression).loc;
        ls.decomposition.max_depth = compile_expression();
        expect_eol("'maximum depth:'");
    }
    parse_productions(ls.decomposition);
}

void Parser::parse_homomorphism(LSystemDefinition& ls)
{
    next(LexMode::Module);
    parse_warning_flag(ls.homomorphism);
    for (;;) {
        skip_blank_lines();
        if (at_keyword("maximum depth:")) {
            next(LexMode::Module);
            m_context = "the homomorphism's 'maximum depth:'";
            ls.homomorphism.max_depth_loc = peek(LexMode::Expression).loc;
            ls.homomorphism.max_depth = compile_expression();
            expect_eol("'maximum depth:'");
        } else if (at_keyword("seed:")) {
            next(LexMode::Module);
            m_context = "the homomorphism's 'seed:'";
            ls.homomorphism.seed_loc = peek(LexMode::Expression).loc;
            ls.homomorphism.seed = compile_expression();
            expect_eol("'seed:'");
        } else {
            break;
        }
    }
    parse_productions(ls.homomorphism);
}

void Parser::parse_productions(ProductionSet& set)
{
    for (;;) {
        std::size_t start = m_lexer.offset();
        try {
            Token t = peek(LexMode::Module);
            if (t.kind == TokenKind::Eol) {
                next(LexMode::Module);
                continue;
            }
            if (t.kind == TokenKind::Keyword || t.kind == TokenKind::End)
                return;
            parse_production(set);
        } catch (const Error& e) {
            m_errors.add(e);  // and on to the next production
            recover(start);
        }
    }
}

void Parser::parse_production(ProductionSet& set)
{
    Production p;
    Scope scope;
    m_scope = &scope;
    m_context.clear();
    std::size_t start = m_lexer.offset();
    p.loc = peek(LexMode::Module).loc;
    parse_predecessor(p);
    Token t = next(LexMode::Module);
    if (t.kind == TokenKind::Colon) {
        parse_conditional(p);
        t = next(LexMode::Module);
    }
    if (t.kind != TokenKind::Yields && t.kind != TokenKind::ObjectYields)
        fail(t, "'-->'");
    p.object_production = t.kind == TokenKind::ObjectYields;
    parse_successor(p);
    p.text = one_line(m_lexer.source(start, m_lexer.offset()));
    for (const auto& [name, loc] : scope.undefined)
        warn_undefined(name, loc, "production '" + p.text + "'");
    build_successor_prototype(p);
    p.frame_size = scope.next_slot;
    p.storage = m_program.storage_size;
    m_program.storage_size += static_cast<std::size_t>(p.frame_size);
    m_scope = nullptr;
    set.productions.push_back(std::move(p));
}

void Parser::parse_predecessor(Production& p)
{
    std::vector<FormalModule> first = parse_formal_modules(true);
    Token t = peek(LexMode::Module);
    if (t.kind == TokenKind::LeftSep) {
        next(LexMode::Module);
        p.left_context = std::move(first);
        p.predecessor = parse_formal_modules(false);
        t = peek(LexMode::Module);
    } else {
        p.predecessor = std::move(first);
    }
    if (t.kind == TokenKind::RightSep) {
        next(LexMode::Module);
        p.right_context = parse_formal_modules(true);
    }
    if (p.predecessor.empty())
        fail(peek(LexMode::Module), "a predecessor module");
}

std::vector<FormalModule> Parser::parse_formal_modules(bool allow_star)
{
    std::vector<FormalModule> modules;
    for (;;) {
        Token t = peek(LexMode::Module);
        if (t.kind == TokenKind::Star && allow_star && modules.empty()) {
            next(LexMode::Module);
            return modules;
        }
        if (t.kind != TokenKind::Symbol)
            return modules;
        modules.push_back(parse_formal_module(next(LexMode::Module)));
    }
}

FormalModule Parser::parse_formal_module(const Token& symbol)
{
    FormalModule m;
    m.symbol = m_program.symbols.intern(symbol.text);
    m.loc = symbol.loc;
    if (peek(LexMode::Module).kind != TokenKind::LParen)
        return m;
    next(LexMode::Module);
    do {
        Token name = expect(LexMode::Expression, TokenKind::Name, "a formal parameter name");
        m.param_slots.push_back(m_scope->local_slot(name.text));
    } while (accept_operator(","));
    expect(LexMode::Expression, TokenKind::RParen, "')' after formal parameters");
    if (m.param_slots.size() > ModuleString::max_params)
        throw Error(symbol.loc, "too many parameters");
    return m;
}

void Parser::parse_conditional(Production& p)
{
    Token t = peek(LexMode::Expression);
    if (t.kind == TokenKind::Operator && t.text == "{") {
        Emitter e(p.pre_block);
        parse_block(e);
        t = peek(LexMode::Expression);
    }
    if (t.kind == TokenKind::Operator && t.text == "*")
        next(LexMode::Expression);
    else if (t.kind != TokenKind::Yields && t.kind != TokenKind::ObjectYields &&
             !(t.kind == TokenKind::Operator && t.text == "{"))
        p.condition = compile_expression();
    t = peek(LexMode::Expression);
    if (t.kind == TokenKind::Operator && t.text == "{") {
        Emitter e(p.post_block);
        parse_block(e);
    }
}

void Parser::parse_successor(Production& p)
{
    Token t = peek(LexMode::Module);
    if (t.kind == TokenKind::Star)
        next(LexMode::Module);
    else
        p.successor = parse_modules(true);
    if (peek(LexMode::Module).kind == TokenKind::Colon) {
        next(LexMode::Module);
        p.probability = compile_expression();
    }
    Token end = next(LexMode::Expression);
    if (end.kind != TokenKind::Eol && end.kind != TokenKind::End)
        fail(end, "a successor module or end of line");
}

std::vector<ModuleTemplate> Parser::parse_modules(bool stop_at_colon)
{
    std::vector<ModuleTemplate> modules;
    for (;;) {
        Token t = peek(LexMode::Module);
        if (t.kind == TokenKind::Symbol) {
            modules.push_back(parse_module(next(LexMode::Module)));
        } else if (t.kind == TokenKind::RParen || (t.kind == TokenKind::Star && !stop_at_colon)) {
            next(LexMode::Module);  // cpfg ignores these here
        } else if (t.kind == TokenKind::Eol || t.kind == TokenKind::End ||
                   (t.kind == TokenKind::Colon && stop_at_colon)) {
            return modules;
        } else {
            fail(t, "a module");
        }
    }
}

ModuleTemplate Parser::parse_module(const Token& symbol)
{
    ModuleTemplate m;
    m.symbol = m_program.symbols.intern(symbol.text);
    if (peek(LexMode::Module).kind != TokenKind::LParen)
        return m;
    next(LexMode::Module);
    if (peek(LexMode::Expression).kind == TokenKind::RParen) {
        next(LexMode::Expression);
        return m;
    }
    do
        m.params.push_back(compile_expression());
    while (accept_operator(","));
    expect(LexMode::Expression, TokenKind::RParen, "',' or ')' after a module parameter");
    if (m.params.size() > ModuleString::max_params)
        throw Error(symbol.loc, "too many parameters");
    return m;
}

// ---------------------------------------------------------------- statements

void Parser::parse_block(Emitter& e)
{
    Level level(*this, m_block_nesting, "block");
    expect_operator("{");
    while (!accept_operator("}"))
        parse_statement(e);
}

void Parser::parse_statement(Emitter& e)
{
    Token t = peek(LexMode::Expression);
    if (t.kind == TokenKind::Name && t.text == "if")
        parse_if(e);
    else if (t.kind == TokenKind::Name && t.text == "while")
        parse_while(e);
    else if (t.kind == TokenKind::Name && t.text == "do")
        parse_do(e);
    else if (t.kind == TokenKind::End)
        fail(t, "'}'");
    else
        parse_assignment_or_expression(e);
}

void Parser::parse_if(Emitter& e)
{
    next(LexMode::Expression);
    expect(LexMode::Expression, TokenKind::LParen, "'(' after 'if'");
    parse_expression(e);
    expect(LexMode::Expression, TokenKind::RParen, "')'");
    std::size_t skip_then = e.emit(Op::JumpIfFalse, -1);
    parse_block(e);
    Token t = peek(LexMode::Expression);
    if (t.kind == TokenKind::Name && t.text == "else") {
        next(LexMode::Expression);
        std::size_t skip_else = e.emit(Op::Jump, 0);
        e.patch(skip_then, e.here());
        parse_block(e);
        e.patch(skip_else, e.here());
    } else {
        e.patch(skip_then, e.here());
    }
}

void Parser::parse_while(Emitter& e)
{
    Token loop = next(LexMode::Expression);
    std::int32_t top = e.here();
    expect(LexMode::Expression, TokenKind::LParen, "'(' after 'while'");
    parse_expression(e);
    expect(LexMode::Expression, TokenKind::RParen, "')'");
    std::size_t exit = e.emit(Op::JumpIfFalse, -1);
    parse_block(e);
    e.emit(Op::Jump, 0, top, 0, site(loop.loc));  // the loop's site: its iteration limit
    e.patch(exit, e.here());
}

void Parser::parse_do(Emitter& e)
{
    Token loop = next(LexMode::Expression);
    std::int32_t top = e.here();
    parse_block(e);
    Token w = next(LexMode::Expression);
    if (w.kind != TokenKind::Name || w.text != "while")
        fail(w, "'while' after a 'do' block");
    expect(LexMode::Expression, TokenKind::LParen, "'(' after 'while'");
    parse_expression(e);
    expect(LexMode::Expression, TokenKind::RParen, "')'");
    e.emit(Op::Not, 0);
    e.emit(Op::JumpIfFalse, -1, top, 0, site(loop.loc));
    expect_operator(";");
}

void Parser::parse_assignment_or_expression(Emitter& e)
{
    Token first = peek(LexMode::Expression);
    if (first.kind == TokenKind::Name && !find_function(first.text) && first.text != "printf" &&
        first.text != "fprintf" && first.text != "fscanf") {
        Lexer before_name = m_lexer;  // an expression statement starts the same way
        next(LexMode::Expression);
        Token after = peek(LexMode::Expression);
        std::optional<VariableRef> known = lookup(first.text);
        if (after.text == "[" && known && known->kind == VariableRef::Array) {
            int n = parse_indices(e);
            check_subscripts(first, *known, n);
            expect_operator("=");
            parse_expression(e);
            e.emit(Op::StoreElement, -(n + 1), known->index, static_cast<std::uint8_t>(n),
                   site(first.loc));
            expect_operator(";");
            return;
        }
        if (after.kind == TokenKind::Operator && after.text == "=") {
            VariableRef ref = resolve(first, false);
            next(LexMode::Expression);
            parse_expression(e);
            if (ref.kind == VariableRef::Array)
                throw Error(first.loc, "cannot assign to array '" + first.text + "' as a whole");
            e.emit(ref.kind == VariableRef::Local ? Op::StoreLocal : Op::StoreGlobal, -1,
                   ref.index);
            expect_operator(";");
            return;
        }
        // Not an assignment: cpfg evaluates the expression and drops its value
        // (04-paintbrush has `roll - roll/L0;`).
        m_lexer = before_name;
    }
    parse_expression(e);
    e.emit(Op::Pop, -1);
    expect_operator(";");
}

// ---------------------------------------------------------------- expressions

Code Parser::compile_expression()
{
    Code code;
    Emitter e(code);
    parse_expression(e);
    return code;
}

void Parser::parse_expression(Emitter& e)
{
    {
        Level level(*this, m_nesting, "expression");
        parse_ternary(e);
    }
    if (e.depth() > max_stack)
        throw Error(peek(LexMode::Expression).loc, "expression too complex");
}

void Parser::parse_ternary(Emitter& e)
{
    // `a ? b : c ? d : e` chains in the else branch as a loop, so a long chain needs no
    // stack; a conditional in the then branch nests (and counts as a level).
    parse_or(e);
    std::vector<std::size_t> to_end;
    while (accept_operator("?")) {
        std::size_t to_else = e.emit(Op::JumpIfFalse, -1);
        {
            Level level(*this, m_nesting, "conditional expression");
            parse_ternary(e);
        }
        to_end.push_back(e.emit(Op::Jump, -1));
        expect(LexMode::Expression, TokenKind::Colon, "':' in a conditional expression");
        e.patch(to_else, e.here());
        parse_or(e);
    }
    for (std::size_t jump : to_end)
        e.patch(jump, e.here());
}

void Parser::parse_or(Emitter& e)
{
    parse_and(e);
    while (accept_operator("||")) {
        std::size_t jump = e.emit(Op::OrJump, -1);
        parse_and(e);
        e.emit(Op::ToBool, 0);
        e.patch(jump, e.here());
    }
}

void Parser::parse_and(Emitter& e)
{
    parse_equality(e);
    while (accept_operator("&&")) {
        std::size_t jump = e.emit(Op::AndJump, -1);
        parse_equality(e);
        e.emit(Op::ToBool, 0);
        e.patch(jump, e.here());
    }
}

void Parser::parse_equality(Emitter& e)
{
    parse_relational(e);
    for (;;) {
        if (accept_operator("==")) {
            parse_relational(e);
            e.emit(Op::Equal, -1);
        } else if (accept_operator("!=")) {
            parse_relational(e);
            e.emit(Op::NotEqual, -1);
        } else {
            return;
        }
    }
}

void Parser::parse_relational(Emitter& e)
{
    parse_additive(e);
    for (;;) {
        Op op;
        if (accept_operator("<"))
            op = Op::Less;
        else if (accept_operator("<="))
            op = Op::LessEqual;
        else if (accept_operator(">"))
            op = Op::Greater;
        else if (accept_operator(">="))
            op = Op::GreaterEqual;
        else
            return;
        parse_additive(e);
        e.emit(op, -1);
    }
}

void Parser::parse_additive(Emitter& e)
{
    parse_multiplicative(e);
    for (;;) {
        Token t = peek(LexMode::Expression);
        if (t.kind != TokenKind::Operator || (t.text != "+" && t.text != "-"))
            return;
        next(LexMode::Expression);
        parse_multiplicative(e);
        e.emit(t.text == "+" ? Op::Add : Op::Sub, -1);
    }
}

void Parser::parse_multiplicative(Emitter& e)
{
    parse_power(e);
    for (;;) {
        Token t = peek(LexMode::Expression);
        if (t.kind != TokenKind::Operator || (t.text != "*" && t.text != "/" && t.text != "%"))
            return;
        next(LexMode::Expression);
        parse_power(e);
        e.emit(t.text == "*" ? Op::Mul : t.text == "/" ? Op::Div : Op::Mod, -1, 0, 0,
               t.text == "*" ? 0.0 : site(t.loc));
    }
}

void Parser::parse_power(Emitter& e)
{
    // cpfg's grammar makes '^' left-associative and binds unary minus tighter
    parse_unary(e);
    while (accept_operator("^")) {
        parse_unary(e);
        e.emit(Op::Pow, -1);
    }
}

void Parser::parse_unary(Emitter& e)
{
    if (accept_operator("-")) {
        Level level(*this, m_nesting, "expression");
        parse_unary(e);
        e.emit(Op::Neg, 0);
    } else if (accept_operator("!")) {
        Level level(*this, m_nesting, "expression");
        parse_unary(e);
        e.emit(Op::Not, 0);
    } else if (accept_operator("+")) {
        Level level(*this, m_nesting, "expression");
        parse_unary(e);
    } else {
        parse_primary(e);
    }
}

void Parser::parse_primary(Emitter& e)
{
    Token t = next(LexMode::Expression);
    switch (t.kind) {
    case TokenKind::Number: e.emit(Op::Const, 1, 0, 0, t.number); return;
    case TokenKind::LParen:
        parse_expression(e);
        expect(LexMode::Expression, TokenKind::RParen, "')'");
        return;
    case TokenKind::Name:
        if (peek(LexMode::Expression).kind == TokenKind::LParen)
            parse_call(e, t);
        else
            emit_load(e, t);
        return;
    case TokenKind::String:
        m_program.strings.push_back(t.text);
        e.emit(Op::Const, 1, 0, 0, static_cast<double>(m_program.strings.size() - 1));
        return;
    default: fail(t, "an expression");
    }
}

void Parser::parse_call(Emitter& e, const Token& name)
{
    next(LexMode::Expression);  // '('
    if (name.text == "printf") {
        std::size_t raw_start = m_lexer.offset();
        Token format = expect(LexMode::Expression, TokenKind::String, "a format string");
        std::string_view raw = m_lexer.source(raw_start, m_lexer.offset());
        m_program.strings.push_back(format.text);
        int n = 0;
        while (accept_operator(",")) {
            parse_expression(e);
            ++n;
        }
        expect(LexMode::Expression, TokenKind::RParen, "')'");
        check_format_literal(name.text, format, raw, n);
        e.emit(Op::Print, 1 - n, static_cast<std::int32_t>(m_program.strings.size() - 1),
               static_cast<std::uint8_t>(n));
        return;
    }
    if (name.text == "fprintf" || name.text == "fscanf") {
        parse_file_call(e, name);
        return;
    }
    const FunctionInfo* f = find_function(name.text);
    if (!f)
        throw Error(name.loc, "unknown function '" + name.text + "'");
    int n = 0;
    if (peek(LexMode::Expression).kind != TokenKind::RParen) {
        do {
            parse_expression(e);
            ++n;
        } while (accept_operator(","));
    }
    expect(LexMode::Expression, TokenKind::RParen, "')'");
    if (f->arity >= 0 && n != f->arity && !(f->arity == 1 && n == 0))
        throw Error(name.loc, "'" + name.text + "' takes " + std::to_string(f->arity) +
                                  " argument(s), " + std::to_string(n) + " given");
    if (f->arity == 1 && n == 0) {  // stop() is stop(0): give the argument a value
        e.emit(Op::Const, 1, 0, 0, 0.0);
        n = 1;
    }
    e.emit(Op::Call, 1 - n, static_cast<std::int32_t>(f->function), static_cast<std::uint8_t>(n),
           site(name.loc));
}

void Parser::parse_file_call(Emitter& e, const Token& name)
{
    // fprintf(file, "format", values...) and fscanf(file, "format", &var...) (5.1.5)
    parse_expression(e);
    expect_operator(",");
    std::size_t raw_start = m_lexer.offset();
    Token format = expect(LexMode::Expression, TokenKind::String, "a format string");
    std::string_view raw = m_lexer.source(raw_start, m_lexer.offset());
    m_program.strings.push_back(format.text);
    auto format_index = static_cast<std::int32_t>(m_program.strings.size() - 1);
    if (name.text == "fprintf") {
        int n = 0;
        while (accept_operator(",")) {
            parse_expression(e);
            ++n;
        }
        expect(LexMode::Expression, TokenKind::RParen, "')'");
        if (n > max_stack)
            throw Error(name.loc, "too many arguments");
        check_format_literal(name.text, format, raw, n);
        e.emit(Op::FilePrint, -n, format_index, static_cast<std::uint8_t>(n), site(name.loc));
        return;
    }
    std::vector<VariableRef> targets;
    while (accept_operator(",")) {
        accept_operator("&");
        Token var = expect(LexMode::Expression, TokenKind::Name, "a variable to read into");
        VariableRef ref = resolve(var, false);
        if (ref.kind == VariableRef::Array)
            throw Error(var.loc, "fscanf reads into variables, not arrays ('" + var.text + "')");
        e.emit(ref.kind == VariableRef::Local ? Op::LoadLocal : Op::LoadGlobal, 1, ref.index);
        targets.push_back(ref);
        if (targets.size() > 200)
            throw Error(var.loc, "too many variables");
    }
    expect(LexMode::Expression, TokenKind::RParen, "')'");
    check_format_literal(name.text, format, raw, static_cast<int>(targets.size()));
    e.emit(Op::FileScan, 0, format_index, static_cast<std::uint8_t>(targets.size()),
           site(name.loc));
    for (auto it = targets.rbegin(); it != targets.rend(); ++it)
        e.emit(it->kind == VariableRef::Local ? Op::StoreLocal : Op::StoreGlobal, -1, it->index);
}

/// Where the character at `index` of a string literal's value is in the source: `raw`
/// holds the literal as written (blanks before it allowed); each escape is two
/// characters there and one in the value.
FileLoc string_char_loc(const Token& literal, std::string_view raw, std::size_t index)
{
    std::size_t quote = raw.find('"');
    std::size_t at = quote == std::string_view::npos ? 0 : quote + 1;
    for (std::size_t i = 0; i < index && at < raw.size(); ++i)
        at += raw[at] == '\\' ? 2 : 1;
    FileLoc loc = literal.loc;
    if (quote != std::string_view::npos)
        loc.column += static_cast<int>(at - quote);
    return loc;
}

/// A format literal of printf, fprintf or fscanf: its conversions must be ones
/// check_format allows and take exactly the values given, or loading stops here, so
/// no format reaches libc unchecked and none runs short of values.
void Parser::check_format_literal(const std::string& function, const Token& format,
                                  std::string_view raw, int values) const
{
    FormatCheck check = lsys::check_format(format.text, function == "fscanf");
    if (!check.problem.empty())
        throw Error(string_char_loc(format, raw, check.at), function + " format: " + check.problem);
    if (check.conversions != values)
        throw Error(format.loc, function + " format has " + std::to_string(check.conversions) +
                                    " conversion(s) but " + std::to_string(values) +
                                    (function == "fscanf" ? " variable(s) to read into"
                                                          : " value(s) to print"));
}

int Parser::parse_indices(Emitter& e)
{
    int n = 0;
    while (accept_operator("[")) {
        parse_expression(e);
        expect_operator("]");
        ++n;
    }
    return n;
}

void Parser::emit_load(Emitter& e, const Token& name)
{
    VariableRef ref = resolve(name, true);
    if (ref.kind == VariableRef::Array) {
        int n = parse_indices(e);
        check_subscripts(name, ref, n);
        e.emit(Op::LoadElement, 1 - n, ref.index, static_cast<std::uint8_t>(n), site(name.loc));
    } else {
        e.emit(ref.kind == VariableRef::Local ? Op::LoadLocal : Op::LoadGlobal, 1, ref.index);
    }
}

void Parser::check_subscripts(const Token& name, const VariableRef& ref, int n) const
{
    std::size_t dims = m_program.arrays[static_cast<std::size_t>(ref.index)].initial.dims.size();
    if (static_cast<std::size_t>(n) != dims)
        throw Error(name.loc, "array '" + name.text + "' has " + std::to_string(dims) +
                                  " dimension(s) but is used with " + std::to_string(n) +
                                  " subscript(s)");
}

std::optional<VariableRef> Parser::lookup(const std::string& name) const
{
    for (std::size_t i = 0; i < m_program.arrays.size(); ++i)
        if (m_program.arrays[i].name == name)
            return VariableRef{VariableRef::Array, static_cast<int>(i)};
    if (m_scope && !m_scope->global)
        for (const auto& [n, slot] : m_scope->locals)
            if (n == name)
                return VariableRef{VariableRef::Local, slot};
    for (std::size_t i = 0; i < m_program.global_names.size(); ++i)
        if (m_program.global_names[i] == name)
            return VariableRef{VariableRef::Global, static_cast<int>(i)};
    return std::nullopt;
}

VariableRef Parser::resolve(const Token& name, bool reading)
{
    if (auto known = lookup(name.text))
        return *known;
    // A name read before anything defines it: cpfg warns ("not previously defined") and
    // reads 0. In a production the warning waits until its text is known.
    bool in_production = m_scope && !m_scope->global;
    if (reading && in_production)
        m_scope->undefined.emplace_back(name.text, name.loc);
    else if (reading)
        warn_undefined(name.text, name.loc, m_context.empty() ? "an expression" : m_context);
    if (in_production)
        return {VariableRef::Local, m_scope->local_slot(name.text)};
    m_program.global_names.push_back(name.text);
    return {VariableRef::Global, static_cast<int>(m_program.global_names.size() - 1)};
}

void Parser::warn_undefined(const std::string& name, const FileLoc& loc, const std::string& where)
{
    if (!m_warned.insert(name).second)
        return;  // once per name
    warn(loc, "identifier '" + name + "' is read but not defined before (not a formal "
                                      "parameter, nor a variable assigned earlier); it "
                                      "evaluates to 0, in " + where);
}

double Parser::site(const FileLoc& loc)
{
    m_program.sites.push_back(loc);
    return static_cast<double>(m_program.sites.size() - 1);
}

}  // namespace

void ProductionSet::index(std::size_t symbol_count)
{
    by_symbol.assign(symbol_count, {});
    for (std::size_t i = 0; i < productions.size(); ++i)
        by_symbol[productions[i].predecessor.front().symbol].push_back(
            static_cast<std::uint32_t>(i));
}

namespace {

std::vector<ProductionSet*> production_sets(LSystemDefinition& ls)
{
    return {&ls.productions, &ls.decomposition, &ls.homomorphism};
}

/// The @-commands whose letters some production names as a predecessor or context
/// module (see SplitCommand).
void find_split_commands(Program& program)
{
    std::vector<char> rewritten(256, 0);
    auto note = [&](const std::vector<FormalModule>& modules) {
        for (const auto& f : modules) {
            std::string_view name = program.symbols.name(f.symbol);
            if (name.size() == 1)
                rewritten[static_cast<unsigned char>(name[0])] = 1;
        }
    };
    for (auto& ls : program.lsystems)
        for (ProductionSet* set : production_sets(ls))
            for (const auto& p : set->productions) {
                note(p.predecessor);
                note(p.left_context);
                note(p.right_context);
            }
    std::size_t n = program.symbols.size();
    for (std::size_t id = 0; id < n; ++id) {
        std::string name(program.symbols.name(static_cast<SymbolId>(id)));
        if (name.size() < 2 || name[0] != '@')
            continue;
        bool split = false;
        for (std::size_t i = 1; i < name.size(); ++i)
            split |= rewritten[static_cast<unsigned char>(name[i])] != 0;
        if (!split)
            continue;
        SplitCommand command;
        command.joined = static_cast<SymbolId>(id);
        for (char c : name)
            command.parts.push_back(program.symbols.intern(std::string(1, c)));
        program.split_commands.push_back(std::move(command));
    }
}

const SplitCommand* split_of(const Program& program, SymbolId symbol)
{
    for (const auto& c : program.split_commands)
        if (c.joined == symbol)
            return &c;
    return nullptr;
}

/// Replaces each module that names a split command by '@' and its letters; the last
/// letter keeps the parameters (`params`: a template's expressions or a formal's slots).
template <class Module, class Params>
void split_modules(const Program& program, std::vector<Module>& modules, Params Module::*params)
{
    std::vector<Module> out;
    for (auto& m : modules) {
        const SplitCommand* c = split_of(program, m.symbol);
        if (!c) {
            out.push_back(std::move(m));
            continue;
        }
        for (std::size_t i = 0; i + 1 < c->parts.size(); ++i) {
            Module letter = m;
            letter.symbol = c->parts[i];
            letter.*params = {};
            out.push_back(std::move(letter));
        }
        m.symbol = c->parts.back();
        out.push_back(std::move(m));
    }
    modules = std::move(out);
}

void split_symbols(const Program& program, std::vector<SymbolId>& symbols)
{
    std::vector<SymbolId> extra;
    for (SymbolId s : symbols)
        if (const SplitCommand* c = split_of(program, s))
            extra.insert(extra.end(), c->parts.begin(), c->parts.end());
    symbols.insert(symbols.end(), extra.begin(), extra.end());
}

/// Rewrites every axiom, production and ignore list in terms of the split commands.
void split_at_commands(Program& program)
{
    find_split_commands(program);
    if (program.split_commands.empty())
        return;
    for (auto& ls : program.lsystems) {
        split_modules(program, ls.axiom, &ModuleTemplate::params);
        split_symbols(program, ls.ignore);
        split_symbols(program, ls.consider);
        for (ProductionSet* set : production_sets(ls))
            for (auto& p : set->productions) {
                split_modules(program, p.predecessor, &FormalModule::param_slots);
                split_modules(program, p.left_context, &FormalModule::param_slots);
                split_modules(program, p.right_context, &FormalModule::param_slots);
                split_modules(program, p.successor, &ModuleTemplate::params);
                build_successor_prototype(p);
            }
    }
}

}  // namespace

void build_successor_prototype(Production& p)
{
    // The successor's symbols and constants are the same every time: keep them ready to
    // copy, and note the parameters to evaluate into the copy
    p.successor_prototype.clear();
    p.computed_params.clear();
    std::array<float, ModuleString::max_params> values{};
    for (std::size_t j = 0; j < p.successor.size(); ++j) {
        const ModuleTemplate& m = p.successor[j];
        for (std::size_t k = 0; k < m.params.size(); ++k) {
            const std::vector<Instr>& code = m.params[k].instrs;
            bool constant = code.size() == 1 && code.front().op == Op::Const;
            values[k] = constant ? static_cast<float>(code.front().value) : 0.0f;
            if (!constant)
                p.computed_params.push_back(
                    ComputedParam{static_cast<std::uint32_t>(p.successor_prototype.param_total() + k),
                                  static_cast<std::uint32_t>(j), static_cast<std::uint32_t>(k)});
        }
        p.successor_prototype.append(m.symbol, std::span<const float>(values.data(), m.params.size()));
    }
}

void parse_program(std::string_view preprocessed, const std::string& file_name, Program& program)
{
    program.file_name = file_name;
    Parser parser(preprocessed, file_name, program);
    parser.parse_file();
    split_at_commands(program);
    for (auto& ls : program.lsystems) {
        ls.productions.index(program.symbols.size());
        ls.decomposition.index(program.symbols.size());
        ls.homomorphism.index(program.symbols.size());
    }
}

}  // namespace cambium::lsys
