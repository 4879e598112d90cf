// SPDX-License-Identifier: Apache-2.0
// Compiled expressions and statements: a small stack bytecode evaluated without allocation.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "lsys/random.h"

namespace cambium::lsys {

enum class Op : std::uint8_t {
    Const,        ///< push value
    LoadLocal,    ///< push frame[arg]
    StoreLocal,   ///< frame[arg] = pop
    LoadGlobal,   ///< push globals[arg]
    StoreGlobal,  ///< globals[arg] = pop
    LoadElement,  ///< pop arg2 indices, push array arg element
    StoreElement, ///< pop value, pop arg2 indices, store into array arg
    Neg, Not, Add, Sub, Mul, Div, Mod, Pow, Less, LessEqual, Greater, GreaterEqual, Equal,
    NotEqual,
    AndJump,      ///< if top is 0 jump to arg (keep it), else pop
    OrJump,       ///< if top is not 0 jump to arg (keep 1), else pop
    ToBool,
    Jump,         ///< to arg
    JumpIfFalse,  ///< pop; jump to arg when 0
    Pop,
    Call,         ///< function arg with arg2 arguments
    Print,        ///< printf with format string arg and arg2 arguments; pushes 0
    FilePrint,    ///< fprintf: pop arg2 arguments and the file index; pushes 0
    FileScan,     ///< fscanf: pop arg2 old values and the file index; push the count
                  ///< read, then arg2 values (new where read, else the old ones)
};

/// Predefined functions of cpfg section 5.1.5 (the ones evaluated here).
enum class Function : std::uint8_t {
    Sin, Cos, Tan, Asin, Acos, Atan, Atan2, Exp, Log, Sqrt, Fabs, Floor, Ceil, Trunc, Sign,
    Ran, Nran, Bran, Biran, Srand, Stop, GetDerivationLength, SetDerivationLength, Func,
    CurveX, CurveY, CurveZ, CurveLength, Fopen, Fclose, Fflush,
};

/// A `while` or `do` loop may repeat at most this many times in one evaluation: a model
/// must not hang the renderer (`while (1) {}`); the limit is far above any real model.
inline constexpr std::uint64_t max_loop_iterations = 100'000'000;

/// Instructions that can fail or warn at run time (LoadElement, StoreElement, Div, Mod,
/// Call, FilePrint, FileScan, and a loop's backward jump) keep in `value` the index of their source position in
/// Program::sites, so a runtime error names the column, not only the production.
struct Instr {
    Op op;
    std::uint8_t arg2 = 0;
    std::int32_t arg = 0;
    double value = 0;
};

/// One compiled expression or statement list.
struct Code {
    std::vector<Instr> instrs;
    int max_stack = 0;
    bool empty() const { return instrs.empty(); }
};

/// A defined array (section 5.1.4): dimensions and row-major values.
struct ArrayValues {
    std::string name;  ///< for error messages
    std::vector<int> dims;
    std::vector<double> values;
};

/// Files the L-system opened with fopen (manual 5.1.5), by index; closed with the last
/// Runtime that shares them.
class OpenFiles {
public:
    static constexpr int max_open = 32;
    OpenFiles() = default;
    OpenFiles(const OpenFiles&) = delete;
    OpenFiles& operator=(const OpenFiles&) = delete;
    ~OpenFiles();
    /// Opens `name` (relative to `base_dir`, the model's folder) with mode "r", "w" or
    /// "a"; returns its index. Unless `anywhere`, the file must be a regular file (or a
    /// new one) inside `base_dir` or below once symbolic links and ".." are resolved
    /// (docs/security.md). Failures throw EvaluationError.
    int open(const std::string& base_dir, const std::string& name, const std::string& mode,
             bool anywhere = false);
    /// The open file with `index`, or throws EvaluationError.
    std::FILE* get(double index) const;
    void close(double index);

private:
    std::vector<std::FILE*> m_files;
};

/// Everything an evaluation may read or change besides the production's frame.
struct Runtime {
    std::vector<double> globals;
    std::vector<ArrayValues> arrays;
    const std::vector<std::string>* strings = nullptr;  ///< printf formats
    /// ran/nran/bran/biran: cpfg's erand48 state, 0x330E until srand() sets it
    Rand48 function_random = Rand48::from_state(0x330E);
    /// A scene's seed override: srand(x) then seeds with mixed_seed(x, override).
    std::optional<long> seed_override;
    double normal_spare = 0;     ///< nran's cached second deviate
    bool normal_cached = true;   ///< cpfg starts "cached" with a spare of 0
    int derivation_length = 0;
    /// stop() was called; stop_runs_end: with an argument other than 1 (cpfg's STOP,
    /// after which the End block runs; stop(1) is cpfg's RUN, which ends a batch
    /// derivation too but skips the End block). The last call decides.
    bool stop_requested = false;
    bool stop_runs_end = false;
    /// func(id, x): the view file's functions, provided by the caller (may be empty)
    const std::function<double(int, double)>* function = nullptr;
    /// curveX/Y/Z(id, t) and curveGAL(id): the view file's curves (may be empty)
    const std::function<double(char, int, double)>* curve = nullptr;
    /// named in the warning that an unprovided func() evaluates to 0
    const std::string* file_name = nullptr;
    bool function_warned = false;
    /// Reports a runtime warning (cpfg's "division by 0") at Program::sites[site] (-1:
    /// unknown); the Deriver names the production. Unset: a plain warning.
    const std::function<void(const std::string& message, int site)>* warning = nullptr;
    std::shared_ptr<OpenFiles> files = std::make_shared<OpenFiles>();
    /// fopen may open files outside the model's folder (--allow-file-access)
    bool allow_file_access = false;
};

/// A failure while evaluating: an array subscript out of range, '%' by 0, a file
/// function misused. It holds no file position: the Deriver, which knows the production
/// or block it was running, turns it into a cambium::Error that names them.
class EvaluationError : public std::runtime_error {
public:
    EvaluationError(const std::string& message, int site = -1)
        : std::runtime_error(message), m_site(site)
    {
    }
    /// Index into Program::sites of the failing expression; -1 when unknown.
    int site() const { return m_site; }
    void set_site(int site) { m_site = site; }

private:
    int m_site;
};

/// evaluate() for code that is more than a constant or a variable.
double evaluate_code(const Code& code, std::span<double> frame, Runtime& runtime);

/// Runs `code` with the given local frame. Returns the value left on top of the stack
/// (0 for statement code). Most successor parameters are a constant or a formal
/// parameter: those are read here without entering the interpreter.
inline double evaluate(const Code& code, std::span<double> frame, Runtime& runtime)
{
    if (code.instrs.size() == 1) {
        const Instr& in = code.instrs.front();
        if (in.op == Op::Const)
            return in.value;
        if (in.op == Op::LoadLocal)
            return frame[static_cast<std::size_t>(in.arg)];
    }
    return evaluate_code(code, frame, runtime);
}

/// A printf, fprintf or fscanf format checked when the L-system is compiled (formats are
/// always literals). printf formats allow only %[flags][width][.precision] followed by
/// e E f F g G (each takes a number), d i c (each takes a number converted to int), %lf
/// and the like (C's 'l' changes nothing there), and %%; width and precision at most 99.
/// fscanf formats (`scanning`) allow %[width][l] with d i e E f F g G.
struct FormatCheck {
    int conversions = 0;   ///< the values the format takes (%% takes none)
    std::string problem;   ///< empty when the format is accepted
    std::size_t at = 0;    ///< index in the format of the '%' that the problem is at
};
FormatCheck check_format(std::string_view format, bool scanning = false);

/// `value` truncated toward zero (C's conversion to an integer) when that lies in
/// [lo, hi]; nullopt when it is NaN or outside, where C's conversion is undefined. Every
/// conversion of a user's number to an integer goes through here.
std::optional<long long> truncated_in(double value, long long lo, long long hi);

/// The most steps a derivation length (and --steps) may ask for.
constexpr int max_derivation_steps = 1'000'000;
/// `steps` as a derivation length (truncated as cpfg's int conversion), or an
/// EvaluationError "`what` is ...; it must be from 0 to 1000000 steps".
int derivation_steps(double steps, const std::string& what);

/// A number for messages, as %g prints it.
std::string number_text(double value);

/// Function properties used by the compiler.
struct FunctionInfo {
    std::string_view name;
    Function function;
    int arity;  ///< -1: any
};
/// The function named `name`, or nullptr.
const FunctionInfo* find_function(std::string_view name);

}  // namespace cambium::lsys
