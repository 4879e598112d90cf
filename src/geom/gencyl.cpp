// SPDX-License-Identifier: Apache-2.0
// Generalized cylinders: Hermite and B-spline axes, radius profiles, contours swept along frames.
#include "geom/gencyl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

#include "geom/scene_limits.h"
#include "geom/turtle.h"
#include "geom/view_file.h"

namespace cambium::geom {
namespace {

constexpr double min_segment_length = 0.00001;  // cpfg draws nothing shorter
constexpr int max_strips = 10000;
constexpr int max_sides = CylinderCommands::max_contour_sides;
constexpr long long max_segment_vertices = 1'000'000;

Float3 f3(const Vec3& v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }
Float4 f4(const Vec3& v, double w)
{
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), static_cast<float>(w)};
}
Vec3 vec(const Float3& f) { return {f[0], f[1], f[2]}; }

std::uint16_t material_index(int color) { return static_cast<std::uint16_t>(std::clamp(color, 0, 255)); }

int strips_from(std::span<const float> p, int fallback)
{
    if (p.empty() || std::isnan(p[0]))
        return fallback;
    return static_cast<int>(std::clamp(static_cast<double>(p[0]), 1.0, double(max_strips)));  // cpfg: at least 1
}

/// `up` made perpendicular to the unit `heading` (the turtle is not re-orthonormalised).
Vec3 perpendicular_up(const Vec3& up, const Vec3& heading)
{
    Vec3 u = up - heading * dot(up, heading);
    if (length(u) < 1e-12) {
        // Any perpendicular will do when up and heading coincide.
        u = std::abs(heading.x) < 0.9 ? cross(heading, Vec3{1, 0, 0}) : cross(heading, Vec3{0, 1, 0});
    }
    return normalize(u);
}

/// Signed angle from a to b around the unit axis (both perpendicular to it).
double signed_angle(const Vec3& a, const Vec3& b, const Vec3& axis)
{
    return std::atan2(dot(cross(a, b), axis), dot(a, b));
}

/// Twice the signed area of the contour's x-y polygon: > 0 when counter-clockwise.
double signed_area(const std::vector<Vec3>& v)
{
    double a = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const Vec3& p = v[i];
        const Vec3& q = v[(i + 1) % v.size()];
        a += p.x * q.y - p.y * q.x;
    }
    return a;
}

/// Gives the segment just added to `hc` the material at its end. end_material stays
/// empty while every segment is one material; once needed, it is first padded with the
/// earlier segments' own materials.
void set_end_material(HermiteCurves& hc, std::uint16_t end)
{
    std::size_t i = hc.segments.size() - 1;
    if (end == hc.material[i] && hc.end_material.empty())
        return;
    if (hc.end_material.size() > i)
        hc.end_material.resize(i);  // stale entries of segments cut away since
    while (hc.end_material.size() < i)
        hc.end_material.push_back(hc.material[hc.end_material.size()]);
    hc.end_material.push_back(end);
}

/// A cylinder module's parameter as an int clamped to [lo, hi] (NaN: `fallback`).
int clamped_parameter(float v, int fallback, int lo, int hi)
{
    return std::isnan(v) ? fallback : static_cast<int>(std::clamp(static_cast<double>(v), double(lo), double(hi)));
}

}  // namespace

/// One ring of the sweep: where it is and how it is oriented.
struct SweepRing {
    Vec3 center, heading, left, up;
    double radius = 0;
    double axis_t = 0;  ///< parameter on the axis (contour interpolation factor)
    double s = 0;       ///< parameter of the radius profile
    double v = 0;
};

// ---- math pieces ----------------------------------------------------------------------

Vec3 hermite(const Vec3& p0, const Vec3& p1, const Vec3& t0, const Vec3& t1, double s)
{
    double s2 = s * s, s3 = s2 * s;
    return p0 * (2 * s3 - 3 * s2 + 1) + p1 * (-2 * s3 + 3 * s2) + t0 * (s3 - 2 * s2 + s) + t1 * (s3 - s2);
}

Vec3 hermite_derivative(const Vec3& p0, const Vec3& p1, const Vec3& t0, const Vec3& t1, double s)
{
    double s2 = s * s;
    return p0 * (6 * s2 - 6 * s) + p1 * (-6 * s2 + 6 * s) + t0 * (3 * s2 - 4 * s + 1) + t1 * (3 * s2 - 2 * s);
}

