// SPDX-License-Identifier: Apache-2.0
#include "render/light_report.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <optional>
#include <unordered_map>

#include "base/atomic_file.h"
#include "base/diagnostics.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/ground.h"
#include "render/light.h"
#include "render/material.h"

namespace cambium::render {
namespace {

using Rgb3 = std::array<double, 3>;

double mean(const Rgb3& c) { return (c[0] + c[1] + c[2]) / 3; }

/// A stream of numbers of its own per ray: the same draws whichever thread traces it.
struct RayRandom {
    std::uint64_t state;
    RayRandom(std::uint64_t seed, std::uint64_t light, std::uint64_t ray)
        : state(mix(mix(seed ^ 0x6a09e667f3bcc909ull) ^ (light * 0x9e3779b97f4a7c15ull) ^ mix(ray)))
    {}
    static std::uint64_t mix(std::uint64_t z)
    {
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double next()
    {
        state += 0x9e3779b97f4a7c15ull;
        return static_cast<double>(mix(state) >> 11) * 0x1.0p-53;
    }
};

struct Vec3d {
    double x = 0, y = 0, z = 0;
};
Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3d operator*(Vec3d a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3d cross(Vec3d a, Vec3d b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double length(Vec3d a) { return std::sqrt(dot(a, a)); }
Vec3d unit(Vec3d a) { return a * (1 / length(a)); }
Vec3d v3(const geom::Float3& f) { return {f[0], f[1], f[2]}; }
Vec3d v3(const geom::Float4& f) { return {f[0], f[1], f[2]}; }

/// An instance's transform (identity for the scene's own geometry).
struct Affine {
    std::array<float, 12> m{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    Vec3d column(int c) const { return {m[3 * c], m[3 * c + 1], m[3 * c + 2]}; }
    Vec3d point(Vec3d p) const { return column(0) * p.x + column(1) * p.y + column(2) * p.z + column(3); }
    /// Lengths scale by this in a similarity (radii).
    double scale() const
    {
        return std::cbrt(std::abs(dot(column(0), cross(column(1), column(2)))));
    }
    /// A flat area with unit normal n grows by |cof(M) n|.
    double area_scale(Vec3d n) const
    {
        Vec3d c0 = column(0), c1 = column(1), c2 = column(2);
        return length(cross(c1, c2) * n.x + cross(c2, c0) * n.y + cross(c0, c1) * n.z);
    }
};

double frustum_area(Vec3d a, Vec3d b, double ra, double rb)
{
    const double l = length(b - a);
    return std::numbers::pi * (ra + rb) * std::sqrt((ra - rb) * (ra - rb) + l * l);
}

/// Calls f(kind, primitive, area) for each primitive of g placed by t (pixel-width lines,
/// which have no area in the world, are left out).
template <class F>
void each_area(const geom::Geometry& g, const Affine& t, bool lines_in_pixels, F&& f)
{
    const double s = t.scale();
    if (!lines_in_pixels)
        for (std::size_t i = 0; i < g.lines.segment_count(); ++i) {
            const auto& a = g.lines.keys[g.lines.segments[i]];
            const auto& b = g.lines.keys[g.lines.segments[i] + 1];
            f(PrimitiveKind::lines, i, frustum_area(t.point(v3(a)), t.point(v3(b)), a[3] * s, b[3] * s));
        }
    for (std::size_t i = 0; i < g.curves.segment_count(); ++i) {  // the chord's frustum
        const auto& a = g.curves.points[g.curves.segments[i]];
        const auto& b = g.curves.points[g.curves.segments[i] + 1];
        f(PrimitiveKind::curves, i, frustum_area(t.point(v3(a)), t.point(v3(b)), a[3] * s, b[3] * s));
    }
    for (std::size_t i = 0; i < g.spheres.size(); ++i) {
        const double r = g.spheres.centres[i][3] * s;
        f(PrimitiveKind::spheres, i, 4 * std::numbers::pi * r * r);
    }
    for (std::size_t i = 0; i < g.discs.size(); ++i) {
        const double r = g.discs.centres[i][3];
        f(PrimitiveKind::discs, i, std::numbers::pi * r * r * t.area_scale(v3(g.discs.normals[i])));
    }
    for (std::size_t i = 0; i < g.mesh.size(); ++i) {
        const auto& tri = g.mesh.triangles[i];
        Vec3d a = t.point(v3(g.mesh.positions[tri[0]]));
        Vec3d b = t.point(v3(g.mesh.positions[tri[1]]));
        Vec3d c = t.point(v3(g.mesh.positions[tri[2]]));
        f(PrimitiveKind::mesh, i, 0.5 * length(cross(b - a, c - a)));
    }
}

constexpr std::uint32_t no_organ = 0xffffffffu;

/// The organs and which primitive belongs to which.
struct Organs {
    std::vector<OrganLight> list;
    std::unordered_map<std::uint64_t, std::uint32_t> by_key;  ///< (plant, module)
    /// The scene's own primitives' organs, per kind.
    std::array<std::vector<std::uint32_t>, 5> own;
    /// Per instance: its organ (an organ placed whole), or no_organ.
    std::vector<std::uint32_t> instance;

    static std::uint64_t key(std::uint32_t plant, std::uint32_t module)
    {
        return (std::uint64_t(plant) << 32) | module;
    }
    std::uint32_t organ(std::uint32_t plant, std::uint32_t module, const geom::ModuleTable& table)
    {
        if (module == geom::no_module)
            return no_organ;
        auto [it, fresh] = by_key.try_emplace(key(plant, module), static_cast<std::uint32_t>(list.size()));
        if (fresh) {
            OrganLight o;
            o.module = module;
            o.plant = plant;
            if (const geom::ModuleRecord* r = table.find(module)) {
                o.symbol = std::string(table.name(*r));
                o.age = r->age;
            }
            list.push_back(std::move(o));
        }
        return it->second;
    }

    std::uint32_t of(const geom::Scene& scene, const LightHit& hit) const
    {
        if (hit.primitive == PrimId::none)
            return no_organ;
        const auto k = static_cast<std::size_t>(primitive_kind(hit.shape));
        if (hit.instance == PrimId::none)
            return hit.primitive < own[k].size() ? own[k][hit.primitive] : no_organ;
        if (instance[hit.instance] != no_organ)
            return instance[hit.instance];
        const geom::Instance& in = scene.instances[hit.instance];
        const auto& m = modules_of(scene.prototypes[in.prototype].geometry, primitive_kind(hit.shape));
        if (hit.primitive >= m.size())
            return no_organ;
        auto it = by_key.find(key(in.plant, m[hit.primitive]));
        return it == by_key.end() ? no_organ : it->second;
    }
};

Organs find_organs(const geom::Scene& scene)
{
    Organs o;
    const bool pixels = scene.line_radius_in_pixels;
    const geom::Geometry& g = scene.geometry;
    for (std::size_t k = 0; k < 5; ++k) {
        const std::size_t n = primitive_count(g, static_cast<PrimitiveKind>(k));
        const auto& m = modules_of(g, static_cast<PrimitiveKind>(k));
        o.own[k].assign(n, no_organ);
        if (m.size() == n)
            for (std::size_t i = 0; i < n; ++i)
                o.own[k][i] = o.organ(geom::Instance::no_plant, m[i], scene.geometry.modules);
    }
    each_area(g, Affine{}, pixels, [&](PrimitiveKind k, std::size_t i, double area) {
        std::uint32_t organ = o.own[static_cast<std::size_t>(k)][i];
        if (organ != no_organ)
            o.list[organ].area += area;
    });
    const geom::OrganModules organ_modules(scene);
    o.instance.assign(scene.instances.size(), no_organ);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const geom::Instance& in = scene.instances[i];
        if (in.prototype >= scene.prototypes.size())
            continue;
        const geom::Prototype& p = scene.prototypes[in.prototype];
        Affine t{in.transform};
        if (in.module != geom::no_module) {
            std::uint32_t organ = o.instance[i] = o.organ(in.plant, in.module, organ_modules.of(in));
            each_area(p.geometry, t, pixels, [&](PrimitiveKind, std::size_t, double area) {
                o.list[organ].area += area;
            });
        } else {
            each_area(p.geometry, t, pixels, [&](PrimitiveKind k, std::size_t j, double area) {
                const auto& m = modules_of(p.geometry, k);
                if (j < m.size()) {
                    std::uint32_t organ = o.organ(in.plant, m[j], p.geometry.modules);
                    if (organ != no_organ)
                        o.list[organ].area += area;
                }
            });
        }
    }
    return o;
}

/// The bounds of every primitive as placed (radii included).
geom::Bounds3 world_bounds(const geom::Scene& scene)
{
    geom::Bounds3 b;
    auto add = [&](const geom::Geometry& g, const Affine& t, double pad_scale) {
        auto key = [&](const geom::Float4& k) {
            Vec3d p = t.point(v3(k));
            double r = scene.line_radius_in_pixels ? 0 : k[3] * pad_scale;
            b.extend(geom::Vec3{p.x - r, p.y - r, p.z - r});
            b.extend(geom::Vec3{p.x + r, p.y + r, p.z + r});
        };
        for (const auto& k : g.lines.keys)
            key(k);
        for (const auto& k : g.curves.points)
            key(k);
        for (const auto& k : g.spheres.centres)
            key(k);
        for (const auto& k : g.discs.centres)
            key(k);
        for (const auto& p : g.mesh.positions) {
            Vec3d q = t.point(v3(p));
            b.extend(geom::Vec3{q.x, q.y, q.z});
        }
    };
    add(scene.geometry, Affine{}, 1);
    for (const geom::Instance& in : scene.instances)
        if (in.prototype < scene.prototypes.size()) {
            Affine t{in.transform};
            add(scene.prototypes[in.prototype].geometry, t, t.scale());
        }
    return b;
}

struct Tally {
    double absorbed = 0, front = 0, back = 0;
};

/// A block's tallies, by organ (sorted), and its totals.
struct BlockResult {
    std::vector<std::pair<std::uint32_t, Tally>> organs;
    double absorbed = 0, unattributed = 0, escaped = 0, escaped_down = 0, truncated = 0, emitted = 0;
    double ground_reached = 0, ground_absorbed = 0, ground_emitted = 0;
};

/// A cosine-distributed direction about n.
Vec3d cosine_direction(Vec3d n, RayRandom& rng)
{
    const double u1 = rng.next(), u2 = rng.next();
    const double r = std::sqrt(u1), phi = 2 * std::numbers::pi * u2;
    Vec3d other = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    Vec3d t = unit(cross(other, n));
    Vec3d s = cross(n, t);
    return unit(t * (r * std::cos(phi)) + s * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0, 1 - u1)));
}

Vec3f f3(Vec3d a) { return {float(a.x), float(a.y), float(a.z)}; }
Vec3d d3(const Vec3f& a) { return {a.x, a.y, a.z}; }

/// The slab the rays live in: the bounds of every primitive, and their bounding sphere.
struct Extent {
    Vec3d lo, hi, centre;
    double radius = 0;
    bool canopy = false;  ///< rays wrap across the x and z sides
    double width() const { return hi.x - lo.x; }
    double depth() const { return hi.z - lo.z; }
};

Extent make_extent(const geom::Bounds3& b, const LightReportSettings& settings)
{
    Extent e;
    e.lo = {b.lo.x, b.lo.y, b.lo.z};
    e.hi = {b.hi.x, b.hi.y, b.hi.z};
    e.canopy = settings.infinite_canopy || settings.canopy_tile;
    if (settings.canopy_tile && !b.empty()) {
        const auto& t = *settings.canopy_tile;
        if (!(t[0] < t[2] && t[1] < t[3]) || t[0] > e.lo.x || t[2] < e.hi.x || t[1] > e.lo.z || t[3] < e.hi.z) {
            char text[256];
            std::snprintf(text, sizeof text,
                          "--canopy-tile %g %g %g %g must hold the scene's x-z bounds, x %g .. %g, z %g .. %g",
                          t[0], t[1], t[2], t[3], e.lo.x, e.hi.x, e.lo.z, e.hi.z);
            throw Error(text);
        }
        e.lo.x = t[0];
        e.lo.z = t[1];
        e.hi.x = t[2];
        e.hi.z = t[3];
    }
    e.centre = (e.lo + e.hi) * 0.5;
    // a margin, so that no primitive touches the sphere
    e.radius = length(e.hi - e.lo) * 0.5 * (1 + 1e-3) + 1e-6;
    return e;
}

/// The ground plane as the report traces it.
struct Ground {
    bool on = false;
    double height = 0;
    Rgb3 albedo{};
    /// Its unshadowed irradiance is a source of its own (no canopy): a light's ray that
    /// lands unshadowed ends there, one the plant stops first leaves a shadow ray.
    bool split = false;

