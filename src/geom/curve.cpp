// SPDX-License-Identifier: Apache-2.0
// cpfg's curve functions on `curve:` files, read and evaluated as cpfg does.
#include "geom/curve.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>

#include "geom/contour.h"
#include "geom/surface.h"
#include "geom/text_input.h"

namespace cambium::geom {

using detail::TextCursor;

// Curves (cpfg's curveXYZ: `curve:` files for curveX/curveY/curveZ/curveGAL)

namespace {

// Uniform B-spline basis of order `order` with knots at the integers, by Cox-de Boor
// with half-open intervals (cpfg's Bi1..Bi4; the same arithmetic, so the same bits).
double uniform_basis(int i, int order_, double t)
{
    if (order_ == 1)
        return (i <= t && t < i + 1) ? 1.0 : 0.0;
    double span = order_ - 1;
    return (t - i) / span * uniform_basis(i, order_ - 1, t) +
           (i + order_ - t) / span * uniform_basis(i + 1, order_ - 1, t);
}

// Knot j of the clamped knot vector 0,0,0,0,1,2,...,n-4,n-3,n-3,n-3,n-3 of n points
// (cpfg's uk); n = 4 gives Bernstein polynomials (Bezier segments).
double clamped_knot(int j, int n)
{
    if (j < 4)
        return 0;
    if (j > n - 1)
        return n - 3;
    return j - 3;
}

// Cox-de Boor on the clamped knots; a zero-length interval's term is left out (cpfg's Nk).
double clamped_basis(int k, int order_, double u, int n)
{
    if (order_ == 1)
        return (clamped_knot(k, n) <= u && u < clamped_knot(k + 1, n)) ? 1.0 : 0.0;
    double sum = 0;
    double d1 = clamped_knot(k + order_ - 1, n) - clamped_knot(k, n);
    if (d1 != 0)
        sum += (u - clamped_knot(k, n)) / d1 * clamped_basis(k, order_ - 1, u, n);
    double d2 = clamped_knot(k + order_, n) - clamped_knot(k + 1, n);
    if (d2 != 0)
        sum += (clamped_knot(k + order_, n) - u) / d2 * clamped_basis(k + 1, order_ - 1, u, n);
    return sum;
}

// The sum of p[first + k] * weight(first + k), k = 0..3, in that order (cpfg's order).
template <class Weight>
Vec3 weighted_sum(const std::vector<Vec3>& p, int first, Weight weight)
{
    Vec3 sum;
    for (int k = 0; k < 4; ++k) {
        int j = first + k;
        if (j < 0 || j >= static_cast<int>(p.size()))
            continue;
        double w = weight(j);
        const Vec3& q = p[static_cast<std::size_t>(j)];
        sum = k == 0 ? q * w : sum + q * w;
    }
    return sum;
}

}  // namespace

SpaceCurve::SpaceCurve(const std::vector<ControlPoint>& points, Kind kind, int samples)
    : m_kind(kind)
{
    for (const ControlPoint& c : points)
        if (c.multiplicity > 0)
            m_points.insert(m_points.end(), static_cast<std::size_t>(c.multiplicity), c.position);
    if (m_kind == Kind::bspline_closed && !m_points.empty()) {
        for (std::size_t i = 0; i < 3; ++i)
            m_points.push_back(m_points[i % m_points.size()]);
    } else if (m_kind == Kind::bspline_phantom && m_points.size() >= 2) {
        std::size_t n = m_points.size();
        Vec3 before = m_points[0] * 2.0 - m_points[1];
        Vec3 after = m_points[n - 1] * 2.0 - m_points[n - 2];
        m_points.insert(m_points.begin(), before);
        m_points.push_back(after);
    } else if (m_kind == Kind::bezier_surface) {
        // cpfg's curveX and curveGAL on a surface read its first row: a Bezier curve of
        // the first four points (of the first patch's sixteen).
        if (m_points.size() >= 16)
            m_points.resize(4);
        else
            m_points.clear();
        m_kind = Kind::bezier;
    }
    tabulate_length(std::clamp(samples, 2, max_curve_samples));
}

Vec3 SpaceCurve::at_parameter(double u) const
{
    const int n = static_cast<int>(m_points.size());
    if (n < 4)
        return {};
    switch (m_kind) {
    case Kind::bezier:
    case Kind::bezier_surface: {
        // Segments of 4 points sharing their ends; cpfg's slightly shrunk parameter
        // keeps u = 1 inside the last segment.
        int segments = 1 + (n - 4) / 3;
        int c = std::clamp(static_cast<int>(u / (1.000001 / segments)), 0, segments - 1);
        double local = (u - c * (1.0 / segments)) * segments / 1.000001;
        return weighted_sum(m_points, 3 * c, [&](int j) { return clamped_basis(j - 3 * c, 4, local, 4); });
    }
    case Kind::bspline_endpoint: {
        double t = u * (n - 3.000001);
        int span = std::clamp(static_cast<int>(std::floor(t)), 0, n - 4);
        return weighted_sum(m_points, span, [&](int j) { return clamped_basis(j, 4, t, n); });
    }
    default: {
        // Uniform: segment i (3..n-1) spans knots [i, i+1) and uses points i-3..i.
        int i = 3 + static_cast<int>(u * (n - 3.000001));
        i = std::clamp(i, 3, n - 1);
        double t = 3.0 + u * (n - 3.000001);
        return weighted_sum(m_points, i - 3, [&](int j) { return uniform_basis(j, 4, t); });
    }
    }
}

void SpaceCurve::tabulate_length(int samples)
{
    m_fraction.assign(static_cast<std::size_t>(samples), 0.0);
    m_length = 0;
    Vec3 previous = at_parameter(0);
    for (int i = 1; i < samples; ++i) {
        Vec3 p = at_parameter(i / static_cast<double>(samples - 1));
        Vec3 d = p - previous;
        m_length += std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        m_fraction[static_cast<std::size_t>(i)] = m_length;
        previous = p;
    }
    for (std::size_t i = 0; i < m_fraction.size(); ++i) {
        // A curve of no length (cpfg divides by 0 here) is read by parameter.
        m_fraction[i] = m_length > 0 ? m_fraction[i] / m_length
                                     : static_cast<double>(i) / static_cast<double>(samples - 1);
    }
}

Vec3 SpaceCurve::at_length_fraction(double t) const
{
    if (m_points.size() < 4 || m_fraction.size() < 2)
        return {};
    t = std::clamp(t, 0.0, 1.0);
    std::size_t low = 0, high = m_fraction.size() - 1;
    while (high - low > 1) {
        std::size_t mid = (low + high) / 2;
        if (m_fraction[mid] > t)
            high = mid;
        else
            low = mid;
    }
    double span = m_fraction[high] - m_fraction[low];
    double within = span > 0 ? (t - m_fraction[low]) / span : 0.0;
    double u = (static_cast<double>(low) + within) / static_cast<double>(m_fraction.size() - 1);
    return at_parameter(u);
}

namespace {

constexpr int max_curve_nesting = 20;  // cpfg's limit on nested (variety) curves

SpaceCurve::Kind curve_kind(const std::string& name)
{
    using Kind = SpaceCurve::Kind;
    if (name == "bezier-surface")
        return Kind::bezier_surface;
    if (name == "bezier")
        return Kind::bezier;
    if (name == "bspline-phantom")
        return Kind::bspline_phantom;
    if (name == "bspline-endpoint")
        return Kind::bspline_endpoint;
    if (name == "bspline-closed")
        return Kind::bspline_closed;
    return Kind::bspline;  // cpfg: anything else
}

/// Reads the "version: 1.4" curve format line by line, as cpfg's readCurve does.
class CurveReader {
public:
    CurveReader(std::string file, int samples) : m_file(std::move(file)), m_samples(samples) {}

