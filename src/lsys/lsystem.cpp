// SPDX-License-Identifier: Apache-2.0
// The public face of src/lsys: load a cpfg .l file, read its axiom, derive strings.
#include "lsys/lsystem.h"

#include <fstream>
#include <sstream>

#include "base/diagnostics.h"
#include "lsys/deriver.h"
#include "lsys/parser.h"
#include "lsys/preprocessor.h"
#include "lsys/program.h"

namespace cambium::lsys {

namespace {

std::string read_source(const std::filesystem::path& file, std::size_t limit)
{
    std::error_code ec;
    auto size = std::filesystem::file_size(file, ec);
    if (ec)
        throw Error(FileLoc{file.string(), 0, 0}, "cannot read the L-system file: " + ec.message());
    if (size > limit)
        throw Error(FileLoc{file.string(), 0, 0},
                    "the file is " + std::to_string(size) + " bytes; at most " +
                        std::to_string(limit) + " are accepted");
    std::ifstream in(file, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    if (!in && !in.eof())
        throw Error(FileLoc{file.string(), 0, 0}, "cannot read the L-system file");
    return ss.str();
}

std::unique_ptr<Program> compile(std::string_view source, const std::string& file_name,
                                 const PreprocessOptions& pp)
{
    std::string text = preprocess(source, file_name, pp);
    auto program = std::make_unique<Program>();
    parse_program(text, file_name, *program);
    return program;
}

}  // namespace

LSystem::LSystem(std::unique_ptr<Program> program, LoadOptions options)
    : m_program(std::move(program)), m_options(std::move(options))
{
}
LSystem::LSystem(LSystem&&) noexcept = default;
LSystem& LSystem::operator=(LSystem&&) noexcept = default;
LSystem::~LSystem() = default;

LSystem LSystem::load(const std::filesystem::path& file, const LoadOptions& options)
{
    PreprocessOptions pp;
    pp.defines = options.defines;
    pp.preprocessor = options.preprocessor;
    pp.include_dirs.push_back(file.parent_path().empty() ? "." : file.parent_path());
    std::string source = read_source(file, pp.max_input_bytes);
    return LSystem(compile(source, file.string(), pp), options);
}

LSystem LSystem::from_source(std::string_view source, std::string_view file_name,
                             const LoadOptions& options)
{
    PreprocessOptions pp;
    pp.defines = options.defines;
    pp.preprocessor = options.preprocessor;
    return LSystem(compile(source, std::string(file_name), pp), options);
}

const SymbolTable& LSystem::symbols() const { return m_program->symbols; }
SymbolTable& LSystem::symbols() { return m_program->symbols; }
const Program& LSystem::program() const { return *m_program; }

int LSystem::derivation_length() const
{
    Deriver deriver(*m_program, DeriveLimits{m_options.max_modules});
    return deriver.derivation_length();
}

ModuleString LSystem::axiom() const
{
    Deriver deriver(*m_program, DeriveLimits{m_options.max_modules});
    return deriver.string();
}

ModuleString LSystem::derive(std::optional<int> steps) const
{
    Deriver deriver(*m_program, DeriveLimits{m_options.max_modules});
    int n = steps.value_or(deriver.derivation_length());
    for (int i = 0; i < n; ++i)
        deriver.step();
    deriver.finish();
    return deriver.take_string();
}

}  // namespace cambium::lsys