RadiusProfile RadiusProfile::make(double r0, double r1, std::array<double, 2> tangent_start,
                                  std::array<double, 2> tangent_end, bool scale, double length)
{
    RadiusProfile p;
    p.r0 = r0;
    p.r1 = r1;
    if (scale) {  // @Gr(1): cpfg stretches the radius component with the segment length
        tangent_start[1] *= length;
        tangent_end[1] *= length;
    }
    std::array<double, 2> linear{1, r1 - r0};
    p.t0 = (tangent_start[0] == 0 && tangent_start[1] == 0) ? linear : tangent_start;
    p.t1 = (tangent_end[0] == 0 && tangent_end[1] == 0) ? linear : tangent_end;
    return p;
}

namespace {
double cubic(double a, double b, double ta, double tb, double s)
{
    double s2 = s * s, s3 = s2 * s;
    return a * (2 * s3 - 3 * s2 + 1) + b * (-2 * s3 + 3 * s2) + ta * (s3 - 2 * s2 + s) + tb * (s3 - s2);
}
double cubic_derivative(double a, double b, double ta, double tb, double s)
{
    double s2 = s * s;
    return a * (6 * s2 - 6 * s) + b * (-6 * s2 + 6 * s) + ta * (3 * s2 - 4 * s + 1) + tb * (3 * s2 - 2 * s);
}
}  // namespace

double RadiusProfile::u(double s) const { return cubic(0, 1, t0[0], t1[0], s); }
double RadiusProfile::radius(double s) const { return cubic(r0, r1, t0[1], t1[1], s); }
double RadiusProfile::du(double s) const { return cubic_derivative(0, 1, t0[0], t1[0], s); }
double RadiusProfile::dradius(double s) const { return cubic_derivative(r0, r1, t0[1], t1[1], s); }

bool RadiusProfile::linear() const
{
    double slope = r1 - r0;
    return t0[0] == 1 && t1[0] == 1 && t0[1] == slope && t1[1] == slope;
}

std::array<Vec3, 4> bspline_as_hermite(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3)
{
    // The uniform B-spline basis at u = 0 is (1, 4, 1, 0) / 6 and its derivative
    // (-3, 0, 3, 0) / 6; at u = 1 they are (0, 1, 4, 1) / 6 and (0, -3, 0, 3) / 6.
    return {(p0 + p1 * 4.0 + p2) * (1.0 / 6.0), (p1 + p2 * 4.0 + p3) * (1.0 / 6.0), (p2 - p0) * 0.5,
            (p3 - p1) * 0.5};
}

Vec3 rmf_step(const Vec3& x0, const Vec3& t0, const Vec3& up0, const Vec3& x1, const Vec3& t1)
{
    // First reflection in the bisector plane of x0 x1, then one that aligns the tangents.
    Vec3 v1 = x1 - x0;
    double c1 = dot(v1, v1);
    Vec3 up_l = up0, t_l = t0;
    if (c1 > 1e-24) {
        up_l = up0 - v1 * (2 / c1 * dot(v1, up0));
        t_l = t0 - v1 * (2 / c1 * dot(v1, t0));
    }
    Vec3 v2 = t1 - t_l;
    double c2 = dot(v2, v2);
    Vec3 up1 = c2 > 1e-24 ? up_l - v2 * (2 / c2 * dot(v2, up_l)) : up_l;
    return perpendicular_up(up1, t1);
}

// ---- settings -------------------------------------------------------------------------

/// Reads a `contour:` file into `contours` under its id (a gallery's items under id,
/// id + 1, ..., a Cambium extension). cpfg looks contours up in file order: the first
/// with an id wins.
void load_contours(const ContourFile& c, const std::filesystem::path& folder, ContourTable& contours)
{
    try {
        std::filesystem::path path = c.file.is_absolute() ? c.file : folder / c.file;
        std::vector<Contour> read = read_contours(path);
        for (std::size_t k = 0; k < read.size(); ++k) {
            int item_id = c.id + static_cast<int>(k);
            if (!contours.emplace(item_id, std::move(read[k])).second)
                warn(c.loc, "contour id " + std::to_string(item_id) + " is defined twice; the first is used");
        }
    } catch (const Error& e) {
        warn(c.loc, std::string("contour ") + std::to_string(c.id) + " not loaded: " + e.what());
    }
}

