// SPDX-License-Identifier: Apache-2.0
// Generalized cylinders (graphical-extensions report, section 3; manual 5.1.9 "Drawing
// generalized cylinders"): Hermite or B-spline axes from turtle control points, radius
// profiles, contours swept along rotation-minimising frames.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include "geom/contour.h"
#include "geom/scene.h"
#include "geom/vec.h"

namespace cambium::geom {

struct Turtle;
struct ViewFile;
struct SweepRing;

/// cpfg's default tangent coefficient of the axis (report 3.1).
inline constexpr double default_tangent_parameter = 1.2;
/// Strips between control points when @Gc/@Ge/F give no count (cpfg's DEFAULT_RINGS).
inline constexpr int default_cylinder_strips = 4;

/// How control points are being added.
enum class CylinderMode : std::uint8_t {
    none,     ///< no cylinder in progress
    modules,  ///< @Gs: only @Gc and @Ge add points
    moves,    ///< {(type) or a @Gc without @Gs: F and f add points too
};

/// A control point as the next segment needs it (cpfg keeps the whole turtle).
struct CylinderPoint {
    Vec3 position;
    Vec3 heading{0, 1, 0};
    Vec3 left{-1, 0, 0};
    Vec3 up{0, 0, -1};  ///< the contour frame: the turtle's, or twist-minimised
    double line_width = 1;
    int contour = 0;
    int sides = 8;
    int color = 1;
    int back_color = 1;
    double tangent_out = default_tangent_parameter;  ///< tangent_parameter[1] here
    double tangent_in = default_tangent_parameter;   ///< tangent_parameter[0] here
    std::array<double, 2> radius_tangent_out{0, 0};  ///< radius_tangent[1] here
    /// radius_tangent[0] and @Gr(1) here: a B-spline segment ends with those of its
    /// second-last control point (cpfg), not of the turtle that adds the last one.
    std::array<double, 2> radius_tangent_in{0, 0};
    bool scale_radius_tangents = false;
    int texture = -1;  ///< the turtle's texture (the segment from here uses it)
    double v = 0;      ///< texture v along the cylinder
    /// HermiteCurves point holding this point's key (shared if it is still the last).
    std::int64_t key = -1;
    /// First TriangleMesh vertex of this point's ring, and its contour size.
    std::int64_t ring = -1;
    int ring_sides = 0;
};

/// The control points a B-spline axis ({(3), {(4)) keeps: cpfg draws the segment of the
/// last four points when the fourth arrives, so the three before it wait here; a closed
/// axis adds its first three again at `}`.
struct BsplinePoints {
    std::array<CylinderPoint, 3> window;   ///< the last three control points, oldest first
    std::array<CylinderPoint, 3> opening;  ///< the first three (for closed axes)
};

/// The generalized-cylinder part of the turtle state: copied by `[` and restored by
/// `]`, so branches continue from the active control point.
struct CylinderState {
    /// @Gt: coefficients of the tangents arriving at (0) and leaving (1) a point.
    std::array<double, 2> tangent_parameter{default_tangent_parameter, default_tangent_parameter};
    /// @Gr: radius-profile tangents (u, r) arriving at (0) and leaving (1) a point;
    /// (0, 0) means the linear profile's tangent.
    std::array<std::array<double, 2>, 2> radius_tangent{};
    bool scale_radius_tangents = false;  ///< @Gr(1)
    int contour = 0;                     ///< @#: contour id (0 = circle)
    int sides = 8;                       ///< @! and `contour sides:`

    CylinderMode mode = CylinderMode::none;
    bool closed = false;  ///< {(2), {(4): the axis returns to its first point(s) at }
    bool bspline = false; ///< {(3), {(4): the control points define a uniform cubic B-spline
    int default_strips = default_cylinder_strips;
    int points = 0;       ///< control points so far
    CylinderPoint last;   ///< the active control point
    CylinderPoint first;  ///< for closed axes
    /// B-spline axes: the points still needed (shared, copied on write: `[` copies it).
    std::shared_ptr<const BsplinePoints> bspline_points;
};

/// What the view file says about generalized cylinders.
struct CylinderSettings {
    ContourTable contours;     ///< `contour: id file`, loaded
    int sides = 8;             ///< `contour sides:` (or `polygonization level:`)
    bool keep_twist = false;   ///< `twist of cylinders: on`
    /// `render mode: interpolated`: the first strip of a segment blends from the start
    /// point's colour to the end point's (cpfg's Gouraud colours); otherwise it is flat.
    bool interpolate_colours = false;
    bool draw_surfaces = true; ///< `line style: cylinder`; otherwise the axis as lines
    /// `render mode: wireframe`: the circular contour too is drawn as a triangle mesh
    /// (`sides` around, cpfg's strips along), so that its tessellation edges can be drawn.
    bool mesh_circles = false;
    std::vector<double> texture_aspect_ratios;  ///< per texture, `R:` (v = length / (pi width R))
};

/// The view file's cylinder settings, with its contour files loaded (relative to the
/// view file). A contour file that cannot be read is a warning, as in cpfg.
CylinderSettings cylinder_settings(const ViewFile& view);

// ---- pieces exposed for tests ------------------------------------------------------

/// Cubic Hermite value and derivative: h(0) = p0, h(1) = p1, h'(0) = t0, h'(1) = t1.
Vec3 hermite(const Vec3& p0, const Vec3& p1, const Vec3& t0, const Vec3& t1, double s);
Vec3 hermite_derivative(const Vec3& p0, const Vec3& p1, const Vec3& t0, const Vec3& t1, double s);

/// The radius profile R(s) = (Ru, Rv) of one segment (report 3.2.2): from (0, r0) to
/// (1, r1) with tangents as cpfg sets them from @Gr (zero tangents = linear).
struct RadiusProfile {
    double r0 = 0, r1 = 0;
    std::array<double, 2> t0{1, 0}, t1{1, 0};

