// SPDX-License-Identifier: Apache-2.0
// Compiled expressions and statements: a small stack bytecode evaluated without allocation.
#include "lsys/expression.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <optional>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/confinement.h"
#include "base/diagnostics.h"

namespace cambium::lsys {

namespace {

constexpr double to_radians = std::numbers::pi / 180.0;
constexpr int max_stack_depth = 256;
/// printf widths and precisions: at most 99 (digits), so one conversion prints at most
/// a few hundred characters
constexpr std::size_t max_format_digits = 2;

constexpr std::array<FunctionInfo, 31> functions = {{
    {"sin", Function::Sin, 1},     {"cos", Function::Cos, 1},
    {"tan", Function::Tan, 1},     {"asin", Function::Asin, 1},
    {"acos", Function::Acos, 1},   {"atan", Function::Atan, 1},
    {"atan2", Function::Atan2, 2}, {"exp", Function::Exp, 1},
    {"log", Function::Log, 1},     {"sqrt", Function::Sqrt, 1},
    {"fabs", Function::Fabs, 1},   {"floor", Function::Floor, 1},
    {"ceil", Function::Ceil, 1},   {"trunc", Function::Trunc, 1},
    {"sign", Function::Sign, 1},   {"ran", Function::Ran, 1},
    {"nran", Function::Nran, 2},   {"bran", Function::Bran, 2},
    {"biran", Function::Biran, 2}, {"srand", Function::Srand, 1},
    {"stop", Function::Stop, 1},   {"GetDerivationLength", Function::GetDerivationLength, 1},
    {"SetDerivationLength", Function::SetDerivationLength, 1},
    {"func", Function::Func, 2},         {"curveX", Function::CurveX, 2},
    {"curveY", Function::CurveY, 2},     {"curveZ", Function::CurveZ, 2},
    {"curveGAL", Function::CurveLength, 1},   {"fopen", Function::Fopen, 2},
    {"fclose", Function::Fclose, 1},     {"fflush", Function::Fflush, 1},
}};

/// nran: the polar (Marsaglia) method, which makes two normal deviates per pair of
/// draws and caches the second one, as cpfg's nrand does. cpfg starts with a cached value
/// of 0 that srand() clears, so the first nran before any srand returns the mean.
double normal_random(Runtime& rt, double mean, double sqrt_variance)
{
    if (rt.normal_cached) {
        rt.normal_cached = false;
        return rt.normal_spare * sqrt_variance + mean;
    }
    double v1, v2, rsq;
    do {
        v1 = 2.0 * rt.function_random.next_double() - 1.0;
        v2 = 2.0 * rt.function_random.next_double() - 1.0;
        rsq = v1 * v1 + v2 * v2;
    } while (rsq >= 1.0 || rsq == 0.0);
    double fac = std::sqrt(-2.0 * std::log(rsq) / rsq);
    rt.normal_spare = v1 * fac;
    rt.normal_cached = true;
    return v2 * fac * sqrt_variance + mean;
}

/// bran: Cheng's rejection algorithm for the beta distribution, as cpfg's brand.
double beta_random(Rand48& r, double a, double b)
{
    double s = a + b;
    double lambda = std::min(a, b) <= 1 ? std::min(a, b) : std::sqrt((2 * a * b - s) / (s - 2));
    double u = a + lambda;
    double u1, u2, v, ym;
    do {
        do
            u1 = r.next_double();
        while (u1 == 0);
        do
            u2 = r.next_double();
        while (u2 == 0);
        v = (1 / lambda) * std::log(u1 / (1 - u1));
        ym = a * std::exp(v);
    } while (s * std::log(s / (b + ym)) + u * v - std::log(4.0) < std::log(u1 * u1 * u2));
    return ym / (b + ym);
}

/// func() and the curve functions without the view file's data: 0, said once.
void warn_unbound(Runtime& rt, const std::string& what)
{
    if (rt.function_warned)
        return;
    rt.function_warned = true;
    std::string message = what + " needs the view file's functions or curves, which are "
                                 "not loaded; it evaluates to 0";
    if (rt.file_name)
        warn(FileLoc{*rt.file_name, 0, 0}, message);
    else
        warn(message);
}

constexpr long long max_biran_trials = 100'000'000;

/// A function or curve id: out of int's range it names no function (0, which geom
/// reports as undefined).
int id_value(double id) { return static_cast<int>(truncated_in(id, INT_MIN, INT_MAX).value_or(0)); }

/// A seed for srand48: a whole number within long's range.
long seed_value(double seed, const char* what)
{
    std::optional<long long> whole = truncated_in(seed, LONG_MIN, LONG_MAX);
    if (!whole)
        throw EvaluationError(std::string(what) + ": the seed " + number_text(seed) +
                              " is not a number within +-9.2e18");
    return static_cast<long>(*whole);
}

double call(Function f, const double* a, Runtime& rt)
{
    switch (f) {
    case Function::Sin: return std::sin(a[0] * to_radians);
    case Function::Cos: return std::cos(a[0] * to_radians);
    case Function::Tan: return std::tan(a[0] * to_radians);
    case Function::Asin: return std::asin(a[0]) / to_radians;
    case Function::Acos: return std::acos(a[0]) / to_radians;
    case Function::Atan: return std::atan(a[0]) / to_radians;
    // cpfg pops the arguments in reverse: its atan2(a, b) is C's atan2(b, a)
    case Function::Atan2: return std::atan2(a[1], a[0]) / to_radians;
    case Function::Exp: return std::exp(a[0]);
    case Function::Log: return std::log(a[0]);
    case Function::Sqrt: return std::sqrt(a[0]);
    case Function::Fabs: return std::fabs(a[0]);
    case Function::Floor: return std::floor(a[0]);
    case Function::Ceil: return std::ceil(a[0]);
    // cpfg's trunc rounds to the nearest integer (floor(x + 0.5)), unlike C's
    case Function::Trunc: return std::floor(a[0] + 0.5);
    case Function::Sign: return a[0] > 0 ? 1.0 : a[0] < 0 ? -1.0 : 0.0;
    case Function::Ran: return a[0] * rt.function_random.next_double();
    case Function::Nran: return normal_random(rt, a[0], a[1]);
    case Function::Bran: return beta_random(rt.function_random, a[0], a[1]);
    case Function::Biran: {
        // one draw per trial: bound the trials so that a call cannot run for hours
        std::optional<long long> trials = truncated_in(a[0], INT_MIN, max_biran_trials);
        if (!trials)
            throw EvaluationError("biran(" + number_text(a[0]) + ", p): the number of trials "
                                  "must be at most " + number_text(max_biran_trials));
        long long n = *trials;
        int count = 0;
        for (long long i = 0; i < n; ++i)
            count += rt.function_random.next_double() <= a[1] ? 1 : 0;
        return count;
    }
    case Function::Srand:
        rt.function_random.seed(rt.seed_override
                                    ? mixed_seed(seed_value(a[0], "srand()"), *rt.seed_override)
                                    : seed_value(a[0], "srand()"));
        rt.normal_cached = false;
        return 0;
    case Function::Stop:
        rt.stop_requested = true;
        rt.stop_runs_end = a[0] != 1;
        return 0;
    case Function::GetDerivationLength: return rt.derivation_length;
    case Function::SetDerivationLength:
        rt.derivation_length = derivation_steps(a[0], "SetDerivationLength()");
        return 0;
    case Function::Fopen: {
        std::string l_file = rt.file_name ? *rt.file_name : std::string();
        auto text = [&](double index) -> std::string {
            std::optional<long long> i =
                truncated_in(index, 0, rt.strings ? static_cast<long long>(rt.strings->size()) - 1 : -1);
            if (!i)
                throw EvaluationError("fopen needs a file name and a mode in quotes");
            return (*rt.strings)[static_cast<std::size_t>(*i)];
        };
        std::string base = std::filesystem::path(l_file).parent_path().string();
        return rt.files->open(base, text(a[0]), text(a[1]), rt.allow_file_access);
    }
    case Function::Fclose:
        rt.files->close(a[0]);
        return 0;
    case Function::Fflush:
        std::fflush(rt.files->get(a[0]));
        return 0;
    case Function::Func:
        // function sets live in the view file (geom); the caller binds them
        if (rt.function && *rt.function)
            return (*rt.function)(id_value(a[0]), a[1]);
        warn_unbound(rt, "func()");
        return 0;
    case Function::CurveX:
    case Function::CurveY:
    case Function::CurveZ:
    case Function::CurveLength: {
        char which = f == Function::CurveX   ? 'x'
                     : f == Function::CurveY ? 'y'
                     : f == Function::CurveZ ? 'z'
                                             : 'l';
        if (rt.curve && *rt.curve)
            return (*rt.curve)(which, id_value(a[0]), which == 'l' ? 0.0 : a[1]);
        warn_unbound(rt, "curveX/curveY/curveZ/curveGAL()");
        return 0;
    }
    }
    return 0;
}

/// One validated printf conversion, split into the parts format_values rebuilds.
struct Conversion {
    std::string_view flags;
    std::string_view width;
    std::string_view precision;  ///< with its '.', or empty
    char type = 0;               ///< e E f F g G d i c, or '%'
    std::size_t end = 0;         ///< index just past it in the format
};

bool is_digit_char(char c) { return c >= '0' && c <= '9'; }
bool one_of(const char* set, char c) { return c != 0 && std::strchr(set, c) != nullptr; }

/// The conversion starting at format[i] == '%' (see check_format), or a problem.
std::optional<Conversion> read_conversion(std::string_view format, std::size_t i,
                                          bool scanning, std::string& problem)
{
    Conversion c;
    std::size_t j = i + 1;
    auto span_while = [&](auto accept) {
        std::size_t from = j;
        while (j < format.size() && accept(format[j]))
            ++j;
        return format.substr(from, j - from);
    };
    if (!scanning)
        c.flags = span_while([](char ch) { return one_of("-+ #0", ch); });
    c.width = span_while(is_digit_char);
    if (!scanning && j < format.size() && format[j] == '.') {
        std::size_t dot = j++;
        span_while(is_digit_char);
        c.precision = format.substr(dot, j - dot);
    }
    if (c.width.size() > max_format_digits || c.precision.size() > max_format_digits + 1) {
        problem = "width and precision may have at most " + std::to_string(max_format_digits) +
                  " digits";
        return std::nullopt;
    }
    // 'l' before a floating conversion changes nothing in C (the corpus writes %lf)
    bool long_modifier = j < format.size() && format[j] == 'l';
    if (long_modifier)
        ++j;
    if (j >= format.size()) {
        problem = "the format ends inside a conversion";
        return std::nullopt;
    }
    c.type = format[j];
    c.end = j + 1;
    bool floating = one_of("eEfFgG", c.type);
    bool integer = one_of(scanning ? "di" : "dic", c.type);
    bool percent = c.type == '%' && c.end == i + 2;
    if (percent && !scanning)
        return c;
    if (c.type == '*' || (!floating && !integer) || (long_modifier && !floating)) {
        problem = "conversion '" + std::string(format.substr(i, c.end - i)) +
                  "' is not allowed; only " +
                  (scanning ? "%[width][l](d i e E f F g G)"
                            : "%[flags][width][.precision](e E f F g G d i c), %lf and %%") +
                  " are";
        return std::nullopt;
    }
    return c;
}

/// The int a %d %i %c conversion prints: C's conversion, saturated instead of undefined
/// outside int's range (NaN prints 0).
int saturated_int(double v)
{
    if (!(v == v))
        return 0;
    if (v >= 2147483647.0)
        return 2147483647;
    if (v <= -2147483648.0)
        return -2147483647 - 1;
    return static_cast<int>(v);
}

/// printf over a format that check_format accepted: each conversion is rebuilt from its
/// validated parts and given one value (a value missing is 0), so no user text reaches
/// libc as a format.
std::string format_values(std::string_view format, const double* args, int count)
{
    std::string out;
    int used = 0;
    std::string problem;
    for (std::size_t i = 0; i < format.size(); ++i) {
        if (format[i] != '%') {
            out += format[i];
            continue;
        }
        std::optional<Conversion> c = read_conversion(format, i, false, problem);
        if (!c)
            throw EvaluationError("printf format \"" + std::string(format) + "\": " + problem);
        i = c->end - 1;
        if (c->type == '%') {
            out += '%';
            continue;
        }
        double value = used < count ? args[used++] : 0.0;
        bool integer = one_of("dic", c->type);
        std::string spec(1, '%');
        spec.append(c->flags).append(c->width).append(c->precision).push_back(c->type);
        int n = integer ? std::snprintf(nullptr, 0, spec.c_str(), saturated_int(value))
                        : std::snprintf(nullptr, 0, spec.c_str(), value);
        if (n <= 0)
            continue;
        std::string text(static_cast<std::size_t>(n) + 1, '\0');
        if (integer)
            std::snprintf(text.data(), text.size(), spec.c_str(), saturated_int(value));
        else
            std::snprintf(text.data(), text.size(), spec.c_str(), value);
        out.append(text.data(), static_cast<std::size_t>(n));
    }
    return out;
}

/// fscanf with only number conversions (%f %g %e %lf %d ...): each reads one number
/// into the next value; blanks in the format skip blanks, other characters must match.
/// Returns how many values were read.
int scan_values(std::FILE* file, const std::string& format, double* values, int count)
{
    int read = 0;
    auto skip_blanks = [&] {
        int c;
        while ((c = std::fgetc(file)) != EOF && std::isspace(c)) {
        }
        if (c != EOF)
            std::ungetc(c, file);
    };
    for (std::size_t i = 0; i < format.size(); ++i) {
        char f = format[i];
        if (std::isspace(static_cast<unsigned char>(f))) {
            skip_blanks();
            continue;
        }
        if (f != '%' || i + 1 >= format.size()) {
            int c = std::fgetc(file);
            if (c != f) {
                if (c != EOF)
                    std::ungetc(c, file);
                return read;
            }
            continue;
        }
        std::size_t j = i + 1;
        while (j < format.size() && (format[j] == 'l' || std::isdigit(static_cast<unsigned char>(format[j]))))
            ++j;
        if (j >= format.size() || read >= count)
            return read;
        i = j;
        skip_blanks();
        std::string number;
        int c;
        while (number.size() < 64 && (c = std::fgetc(file)) != EOF) {
            if (std::isdigit(c) || std::strchr("+-.eE", c)) {
                number += static_cast<char>(c);
            } else {
                std::ungetc(c, file);
                break;
            }
        }
        char* end = nullptr;
        double v = std::strtod(number.c_str(), &end);
        if (number.empty() || end == number.c_str())
            return read;
        values[read++] = v;
    }
    return read;
}

double int_modulo(double a, double b)
{
    // cpfg takes % on ints, and its int % 0 kills the process: say so instead
    double divisor = std::trunc(b);
    if (divisor == 0 || !std::isfinite(b))
        throw EvaluationError("'%' with divisor " + number_text(b) +
                              " (the remainder is taken on integers; the divisor truncates to 0)");
    if (!std::isfinite(a) || std::fabs(a) > 2147483647.0 || std::fabs(divisor) > 2147483647.0)
        return std::fmod(std::trunc(a), divisor);
    return static_cast<double>(static_cast<int>(a) % static_cast<int>(divisor));
}

/// The row-major offset of an element. cpfg warns about a subscript outside the array
/// and clamps it; here it is an error that names the array, the subscript and the range.
std::size_t element_index(const ArrayValues& a, const double* idx, int n, const std::string& name)
{
    if (n != static_cast<int>(a.dims.size()))
        throw EvaluationError("array '" + name + "' has " + std::to_string(a.dims.size()) +
                              " dimension(s) but is used with " + std::to_string(n) +
                              " subscript(s)");
    std::size_t flat = 0;
    for (int d = 0; d < n; ++d) {
        int size = a.dims[static_cast<std::size_t>(d)];
        // cpfg's test: a subscript is out of range when < 0 or >= the size
        if (!(idx[d] >= 0 && idx[d] < size))
            throw EvaluationError("subscript " + std::to_string(d + 1) + " of array '" + name +
                                  "' is " + number_text(idx[d]) + ", outside 0.." +
                                  std::to_string(size - 1));
        flat = flat * static_cast<std::size_t>(size) + static_cast<std::size_t>(idx[d]);
    }
    return flat;
}

void warn_division_by_zero(Runtime& rt, int site)
{
    std::string message = "division by 0; cpfg divides by 1 instead";
    if (rt.warning && *rt.warning)
        (*rt.warning)(message, site);
    else
        warn(FileLoc{rt.file_name ? *rt.file_name : std::string(), 0, 0}, message);
}

}  // namespace

std::optional<long long> truncated_in(double value, long long lo, long long hi)
{
    // compare before converting: the conversion itself is undefined out of range
    // (2^63 itself is a double within LLONG_MAX's rounding but not a long long)
    constexpr double two_to_63 = 9223372036854775808.0;
    double whole = std::trunc(value);
    if (!(whole >= static_cast<double>(lo) && whole <= static_cast<double>(hi) &&
          whole < two_to_63))
        return std::nullopt;
    return static_cast<long long>(whole);
}

int derivation_steps(double steps, const std::string& what)
{
    std::optional<long long> whole = truncated_in(steps, 0, max_derivation_steps);
    if (!whole)
        throw EvaluationError(what + " is " + number_text(steps) + "; it must be from 0 to " +
                              std::to_string(max_derivation_steps) + " steps");
    return static_cast<int>(*whole);
}

std::string number_text(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

FormatCheck check_format(std::string_view format, bool scanning)
{
    FormatCheck check;
    for (std::size_t i = 0; i < format.size(); ++i) {
        if (format[i] != '%')
            continue;
        std::optional<Conversion> c = read_conversion(format, i, scanning, check.problem);
        if (!c) {
            check.at = i;
            return check;
        }
        if (c->type != '%')
            ++check.conversions;
        i = c->end - 1;
    }
    return check;
}

OpenFiles::~OpenFiles()
{
    for (std::FILE* f : m_files)
        if (f)
            std::fclose(f);
}

namespace {

/// The file `name` names in the model's folder `base_dir`, links and ".." resolved,
/// or an EvaluationError when it lies outside.
std::filesystem::path confined_path(const std::string& base_dir, const std::string& name)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path folder = fs::canonical(base_dir.empty() ? fs::path(".") : fs::path(base_dir), ec);
    if (ec)
        throw EvaluationError("fopen(\"" + name + "\"): the model's folder '" + base_dir +
                              "' cannot be resolved: " + ec.message());
    fs::path path = fs::weakly_canonical(folder / name, ec);
    // a link whose target does not exist yet stays unresolved: judge it by its target
    // (open_regular does not follow it either way)
    std::error_code link_ec;
    if (!ec && fs::is_symlink(fs::symlink_status(path, link_ec))) {
        fs::path target = fs::read_symlink(path, link_ec);
        if (!link_ec)
            path = fs::weakly_canonical(
                target.is_absolute() ? target : path.parent_path() / target, ec);
    }
    if (ec || !is_within(folder, path) || path == folder)
        throw EvaluationError("fopen(\"" + name + "\"): '" + (ec ? name : path.string()) +
                              "' is outside the model's folder '" + folder.string() +
                              "'; an L-system opens files only there and below "
                              "(--allow-file-access lifts this)");
    return path;
}

/// Opens a confined file without following a link in its last component (a link that
/// points nowhere yet would create its target) and only if it is a regular file, so a
/// device or a FIFO is neither read nor waited on. A file to write must have one name:
/// a hard link shipped in the model's folder may share its data with a file outside, so
/// it is checked before anything is truncated.
std::FILE* open_regular(const std::filesystem::path& path, const std::string& mode)
{
    int flags = mode == "r" ? O_RDONLY : O_WRONLY | O_CREAT | (mode == "a" ? O_APPEND : 0);
    int fd = ::open(path.c_str(), flags | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0666);
    if (fd < 0)
        return nullptr;
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        throw EvaluationError("fopen: '" + path.string() + "' is not a regular file");
    }
    if (mode != "r" && st.st_nlink > 1) {
        ::close(fd);
        throw EvaluationError("fopen: '" + path.string() + "' has " + std::to_string(st.st_nlink) +
                              " hard links, so writing it could change a file outside the model's "
                              "folder; an L-system writes only files of one name "
                              "(--allow-file-access lifts this)");
    }
    if (mode == "w" && ::ftruncate(fd, 0) != 0) {
        ::close(fd);
        return nullptr;
    }
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    std::FILE* f = ::fdopen(fd, mode.c_str());
    if (!f)
        ::close(fd);
    return f;
}

}  // namespace