    /// The distance along dir from org to the plane, infinity where the ray never meets
    /// it; a light's ray that starts under it (outside the bounds) going down is on it.
    double distance(Vec3d org, Vec3d dir, bool from_light) const
    {
        if (!on || dir.y == 0)
            return std::numeric_limits<double>::infinity();
        const double t = (height - org.y) / dir.y;
        if (t > 0)
            return t;
        return from_light && dir.y < 0 ? 0.0 : std::numeric_limits<double>::infinity();
    }
};

Ground make_ground(const geom::Scene& scene, const LightReportSettings& settings)
{
    Ground g;
    if (!settings.ground)
        return g;
    g.on = true;
    g.height = settings.ground->height.value_or(lowest_point(scene));
    geom::Material surface;  // as the renderer makes its ground's material
    surface.diffuse = settings.ground->colour;
    const Bsdf b = make_bsdf(make_materials({surface}).front());
    const Vec3f a = b.reflect + b.glossy;
    g.albedo = {std::clamp<double>(a.x, 0, 1), std::clamp<double>(a.y, 0, 1), std::clamp<double>(a.z, 0, 1)};
    g.split = !(settings.infinite_canopy || settings.canopy_tile);
    return g;
}

/// Two unit vectors across the unit vector d.
std::pair<Vec3d, Vec3d> frame(Vec3d d)
{
    Vec3d other = std::abs(d.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    Vec3d u = unit(cross(other, d));
    return {u, cross(d, u)};
}

/// One light as the report emits it: a directional light's parallel beam, the
/// environment's directions, or a point (spot) light's rays. Each ray stands for a cell
/// of an nx x ny grid over the unit square of the two numbers that place it
/// (stratified).
struct Source {
    enum class Kind { beam, environment, point, ground };
    Kind kind = Kind::beam;
    Rgb3 colour{};  ///< beam: irradiance; point: intensity at unit falloff
    double power = 0;  ///< what it sends into the scene, roughly: shares the rays
    std::uint64_t nx = 1, ny = 1;
    std::string text;
    // beam: rays along -to_light from corner + x u + y v, over `area` across the beam
    Vec3d to_light, corner, u, v;
    double area = 0;
    // point: rays from `position` within the cone about `axis` of cosine `cos_cone`
    RenderLight light;
    Vec3d position, axis;
    double cos_cone = -1;
    double solid_angle() const { return 2 * std::numbers::pi * (1 - cos_cone); }
    // ground: its unshadowed irradiance, the directional lights' (uniform) and the point
    // lights' (by place), with the environment's drawn for each ray
    Rgb3 uniform{};
    std::vector<RenderLight> points;
    bool environment = false;
};

/// A ray as emitted: its power per channel, and for a point light the falloff by the
/// distance it travels to its first surface.
struct Emitted {
    Vec3d org, dir;
    Rgb3 w{};
    const RenderLight* falloff = nullptr;
    bool from_ground = false;
};

/// A directional light's beam: over the rectangle the scene's bounds project onto across
/// its direction, or with the canopy over the bounds' top.
std::optional<Source> make_beam(const RenderLight& light, const Extent& e)
{
    Source s;
    s.to_light = unit(d3(light.toward_light));
    s.colour = {light.colour.x, light.colour.y, light.colour.z};
    if (e.canopy) {
        if (!(s.to_light.y > 0))
            return std::nullopt;  // below the horizon: nothing enters the stand from above
        const double margin = 1e-3 * std::max({e.hi.y - e.lo.y, e.width(), e.depth(), 1e-6});
        s.corner = {e.lo.x, e.hi.y + margin, e.lo.z};
        s.u = {e.width(), 0, 0};
        s.v = {0, 0, e.depth()};
        s.area = e.width() * e.depth() * s.to_light.y;
    } else {
        auto [u, v] = frame(s.to_light);
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (int c = 0; c < 8; ++c) {
            Vec3d p{c & 1 ? e.hi.x : e.lo.x, c & 2 ? e.hi.y : e.lo.y, c & 4 ? e.hi.z : e.lo.z};
            double q[3] = {dot(p, u), dot(p, v), dot(p, s.to_light)};
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], q[k]);
                hi[k] = std::max(hi[k], q[k]);
            }
        }
        // a margin, so that nothing lies on the rectangle's edge
        const double margin = 1e-3 * std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-6});
        for (int k = 0; k < 3; ++k) {
            lo[k] -= margin;
            hi[k] += margin;
        }
        s.corner = u * lo[0] + v * lo[1] + s.to_light * (hi[2] + margin);
        s.u = u * (hi[0] - lo[0]);
        s.v = v * (hi[1] - lo[1]);
        s.area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    }
    s.power = mean(s.colour) * s.area;
    return s;
}

