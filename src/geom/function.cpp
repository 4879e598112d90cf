// SPDX-License-Identifier: Apache-2.0
// cpfg's user-defined functions (`.func` files, function sets), read and evaluated as
// cpfg does.
#include "geom/function.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>

#include "geom/surface.h"
#include "geom/text_input.h"

namespace cambium::geom {

using detail::TextCursor;

// ---------------------------------------------------------------------------------------
// Evaluation (cpfg's splinefun.cpp: an open uniform B-spline of order 4)

namespace {

constexpr int order = 4;

// Knot j of the clamped uniform knot vector 0,0,0,0,1,2,...,n-2,n-2,n-2,n-2.
int knot(int j, int n)
{
    if (j < order)
        return 0;
    if (j > n)
        return n - order + 2;
    return j - order + 1;
}

// Cox-de Boor with cpfg's half-open intervals (so every basis is 0 at the very end).
double basis(int k, int t, double u, int n)
{
    if (t == 1)
        return (knot(k, n) <= u && u < knot(k + 1, n)) ? 1.0 : 0.0;
    double sum = 0;
    int div = knot(k + t - 1, n) - knot(k, n);
    if (div != 0)
        sum = (u - knot(k, n)) / div * basis(k, t - 1, u, n);
    div = knot(k + t, n) - knot(k + 1, n);
    if (div != 0)
        sum += (knot(k + t, n) - u) / div * basis(k + 1, t - 1, u, n);
    return sum;
}

// cpfg reads the points as float.
double as_read(double v) { return static_cast<double>(static_cast<float>(v)); }

}  // namespace

SplineFunction::SplineFunction(std::string name, std::vector<Point> points, int samples,
                               const FileLoc& loc)
    : m_name(std::move(name)), m_points(std::move(points))
{
    if (m_points.size() < 4)
        throw Error(loc, "a function needs at least 4 control points, not " +
                             std::to_string(m_points.size()));
    if (m_points.size() > max_function_points)
        throw Error(loc, "too many function control points (the limit is " +
                             std::to_string(max_function_points) + ")");
    if (samples > max_function_samples)
        throw Error(loc, "too many function samples (the limit is " +
                             std::to_string(max_function_samples) + ")");
    if (samples > 2) {
        m_table.reserve(static_cast<std::size_t>(samples));
        for (int i = 0; i < samples; ++i)
            m_table.push_back(evaluate_exact(static_cast<double>(i) / (samples - 1)));
        m_samples = samples;
    }
}

SplineFunction::Point SplineFunction::curve_point(double d) const
{
    const int n = static_cast<int>(m_points.size()) - 1;
    const double u = d * (n - order + 2);
    Point sum;
    // Only the bases k = floor(u) .. floor(u) + 3 can be non-zero at u.
    const int first = std::max(0, static_cast<int>(std::floor(u)));
    const int last = std::min(n, first + order - 1);
    for (int k = first; k <= last; ++k) {
        double w = basis(k, order, u, n);
        sum.x += m_points[static_cast<std::size_t>(k)].x * w;
        sum.y += m_points[static_cast<std::size_t>(k)].y * w;
    }
    return sum;
}

// cpfg bisects the curve parameter until x is within 0.001 and returns y there. It
// would loop for ever when x is never reached; the iteration count is bounded here.
double SplineFunction::evaluate_exact(double x) const
{
    constexpr double max_error = 0.001;
    constexpr int max_iterations = 200;
    double low = 0, high = 1;
    Point p;
    for (int i = 0; i < max_iterations; ++i) {
        double check = (low + high) / 2;
        p = curve_point(check);
        if (p.x > x)
            high = check;
        else
            low = check;
        if (std::fabs(p.x - x) <= max_error)
            break;
    }
    return p.y;
}

double SplineFunction::evaluate(double x) const
{
    x = std::clamp(x, 0.0, 1.0);
    if (m_samples <= 2)
        return evaluate_exact(x);
    double index = x * (m_samples - 1);
    int i = static_cast<int>(std::floor(index));
    if (i >= m_samples - 1)
        return m_table.back();
    double w2 = index - i;
    return (1 - w2) * m_table[static_cast<std::size_t>(i)] + w2 * m_table[static_cast<std::size_t>(i) + 1];
}

// ---------------------------------------------------------------------------------------
// Reading

namespace {

/// The file as lines, read one at a time as cpfg's fgets calls do.
class LineStream {
public:
    LineStream(std::string_view text, std::string file) : m_file(std::move(file))
    {
        std::size_t pos = 0;
        while (pos < text.size()) {
            std::size_t end = text.find('\n', pos);
            if (end == std::string_view::npos)
                end = text.size();
            m_lines.push_back(text.substr(pos, end - pos));
            pos = end + 1;
        }
    }