CylinderSettings cylinder_settings(const ViewFile& view)
{
    CylinderSettings s;
    s.draw_surfaces = view.line_style == LineStyle::cylinder;
    s.texture_aspect_ratios = view.texture_aspect_ratios;
    s.mesh_circles = view.render_mode.shading == Shading::wireframe;
    s.interpolate_colours = view.render_mode.interpolated;
    s.keep_twist = view.cylinders.keep_twist;
    s.sides = view.cylinders.sides;
    for (const ContourFile& c : view.cylinders.contours)
        load_contours(c, view.path.parent_path(), s.contours);
    return s;
}

// ---- the builder ----------------------------------------------------------------------

CylinderBuilder::CylinderBuilder(CylinderSettings settings, Geometry& out, Bounds3& bounds)
    : m_settings(std::move(settings)), m_out(out), m_bounds(bounds)
{
}

void CylinderBuilder::start(Turtle& turtle)
{
    CylinderState& c = turtle.cylinder;
    c.mode = CylinderMode::modules;  // cpfg: F and f do not add points after @Gs
    c.closed = false;
    c.bspline = false;
    c.bspline_points.reset();
    c.default_strips = default_cylinder_strips;
    c.points = 0;
    add_point(turtle, 0);
}

void CylinderBuilder::control_point(Turtle& turtle, std::span<const float> p)
{
    CylinderState& c = turtle.cylinder;
    if (c.mode == CylinderMode::none) {  // cpfg starts an open curve whose F's add points
        c.mode = CylinderMode::moves;
        c.closed = false;
        c.bspline = false;
        c.bspline_points.reset();
        c.default_strips = default_cylinder_strips;
        c.points = 0;
    }
    add_point(turtle, strips_from(p, 0));
}

void CylinderBuilder::end(Turtle& turtle, std::span<const float> p)
{
    control_point(turtle, p);
    close_curve(turtle);
}

void CylinderBuilder::open_curve(Turtle& turtle, std::span<const float> p)
{
    int type = p.empty() ? 0 : whole_number(p[0]).value_or(0);
    if (type <= 0 || type > 4) {
        char shown[32];
        std::snprintf(shown, sizeof shown, "%g", p.empty() ? 0.0 : static_cast<double>(p[0]));
        warn(std::string("'{(") + shown + ")': the cylinder type must be 1 to 4; ignored");
        return;
    }
    CylinderState& c = turtle.cylinder;
    c.mode = CylinderMode::moves;
    c.closed = type == 2 || type == 4;
    c.bspline = type >= 3;
    c.bspline_points.reset();
    int rings = p.size() >= 2 ? clamped_parameter(p[1], 0, 0, max_strips) : 0;
    c.default_strips = rings <= 0 ? default_cylinder_strips : std::min(rings, max_strips);
    c.points = 0;
}

void CylinderBuilder::close_curve(Turtle& turtle)
{
    CylinderState& c = turtle.cylinder;
    if (c.mode == CylinderMode::none) {
        warn("a generalized cylinder is ended that was not started; ignored");
        return;
    }
    if (c.bspline && c.closed && c.points >= 3 && c.bspline_points) {
        // cpfg adds the first three control points again, with their turtles.
        std::shared_ptr<const BsplinePoints> points = c.bspline_points;
        for (const CylinderPoint& p : points->opening) {
            CylinderPoint again = p;
            again.key = -1;
            again.ring = -1;
            add_bspline_point(turtle, again, 0);
        }
    } else if (!c.bspline && c.closed && c.points > 1) {
        // The axis returns to its first point, with that point's turtle.
        CylinderPoint target = c.first;
        target.key = -1;
        target.ring = -1;
        CylinderPoint from = c.last;
        draw_segment(from, target, c.default_strips);
    }
    c.mode = CylinderMode::none;
    c.points = 0;
    c.bspline_points.reset();
}

void CylinderBuilder::moved(Turtle& turtle)
{
    if (turtle.cylinder.mode == CylinderMode::moves)
        add_point(turtle, 0);
}