/// A point or spot light: rays from it within the narrower of the cone that holds the
/// scene's bounding sphere (the light outside it, no canopy) and the spot's cutoff cone.
Source make_point(const RenderLight& light, const Extent& e)
{
    Source s;
    s.kind = Source::Kind::point;
    s.light = light;
    s.position = d3(light.position);
    s.colour = {light.colour.x, light.colour.y, light.colour.z};
    s.axis = {0, 1, 0};
    const Vec3d to_centre = e.centre - s.position;
    const double d = length(to_centre);
    if (!e.canopy && d > e.radius) {
        s.axis = to_centre * (1 / d);
        s.cos_cone = std::sqrt(1 - (e.radius / d) * (e.radius / d));
    }
    if (light.kind == RenderLight::Kind::spot && light.spot_cos_cutoff > s.cos_cone) {
        s.axis = unit(d3(light.spot_axis));
        s.cos_cone = light.spot_cos_cutoff;
    }
    // roughly the flux its nearest reach of the scene receives
    const double reach = std::max(e.radius, d - e.radius);
    const float a = light.att_constant + light.att_linear * float(reach) +
                    light.att_quadratic * float(reach * reach);
    s.power = a > 0 ? mean(s.colour) * s.solid_angle() * reach * reach / a : 0;
    return s;
}

/// The environment: directions drawn from its own sampling, each ray from a point drawn
/// uniformly over the disc across that direction that covers the bounding sphere (with
/// the canopy, over the bounds' top or bottom face).
Source make_environment_source(const Environment& env, const Extent& e, const Ground& g, std::uint64_t seed)
{
    Source s;
    s.kind = Source::Kind::environment;
    // its power from a few of its own samples (only shares the rays out)
    RayRandom rng(seed, 0xe4, 0);
    double sum = 0;
    constexpr int n = 1024;
    for (int i = 0; i < n; ++i) {
        EnvironmentSample es = env.sample(float(rng.next()), float(rng.next()));
        if (es.pdf > 0 && !(g.on && es.direction.y <= 0))  // the ground hides the lower half
            sum += mean({es.radiance.x, es.radiance.y, es.radiance.z}) / es.pdf *
                   (e.canopy ? std::abs(es.direction.y) * e.width() * e.depth() / std::numbers::pi
                             : e.radius * e.radius);
    }
    s.power = sum / n;
    return s;
}

/// A point or spot light's irradiance on the ground's upper side at x, unshadowed.
Rgb3 point_irradiance(const RenderLight& l, Vec3d x)
{
    const Vec3d to = d3(l.position) - x;
    const double d = length(to);
    if (!(to.y > 0))
        return {};
    const double a = l.att_constant + l.att_linear * d + l.att_quadratic * d * d;
    if (!(a > 0))
        return {};
    double k = to.y / d / a;
    if (l.kind == RenderLight::Kind::spot) {  // OpenGL's spot factor, as emit's
        const double along = -dot(to, d3(l.spot_axis)) / d;
        if (along < l.spot_cos_cutoff)
            return {};
        if (l.spot_exponent > 0)
            k *= std::pow(std::max(along, 0.0), double(l.spot_exponent));
    }
    return {l.colour.x * k, l.colour.y * k, l.colour.z * k};
}

