// SPDX-License-Identifier: Apache-2.0
#include "render/light_report.h"

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

const std::vector<std::uint32_t>& modules_of(const geom::Geometry& g, PrimitiveKind k)
{
    switch (k) {
    case PrimitiveKind::lines: return g.lines.module;
    case PrimitiveKind::curves: return g.curves.module;
    case PrimitiveKind::spheres: return g.spheres.module;
    case PrimitiveKind::discs: return g.discs.module;
    default: return g.mesh.module;
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

    std::uint32_t of(const geom::Scene& scene, const SurfaceHit& hit) const
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
    const std::array<std::size_t, 5> counts{g.lines.segment_count(), g.curves.segment_count(),
                                            g.spheres.size(), g.discs.size(), g.mesh.size()};
    for (std::size_t k = 0; k < 5; ++k) {
        const auto& m = modules_of(g, static_cast<PrimitiveKind>(k));
        o.own[k].assign(counts[k], no_organ);
        if (m.size() == counts[k])
            for (std::size_t i = 0; i < counts[k]; ++i)
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

/// A directional light's parallel rays: from a rectangle beyond the scene, across the
/// scene's projection onto it.
struct Beam {
    Vec3d to_light, u, v, corner;  ///< corner: the rectangle's origin, beyond the scene
    double width = 0, height = 0;
    Rgb3 colour{};
    std::uint64_t nx = 0, ny = 0;
    double power() const { return mean(colour) * width * height; }
};

std::optional<Beam> make_beam(const geom::Light& light, const geom::Bounds3& b)
{
    Vec3d d{light.direction.x, light.direction.y, light.direction.z};
    if (!(length(d) > 0))
        return std::nullopt;
    Beam beam;
    beam.to_light = unit(d);
    Vec3d other = std::abs(beam.to_light.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    beam.u = unit(cross(other, beam.to_light));
    beam.v = cross(beam.to_light, beam.u);
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int c = 0; c < 8; ++c) {
        Vec3d p{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z};
        double q[3] = {dot(p, beam.u), dot(p, beam.v), dot(p, beam.to_light)};
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
    beam.width = hi[0] - lo[0];
    beam.height = hi[1] - lo[1];
    beam.corner = beam.u * lo[0] + beam.v * lo[1] + beam.to_light * (hi[2] + margin);
    beam.colour = {light.diffuse.r, light.diffuse.g, light.diffuse.b};
    return beam;
}

struct Tally {
    double absorbed = 0, front = 0, back = 0;
};

/// A block's tallies, by organ (sorted), and its totals.
struct BlockResult {
    std::vector<std::pair<std::uint32_t, Tally>> organs;
    double absorbed = 0, unattributed = 0, escaped = 0, truncated = 0, emitted = 0;
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

struct Tracer {
    const geom::Scene& scene;
    const EmbreeScene& accel;
    const Organs& organs;
    const std::vector<SurfaceMaterial>& materials;
    const LightReportSettings& settings;

    /// One path: `w` its power per channel; tallies into `t` (by organ, dense) and `r`.
    void trace(Vec3d org, Vec3d dir, Rgb3 w, RayRandom& rng, std::vector<Tally>& t,
               std::vector<std::uint32_t>& touched, BlockResult& r) const
    {
        const double start = mean(w);
        PrimId skip{};
        for (int bounce = 0;; ++bounce) {
            if (bounce >= settings.max_bounces || mean(w) < settings.cutoff * start) {
                r.truncated += mean(w);
                return;
            }
            std::optional<SurfaceHit> hit =
                accel.intersect(f3(org), f3(dir), 0, std::numeric_limits<float>::infinity(), skip);
            if (!hit) {
                r.escaped += mean(w);
                return;
            }
            const Vec3d p = d3(hit->position);
            const Vec3d n = d3(hit->geometric_normal);  // toward the incoming ray
            if (hit->unlit) {  // pixel-width lines have no area: light passes
                org = p;
                skip = hit->prim();
                continue;
            }
            SurfaceMaterial m = hit->material < materials.size() ? materials[hit->material] : SurfaceMaterial{};
            if (hit->material_blend > 0 && hit->end_material < materials.size())
                m = mix(m, materials[hit->end_material], hit->material_blend);
            if (m.opacity < 1 && rng.next() >= m.opacity) {  // passes straight through
                org = hit->closed() ? p : p - n * hit->spawn_offset;
                skip = hit->prim();
                continue;
            }
            const std::uint32_t organ = organs.of(scene, *hit);
            const Bsdf b = make_bsdf(m);
            Rgb3 keep{}, absorbed{};
            double transmitted = 0;
            const Vec3f refl = b.reflect + b.glossy, trans = b.transmit;
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
            if (!(kept > 0))
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
    std::vector<Beam> beams;
    for (const geom::Light& l : scene.lights) {
        if (l.kind != geom::Light::Kind::directional) {
            report.skipped_lights.push_back(std::string(l.kind == geom::Light::Kind::point ? "point" : "spot") +
                                            " light at " + format_vec({l.position.x, l.position.y, l.position.z}) +
                                            ": only directional lights are traced");
            continue;
        }
        if (bounds.empty())
            continue;
        if (auto b = make_beam(l, bounds); b && b->power() > 0)
            beams.push_back(*b);
    }
    double total_power = 0;
    for (const Beam& b : beams)
        total_power += b.power();
    std::vector<std::uint64_t> first{0};  // each beam's first ray
    for (Beam& b : beams) {
        const double n = std::max(1.0, std::round(double(settings.rays) * b.power() / total_power));
        b.nx = std::max<std::uint64_t>(1, std::llround(std::sqrt(n * b.width / b.height)));
        b.ny = std::max<std::uint64_t>(1, std::llround(n / double(b.nx)));
        first.push_back(first.back() + b.nx * b.ny);
        char text[256];
        std::snprintf(text, sizeof text, "directional toward %s, irradiance %g, %llu x %llu rays",
                      format_vec(b.to_light).c_str(), mean(b.colour), (unsigned long long)b.nx,
                      (unsigned long long)b.ny);
        report.lights.emplace_back(text);
    }
    report.rays = first.back();
    if (report.rays == 0) {
        report.organs = std::move(organs.list);
        return report;
    }

    Camera camera = make_camera(scene.view, scene.bounds.empty() ? bounds : scene.bounds, 512, 512);
    EmbreeScene accel(scene, camera);
    std::vector<SurfaceMaterial> materials = make_materials(scene.materials);
    Tracer tracer{scene, accel, organs, materials, settings};

    // Blocks take every blocks-th ray (strided), so each samples the whole beam: their
    // sums are independent batches for the confidence intervals, and their number does
    // not depend on the threads.
    const std::uint64_t blocks = std::min<std::uint64_t>(256, report.rays);
    std::vector<BlockResult> results(blocks);
    const std::size_t organ_count = organs.list.size();
    auto run = [&] {
        tbb::parallel_for(std::uint64_t(0), blocks, [&](std::uint64_t k) {
            std::vector<Tally> t(organ_count);
            std::vector<std::uint32_t> touched;
            BlockResult& r = results[k];
            std::size_t beam = 0;
            for (std::uint64_t i = k; i < report.rays; i += blocks) {
                while (i >= first[beam + 1])
                    ++beam;
                const Beam& b = beams[beam];
                const std::uint64_t j = i - first[beam];
                RayRandom rng(settings.seed, beam, j);
                const double x = (double(j % b.nx) + rng.next()) / double(b.nx);
                const double y = (double(j / b.nx) + rng.next()) / double(b.ny);
                const Vec3d org = b.corner + b.u * (x * b.width) + b.v * (y * b.height);
                const double flux = b.width * b.height / double(b.nx * b.ny);
                const Rgb3 w{b.colour[0] * flux, b.colour[1] * flux, b.colour[2] * flux};
                r.emitted += mean(w);
                tracer.trace(org, b.to_light * -1.0, w, rng, t, touched, r);
            }
            std::sort(touched.begin(), touched.end());
            r.organs.reserve(touched.size());
            for (std::uint32_t o : touched)
                r.organs.emplace_back(o, t[o]);
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
        report.truncated += r.truncated;
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
                ",\n  \"truncated\": " + number(report.truncated) + ",\n  \"organs\": [";
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
                number(report.unattributed) + ", escaped " + number(report.escaped) + ", truncated " +
                number(report.truncated) + "\n";
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