int OpenFiles::open(const std::string& base_dir, const std::string& name,
                    const std::string& mode, bool anywhere)
{
    if (mode != "r" && mode != "w" && mode != "a")
        throw EvaluationError("fopen(\"" + name + "\", \"" + mode +
                              "\"): the mode must be \"r\", \"w\" or \"a\"");
    std::size_t slot = 0;
    while (slot < m_files.size() && m_files[slot])
        ++slot;
    if (slot >= static_cast<std::size_t>(max_open))
        throw EvaluationError("fopen(\"" + name + "\"): more than " +
                              std::to_string(max_open) + " files open at once");
    std::filesystem::path path(name);
    std::FILE* f = nullptr;
    if (anywhere) {
        if (path.is_relative() && !base_dir.empty())
            path = std::filesystem::path(base_dir) / path;
        f = std::fopen(path.string().c_str(), mode.c_str());
    } else {
        path = confined_path(base_dir, name);
        f = open_regular(path, mode);
    }
    if (!f)
        throw EvaluationError("fopen: cannot open '" + path.string() + "' for " +
                              (mode == "r" ? "reading" : "writing") + ": " +
                              std::strerror(errno));
    if (slot == m_files.size())
        m_files.push_back(f);
    else
        m_files[slot] = f;
    return static_cast<int>(slot);
}