/// The environment's irradiance on an upward face from one of its own samples (unbiased;
/// exact for a uniform one).
Rgb3 environment_irradiance(const Environment& env, RayRandom& rng)
{
    if (env.uniform()) {
        const Vec3f l = env.radiance(Vec3f(0, 1, 0));
        return {l.x, l.y, l.z};
    }
    const EnvironmentSample es = env.sample(float(rng.next()), float(rng.next()));
    if (!(es.pdf > 0) || !(es.direction.y > 0))
        return {};
    const double k = es.direction.y / (std::numbers::pi * es.pdf);
    return {es.radiance.x * k, es.radiance.y * k, es.radiance.z * k};
}

/// The ground's unshadowed irradiance at x (on the plane).
Rgb3 ground_irradiance(const Source& s, const Environment* env, Vec3d x, RayRandom& rng)
{
    Rgb3 e = s.uniform;
    auto add = [&](const Rgb3& a) {
        for (int c = 0; c < 3; ++c)
            e[c] += a[c];
    };
    for (const RenderLight& l : s.points)
        add(point_irradiance(l, x));
    if (s.environment && env)
        add(environment_irradiance(*env, rng));
    return e;
}

/// The ground's unshadowed reflection as a source: radiance albedo x irradiance (its
/// irradiance as a view-file light's, over pi), up through the bounding sphere from
/// every direction of the upper hemisphere (uniform: a sphere's cross-section is the
/// same from all).
Source make_ground_source(Source s, const Extent& e, const Ground& g, const Environment* env,
                          std::uint64_t seed)
{
    s.kind = Source::Kind::ground;
    RayRandom rng(seed, 0x96, 0);
    const Vec3d below{e.centre.x, g.height, e.centre.z};
    double sum = 0;
    constexpr int n = 64;
    for (int i = 0; i < n; ++i)
        sum += mean(ground_irradiance(s, env, below, rng));
    s.power = mean(g.albedo) * sum / n * 2 * std::numbers::pi * e.radius * e.radius;
    char text[256];
    std::snprintf(text, sizeof text,
                  "ground at height %g, albedo (%g, %g, %g): its unshadowed reflection, up through the "
                  "scene's bounding sphere",
                  g.height, g.albedo[0], g.albedo[1], g.albedo[2]);
    s.text = text;
    return s;
}

std::optional<Emitted> emit(const Source& s, const Extent& e, const Ground& g, const Environment* env,
                            std::uint64_t j, std::uint64_t count, RayRandom& rng)
{
    const double x = (double(j % s.nx) + rng.next()) / double(s.nx);
    const double y = (double(j / s.nx) + rng.next()) / double(s.ny);
    Emitted out;
    switch (s.kind) {
    case Source::Kind::beam: {
        out.org = s.corner + s.u * x + s.v * y;
        out.dir = s.to_light * -1.0;
        const double flux = s.area / double(count);
        out.w = {s.colour[0] * flux, s.colour[1] * flux, s.colour[2] * flux};
        return out;
    }
    case Source::Kind::environment: {
        const EnvironmentSample es = env->sample(float(x), float(y));
        if (!(es.pdf > 0))
            return std::nullopt;
        const Vec3d w = unit(d3(es.direction));  // toward the sky
        if (g.on && w.y <= 0)
            return std::nullopt;  // the ground hides it
        // radiance / pdf over the area rays start from, in units where irradiance pi
        // (the renderer's) is 1
        double area = 0;
        if (e.canopy) {
            if (w.y == 0)
                return std::nullopt;
            const double margin = 1e-3 * std::max({e.hi.y - e.lo.y, e.width(), e.depth(), 1e-6});
            out.org = {e.lo.x + rng.next() * e.width(), w.y > 0 ? e.hi.y + margin : e.lo.y - margin,
                       e.lo.z + rng.next() * e.depth()};
            area = e.width() * e.depth() * std::abs(w.y);
        } else {
            auto [t, b] = frame(w);
            const double r = e.radius * std::sqrt(rng.next()), phi = 2 * std::numbers::pi * rng.next();
            out.org = e.centre + w * e.radius + t * (r * std::cos(phi)) + b * (r * std::sin(phi));
            area = std::numbers::pi * e.radius * e.radius;
        }
        out.dir = w * -1.0;
        const double k = area / (std::numbers::pi * double(es.pdf) * double(count));
        out.w = {es.radiance.x * k, es.radiance.y * k, es.radiance.z * k};
        return out;
    }
    case Source::Kind::point: {
        const double c = 1 - x * (1 - s.cos_cone), sine = std::sqrt(std::max(0.0, 1 - c * c));
        const double phi = 2 * std::numbers::pi * y;
        auto [t, b] = frame(s.axis);
        out.org = s.position;
        out.dir = unit(s.axis * c + t * (sine * std::cos(phi)) + b * (sine * std::sin(phi)));
        double k = s.solid_angle() / double(count);
        const RenderLight& l = s.light;
        if (l.kind == RenderLight::Kind::spot) {  // OpenGL's spot factor, as the renderer's
            const double along = dot(out.dir, d3(l.spot_axis));
            if (along < l.spot_cos_cutoff)
                return std::nullopt;
            if (l.spot_exponent > 0)
                k *= std::pow(std::max(along, 0.0), double(l.spot_exponent));
        }
        out.w = {s.colour[0] * k, s.colour[1] * k, s.colour[2] * k};
        out.falloff = &s.light;
        return out;
    }
    case Source::Kind::ground: {
        if (!(x > 0))
            return std::nullopt;
        const double sine = std::sqrt(std::max(0.0, 1 - x * x)), phi = 2 * std::numbers::pi * y;
        const Vec3d d{sine * std::cos(phi), x, sine * std::sin(phi)};  // up, uniform in solid angle
        auto [t, b] = frame(d);
        const double r = e.radius * std::sqrt(rng.next()), psi = 2 * std::numbers::pi * rng.next();
        const Vec3d q = e.centre - d * e.radius + t * (r * std::cos(psi)) + b * (r * std::sin(psi));
        const double along = (g.height - q.y) / d.y;
        Vec3d land = q + d * along;  // where the line leaves the ground
        land.y = g.height;
        out.org = along > 0 ? land : q;  // nothing lies between the ground and the disc
        out.dir = d;
        const Rgb3 irradiance = ground_irradiance(s, env, land, rng);
        // radiance albedo E (the renderer's pi E / pi) x pi R^2 / (pi pdf), pdf = 1 / 2 pi
        const double k = 2 * std::numbers::pi * e.radius * e.radius / double(count);
        for (int c = 0; c < 3; ++c)
            out.w[c] = g.albedo[c] * irradiance[c] * k;
        out.from_ground = true;
        return out;
    }
    }
    return std::nullopt;
}