void CylinderBuilder::set_tangent_parameters(Turtle& turtle, std::span<const float> p)
{
    if (p.empty())
        return;
    CylinderState& c = turtle.cylinder;
    c.tangent_parameter[0] = p[0];
    c.tangent_parameter[1] = p.size() > 1 ? p[1] : p[0];
}

void CylinderBuilder::set_radius_tangents(Turtle& turtle, std::span<const float> p)
{
    CylinderState& c = turtle.cylinder;
    if (p.size() == 1) {
        c.scale_radius_tangents = p[0] != 0;
        return;
    }
    if (p.size() < 2)
        return;
    auto tangent = [](double angle_deg, double length) {
        double a = angle_deg * std::numbers::pi / 180.0;
        return std::array<double, 2>{std::cos(a) * length, std::sin(a) * length};
    };
    c.radius_tangent[0] = c.radius_tangent[1] = tangent(p[0], p[1]);
    if (p.size() >= 4)
        c.radius_tangent[1] = tangent(p[2], p[3]);
}

void CylinderBuilder::set_contour(Turtle& turtle, std::span<const float> p)
{
    std::optional<int> number = p.empty() ? std::optional<int>(0) : whole_number(p[0]);
    int id = number.value_or(-1);
    if (id != 0 && (!number || !m_settings.contours.contains(id))) {
        char shown[32];
        std::snprintf(shown, sizeof shown, "%g", p.empty() ? 0.0 : static_cast<double>(p[0]));
        if (!m_warned_unknown_contour)
            warn(std::string("contour id ") + shown + " is not defined in the view file; the circle is used");
        m_warned_unknown_contour = true;
        id = 0;
    }
    turtle.cylinder.contour = id;
}

void CylinderBuilder::set_sides(Turtle& turtle, std::span<const float> p)
{
    turtle.cylinder.sides = p.empty() ? 8 : clamped_parameter(p[0], 8, 3, max_sides);
}

const ContourSamples& CylinderBuilder::samples(int contour, int sides)
{
    auto key = std::make_pair(contour, sides);
    auto it = m_sample_cache.find(key);
    if (it != m_sample_cache.end())
        return it->second;
    auto found = m_settings.contours.find(contour);
    ContourSamples s = found == m_settings.contours.end() ? circle_samples(sides) : resample(found->second, sides);
    if (s.closed) {  // the seam vertex repeats the first one (u = 0 there)
        s.vertices.push_back(s.vertices.front());
        s.normals.push_back(s.normals.front());
    }
    return m_sample_cache.emplace(key, std::move(s)).first->second;
}

void CylinderBuilder::add_point(Turtle& turtle, int strips)
{
    CylinderState& c = turtle.cylinder;
    CylinderPoint point;
    point.position = turtle.position;
    point.heading = turtle.heading;
    point.left = turtle.left;
    point.up = turtle.up;
    point.line_width = turtle.line_width;
    point.contour = c.contour;
    point.sides = c.sides;
    point.color = turtle.color;
    point.back_color = turtle.back_color;
    point.tangent_out = c.tangent_parameter[1];
    point.tangent_in = c.tangent_parameter[0];
    point.radius_tangent_out = c.radius_tangent[1];
    point.radius_tangent_in = c.radius_tangent[0];
    point.scale_radius_tangents = c.scale_radius_tangents;
    point.texture = turtle.texture;
    point.v = turtle.texture_v;

    if (c.bspline) {
        add_bspline_point(turtle, point, strips);
        return;
    }
    if (c.points == 0) {
        c.first = point;
        c.last = point;
        c.points = 1;
        return;
    }
    draw_segment(c.last, point, strips > 0 ? strips : c.default_strips);
    turtle.texture_v = point.v;
    c.last = point;
    ++c.points;
}

