// SPDX-License-Identifier: Apache-2.0
// Cross-sections of generalized cylinders: contour files, galleries, arc-length resampling.
#include "geom/contour.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "geom/text_input.h"

namespace cambium::geom {
namespace {

constexpr int max_contour_points = 100000;   // distinct points and their expansion
constexpr int max_multiplicity = 1000;
constexpr int max_contour_sides = 100000;
constexpr int samples_per_segment = 10;      // cpfg's length table density

/// The lines of a contour file with their numbers, read one after another.
class LineCursor {
public:
    LineCursor(std::string_view text, std::string file) : m_file(std::move(file))
    {
        std::size_t start = 0;
        int number = 1;
        while (start <= text.size()) {
            std::size_t end = text.find('\n', start);
            if (end == std::string_view::npos)
                end = text.size();
            std::string line(text.substr(start, end - start));
            if (!line.empty() && line.back() == '\r')
                line.pop_back();
            m_lines.push_back({number++, std::move(line)});
            start = end + 1;
        }
    }

    bool at_end()
    {
        skip_blank();
        return m_next >= m_lines.size();
    }

    /// The next non-blank line; Error when there is none.
    const SourceLine& next(const char* what)
    {
        skip_blank();
        if (m_next >= m_lines.size())
            throw Error(loc_at_end(), std::string("contour file ends before ") + what);
        return m_lines[m_next++];
    }

    /// The next non-blank line without consuming it (nullptr at the end).
    const SourceLine* peek()
    {
        skip_blank();
        return m_next < m_lines.size() ? &m_lines[m_next] : nullptr;
    }

    FileLoc loc(const SourceLine& line) const { return {m_file, line.number, 1}; }
    const std::string& file() const { return m_file; }

    /// A reader for the values after "label:" on the next line.
    ValueReader labelled(const char* label, const SourceLine*& line_out)
    {
        const SourceLine& line = next(label);
        line_out = &line;
        std::string_view text = line.text;
        std::size_t at = text.find_first_not_of(" \t");
        std::string_view l(label);
        if (at == std::string_view::npos || text.substr(at, l.size()) != l)
            throw Error(loc(line), std::string("expected '") + label + ":' in the contour file");
        at += l.size();
        if (at < text.size() && text[at] == ':')
            ++at;
        return ValueReader(text, at, loc(line));
    }

private:
    void skip_blank()
    {
        while (m_next < m_lines.size() &&
               m_lines[m_next].text.find_first_not_of(" \t\r") == std::string::npos)
            ++m_next;
    }

    FileLoc loc_at_end() const
    {
        return {m_file, m_lines.empty() ? 0 : m_lines.back().number, 0};
    }