    static RadiusProfile make(double r0, double r1, std::array<double, 2> tangent_start,
                              std::array<double, 2> tangent_end, bool scale, double length);
    double u(double s) const;        ///< position along the axis parameter
    double radius(double s) const;
    double du(double s) const;
    double dradius(double s) const;
    bool linear() const;             ///< u(s) = s and the radius linear
};

/// The uniform cubic B-spline segment of control points P0..P3 as a cubic Hermite
/// segment (exact): from (P0 + 4 P1 + P2) / 6 to (P1 + 4 P2 + P3) / 6 with tangents
/// (P2 - P0) / 2 and (P3 - P1) / 2. Returns {p0, p1, t0, t1} for hermite().
std::array<Vec3, 4> bspline_as_hermite(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3);

/// One double-reflection step (Wang et al. 2008) of a rotation-minimising frame: the
/// `up` vector at (x0, t0) carried to (x1, t1).
Vec3 rmf_step(const Vec3& x0, const Vec3& t0, const Vec3& up0, const Vec3& x1, const Vec3& t1);

/// Builds generalized cylinders into a Geometry as the turtle meets @G modules.
///
/// Circular contours become HermiteCurves: one cubic segment per control-point pair
/// (the axis exactly, radius in the 4th component), or one per strip when @Gr bends the
/// radius profile. Other contours become TriangleMesh strips: `strips` rings per pair,
/// at cpfg's positions, with smooth normals. Colours follow cpfg: the first strip (or
/// axis line) of a pair in the start point's colours, the rest in the end point's; a
/// round segment whose colour changes is cut at the first ring for it, and blends
/// across its first piece (HermiteCurves::end_material) under `render mode:
/// interpolated`. Bounds receive what cpfg's view volume sees (the ring vertices, or
/// the axis points when lines are drawn).
class CylinderBuilder {
public:
    CylinderBuilder(CylinderSettings settings, Geometry& out, Bounds3& bounds);

    void start(Turtle& turtle);                                   ///< @Gs
    void control_point(Turtle& turtle, std::span<const float> p); ///< @Gc(strips)
    void end(Turtle& turtle, std::span<const float> p);           ///< @Ge(strips)
    /// `{(type[, strips])` with type 1..4: Hermite open/closed, B-spline open/closed.
    /// B-spline axes (cpfg): control points P0, P1, ... are not on the axis; each new
    /// point Pk (k >= 3) draws the segment of Pk-3..Pk, from (Pk-3 + 4 Pk-2 + Pk-1) / 6 to
    /// (Pk-2 + 4 Pk-1 + Pk) / 6, with the line width, colour, contour and texture of Pk-2
    /// at its start and of Pk-1 at its end; open axes do not reach their end points
    /// (n points give n - 3 segments); closed ones add their first three points at `}`
    /// (n segments).
    void open_curve(Turtle& turtle, std::span<const float> p);
    /// `}(type)` with type != 0.
    void close_curve(Turtle& turtle);
    /// After F (and f) moved the turtle: a control point in `{` mode.
    void moved(Turtle& turtle);

    static void set_tangent_parameters(Turtle& turtle, std::span<const float> p);  ///< @Gt
    static void set_radius_tangents(Turtle& turtle, std::span<const float> p);     ///< @Gr
    void set_contour(Turtle& turtle, std::span<const float> p);                    ///< @#
    void set_sides(Turtle& turtle, std::span<const float> p);                      ///< @!

    const CylinderSettings& settings() const { return m_settings; }

private:
    void add_point(Turtle& turtle, int strips);
    void add_bspline_point(Turtle& turtle, const CylinderPoint& point, int strips);
    /// The segment arrives with `to`'s tangent coefficient and radius tangent (cpfg's
    /// tu2); `axis_override` replaces the Hermite axis from the points' headings.
    void draw_segment(const CylinderPoint& from, CylinderPoint& to, int strips,
                      const std::array<Vec3, 4>* axis_override = nullptr);
    void draw_round(const std::vector<SweepRing>& rings, const RadiusProfile& profile, const Vec3 (&axis)[4],
                    const CylinderPoint& from, CylinderPoint& to);
    void draw_mesh(const std::vector<SweepRing>& rings, const CylinderPoint& from, CylinderPoint& to,
                   double len);
    void draw_axis_lines(const std::vector<SweepRing>& rings, const CylinderPoint& from, const CylinderPoint& to);
    void extend_bounds(const std::vector<SweepRing>& rings, const CylinderPoint& from, const CylinderPoint& to,
                       double len);
    const ContourSamples& samples(int contour, int sides);

    CylinderSettings m_settings;
    Geometry& m_out;
    Bounds3& m_bounds;
    std::map<std::pair<int, int>, ContourSamples> m_sample_cache;
    bool m_warned_unknown_contour = false;
    bool m_warned_segment_size = false;
};

}  // namespace cambium::geom