void CylinderBuilder::add_bspline_point(Turtle& turtle, const CylinderPoint& point, int strips)
{
    CylinderState& c = turtle.cylinder;
    // Copied on write: a branch ([) shares the points it started with.
    auto next = c.bspline_points ? std::make_shared<BsplinePoints>(*c.bspline_points)
                                 : std::make_shared<BsplinePoints>();
    if (c.points < 3) {  // cpfg draws nothing until the fourth point
        auto i = static_cast<std::size_t>(c.points);
        next->window[i] = point;
        next->opening[i] = point;
        if (c.points == 0)
            c.first = point;
        ++c.points;
        c.bspline_points = std::move(next);
        return;
    }
    const std::array<CylinderPoint, 3>& w = next->window;
    std::array<Vec3, 4> axis = bspline_as_hermite(w[0].position, w[1].position, w[2].position, point.position);
    auto direction = [](const Vec3& tangent, const Vec3& fallback) {
        return length(tangent) > 1e-7 ? normalize(tangent) : fallback;  // coinciding points
    };
    // The segment starts where the previous one ended (the first: at P1's turtle) and
    // ends with the second-last point's turtle.
    CylinderPoint from = c.last;
    if (c.points == 3) {
        from = w[1];
        from.position = axis[0];
        from.heading = direction(axis[2], w[1].heading);
        from.key = -1;
        from.ring = -1;
    }
    CylinderPoint to = w[2];
    to.position = axis[1];
    to.heading = direction(axis[3], w[2].heading);
    draw_segment(from, to, strips > 0 ? strips : c.default_strips, &axis);
    turtle.texture_v = to.v;
    c.last = to;
    ++c.points;
    next->window = {w[1], w[2], point};
    c.bspline_points = std::move(next);
}

/// Draws the part of the cylinder between two control points and leaves in `to` the
/// frame, texture v, key and ring the next segment continues from.
void CylinderBuilder::draw_segment(const CylinderPoint& from, CylinderPoint& to, int strips,
                                   const std::array<Vec3, 4>* axis_override)
{
    double len = length(to.position - from.position);
    Vec3 h0 = normalize(from.heading), h1 = normalize(to.heading);
    Vec3 up0 = perpendicular_up(from.up, h0);

    // The axis: Hermite with tangents scaled by the control points' distance; the start
    // uses the coefficient leaving the first point, the end the one arriving here.
    // B-spline segments give their axis (the same cubic in Hermite form).
    Vec3 axis[4] = {from.position, to.position, h0 * (len * from.tangent_out), h1 * (len * to.tangent_in)};
    if (axis_override)
        std::copy(axis_override->begin(), axis_override->end(), axis);
    RadiusProfile profile = RadiusProfile::make(0.5 * from.line_width, 0.5 * to.line_width, from.radius_tangent_out,
                                                to.radius_tangent_in, to.scale_radius_tangents, len);

    // Each factor of a mesh segment's (strips + 1) x (sides + 1) vertices is bounded;
    // their product is too, by fewer strips.
    if (to.contour != 0 && (strips + 1LL) * (to.sides + 1LL) > max_segment_vertices) {
        int fewer = std::max(1, static_cast<int>(max_segment_vertices / (to.sides + 1LL)) - 1);
        if (!m_warned_segment_size)
            warn("a generalized-cylinder segment of " + std::to_string(strips) + " strips and " +
                 std::to_string(to.sides) + " sides is drawn with " + std::to_string(fewer) +
                 " strips (at most " + std::to_string(max_segment_vertices) + " vertices a segment)");
        m_warned_segment_size = true;
        strips = fewer;
    }
    // Rings at cpfg's strip boundaries; frames carried by double reflection.
    std::vector<SweepRing> rings(static_cast<std::size_t>(strips) + 1);
    for (int k = 0; k <= strips; ++k) {
        SweepRing& r = rings[static_cast<std::size_t>(k)];
        r.s = static_cast<double>(k) / strips;
        bool first = k == 0, last = k == strips;
        r.axis_t = first ? 0 : last ? 1 : profile.u(r.s);
        r.center = first ? axis[0] : last ? axis[1] : hermite(axis[0], axis[1], axis[2], axis[3], r.axis_t);
        Vec3 d = hermite_derivative(axis[0], axis[1], axis[2], axis[3], r.axis_t);
        r.heading = first ? h0 : last ? h1 : (length(d) > 0 ? normalize(d) : h0);
        r.radius = first ? profile.r0 : last ? profile.r1 : profile.radius(r.s);
        if (first) {
            r.up = up0;
        } else {
            const SweepRing& q = rings[static_cast<std::size_t>(k - 1)];
            r.up = rmf_step(q.center, q.heading, q.up, r.center, r.heading);
        }
    }
    if (m_settings.keep_twist) {
        // `twist of cylinders: on`: the end contour follows the turtle; the twist is
        // spread along the segment in proportion to the axis parameter.
        Vec3 target = perpendicular_up(to.up, h1);
        double twist = signed_angle(rings.back().up, target, h1);
        for (SweepRing& r : rings)
            r.up = rotate_about(r.up, r.heading, twist * r.axis_t);
        rings.back().up = target;
    }
    for (SweepRing& r : rings)
        r.left = cross(r.heading, r.up);

    // The contour frame the next segment starts from.
    to.up = rings.back().up;
    to.left = rings.back().left;
    to.v = from.v;
    to.key = -1;
    to.ring = -1;
    if (len < min_segment_length)
        return;

    // Texture v along the axis (cpfg: length / (pi diameter R)) while textured.
    rings.front().v = from.v;
    for (std::size_t k = 1; k < rings.size(); ++k) {
        double diameter = 2 * rings[k].radius;
        double advance = 0;
        if (from.texture >= 0 && diameter > 0) {
            auto t = static_cast<std::size_t>(from.texture);
            double ratio = t < m_settings.texture_aspect_ratios.size() ? m_settings.texture_aspect_ratios[t] : 1.0;
            advance = length(rings[k].center - rings[k - 1].center) / (std::numbers::pi * diameter) /
                      (ratio > 0 ? ratio : 1.0);
        }
        rings[k].v = rings[k - 1].v + advance;
    }
    to.v = rings.back().v;

    if (!m_settings.draw_surfaces) {
        draw_axis_lines(rings, from, to);
    } else if (from.contour == 0 && to.contour == 0 && !m_settings.mesh_circles) {
        draw_round(rings, profile, axis, from, to);
        extend_bounds(rings, from, to, len);
    } else {
        draw_mesh(rings, from, to, len);
    }
}