    std::string m_file;
    std::vector<SourceLine> m_lines;
    std::size_t m_next = 0;
};

int checked_count(ValueReader& in, int lo, int hi, const char* what)
{
    FileLoc at = in.loc();
    int n = in.integer();
    if (n < lo || n > hi)
        throw Error(at, std::string(what) + " must be between " + std::to_string(lo) + " and " +
                            std::to_string(hi) + ", not " + std::to_string(n));
    return n;
}

/// The original format: "num dim type", then num points of dim coordinates, read as a
/// stream of numbers (cpfg uses fscanf, so line breaks do not matter).
Contour parse_plain(LineCursor& lines)
{
    Contour c;
    const SourceLine& header = lines.next("its header");
    ValueReader in(header.text, 0, lines.loc(header));
    int count = checked_count(in, 1, max_contour_points, "the number of contour points");
    FileLoc dim_at = in.loc();
    int dim = in.integer();
    if (dim != 2 && dim != 3)
        throw Error(dim_at, "the contour dimension must be 2 or 3, not " + std::to_string(dim));
    c.closed = in.word("contour type") == "closed";  // cpfg: anything else is open

    std::vector<double> values;
    std::size_t wanted = static_cast<std::size_t>(count) * static_cast<std::size_t>(dim);
    FileLoc last = lines.loc(header);
    while (values.size() < wanted && !lines.at_end()) {
        const SourceLine& line = lines.next("its points");
        last = lines.loc(line);
        ValueReader row(line.text, 0, last);
        while (!row.at_end() && values.size() < wanted)
            values.push_back(row.number());
    }
    if (values.size() < wanted)
        throw Error(last, "the contour file promises " + std::to_string(count) + " points but holds " +
                              std::to_string(values.size() / static_cast<std::size_t>(dim)));
    for (std::size_t i = 0; i < wanted; i += static_cast<std::size_t>(dim))
        c.points.push_back({values[i], values[i + 1], dim == 3 ? values[i + 2] : 0.0});
    return c;
}

/// `type:` of versions 1.01 (open|closed) and 1.02+ ({o|c}{r|e}).
void parse_type(Contour& c, LineCursor& lines)
{
    const SourceLine* line = nullptr;
    ValueReader in = lines.labelled("type", line);
    std::string type = in.word("contour type");
    if (c.version == 101) {
        c.closed = type.rfind("open", 0) != 0;  // cpfg: anything but "open" is closed
        return;
    }
    if (type.size() != 2 || (type[0] != 'o' && type[0] != 'c') || (type[1] != 'r' && type[1] != 'e'))
        throw Error(lines.loc(*line), "contour type must be or, oe, cr or ce, not '" + type + "'");
    c.closed = type[0] == 'c';
    c.endpoint_interpolation = type[1] == 'e';
}

/// Version 1.03's optional editor records between `samples:` and the points.
void skip_editor_records(LineCursor& lines)
{
    for (;;) {
        const SourceLine* line = lines.peek();
        if (!line)
            return;
        std::string_view text = line->text;
        text.remove_prefix(std::min(text.find_first_not_of(" \t"), text.size()));
        if (text.starts_with("background")) {
            lines.next("background");
            lines.next("background");  // cpfg skips this line and the next
        } else if (text.starts_with("markers")) {
            const SourceLine* l = nullptr;
            ValueReader in = lines.labelled("markers", l);
            int markers = checked_count(in, 0, max_contour_points, "the number of markers");
            for (int i = 0; i < markers; ++i)
                lines.next("its markers");
        } else {
            return;
        }
    }
}

/// Versions 1.01 to 1.03 after the `cver` line.
Contour parse_versioned(LineCursor& lines, int version)
{
    Contour c;
    c.version = version;
    const SourceLine* line = nullptr;
    {
        const SourceLine& name = lines.next("its name");
        std::string_view text = name.text;
        std::size_t colon = text.find(':');
        std::string_view value = colon == std::string_view::npos ? text : text.substr(colon + 1);
        std::size_t b = value.find_first_not_of(" \t");
        std::size_t e = value.find_last_not_of(" \t");
        c.name = b == std::string_view::npos ? std::string() : std::string(value.substr(b, e - b + 1));
    }
    ValueReader points = lines.labelled("points", line);
    int distinct = checked_count(points, 1, max_contour_points, "the number of distinct points");
    int total = checked_count(points, 1, max_contour_points, "the number of points");
    parse_type(c, lines);
    if (version >= 103) {
        ValueReader samples = lines.labelled("samples", line);
        c.samples = checked_count(samples, 0, max_contour_sides, "samples");
        skip_editor_records(lines);
    }
    for (int i = 0; i < distinct; ++i) {
        const SourceLine& row = lines.next("its points");
        ValueReader in(row.text, 0, lines.loc(row));
        Vec3 p;
        p.x = in.number();
        p.y = in.number();
        p.z = in.number();
        int m = checked_count(in, 1, max_multiplicity, "a point's multiplicity");
        if (c.points.size() + static_cast<std::size_t>(m) > max_contour_points)
            throw Error(lines.loc(row), "too many contour points");
        c.points.insert(c.points.end(), static_cast<std::size_t>(m), p);
    }
    if (static_cast<int>(c.points.size()) != total)
        warn(FileLoc{lines.file()}, "contour '" + c.name + "' declares " + std::to_string(total) +
                                        " points with multiplicities but holds " +
                                        std::to_string(c.points.size()));
    return c;
}

/// Open contours with end-point interpolation: tripling the end points makes the uniform
/// B-spline start and end there (the file format's intent; cpfg itself ignores it).
void apply_endpoint_interpolation(Contour& c)
{
    if (!c.endpoint_interpolation || c.closed || c.points.empty())
        return;
    Vec3 first = c.points.front(), last = c.points.back();
    c.points.insert(c.points.begin(), 2, first);
    c.points.insert(c.points.end(), 2, last);
}

void validate(const Contour& c, const FileLoc& loc)
{
    std::size_t need = c.closed ? 3 : 4;
    if (c.points.size() < need)
        throw Error(loc, std::string(c.closed ? "a closed" : "an open") + " contour needs at least " +
                             std::to_string(need) + " control points, not " +
                             std::to_string(c.points.size()));
}

Contour parse_one(LineCursor& lines)
{
    const SourceLine* first = lines.peek();
    if (!first)
        throw Error(FileLoc{lines.file()}, "the contour file is empty");
    FileLoc at = lines.loc(*first);
    std::string_view text = first->text;
    text.remove_prefix(std::min(text.find_first_not_of(" \t"), text.size()));
    Contour c;
    if (text.starts_with("cver")) {
        const SourceLine& line = lines.next("its version");
        ValueReader in(line.text, line.text.find("cver") + 4, lines.loc(line));
        FileLoc version_at = in.loc();
        int major = in.integer();
        int minor = in.integer();
        // Compared before combining: 100 * major overflows int for a large major.
        if (major != 1 || minor < 1 || minor > 3)
            throw Error(version_at, "unknown contour format " + std::to_string(major) + "." +
                                        std::to_string(minor) + " (cpfg reads 1 1, 1 2 and 1 3)");
        c = parse_versioned(lines, 100 * major + minor);
    } else {
        c = parse_plain(lines);
    }
    validate(c, at);
    apply_endpoint_interpolation(c);
    return c;
}

/// Uniform cubic B-spline basis and its derivative at local parameter u.
std::array<double, 4> basis(double u)
{
    double u2 = u * u, u3 = u2 * u, v = 1 - u;
    return {v * v * v / 6, (3 * u3 - 6 * u2 + 4) / 6, (-3 * u3 + 3 * u2 + 3 * u + 1) / 6, u3 / 6};
}

std::array<double, 4> basis_derivative(double u)
{
    double u2 = u * u, v = 1 - u;
    return {-v * v / 2, (9 * u2 - 12 * u) / 6, (-9 * u2 + 6 * u + 3) / 6, u2 / 2};
}

template <class Basis>
Vec3 spline_sum(const Contour& c, double t, Basis weights_of)
{
    int n = static_cast<int>(c.points.size());
    int segments = c.segment_count();
    int first = static_cast<int>(std::floor(t));
    // Open splines end at t = segments: use the last segment's u = 1 there.
    if (!c.closed && first >= segments)
        first = segments - 1;
    if (!c.closed)
        first = std::max(first, 0);
    double u = t - first;
    std::array<double, 4> w = weights_of(u);
    Vec3 sum;
    for (int k = 0; k < 4; ++k) {
        int index = ((first + k) % n + n) % n;  // closed contours wrap around
        sum += c.points[static_cast<std::size_t>(index)] * w[static_cast<std::size_t>(k)];
    }
    return sum;
}

double planar_distance(const Vec3& a, const Vec3& b) { return std::hypot(a.x - b.x, a.y - b.y); }

}  // namespace

int Contour::segment_count() const
{
    int n = static_cast<int>(points.size());
    return closed ? n : n - 3;
}

Vec3 Contour::evaluate(double t) const { return spline_sum(*this, t, basis); }

Vec3 Contour::derivative(double t) const { return spline_sum(*this, t, basis_derivative); }

ContourSamples circle_samples(int sides)
{
    ContourSamples s;
    sides = std::clamp(sides, 3, max_contour_sides);
    double step = 2 * std::numbers::pi / sides;
    for (int i = 0; i < sides; ++i) {
        Vec3 p{std::cos(i * step), std::sin(i * step), 0};
        s.vertices.push_back(p);
        s.normals.push_back(p);
    }
    s.closed = true;
    s.length = 2 * std::numbers::pi;
    return s;
}

ContourSamples resample(const Contour& contour, int sides)
{
    sides = std::clamp(sides, 3, max_contour_sides);
    ContourSamples out;
    out.closed = contour.closed;
    int segments = contour.segment_count();
    if (segments < 1)
        return out;

    // Cumulative x-y length at t = k/10, k = 0 .. 10*segments - 1 (cpfg's table: the
    // open contour's last tenth is not in it; the closed one adds the closing chord).
    int table_size = segments * samples_per_segment;
    std::vector<double> lengths(static_cast<std::size_t>(table_size));
    Vec3 previous = contour.evaluate(0);
    double total = 0;
    for (int k = 0; k < table_size; ++k) {
        Vec3 p = contour.evaluate(static_cast<double>(k) / samples_per_segment);
        total += planar_distance(previous, p);
        lengths[static_cast<std::size_t>(k)] = total;
        previous = p;
    }
    if (contour.closed)
        total += planar_distance(previous, contour.evaluate(0));
    out.length = total;

    // Closed contours turn about z so that the first vertex lies on +x.
    double cos_a = 1, sin_a = 0;
    if (contour.closed) {
        Vec3 first = contour.evaluate(0);
        double r = std::hypot(first.x, first.y);
        if (r * r >= 1e-9) {
            cos_a = first.x / r;
            sin_a = first.y / r;
        }
    }
    auto rotate = [&](const Vec3& p) {
        return Vec3{p.x * cos_a + p.y * sin_a, -p.x * sin_a + p.y * cos_a, p.z};
    };

    double step = total / sides;
    double tiny = step > 0 ? 1e-10 / step : 0;
    int count = contour.closed ? sides : sides + 1;
    int j = 0;
    for (int i = 0; i < count; ++i) {
        double arc = i * step;
        double t = 0;
        if (i > 0) {
            while (j < table_size - 1 && lengths[static_cast<std::size_t>(j)] < arc)
                ++j;
            int j2 = j - 1;
            while (j2 > 0 && lengths[static_cast<std::size_t>(j)] - lengths[static_cast<std::size_t>(j2)] <= tiny)
                --j2;
            j2 = std::max(j2, 0);
            double l2 = lengths[static_cast<std::size_t>(j2)];
            double span = lengths[static_cast<std::size_t>(j)] - l2;
            t = (j2 + (span > 0 ? (arc - l2) / span : 0)) / samples_per_segment;
        }
        out.vertices.push_back(rotate(contour.evaluate(t)));

        // The in-plane normal: the derivative turned clockwise (cpfg's (dy, -dx)).
        Vec3 d = contour.derivative(t);
        if (d.x * d.x + d.y * d.y == 0)
            d = contour.derivative(t == 0 ? t + 0.01 : t - 0.01);
        Vec3 n = normalize(Vec3{d.y, -d.x, 0});
        out.normals.push_back(rotate(n));
    }
    return out;
}

Contour parse_contour(std::string_view text, const std::string& file_name)
{
    LineCursor lines(text, file_name);
    return parse_one(lines);
}

Contour read_contour(const std::filesystem::path& file)
{
    return parse_contour(read_text_file(file, "contour file"), file.string());
}

std::vector<Contour> parse_contour_gallery(std::string_view text, const std::string& file_name)
{
    LineCursor lines(text, file_name);
    const SourceLine& header = lines.next("its header");
    std::size_t at = header.text.find("contourgalleryver");
    if (at == std::string::npos)
        throw Error(lines.loc(header), "a contour gallery starts with 'contourgalleryver 1 1'");
    ValueReader version(header.text, at + 17, lines.loc(header));
    int major = version.integer(), minor = version.integer();
    if (major != 1 || minor != 1)
        throw Error(lines.loc(header), "unknown contour gallery version " + std::to_string(major) +
                                           "." + std::to_string(minor));
    const SourceLine* line = nullptr;
    ValueReader items = lines.labelled("items", line);
    int count = checked_count(items, 1, 10000, "the number of gallery items");
    std::vector<Contour> contours;
    for (int i = 0; i < count; ++i)
        contours.push_back(parse_one(lines));
    return contours;
}

std::vector<Contour> parse_contours(std::string_view text, const std::string& file_name)
{
    std::size_t start = text.find_first_not_of(" \t\r\n");
    if (start != std::string_view::npos && text.substr(start).starts_with("contourgalleryver"))
        return parse_contour_gallery(text, file_name);
    return {parse_contour(text, file_name)};
}

std::vector<Contour> read_contours(const std::filesystem::path& file)
{
    return parse_contours(read_text_file(file, "contour file"), file.string());
}

}  // namespace cambium::geom