struct Tracer {
    const geom::Scene& scene;
    const EmbreeScene& accel;
    const Organs& organs;
    const std::vector<SurfaceMaterial>& materials;
    const LightReportSettings& settings;
    /// Wraps across the canopy's sides before a path is cut short (a ray level with the
    /// ground could wrap for ever).
    static constexpr std::uint32_t wrap_limit = 1u << 16;

    const Extent& extent;
    const Ground& ground;

    /// The distance from org along dir to where the ray leaves the slab of the bounds
    /// (the canopy) or their bounding sphere.
    double exit_distance(Vec3d org, Vec3d dir) const
    {
        const Extent& e = extent;
        if (e.canopy)
            return dir.y > 0 ? std::max(0.0, (e.hi.y - org.y) / dir.y)
                 : dir.y < 0 ? std::max(0.0, (e.lo.y - org.y) / dir.y)
                             : 0.0;
        const Vec3d c = e.centre - org;
        const double b = dot(c, dir), disc = b * b - (dot(c, c) - e.radius * e.radius);
        return std::max(0.0, disc > 0 ? b + std::sqrt(disc) : b);
    }

    /// With the canopy, the distance along dir to the side the ray leaves the bounds by
    /// and that side's axis (0: x, 2: z); else infinity and -1.
    std::pair<double, int> to_side(Vec3d org, Vec3d dir) const
    {
        const Extent& e = extent;
        double wall = std::numeric_limits<double>::infinity();
        if (!e.canopy)
            return {wall, -1};
        auto to_wall = [&](double o, double d, double lo, double hi) {
            return d > 0 ? (hi - o) / d : d < 0 ? (lo - o) / d : wall;
        };
        const double tx = to_wall(org.x, dir.x, e.lo.x, e.hi.x);
        const double tz = to_wall(org.z, dir.z, e.lo.z, e.hi.z);
        return {std::max(0.0, std::min(tx, tz)), tx <= tz ? 0 : 2};
    }

    /// The query trace() makes first for a ray from org along dir.
    LightRay first_query(Vec3d org, Vec3d dir) const
    {
        return {f3(org), f3(dir), float(std::min(to_side(org, dir).first, ground.distance(org, dir, true)))};
    }

    /// One path: `w` its power per channel (for a point light, at unit distance: its
    /// falloff by the distance to the first surface still to come); tallies into `t` (by
    /// organ, dense) and `r`. `first`: where given, the answer to its first query
    /// (first_query(org, dir)), traced already (in a stream): its hit, or null for none.
    /// With the ground split off, a light's ray that the plant stops before the ground
    /// leaves a shadow: the ground's reflection of it, negative, traced after it.
    void trace(Vec3d org, Vec3d dir, Rgb3 w, const RenderLight* falloff, bool from_ground, RayRandom& rng,
               std::vector<Tally>& t, std::vector<std::uint32_t>& touched, BlockResult& r,
               std::optional<const LightHit*> first = std::nullopt) const
    {
        if (!falloff)
            (from_ground ? r.ground_emitted : r.emitted) += mean(w);
        std::optional<Shadow> shadow;
        follow(org, dir, w, falloff, !from_ground, rng, t, touched, r, first, shadow);
        if (shadow) {
            r.ground_emitted += mean(shadow->w);
            std::optional<Shadow> none;
            follow(shadow->org, cosine_direction({0, 1, 0}, rng), shadow->w, nullptr, false, rng, t, touched, r,
                   std::nullopt, none);
        }
    }

    /// Where the plane would have taken a light's ray, its reflection of it negated.
    struct Shadow {
        Vec3d org;
        Rgb3 w;
    };