    void line(std::string_view text, int number)
    {
        std::size_t start = text.find_first_not_of(" \t");
        if (start == std::string_view::npos)
            return;
        text.remove_prefix(start);
        int column = static_cast<int>(start) + 1;
        if (text.starts_with("//"))
            return;
        if (labelled(text, number, column))
            return;
        // cpfg ignores other lines with a colon and lines of at most two characters.
        if (text.find(':') != std::string_view::npos || text.size() <= 2)
            return;
        point(text, number, column);
    }

    SpaceCurve finish(int last_line)
    {
        if (m_levels.empty() && !m_top_opened)
            throw Error(FileLoc{m_file, last_line, 0}, "the curve file has no 'points:' line");
        if (m_top_read < m_top.size())
            warn(FileLoc{m_file, last_line, 0},
                 "the curve declares " + std::to_string(m_top.size()) + " points but holds " +
                     std::to_string(m_top_read) + "; the others lie at the origin (as in cpfg)");
        std::size_t expanded = 0;
        for (const SpaceCurve::ControlPoint& p : m_top)
            expanded += static_cast<std::size_t>(std::max(p.multiplicity, 0));
        if (expanded > max_curve_points)
            throw Error(FileLoc{m_file, last_line, 0}, "too many curve points after multiplicities");
        return SpaceCurve(m_top, m_kind, m_samples);
    }

private:
    struct Level {
        std::size_t declared = 0;
        std::size_t read = 0;
        int dimension = 2;
    };

