// SPDX-License-Identifier: Apache-2.0
// cpfg's curve functions (`curveX(id, t)`, `curveY`, `curveZ`, `curveGAL(id)`) on the
// view file's `curve:` files.
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

/// A `curve:` file as cpfg 6.4+ reads it (the curve editor's "version: 1.4" format) for
/// the L-system functions curveX/curveY/curveZ(id, t) and curveGAL(id).
///
/// The control points (each repeated by its multiplicity) define, by `type:`:
/// `bspline` (the default, and any unknown type): a uniform cubic B-spline that does not
/// pass through its end points unless they are repeated; `bspline-closed`: the same with
/// the first three points appended; `bspline-endpoint`: a clamped cubic B-spline (knots
/// 0,0,0,0,1,...,n-3,n-3,n-3,n-3) through both end points; `bspline-phantom`: the uniform
/// spline with a phantom point 2 P0 - P1 before and 2 Pn - Pn-1 after (through both ends);
/// `bezier`: cubic Bezier segments sharing end points (1 + 3k points); `bezier-surface`:
/// curveX and curveGAL see only the Bezier curve through its first four points.
///
/// curveX(id, t) reads the curve at the fraction t (clamped to [0, 1]) of its length, as
/// cpfg does: the length is tabulated at `samples` equally spaced parameters (the view
/// file's `curve: file samples`, default 100), t is found in that table by bisection and
/// linear interpolation, and the curve is evaluated at the parameter found. curveGAL is
/// the length of that polyline. Fewer than 4 points give 0 everywhere.
class SpaceCurve {
public:
    enum class Kind { bspline, bspline_closed, bspline_endpoint, bspline_phantom, bezier, bezier_surface };

    struct ControlPoint {
        Vec3 position;
        int multiplicity = 1;
    };

    /// An empty curve: every coordinate and the length are 0.
    SpaceCurve() = default;
    /// `samples` is clamped to [2, max_curve_samples].
    SpaceCurve(const std::vector<ControlPoint>& points, Kind kind, int samples = default_curve_samples);

    static constexpr int default_curve_samples = CurveFile::default_samples;
    static constexpr int max_curve_samples = CurveFile::max_samples;

    Kind kind() const { return m_kind; }
    /// The control points after multiplicities and the closing or phantom points.
    const std::vector<Vec3>& expanded_points() const { return m_points; }

    /// The point at curve parameter u in [0, 1] (cpfg's calcPValue).
    Vec3 at_parameter(double u) const;
    /// The point at the fraction t of the curve's length (curveX/Y/Z; t clamped to [0, 1]).
    Vec3 at_length_fraction(double t) const;
    /// The tabulated length (curveGAL).
    double length() const { return m_length; }

private:
    void tabulate_length(int samples);

    std::vector<Vec3> m_points;
    Kind m_kind = Kind::bspline;
    std::vector<double> m_fraction;  ///< cumulative length / total at u = i / (samples - 1)
    double m_length = 0;
};

/// Most control points (after multiplicities) of a curve.
inline constexpr std::size_t max_curve_points = 1u << 16;

/// Reads a curve file. The "version: 1.4" format: `label: values` lines (`version:`,
/// `contact:`, `end:`, `heading:`, `up:`, `size:`, `range:` are read and unused, as in
/// cpfg; other labelled lines and `//` lines are ignored), `points: n`, `dimension: d`
/// (2: "x y", 3: "x y z", 4: "x y z multiplicity"; default 2), `type: name`, then the
/// points, one a line. A `points:` line among the points opens a nested curve of the
/// point before it (the editor's varieties); its points are read and not used.
/// A file in a contour format (`cver`, or the original "n dim type" header) is read as
/// a contour and used as a B-spline (closed contours as `bspline-closed`): a Cambium
/// extension, cpfg reads only its own format here.
/// Malformed text (a point line with the wrong number of values, more points than
/// declared) is an Error at file:line:column; fewer points than declared are a warning
/// and the missing points lie at the origin (as in cpfg).
SpaceCurve parse_curve_text(std::string_view text, const std::string& file_name,
                            int samples = SpaceCurve::default_curve_samples);
SpaceCurve read_curve_file(const std::filesystem::path& file,
                           int samples = SpaceCurve::default_curve_samples);

/// The curves curveX/Y/Z(id, t) and curveGAL(id) see, id from 1, in the order of the
/// view file's `curve: file [samples]` commands.
class CurveSet {
public:
    /// From the view file's `curve:` commands. A file that cannot be read is a
    /// warning; its id stays taken by a curve that is 0 everywhere (as in cpfg).
    static CurveSet from_view_file(const ViewFile& view);
    static CurveSet from_view_commands(std::span<const CurveFile> commands,
                                       const std::filesystem::path& base_dir);

    void add(SpaceCurve curve) { m_curves.push_back(std::move(curve)); }
    std::size_t size() const { return m_curves.size(); }
    bool empty() const { return m_curves.empty(); }
    const SpaceCurve& curve(int id) const { return m_curves.at(static_cast<std::size_t>(id - 1)); }

    /// The value lsys::LoadOptions::curve gives: `which` 'x', 'y' or 'z' of the point at
    /// the fraction t of the length, or 'l' for the length. An id outside 1..size()
    /// warns and gives 0 (cpfg).
    double evaluate(char which, int id, double t) const;

private:
    std::vector<SpaceCurve> m_curves;
};

}  // namespace cambium::geom