std::FILE* OpenFiles::get(double index) const
{
    if (!(index >= 0 && index < static_cast<double>(m_files.size())) ||
        !m_files[static_cast<std::size_t>(index)])
        throw EvaluationError("file index " + number_text(index) +
                              " does not name a file opened with fopen");
    return m_files[static_cast<std::size_t>(index)];
}

void OpenFiles::close(double index)
{
    std::FILE* f = get(index);
    std::fclose(f);
    m_files[static_cast<std::size_t>(index)] = nullptr;
}

const FunctionInfo* find_function(std::string_view name)
{
    for (const auto& f : functions)
        if (f.name == name)
            return &f;
    return nullptr;
}

namespace {

double run(const Code& code, std::span<double> frame, Runtime& rt, std::size_t& pc)
{
    std::array<double, max_stack_depth> stack;
    int sp = 0;
    const Instr* instrs = code.instrs.data();
    const std::size_t count = code.instrs.size();
    std::uint64_t loop_iterations = 0;
    // A jump back is one more iteration of a while or do loop: bounded, never a hang.
    auto jump_to = [&](const Instr& in) {
        std::size_t target = static_cast<std::size_t>(in.arg);
        if (target <= pc && ++loop_iterations > max_loop_iterations)
            throw EvaluationError("a loop repeated more than " +
                                      std::to_string(max_loop_iterations) +
                                      " times (a loop that never ends?)",
                                  static_cast<int>(in.value));
        pc = target - 1;
    };
    for (pc = 0; pc < count; ++pc) {
        const Instr& in = instrs[pc];
        switch (in.op) {
        case Op::Const: stack[sp++] = in.value; break;
        case Op::LoadLocal: stack[sp++] = frame[static_cast<std::size_t>(in.arg)]; break;
        case Op::StoreLocal: frame[static_cast<std::size_t>(in.arg)] = stack[--sp]; break;
        case Op::LoadGlobal: stack[sp++] = rt.globals[static_cast<std::size_t>(in.arg)]; break;
        case Op::StoreGlobal: rt.globals[static_cast<std::size_t>(in.arg)] = stack[--sp]; break;
        case Op::LoadElement: {
            sp -= in.arg2;
            const auto& a = rt.arrays[static_cast<std::size_t>(in.arg)];
            stack[sp] = a.values[element_index(a, &stack[sp], in.arg2, a.name)];
            ++sp;
            break;
        }
        case Op::StoreElement: {
            double v = stack[--sp];
            sp -= in.arg2;
            auto& a = rt.arrays[static_cast<std::size_t>(in.arg)];
            a.values[element_index(a, &stack[sp], in.arg2, a.name)] = v;
            break;
        }
        case Op::Neg: stack[sp - 1] = -stack[sp - 1]; break;
        case Op::Not: stack[sp - 1] = stack[sp - 1] == 0 ? 1 : 0; break;
        case Op::ToBool: stack[sp - 1] = stack[sp - 1] != 0 ? 1 : 0; break;
#define CAMBIUM_BINARY(OPNAME, EXPR)          \
    case Op::OPNAME: {                        \
        double b = stack[--sp];               \
        double a = stack[sp - 1];             \
        stack[sp - 1] = (EXPR);               \
        break;                                \
    }
        CAMBIUM_BINARY(Add, a + b)
        CAMBIUM_BINARY(Sub, a - b)
        CAMBIUM_BINARY(Mul, a * b)
        // cpfg divides by 1 instead of 0 (with a warning) and takes % on ints
        case Op::Div: {
            double b = stack[--sp];
            if (b == 0.0) {
                warn_division_by_zero(rt, static_cast<int>(in.value));
                b = 1.0;
            }
            stack[sp - 1] /= b;
            break;
        }
        CAMBIUM_BINARY(Mod, int_modulo(a, b))
        CAMBIUM_BINARY(Pow, std::pow(a, b))
        CAMBIUM_BINARY(Less, a < b ? 1.0 : 0.0)
        CAMBIUM_BINARY(LessEqual, a <= b ? 1.0 : 0.0)
        CAMBIUM_BINARY(Greater, a > b ? 1.0 : 0.0)
        CAMBIUM_BINARY(GreaterEqual, a >= b ? 1.0 : 0.0)
        CAMBIUM_BINARY(Equal, a == b ? 1.0 : 0.0)
        CAMBIUM_BINARY(NotEqual, a != b ? 1.0 : 0.0)
#undef CAMBIUM_BINARY
        case Op::AndJump:
            if (stack[sp - 1] == 0)
                pc = static_cast<std::size_t>(in.arg) - 1;
            else
                --sp;
            break;
        case Op::OrJump:
            if (stack[sp - 1] != 0) {
                stack[sp - 1] = 1;
                pc = static_cast<std::size_t>(in.arg) - 1;
            } else {
                --sp;
            }
            break;
        case Op::Jump: jump_to(in); break;
        case Op::JumpIfFalse:
            if (stack[--sp] == 0)
                jump_to(in);
            break;
        case Op::Pop: --sp; break;
        case Op::Call:
            sp -= in.arg2;
            stack[sp] = call(static_cast<Function>(in.arg), &stack[sp], rt);
            ++sp;
            break;
        case Op::Print:
            sp -= in.arg2;
            if (rt.strings)
                std::fputs(format_values((*rt.strings)[static_cast<std::size_t>(in.arg)],
                                         &stack[sp], in.arg2)
                               .c_str(),
                           stdout);
            stack[sp++] = 0;
            break;
        case Op::FilePrint: {
            sp -= in.arg2;
            std::FILE* f = rt.files->get(stack[sp - 1]);
            if (rt.strings)
                std::fputs(format_values((*rt.strings)[static_cast<std::size_t>(in.arg)],
                                         &stack[sp], in.arg2)
                               .c_str(),
                           f);
            stack[sp - 1] = 0;
            break;
        }
        case Op::FileScan: {
            // stack: file, old values; becomes: count, values
            int n = in.arg2;
            sp -= n;
            double* values = &stack[sp];
            std::FILE* f = rt.files->get(stack[sp - 1]);
            std::array<double, max_stack_depth> read_values;
            int count = rt.strings ? scan_values(f, (*rt.strings)[static_cast<std::size_t>(in.arg)],
                                                 read_values.data(), n)
                                   : 0;
            for (int k = 0; k < count; ++k)
                values[k] = read_values[static_cast<std::size_t>(k)];
            stack[sp - 1] = count;
            sp += n;
            break;
        }
        }
    }
    return sp > 0 ? stack[sp - 1] : 0.0;
}

}  // namespace

double evaluate_code(const Code& code, std::span<double> frame, Runtime& rt)
{
    std::size_t pc = 0;
    try {
        return run(code, frame, rt, pc);
    } catch (EvaluationError& e) {
        // the failing instruction knows where in the source it came from
        if (e.site() < 0 && pc < code.instrs.size())
            e.set_site(static_cast<int>(code.instrs[pc].value));
        throw;
    }
}

}  // namespace cambium::lsys