    void follow(Vec3d org, Vec3d dir, Rgb3 w, const RenderLight* falloff, bool from_light, RayRandom& rng,
                std::vector<Tally>& t, std::vector<std::uint32_t>& touched, BlockResult& r,
                std::optional<const LightHit*> first, std::optional<Shadow>& shadow) const
    {
        const Extent& e = extent;
        // unshadowed so far: where it lands is the ground source's (no canopy)
        bool unshadowed = from_light && ground.split;
        double travelled = 0;  // from a point light, until its first surface
        auto falloff_at = [&](double d) {
            const double a = falloff->att_constant + falloff->att_linear * d + falloff->att_quadratic * d * d;
            return a > 0 ? d * d / a : 0;
        };
        // a point light's ray has its power once its distance is known
        auto arrive = [&](double d) {
            const double k = falloff_at(d);
            for (double& c : w)
                c *= k;
            falloff = nullptr;
            r.emitted += mean(w);
        };
        double start = mean(w);
        PrimId skip{};
        std::uint32_t wraps = 0;
        LightHit found;
        for (int bounce = 0;; ++bounce) {
            // signed: a shadow's power is negative
            if (!falloff && (bounce >= settings.max_bounces || std::abs(mean(w)) < settings.cutoff * std::abs(start))) {
                r.truncated += mean(w);
                return;
            }
            // with the canopy, up to the side the ray leaves the bounds by
            const auto [wall, axis] = to_side(org, dir);
            const double to_ground = ground.distance(org, dir, unshadowed);
            const LightHit* hit = nullptr;
            if (first) {
                hit = *first;
                first.reset();
            } else if (accel.intersect_light(found, f3(org), f3(dir), 0, float(std::min(wall, to_ground)), skip)) {
                hit = &found;
            }
            if (hit && !(hit->t < to_ground))
                hit = nullptr;  // the ground comes first
            if (!hit && std::isfinite(to_ground) && to_ground <= wall) {
                if (falloff)
                    arrive(travelled + to_ground);
                Rgb3 keep{};
                for (int c = 0; c < 3; ++c)
                    keep[c] = w[c] * ground.albedo[c];
                r.ground_reached += mean(w);
                r.ground_absorbed += mean(w) - mean(keep);
                if (unshadowed || !(std::abs(mean(keep)) > 0))
                    return;  // unshadowed: its reflection is the ground source's
                w = keep;
                r.ground_emitted += mean(w);
                org = org + dir * to_ground;
                org.y = ground.height;  // on the plane: it cannot meet it again going away
                dir = cosine_direction({0, dir.y < 0 ? 1.0 : -1.0, 0}, rng);
                skip = {};
                continue;
            }
            if (!hit && axis >= 0) {
                Vec3d q = org + dir * wall;
                const bool leaving = (q.y >= e.hi.y && dir.y >= 0) || (q.y <= e.lo.y && dir.y <= 0);
                if (!leaving) {  // in through the opposite side
                    if (++wraps > wrap_limit) {
                        if (falloff)
                            arrive(travelled + wall);
                        r.truncated += mean(w);
                        return;
                    }
                    if (axis == 0)
                        q.x = dir.x > 0 ? e.lo.x : e.hi.x;
                    else
                        q.z = dir.z > 0 ? e.lo.z : e.hi.z;
                    travelled += wall;
                    org = q;
                    skip = {};
                    --bounce;  // a wrap meets no surface
                    continue;
                }
            }
            if (!hit) {
                if (falloff)
                    arrive(travelled + exit_distance(org, dir));
                r.escaped += mean(w);
                if (dir.y < 0)
                    r.escaped_down += mean(w);
                return;
            }
            const Vec3d p = d3(hit->position);
            const Vec3d n = d3(hit->geometric_normal);  // toward the incoming ray
            if (hit->unlit) {  // pixel-width lines have no area: light passes
                travelled += length(p - org);
                org = p;
                skip = hit->prim();
                continue;
            }
            SurfaceMaterial m = hit->material < materials.size() ? materials[hit->material] : SurfaceMaterial{};
            if (hit->material_blend > 0 && hit->end_material < materials.size())
                m = mix(m, materials[hit->end_material], hit->material_blend);
            if (!settings.optics && m.opacity < 1 && rng.next() >= m.opacity) {  // passes straight through
                travelled += length(p - org);
                org = hit->closed() ? p : p - n * hit->spawn_offset;
                skip = hit->prim();
                continue;
            }
            if (unshadowed) {
                unshadowed = false;
                if (std::isfinite(to_ground))
                    shadow = shadow_of(org, dir, w, to_ground, falloff ? falloff_at(travelled + to_ground) : 1.0);
            }
            if (falloff) {
                arrive(travelled + length(p - org));
                start = mean(w);
            }
            const std::uint32_t organ = organs.of(scene, *hit);
            const Bsdf b = make_bsdf(m);
            Rgb3 keep{}, absorbed{};
            double transmitted = 0;
            Vec3f refl = b.reflect + b.glossy, trans = b.transmit;
            if (settings.optics) {
                const SurfaceOptics& o = (*settings.optics)[hit->back ? 1 : 0];
                refl = Vec3f(float(o.reflectance));
                trans = Vec3f(float(o.transmittance));
            }
            const float rf[3] = {refl.x, refl.y, refl.z}, tr[3] = {trans.x, trans.y, trans.z};
            for (int c = 0; c < 3; ++c) {
                double rc = std::clamp<double>(rf[c], 0, 1), tc = std::clamp<double>(tr[c], 0, 1 - rc);
                keep[c] = w[c] * (rc + tc);
                absorbed[c] = w[c] - keep[c];
                transmitted += tc / 3;
            }
            const double a = mean(absorbed);
            r.absorbed += a;
            if (organ == no_organ) {
                r.unattributed += a;
            } else {
                if (t[organ].absorbed == 0 && t[organ].front == 0 && t[organ].back == 0)
                    touched.push_back(organ);
                t[organ].absorbed += a;
                (hit->back ? t[organ].back : t[organ].front) += mean(w);
            }
            const double kept = mean(keep);
            if (!(std::abs(kept) > 0))
                return;
            w = keep;
            // the direction: transmitted with transmission's share of what goes on
            const double share = transmitted / std::max(1e-300, mean_of_sum(rf, tr));
            const bool transmit = rng.next() < share;
            const Vec3d side = transmit ? n * -1.0 : n;
            dir = cosine_direction(side, rng);
            org = p + side * hit->spawn_offset;
            skip = hit->prim();
        }
    }

    /// The shadow a light's ray of power w leaves where the ground, `to_ground` along dir,
    /// would have taken it (`falloff`: a point light's at that distance).
    std::optional<Shadow> shadow_of(Vec3d org, Vec3d dir, const Rgb3& w, double to_ground, double falloff) const
    {
        Shadow s{org + dir * to_ground, {}};
        s.org.y = ground.height;
        for (int c = 0; c < 3; ++c)
            s.w[c] = -w[c] * falloff * ground.albedo[c];
        if (!(std::abs(mean(s.w)) > 0))
            return std::nullopt;
        return s;
    }

    static double mean_of_sum(const float* rf, const float* tr)
    {
        double s = 0;
        for (int c = 0; c < 3; ++c) {
            double rc = std::clamp<double>(rf[c], 0, 1);
            s += rc + std::clamp<double>(tr[c], 0, 1 - rc);
        }
        return s / 3;
    }
};

std::string format_vec(Vec3d v)
{
    char b[128];
    std::snprintf(b, sizeof b, "(%g, %g, %g)", v.x, v.y, v.z);
    return b;
}

}  // namespace