/// The circular contour as Embree round Hermite segments: exact for the linear radius
/// profile (one segment); a bent profile gives one segment per strip, each matching the
/// composite curve F(Ru(s)), Rv(s) and its derivative at the strip ends.
///
/// Colours as cpfg draws them (strip_to_mesh): the first strip starts in the start
/// point's colour and the others are in the end point's, since every ring after the
/// first is a copy of the end turtle. The first strip is flat, or blends to the end
/// colour under `render mode: interpolated`. A linear profile whose colour changes is
/// therefore cut in two at the first ring: the cut is exact (the same cubic).
void CylinderBuilder::draw_round(const std::vector<SweepRing>& rings, const RadiusProfile& profile,
                                 const Vec3 (&axis)[4], const CylinderPoint& from, CylinderPoint& to)
{
    HermiteCurves& hc = m_out.curves;
    const int strips = static_cast<int>(rings.size()) - 1;
    const std::uint16_t start_colour = material_index(from.color), end_colour = material_index(to.color);
    // The pieces' ends, as ring indices.
    std::vector<int> cuts;
    if (!profile.linear()) {
        for (int k = 0; k <= strips; ++k)
            cuts.push_back(k);
    } else if (start_colour != end_colour && strips > 1) {
        cuts = {0, 1, strips};
    } else {
        cuts = {0, strips};
    }
    // The key at ring k of a piece `span` rings long (tangents scale with its length).
    auto key_at = [&](int k, int span, Float4& point, Float4& tangent) {
        double s = static_cast<double>(k) / strips, ds = static_cast<double>(span) / strips;
        double t = k == 0 ? 0 : k == strips ? 1 : profile.u(s);
        Vec3 p = k == 0 ? axis[0] : k == strips ? axis[1] : hermite(axis[0], axis[1], axis[2], axis[3], t);
        Vec3 d = hermite_derivative(axis[0], axis[1], axis[2], axis[3], t) * (profile.du(s) * ds);
        point = f4(p, k == 0 ? profile.r0 : k == strips ? profile.r1 : profile.radius(s));
        tangent = f4(d, profile.dradius(s) * ds);
    };
    auto push_key = [&](int k, const Float4& point, const Float4& tangent) {
        hc.points.push_back(point);
        hc.tangents.push_back(tangent);
        hc.v.push_back(static_cast<float>(rings[static_cast<std::size_t>(k)].v));
    };

    Float4 point, tangent;
    for (std::size_t j = 1; j < cuts.size(); ++j) {
        int a = cuts[j - 1], b = cuts[j];
        key_at(a, b - a, point, tangent);
        // Share the previous key when it is the same (equal tangents): the previous
        // piece's end, or for the first piece the previous segment's last key.
        bool continues = j > 1 || (from.key >= 0 && static_cast<std::size_t>(from.key) + 1 == hc.points.size());
        bool shared = continues && hc.points.back() == point && hc.tangents.back() == tangent;
        if (!shared)
            push_key(a, point, tangent);
        auto first = static_cast<std::uint32_t>(hc.points.size() - 1);
        key_at(b, b - a, point, tangent);
        push_key(b, point, tangent);
        // A cut piece continues its neighbour exactly (same point, radius and direction).
        bool joined = j > 1 || shared;
        if (joined)
            hc.flags.back() |= CurveFlags::neighbour_right;
        hc.segments.push_back(first);
        hc.flags.push_back(joined ? CurveFlags::neighbour_left : 0);
        hc.material.push_back(a == 0 ? start_colour : end_colour);
        hc.texture.push_back(static_cast<std::int16_t>(from.texture >= 0 ? from.texture : no_texture));
        set_end_material(hc, a == 0 && m_settings.interpolate_colours ? end_colour : hc.material.back());
    }
    to.key = static_cast<std::int64_t>(hc.points.size() - 1);
}