    bool labelled(std::string_view text, int number, int column)
    {
        static constexpr std::string_view ignored[] = {"version:", "contact:", "end:", "heading:",
                                                       "up:", "size:", "range:"};
        static constexpr int ignored_values[] = {0, 3, 3, 3, 3, 1, 2};
        for (std::size_t k = 0; k < std::size(ignored); ++k) {
            if (!text.starts_with(ignored[k]))
                continue;
            TextCursor in(text.substr(ignored[k].size()), m_file, number,
                          column + static_cast<int>(ignored[k].size()));
            if (ignored_values[k] == 0)
                in.word("the version");
            for (int v = 0; v < ignored_values[k]; ++v)
                in.number(ignored[k].data());
            return true;
        }
        if (text.starts_with("points:")) {
            TextCursor in(text.substr(7), m_file, number, column + 7);
            FileLoc at = in.loc();
            int count = in.integer("the number of points");
            if (count < 0 || static_cast<std::size_t>(count) > max_curve_points)
                throw Error(at, "bad number of curve points: " + std::to_string(count));
            open_level(static_cast<std::size_t>(count), at);
            return true;
        }
        for (std::string_view label : {std::string_view("dimension:"), std::string_view("dim:")}) {
            if (!text.starts_with(label))
                continue;
            TextCursor in(text.substr(label.size()), m_file, number, column + static_cast<int>(label.size()));
            FileLoc at = in.loc();
            int d = in.integer("the dimension");
            if (d < 2 || d > 4)
                throw Error(at, "the curve dimension must be 2, 3 or 4, not " + std::to_string(d));
            current(at).dimension = d;
            return true;
        }
        if (text.starts_with("type:")) {
            TextCursor in(text.substr(5), m_file, number, column + 5);
            FileLoc at = in.loc();
            std::string name = in.word("the curve type");
            current(at);
            if (m_levels.size() == 1)
                m_kind = curve_kind(name);
            return true;
        }
        return false;
    }

    Level& current(const FileLoc& at)
    {
        if (m_levels.empty())
            throw Error(at, "'dimension:' and 'type:' must follow 'points:'");
        return m_levels.back();
    }

    void open_level(std::size_t count, const FileLoc& at)
    {
        if (m_levels.empty()) {
            if (m_top_opened)
                throw Error(at, "a second curve in one curve file");
            m_top_opened = true;
            m_top.assign(count, SpaceCurve::ControlPoint{});
        } else {
            // A nested curve belongs to the point read last (the editor's varieties).
            if (m_levels.back().read == 0)
                throw Error(at, "a nested 'points:' before the point it belongs to");
            if (m_levels.size() >= max_curve_nesting)
                throw Error(at, "curves nested too deep");
        }
        m_levels.push_back(Level{count, 0, 2});
    }

