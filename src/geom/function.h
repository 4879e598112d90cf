// SPDX-License-Identifier: Apache-2.0
// cpfg's user-defined functions (`func(id, x)`): `.func` files (CPFG manual 5.4.7),
// function sets (5.4.8, view file `function set:`) and the view file's `function:`.
// (Its curve functions, `curveX(id, t)`..., are in geom/curve.h.)
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "geom/vec.h"
#include "geom/view_file.h"

namespace cambium::geom {

/// One function: an open uniform cubic B-spline through control points (x, y), with the
/// first x = 0 and the last x = 1, read as y(x).
///
/// cpfg evaluates y(x) by bisection on the curve parameter until the curve's x is within
/// 0.001 of the wanted x, and returns the curve's y there; with `samples` > 2 it instead
/// precomputes that many values at x = i / (samples - 1) and interpolates linearly.
/// x outside [0, 1] is clamped. Both are reproduced exactly.
class SplineFunction {
public:
    struct Point {
        double x = 0, y = 0;
    };

    SplineFunction() = default;
    /// At least 4 points (after multiplicities); otherwise an Error at `loc`.
    SplineFunction(std::string name, std::vector<Point> points, int samples, const FileLoc& loc);

    const std::string& name() const { return m_name; }
    const std::vector<Point>& points() const { return m_points; }
    int samples() const { return m_samples; }

    /// y at x (clamped to [0, 1]), as cpfg's func(id, x).
    double evaluate(double x) const;

    /// The curve point at parameter d in [0, 1] (cpfg's P(d)); exposed for tests.
    Point curve_point(double d) const;

private:
    double evaluate_exact(double x) const;

    std::string m_name;
    std::vector<Point> m_points;
    int m_samples = 0;
    std::vector<double> m_table;
};

/// Most control points (after multiplicities) and precomputed samples per function.
inline constexpr std::size_t max_function_points = 1u << 16;
inline constexpr int max_function_samples = 1 << 20;

/// Reads one function from text. Versions: the original (`range: a b` / `points: n` /
/// n lines "x y"; the view file's `samples` are used) and `fver 1 1` (`name:`,
/// `samples:`, optional `background:` lines and `markers: n` + n lines, `flip:`,
/// `points: n`, n lines "x y [multiplicity]"; the file's samples are used and
/// view_samples is ignored, as cpfg does). Malformed text is an Error at line:column.
/// `name_if_unnamed` names original-version functions (the file stem).
SplineFunction parse_function_text(std::string_view text, const std::string& file_name,
                                   int view_samples, const std::string& name_if_unnamed);

/// A `.func` file (see parse_function_text).
SplineFunction read_function_file(const std::filesystem::path& file, int view_samples);

/// A function set / gallery file: `funcgalleryver 1 1`, `items: n`, n `fver 1 1`
/// functions one after another.
std::vector<SplineFunction> parse_function_set_text(std::string_view text,
                                                    const std::string& file_name);
std::vector<SplineFunction> read_function_set_file(const std::filesystem::path& file);

/// The functions `func(id, x)` sees, id from 1.
class FunctionSet {
public:
    /// From the view file's `function:` and `function set:` commands, in order: each `function: file [n]`
    /// appends one function; a `function set: file` replaces all functions read so far
    /// with the set's (cpfg resets its list there) and marks them as named. Files are
    /// relative to the view file's folder. An unreadable file is an Error.
    static FunctionSet from_view_file(const ViewFile& view);

    /// The same from a list of commands; `base_dir` resolves file names.
    static FunctionSet from_view_commands(std::span<const FunctionFile> commands,
                                          const std::filesystem::path& base_dir);

    void add(SplineFunction function) { m_functions.push_back(std::move(function)); }
    std::size_t size() const { return m_functions.size(); }
    bool empty() const { return m_functions.empty(); }
    const SplineFunction& function(int id) const { return m_functions.at(static_cast<std::size_t>(id - 1)); }

    /// func(id, x): x clamped to [0, 1]; id outside 1..size() warns and gives 0 (cpfg).
    double evaluate(int id, double x) const;

    /// For a function set: "NAME=id" per function, NAME the function's name in capitals
    /// (cpfg's -DNAME=id), ready for lsys::LoadOptions::defines. Empty when the
    /// functions came from `function:` commands only.
    std::vector<std::string> define_names() const;

private:
    std::vector<SplineFunction> m_functions;
    bool m_from_set = false;
};

}  // namespace cambium::geom