    bool at_end() const { return m_next >= m_lines.size(); }
    /// The next line as a cursor (Error at the end of the file).
    TextCursor next(const char* what)
    {
        if (at_end())
            throw Error(FileLoc{m_file, static_cast<int>(m_lines.size())},
                        std::string("unexpected end of file: expected ") + what);
        ++m_next;
        return TextCursor(m_lines[m_next - 1], m_file, static_cast<int>(m_next), 1);
    }
    /// The next line that is not blank.
    TextCursor next_nonblank(const char* what)
    {
        while (!at_end() && m_lines[m_next].find_first_not_of(" \t\r") == std::string_view::npos)
            ++m_next;
        return next(what);
    }
    /// The first character of the next line after blanks, or 0.
    char peek() const
    {
        if (at_end())
            return 0;
        std::string_view l = m_lines[m_next];
        std::size_t i = l.find_first_not_of(" \t\r");
        return i == std::string_view::npos ? 0 : l[i];
    }
    void skip() { if (!at_end()) ++m_next; }
    const std::string& file() const { return m_file; }

private:
    std::string m_file;
    std::vector<std::string_view> m_lines;
    std::size_t m_next = 0;
};

std::size_t read_point_count(LineStream& lines)
{
    TextCursor line = lines.next_nonblank("'points: n'");
    FileLoc loc = line.loc();
    line.expect("points:", "(function)");
    int n = line.integer("the number of points");
    if (n < 0 || static_cast<std::size_t>(n) > max_function_points)
        throw Error(loc, "bad number of function points: " + std::to_string(n));
    return static_cast<std::size_t>(n);
}

std::vector<SplineFunction::Point> read_points(LineStream& lines, std::size_t count, bool multiplicity)
{
    std::vector<SplineFunction::Point> points;
    for (std::size_t i = 0; i < count; ++i) {
        TextCursor line = lines.next_nonblank("a function point 'x y'");
        double x = as_read(line.number("the point's x"));
        double y = as_read(line.number("the point's y"));
        int times = 1;
        if (multiplicity && !line.at_line_end()) {
            FileLoc mloc = line.loc();
            times = line.integer("the point's multiplicity");
            if (times < 0 || points.size() + static_cast<std::size_t>(times) > max_function_points)
                throw Error(mloc, "bad point multiplicity: " + std::to_string(times));
        }
        if (!line.at_line_end())
            throw line.error("unexpected text after a function point");
        points.insert(points.end(), static_cast<std::size_t>(times), {x, y});
    }
    return points;
}

SplineFunction read_version_101(LineStream& lines)
{
    TextCursor name_line = lines.next("'name: name'");
    FileLoc loc = name_line.loc();
    name_line.expect("name:", "(function)");
    std::string name = name_line.word("the function's name");
    TextCursor samples_line = lines.next("'samples: n'");
    samples_line.expect("samples:", "(function)");
    int samples = samples_line.integer("the number of samples");
    if (lines.peek() == 'b') {  // an editor background image: two lines, ignored
        lines.skip();
        lines.skip();
    }
    if (lines.peek() == 'm') {  // editor markers, ignored
        TextCursor markers_line = lines.next("'markers: n'");
        markers_line.expect("markers:", "(function)");
        int markers = markers_line.integer("the number of markers");
        if (markers < 0 || static_cast<std::size_t>(markers) > max_function_points)
            throw markers_line.error("bad number of markers");
        for (int i = 0; i < markers; ++i)
            lines.next("a marker line");
    }
    TextCursor flip_line = lines.next("'flip: on|off'");  // display only, ignored
    (void)flip_line;
    std::size_t count = read_point_count(lines);
    std::vector<SplineFunction::Point> points = read_points(lines, count, true);
    return SplineFunction(name, std::move(points), samples, loc);
}

SplineFunction read_one_function(LineStream& lines, int view_samples, const std::string& fallback_name)
{
    TextCursor first = lines.next_nonblank("'range:' or 'fver'");
    FileLoc loc = first.loc();
    if (first.try_literal("range:")) {
        first.number("the lower limit of the range");
        first.number("the upper limit of the range");
        std::size_t count = read_point_count(lines);
        std::vector<SplineFunction::Point> points = read_points(lines, count, false);
        return SplineFunction(fallback_name, std::move(points), view_samples, loc);
    }
    if (!first.try_literal("fver"))
        throw Error(loc, "expected 'range:' or 'fver' at the start of a function");
    int major = first.integer("the major version");
    int minor = first.integer("the minor version");
    if (major != 1 || minor != 1)
        throw Error(loc, "unsupported function version " + std::to_string(major) + "." +
                             std::to_string(minor) + " (1.1 and the original are known)");
    return read_version_101(lines);
}

}  // namespace

SplineFunction parse_function_text(std::string_view text, const std::string& file_name,
                                   int view_samples, const std::string& name_if_unnamed)
{
    LineStream lines(text, file_name);
    return read_one_function(lines, view_samples, name_if_unnamed);
}

SplineFunction read_function_file(const std::filesystem::path& file, int view_samples)
{
    return parse_function_text(read_text_file(file, "function file"), file.string(), view_samples,
                               file.stem().string());
}

std::vector<SplineFunction> parse_function_set_text(std::string_view text, const std::string& file_name)
{
    LineStream lines(text, file_name);
    TextCursor header = lines.next_nonblank("'funcgalleryver 1 1'");
    FileLoc loc = header.loc();
    header.expect("funcgalleryver", "(function set)");
    int major = header.integer("the major version");
    int minor = header.integer("the minor version");
    if (major != 1 || minor != 1)
        throw Error(loc, "unsupported function set version " + std::to_string(major) + "." +
                             std::to_string(minor));
    TextCursor items_line = lines.next_nonblank("'items: n'");
    items_line.expect("items:", "(function set)");
    FileLoc items_loc = items_line.loc();
    int items = items_line.integer("the number of items");
    if (items < 0 || items > 4096)
        throw Error(items_loc, "bad number of function set items: " + std::to_string(items));
    std::vector<SplineFunction> functions;
    for (int i = 0; i < items; ++i)
        functions.push_back(read_one_function(lines, 0, "function" + std::to_string(i + 1)));
    return functions;
}

std::vector<SplineFunction> read_function_set_file(const std::filesystem::path& file)
{
    return parse_function_set_text(read_text_file(file, "function set file"), file.string());
}

// ---------------------------------------------------------------------------------------
// FunctionSet

FunctionSet FunctionSet::from_view_file(const ViewFile& view)
{
    return from_view_commands(view.functions, view.path.parent_path());
}

FunctionSet FunctionSet::from_view_commands(std::span<const FunctionFile> commands,
                                            const std::filesystem::path& base_dir)
{
    FunctionSet set;
    for (const FunctionFile& c : commands) {
        std::filesystem::path file = c.file.is_relative() ? base_dir / c.file : c.file;
        if (c.is_set) {
            set.m_functions = read_function_set_file(file);  // cpfg starts a new list
            set.m_from_set = true;
        } else {
            set.add(read_function_file(file, c.samples));
        }
    }
    return set;
}

double FunctionSet::evaluate(int id, double x) const
{
    if (id < 1 || static_cast<std::size_t>(id) > m_functions.size()) {
        warn("func(" + std::to_string(id) + ", x): no such function (there are " +
             std::to_string(m_functions.size()) + "); 0 used");
        return 0;
    }
    if (std::isnan(x)) {  // no place on the curve; also no int to floor it to
        warn("func(" + std::to_string(id) + ", x): x is not a number; 0 used");
        x = 0;
    }
    return m_functions[static_cast<std::size_t>(id - 1)].evaluate(x);
}

std::vector<std::string> FunctionSet::define_names() const
{
    std::vector<std::string> defines;
    if (!m_from_set)
        return defines;
    for (std::size_t i = 0; i < m_functions.size(); ++i) {
        std::string name = m_functions[i].name();
        std::transform(name.begin(), name.end(), name.begin(),
                       [](unsigned char ch) { return static_cast<char>(std::toupper(ch)); });
        defines.push_back(name + "=" + std::to_string(i + 1));
    }
    return defines;
}

}  // namespace cambium::geom