namespace {

/// A contour vertex placed on a ring: P + r (x U - y L) + (r z / len) H, cpfg's
/// make_contour (the z of 3D contours is divided by the control points' distance).
Vec3 ring_vertex(const SweepRing& r, const Vec3& c, double len)
{
    return r.center + (r.up * c.x - r.left * c.y) * r.radius + r.heading * (r.radius * c.z / len);
}

Vec3 lerp(const Vec3& a, const Vec3& b, double f) { return a * (1 - f) + b * f; }

}  // namespace

void CylinderBuilder::extend_bounds(const std::vector<SweepRing>& rings, const CylinderPoint& from,
                                    const CylinderPoint& to, double len)
{
    const ContourSamples& a = samples(from.contour, to.sides);
    const ContourSamples& b = samples(to.contour, to.sides);
    std::size_t n = std::min(a.vertices.size(), b.vertices.size());
    for (const SweepRing& r : rings)
        for (std::size_t i = 0; i < n; ++i)
            m_bounds.extend(ring_vertex(r, lerp(a.vertices[i], b.vertices[i], r.axis_t), len));
}

/// Other contours: triangle strips between the rings, the contours interpolated by the
/// axis parameter, smooth normals (shared with the previous segment's end ring).
void CylinderBuilder::draw_mesh(const std::vector<SweepRing>& rings, const CylinderPoint& from, CylinderPoint& to,
                                double len)
{
    TriangleMesh& mesh = m_out.mesh;
    const ContourSamples& a = samples(from.contour, to.sides);
    const ContourSamples& b = samples(to.contour, to.sides);
    std::size_t n = std::min(a.vertices.size(), b.vertices.size());  // sides + 1
    if (n < 2)
        return;
    int sides = static_cast<int>(n) - 1;
    // Counter-clockwise contours face outward with this winding; clockwise ones flip.
    bool flip = a.closed && signed_area(std::vector<Vec3>(a.vertices.begin(), a.vertices.end() - 1)) < 0;

    std::vector<std::uint32_t> ring_start(rings.size());
    std::vector<Vec3> positions;
    for (std::size_t k = 0; k < rings.size(); ++k) {
        const SweepRing& r = rings[k];
        positions.clear();
        for (std::size_t i = 0; i < n; ++i) {
            positions.push_back(ring_vertex(r, lerp(a.vertices[i], b.vertices[i], r.axis_t), len));
            m_bounds.extend(positions.back());
        }
        // The first ring may be the previous segment's last one.
        if (k == 0 && from.ring >= 0 && from.ring_sides == sides &&
            static_cast<std::size_t>(from.ring) + n <= mesh.positions.size()) {
            bool same = true;
            for (std::size_t i = 0; i < n && same; ++i) {
                Vec3 old = vec(mesh.positions[static_cast<std::size_t>(from.ring) + i]);
                same = length(old - positions[i]) <= 1e-5 * std::max(1.0, r.radius);
            }
            if (same) {
                ring_start[0] = static_cast<std::uint32_t>(from.ring);
                continue;
            }
        }
        ring_start[k] = static_cast<std::uint32_t>(mesh.positions.size());
        for (std::size_t i = 0; i < n; ++i) {
            mesh.positions.push_back(f3(positions[i]));
            mesh.normals.push_back({0, 0, 0});
            mesh.uvs.push_back({static_cast<float>(1.0 - static_cast<double>(i) / sides), static_cast<float>(r.v)});
        }
    }

    // Area-weighted face normals gathered per vertex of this segment.
    std::vector<Vec3> sums(rings.size() * n);
    auto add_triangle = [&](std::size_t ka, std::size_t ia, std::size_t kb, std::size_t ib, std::size_t kc,
                            std::size_t ic) {
        std::uint32_t va = ring_start[ka] + static_cast<std::uint32_t>(ia);
        std::uint32_t vb = ring_start[kb] + static_cast<std::uint32_t>(ib);
        std::uint32_t vc = ring_start[kc] + static_cast<std::uint32_t>(ic);
        if (flip)
            std::swap(vb, vc), std::swap(kb, kc), std::swap(ib, ic);
        mesh.triangles.push_back({va, vb, vc});
        // cpfg: the first strip in the start point's colours, the others in the end's
        // (see draw_round; `render mode: interpolated` is not blended here).
        const CylinderPoint& colours = ka == 0 ? from : to;
        mesh.material.push_back(material_index(colours.color));
        mesh.back_material.push_back(material_index(colours.back_color));
        mesh.texture.push_back(static_cast<std::int16_t>(from.texture >= 0 ? from.texture : no_texture));
        Vec3 pa = vec(mesh.positions[va]), pb = vec(mesh.positions[vb]), pc = vec(mesh.positions[vc]);
        Vec3 face = cross(pb - pa, pc - pa);
        sums[ka * n + ia] += face;
        sums[kb * n + ib] += face;
        sums[kc * n + ic] += face;
    };
    for (std::size_t k = 1; k < rings.size(); ++k)
        for (std::size_t i = 0; i + 1 < n; ++i) {
            add_triangle(k - 1, i, k, i, k - 1, i + 1);
            add_triangle(k - 1, i + 1, k, i, k, i + 1);
        }

    for (std::size_t k = 0; k < rings.size(); ++k) {
        if (a.closed && b.closed) {  // the seam's two copies are one point of the surface
            Vec3 seam = sums[k * n] + sums[k * n + n - 1];
            sums[k * n] = sums[k * n + n - 1] = seam;
        }
        bool reused = k == 0 && static_cast<std::int64_t>(ring_start[0]) == from.ring;
        for (std::size_t i = 0; i < n; ++i) {
            Vec3 normal = sums[k * n + i];
            if (length(normal) == 0)  // degenerate (zero radius): point away from the axis
                normal = vec(mesh.positions[ring_start[k] + i]) - rings[k].center;
            normal = normalize(normal);
            Float3& out = mesh.normals[ring_start[k] + i];
            if (reused)
                normal = normalize(vec(out) + normal);
            out = f3(normal);
        }
    }
    to.ring = ring_start.back();
    to.ring_sides = sides;
}

void CylinderBuilder::draw_axis_lines(const std::vector<SweepRing>& rings, const CylinderPoint& from,
                                      const CylinderPoint& to)
{
    LinearCurves& lines = m_out.lines;
    for (std::size_t k = 0; k < rings.size(); ++k) {
        lines.keys.push_back(f4(rings[k].center, rings[k].radius));
        lines.v.push_back(static_cast<float>(rings[k].v));
        m_bounds.extend(rings[k].center);
        if (k == 0)
            continue;
        lines.segments.push_back(static_cast<std::uint32_t>(lines.keys.size() - 2));
        std::uint8_t flags = k > 1 ? LinearCurves::neighbour_left : 0;
        if (k > 1)
            lines.flags.back() |= LinearCurves::neighbour_right;
        lines.flags.push_back(flags);
        // The line from ring k - 1 in that ring's turtle's colour, as cpfg draws it.
        lines.material.push_back(material_index(k == 1 ? from.color : to.color));
        lines.texture.push_back(static_cast<std::int16_t>(from.texture >= 0 ? from.texture : no_texture));
    }
}

}  // namespace cambium::geom