LightReport trace_light(const geom::Scene& scene, const LightReportSettings& settings)
{
    LightReport report;
    Organs organs = find_organs(scene);
    const geom::Bounds3 bounds = world_bounds(scene);
    const Extent extent = make_extent(bounds, settings);
    const Ground ground = make_ground(scene, settings);
    // with the ground, the environment's sampling spends nothing below the horizon
    std::optional<Environment> hidden;
    if (ground.on && settings.environment)
        hidden = settings.environment->hidden_below_horizon();
    const Environment* env = hidden ? &*hidden : settings.environment.get();
    std::vector<Source> sources;
    Source unshadowed_ground;  // the ground's unshadowed irradiance, by light
    std::vector<RenderLight> lights = settings.view_lights ? make_lights(scene.lights) : std::vector<RenderLight>{};
    lights.insert(lights.end(), settings.lights.begin(), settings.lights.end());
    if (!bounds.empty())
        for (const RenderLight& l : lights) {
            if (l.kind == RenderLight::Kind::directional) {
                if (ground.on && !(l.toward_light.y > 0))
                    report.skipped_lights.push_back("directional light toward " + format_vec(d3(l.toward_light)) +
                                                    ": below the ground's horizon");
                else if (auto b = make_beam(l, extent)) {
                    for (int c = 0; c < 3; ++c)
                        unshadowed_ground.uniform[c] += b->colour[c] * b->to_light.y;
                    sources.push_back(std::move(*b));
                } else
                    report.skipped_lights.push_back("directional light toward " + format_vec(d3(l.toward_light)) +
                                                    ": below the horizon of the infinite canopy");
                continue;
            }
            const char* kind = l.kind == RenderLight::Kind::point ? "point" : "spot";
            const Vec3d p = d3(l.position);
            const bool outside = p.x < extent.lo.x || p.x > extent.hi.x || p.z < extent.lo.z || p.z > extent.hi.z;
            if (extent.canopy && outside) {
                report.skipped_lights.push_back(std::string(kind) + " light at " + format_vec(p) +
                                                ": outside the infinite canopy's tile");
                continue;
            }
            if (ground.on && !(p.y > ground.height)) {
                report.skipped_lights.push_back(std::string(kind) + " light at " + format_vec(p) +
                                                ": under the ground");
                continue;
            }
            Source s = make_point(l, extent);
            unshadowed_ground.points.push_back(l);
            char text[256];
            std::snprintf(text, sizeof text, "%s light at %s, intensity %g, attenuation 1/(%g + %g d + %g d^2)",
                          kind, format_vec(p).c_str(), mean(s.colour), l.att_constant, l.att_linear,
                          l.att_quadratic);
            s.text = text;
            sources.push_back(std::move(s));
        }
    if (env && !env->black() && !bounds.empty()) {
        Source s = make_environment_source(*env, extent, ground, settings.seed);
        unshadowed_ground.environment = true;
        s.text = env->kind() == Environment::Kind::sky   ? "sky and sun"
                 : env->kind() == Environment::Kind::map ? "environment map"
                                                          : "uniform environment";
        s.text += " (radiance L gives irradiance L to a surface under all of it)";
        sources.push_back(std::move(s));
    }
    if (ground.split && mean(ground.albedo) > 0 && !bounds.empty())
        sources.push_back(make_ground_source(std::move(unshadowed_ground), extent, ground, env, settings.seed));
    else if (ground.on) {
        char text[256];
        std::snprintf(text, sizeof text, "ground at height %g, albedo (%g, %g, %g)", ground.height,
                      ground.albedo[0], ground.albedo[1], ground.albedo[2]);
        report.lights.emplace_back(text);
    }
    report.ground = ground.on;
    report.ground_height = ground.height;
    report.ground_albedo = mean(ground.albedo);
    if (extent.canopy) {
        char text[256];
        std::snprintf(text, sizeof text, "infinite canopy: the tile x %g .. %g, z %g .. %g repeats sideways",
                      extent.lo.x, extent.hi.x, extent.lo.z, extent.hi.z);
        report.lights.emplace_back(text);
    }
    std::erase_if(sources, [](const Source& s) { return !(s.power > 0); });
    double total_power = 0;
    for (const Source& s : sources)
        total_power += s.power;
    std::vector<std::uint64_t> first{0};  // each source's first ray
    for (Source& s : sources) {
        const double n = std::max(1.0, std::round(double(settings.rays) * s.power / total_power));
        const double aspect = s.kind == Source::Kind::beam ? length(s.u) / length(s.v) : 1.0;
        s.nx = std::max<std::uint64_t>(1, std::llround(std::sqrt(n * aspect)));
        s.ny = std::max<std::uint64_t>(1, std::llround(n / double(s.nx)));
        first.push_back(first.back() + s.nx * s.ny);
        if (s.kind == Source::Kind::beam) {
            char text[256];
            std::snprintf(text, sizeof text, "directional toward %s, irradiance %g", format_vec(s.to_light).c_str(),
                          mean(s.colour));
            s.text = text;
        }
        s.text += ", " + std::to_string(s.nx) + " x " + std::to_string(s.ny) + " rays";
        report.lights.push_back(s.text);
    }
    report.rays = first.back();
    if (report.rays == 0) {
        report.organs = std::move(organs.list);
        return report;
    }

    Camera camera = make_camera(scene.view, scene.bounds.empty() ? bounds : scene.bounds, 512, 512);
    EmbreeScene accel(scene, camera);
    std::vector<SurfaceMaterial> materials = make_materials(scene.materials);
    Tracer tracer{scene, accel, organs, materials, settings, extent, ground};

    // Blocks take every blocks-th run of `run` neighbouring rays (strided), so each
    // samples the whole beam: their sums are independent batches for the confidence
    // intervals, and their number does not depend on the threads. A run's first rays
    // are traced as one stream (neighbours in a beam or about a point light: coherent),
    // which Embree takes in SIMD packets (benchmarks/light_report).
    const std::uint64_t run_length =
        std::clamp<std::uint64_t>(report.rays / 256, 1, EmbreeScene::max_coherent_rays);
    const std::uint64_t runs = (report.rays + run_length - 1) / run_length;
    const std::uint64_t blocks = std::min<std::uint64_t>(256, runs);
    std::vector<BlockResult> results(blocks);
    const std::size_t organ_count = organs.list.size();
    // Each thread's tallies by organ, zero between blocks (only the organs a block touched
    // are reset): a fresh vector a block cost a page fault per 4 KiB and cold loads
    // (benchmarks/light_report, --synthetic 10000).
    struct Scratch {
        std::vector<Tally> t;
        std::vector<std::uint32_t> touched;
    };
    tbb::enumerable_thread_specific<Scratch> scratch;
    auto run = [&] {
        tbb::parallel_for(std::uint64_t(0), blocks, [&](std::uint64_t k) {
            Scratch& own = scratch.local();
            if (own.t.size() != organ_count)
                own.t.assign(organ_count, Tally{});
            std::vector<Tally>& t = own.t;
            std::vector<std::uint32_t>& touched = own.touched;
            touched.clear();
            BlockResult& r = results[k];
            std::size_t source = 0;
            constexpr std::size_t most = EmbreeScene::max_coherent_rays;
            struct Ray {
                Emitted e;
                RayRandom rng;
                int slot;  ///< its place in the stream (-1: traced alone)
            };
            std::array<std::optional<Ray>, most> ray;
            std::array<LightRay, most> stream;
            std::array<LightHit, most> hits;
            for (std::uint64_t c = k; c < runs; c += blocks) {
                const std::uint64_t i0 = c * run_length, i1 = std::min(report.rays, i0 + run_length);
                std::size_t streamed = 0;
                for (std::uint64_t i = i0; i < i1; ++i) {
                    while (i >= first[source + 1])
                        ++source;
                    const Source& s = sources[source];
                    const std::uint64_t j = i - first[source];
                    RayRandom rng(settings.seed, source, j);
                    std::optional<Ray>& here = ray[i - i0];
                    here.reset();
                    if (std::optional<Emitted> e = emit(s, extent, ground, env, j, s.nx * s.ny, rng)) {
                        // the environment's and the ground's directions are random: no stream
                        const bool coherent = s.kind == Source::Kind::beam || s.kind == Source::Kind::point;
                        here = Ray{*e, rng, coherent ? int(streamed) : -1};
                        if (coherent)
                            stream[streamed++] = tracer.first_query(e->org, e->dir);
                    }
                }
                const std::uint32_t hit_bits =
                    accel.intersect_light(std::span(stream.data(), streamed), std::span(hits.data(), streamed));
                for (std::uint64_t i = i0; i < i1; ++i)
                    if (std::optional<Ray>& x = ray[i - i0]) {
                        std::optional<const LightHit*> known;
                        if (x->slot >= 0)
                            known = (hit_bits >> x->slot & 1) ? &hits[std::size_t(x->slot)] : nullptr;
                        tracer.trace(x->e.org, x->e.dir, x->e.w, x->e.falloff, x->e.from_ground, x->rng, t, touched,
                                     r, known);
                    }
            }
            std::sort(touched.begin(), touched.end());
            r.organs.reserve(touched.size());
            for (std::uint32_t o : touched) {
                r.organs.emplace_back(o, t[o]);
                t[o] = Tally{};
            }
        });
    };
    if (settings.threads > 0)
        tbb::task_arena(settings.threads).execute(run);
    else
        run();

    // In block order: the same sums whatever ran where.
    std::vector<double> square(organ_count, 0);
    for (const BlockResult& r : results) {
        report.emitted += r.emitted;
        report.absorbed += r.absorbed;
        report.unattributed += r.unattributed;
        report.escaped += r.escaped;
        report.escaped_down += r.escaped_down;
        report.truncated += r.truncated;
        report.ground_reached += r.ground_reached;
        report.ground_absorbed += r.ground_absorbed;
        report.ground_emitted += r.ground_emitted;
        for (const auto& [o, t] : r.organs) {
            OrganLight& organ = organs.list[o];
            organ.absorbed += t.absorbed;
            organ.incident_front += t.front;
            organ.incident_back += t.back;
            square[o] += t.absorbed * t.absorbed;
        }
    }
    const double nb = double(blocks);
    for (std::size_t o = 0; o < organ_count; ++o) {
        OrganLight& organ = organs.list[o];
        if (blocks > 1) {
            // the sum of nb batch sums: its variance is nb times the batches' variance
            const double spread = std::max(0.0, square[o] - organ.absorbed * organ.absorbed / nb);
            organ.absorbed_ci95 = 1.96 * std::sqrt(nb / (nb - 1) * spread);
        }
    }
    std::sort(organs.list.begin(), organs.list.end(), [](const OrganLight& a, const OrganLight& b) {
        return a.plant != b.plant ? a.plant < b.plant : a.module < b.module;
    });
    report.organs = std::move(organs.list);
    return report;
}