    void point(std::string_view text, int number, int column)
    {
        FileLoc at{m_file, number, column};
        if (m_levels.empty())
            throw Error(at, "a curve point before 'points:'");
        // A full nested curve hands the next point to the curve it belongs to.
        ++m_levels.back().read;
        while (m_levels.back().read > m_levels.back().declared) {
            m_levels.pop_back();
            if (m_levels.empty())
                throw Error(at, "more curve points than 'points:' declares");
            ++m_levels.back().read;
        }
        const Level& level = m_levels.back();
        TextCursor in(text, m_file, number, column);
        double values[4] = {0, 0, 0, 1};
        int count = 0;
        while (!in.at_line_end() && count < 4) {
            values[count] = in.number("a curve point coordinate");
            ++count;
        }
        if (count != level.dimension)
            throw Error(at, "a curve point of dimension " + std::to_string(level.dimension) +
                                " needs " + std::to_string(level.dimension) + " values");
        if (m_levels.size() > 1)
            return;  // nested curves are read and not used
        SpaceCurve::ControlPoint& p = m_top[level.read - 1];
        p.position = {values[0], values[1], level.dimension > 2 ? values[2] : 0.0};
        if (level.dimension > 3) {
            if (values[3] < 0 || values[3] > static_cast<double>(max_curve_points))
                throw Error(at, "bad curve point multiplicity");
            p.multiplicity = static_cast<int>(values[3]);
        }
        m_top_read = level.read;
    }

    std::string m_file;
    int m_samples;
    std::vector<Level> m_levels;
    std::vector<SpaceCurve::ControlPoint> m_top;
    std::size_t m_top_read = 0;
    bool m_top_opened = false;
    SpaceCurve::Kind m_kind = SpaceCurve::Kind::bspline;
};

/// Whether the text is one of the contour formats (`cver`, or "n dim type") rather than
/// the curve editor's labelled format.
bool looks_like_contour(std::string_view text)
{
    for (const SourceLine& line : split_lines_without_comments(text)) {
        std::string_view l = line.text;
        std::size_t start = l.find_first_not_of(" \t\r");
        if (start == std::string_view::npos)
            continue;
        l.remove_prefix(start);
        if (l.starts_with("cver"))
            return true;
        return std::isdigit(static_cast<unsigned char>(l[0])) && l.find(':') == std::string_view::npos;
    }
    return false;
}

}  // namespace

SpaceCurve parse_curve_text(std::string_view text, const std::string& file_name, int samples)
{
    if (looks_like_contour(text)) {
        Contour c = parse_contour(text, file_name);
        std::vector<SpaceCurve::ControlPoint> points;
        for (const Vec3& p : c.points)
            points.push_back({p, 1});
        return SpaceCurve(points, c.closed ? SpaceCurve::Kind::bspline_closed : SpaceCurve::Kind::bspline,
                          samples);
    }
    CurveReader reader(file_name, samples);
    int number = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos)
            end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        if (!line.empty() && line.back() == '\r')
            line.remove_suffix(1);
        reader.line(line, ++number);
        pos = end + 1;
    }
    return reader.finish(number);
}

SpaceCurve read_curve_file(const std::filesystem::path& file, int samples)
{
    return parse_curve_text(read_text_file(file, "curve file"), file.string(), samples);
}

CurveSet CurveSet::from_view_file(const ViewFile& view)
{
    return from_view_commands(view.curves, view.path.parent_path());
}

CurveSet CurveSet::from_view_commands(std::span<const CurveFile> commands,
                                      const std::filesystem::path& base_dir)
{
    CurveSet set;
    for (const CurveFile& c : commands) {
        try {
            std::filesystem::path file = c.file.is_relative() ? base_dir / c.file : c.file;
            set.add(read_curve_file(file, c.samples));
        } catch (const Error& e) {
            warn(c.loc, std::string("curve not read, its coordinates and length are 0: ") + e.what());
            set.add(SpaceCurve());
        }
    }
    return set;
}

double CurveSet::evaluate(char which, int id, double t) const
{
    if (id < 1 || static_cast<std::size_t>(id) > m_curves.size()) {
        warn("curve id " + std::to_string(id) + " is not defined by the view file (there are " +
             std::to_string(m_curves.size()) + "); 0 used");
        return 0;
    }
    const SpaceCurve& curve = m_curves[static_cast<std::size_t>(id - 1)];
    if (which == 'l')
        return curve.length();
    if (std::isnan(t)) {
        warn(std::string("curve") + static_cast<char>(std::toupper(which)) + "(" + std::to_string(id) +
             ", t): t is not a number; 0 used");
        t = 0;
    }
    Vec3 p = curve.at_length_fraction(t);
    return which == 'x' ? p.x : which == 'y' ? p.y : p.z;
}

}  // namespace cambium::geom