namespace {

std::string number(double v)
{
    char b[64];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}

std::string json_string(std::string_view s)
{
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char b[8];
            std::snprintf(b, sizeof b, "\\u%04x", c);
            out += b;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

std::string csv_field(std::string_view s)
{
    if (s.find_first_of(",\"\n") == std::string_view::npos)
        return std::string(s);
    std::string out = "\"";
    for (char c : s)
        out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

constexpr const char* irradiance_unit =
    "irradiance: a view-file directional light of colour (1,1,1) delivers 1 to a surface facing it";

double per_area(double flux, double area) { return area > 0 ? flux / area : 0; }

}  // namespace

void write_light_report(const LightReport& report, const std::filesystem::path& file)
{
    const std::string ext = file.extension().string();
    if (ext != ".json" && ext != ".csv")
        throw Error("--light-report " + file.string() + ": expected a .json or .csv file");
    std::string text;
    if (ext == ".json") {
        text += "{\n  \"units\": {\"area\": \"model units squared\", \"flux\": \"irradiance x area\", "
                "\"irradiance\": " + json_string(irradiance_unit) + "},\n";
        text += "  \"rays\": " + std::to_string(report.rays) + ",\n  \"lights\": [";
        for (std::size_t i = 0; i < report.lights.size(); ++i)
            text += (i ? ", " : "") + json_string(report.lights[i]);
        text += "],\n  \"skipped_lights\": [";
        for (std::size_t i = 0; i < report.skipped_lights.size(); ++i)
            text += (i ? ", " : "") + json_string(report.skipped_lights[i]);
        text += "],\n  \"emitted\": " + number(report.emitted) +
                ",\n  \"total_absorbed\": " + number(report.absorbed) +
                ",\n  \"unattributed_absorbed\": " + number(report.unattributed) +
                ",\n  \"escaped\": " + number(report.escaped) +
                ",\n  \"escaped_down\": " + number(report.escaped_down) +
                ",\n  \"truncated\": " + number(report.truncated);
        if (report.ground)
            text += ",\n  \"ground\": {\"height\": " + number(report.ground_height) +
                    ", \"albedo\": " + number(report.ground_albedo) +
                    ", \"reached\": " + number(report.ground_reached) +
                    ", \"absorbed\": " + number(report.ground_absorbed) +
                    ", \"emitted\": " + number(report.ground_emitted) + "}";
        text += ",\n  \"organs\": [";
        for (std::size_t i = 0; i < report.organs.size(); ++i) {
            const OrganLight& o = report.organs[i];
            text += i ? ",\n    " : "\n    ";
            text += "{\"module\": " + json_string(o.symbol) + ", \"index\": " + std::to_string(o.module) +
                    ", \"plant\": " + (o.plant == geom::Instance::no_plant ? "null" : std::to_string(o.plant)) +
                    ", \"age\": " + (o.age == geom::unknown_age ? "null" : std::to_string(o.age)) +
                    ", \"area\": " + number(o.area) + ", \"absorbed\": " + number(o.absorbed) +
                    ", \"absorbed_ci95\": " + number(o.absorbed_ci95) +
                    ", \"irradiance_front\": " + number(per_area(o.incident_front, o.area)) +
                    ", \"irradiance_back\": " + number(per_area(o.incident_back, o.area)) + "}";
        }
        text += report.organs.empty() ? "]\n}\n" : "\n  ]\n}\n";
    } else {
        text += std::string("# ") + irradiance_unit + "; area in model units squared; flux = irradiance x area\n";
        text += "# rays " + std::to_string(report.rays) + ", emitted " + number(report.emitted) +
                ", total_absorbed " + number(report.absorbed) + ", unattributed_absorbed " +
                number(report.unattributed) + ", escaped " + number(report.escaped) + ", escaped_down " +
                number(report.escaped_down) + ", truncated " + number(report.truncated);
        if (report.ground)
            text += ", ground_height " + number(report.ground_height) + ", ground_albedo " +
                    number(report.ground_albedo) + ", ground_reached " + number(report.ground_reached) +
                    ", ground_absorbed " + number(report.ground_absorbed) + ", ground_emitted " +
                    number(report.ground_emitted);
        text += "\n";
        text += "module,index,plant,age,area,absorbed,absorbed_ci95,irradiance_front,irradiance_back\n";
        for (const OrganLight& o : report.organs)
            text += csv_field(o.symbol) + "," + std::to_string(o.module) + "," +
                    (o.plant == geom::Instance::no_plant ? "" : std::to_string(o.plant)) + "," +
                    (o.age == geom::unknown_age ? "" : std::to_string(o.age)) + "," + number(o.area) + "," +
                    number(o.absorbed) + "," + number(o.absorbed_ci95) + "," +
                    number(per_area(o.incident_front, o.area)) + "," +
                    number(per_area(o.incident_back, o.area)) + "\n";
    }
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << text;
        out.close();
        if (!out)
            throw Error("cannot write " + file.string());
    });
}

}  // namespace cambium::render
