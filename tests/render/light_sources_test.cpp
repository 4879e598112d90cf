// SPDX-License-Identifier: Apache-2.0
// The light report's other lights against known answers: a uniform environment, the sky
// and its sun, point and spot lights as the renderer lights a surface, and the infinite
// canopy against Beer-Lambert's law.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "render/environment.h"
#include "render/light.h"
#include "render/light_report.h"

using namespace cambium;
using namespace cambium::render;

namespace {

using geom::Float3;
constexpr double pi = std::numbers::pi;
constexpr std::uint16_t black = 1;

geom::Scene dark_scene()
{
    geom::Scene scene;
    scene.materials[black].diffuse = {0, 0, 0};
    scene.geometry.modules.names = {"L"};
    return scene;
}

void add_triangle(geom::Scene& scene, std::uint32_t module, Float3 a, Float3 b, Float3 c)
{
    geom::TriangleMesh& m = scene.geometry.mesh;
    auto base = static_cast<std::uint32_t>(m.positions.size());
    for (const Float3& p : {a, b, c}) {
        m.positions.push_back(p);
        m.normals.push_back({0, 0, 0});
    }
    m.triangles.push_back({base, base + 1, base + 2});
    m.material.push_back(black);
    m.back_material.push_back(black);
    m.module.push_back(module);
}

/// A horizontal black w x d rectangle at height y, its front facing up, module 0.
void add_floor(geom::Scene& scene, double w, double d, float y = 0)
{
    const float x = float(w), z = float(d);
    add_triangle(scene, 0, {0, y, 0}, {0, y, z}, {x, y, z});
    add_triangle(scene, 0, {0, y, 0}, {x, y, z}, {x, y, 0});
    scene.geometry.modules.records.push_back({0, 0, 0});
}

LightReportSettings lit_by(std::shared_ptr<const Environment> env, std::uint64_t rays)
{
    LightReportSettings s;
    s.rays = rays;
    s.environment = std::move(env);
    return s;
}

}  // namespace

// A black 2 x 3 rectangle under a uniform environment of radiance L: each side gets the
// cosine-weighted irradiance, pi L in the renderer's units, L in the report's (where the
// renderer's pi is 1), so it absorbs 2 L area, within its confidence interval.
TEST(LightSources, UniformEnvironmentGivesItsRadianceOnEachSide)
{
    geom::Scene scene = dark_scene();
    add_floor(scene, 2, 3);
    const float L = 0.7f;
    LightReport r = trace_light(
        scene, lit_by(std::make_shared<Environment>(make_uniform_environment({L, L, L})), 400'000));
    ASSERT_EQ(r.organs.size(), 1u);
    const OrganLight& o = r.organs[0];
    RecordProperty("absorbed", std::to_string(o.absorbed));
    RecordProperty("ci95", std::to_string(o.absorbed_ci95));
    EXPECT_TRUE(r.skipped_lights.empty());
    EXPECT_NEAR(o.absorbed, 2 * L * 6, o.absorbed_ci95);
    EXPECT_LT(o.absorbed_ci95, 0.01 * 2 * L * 6);
    EXPECT_NEAR(o.incident_front, L * 6, 0.02 * L * 6);  // the upper side alone
    EXPECT_NEAR(r.absorbed + r.escaped + r.truncated, r.emitted, 1e-9 * r.emitted);
}

// An --env map bright above the horizon and black below, turned (a turn about +y changes
// nothing here): the rectangle's upper side gets the radiance, its lower side nothing.
TEST(LightSources, MapLightsTheUpperSideOnly)
{
    geom::Scene scene = dark_scene();
    add_floor(scene, 2, 3);
    // 8 x 2 texels: the top row (the upper hemisphere) radiance 0.5 in grey, 1.5 in red
    std::vector<float> rgb(8 * 2 * 3, 0.0f);
    for (int i = 0; i < 8; ++i)
        for (int c = 0; c < 3; ++c)
            rgb[3 * i + c] = i == 3 && c == 0 ? 1.5f : 0.5f;
    const double mean_up = (7 * 0.5 + (1.5 + 0.5 + 0.5) / 3) / 8;
    auto map = std::make_shared<Environment>(make_map_environment(8, 2, rgb).rotated(30));
    LightReport r = trace_light(scene, lit_by(map, 200'000));
    ASSERT_EQ(r.organs.size(), 1u);
    const OrganLight& o = r.organs[0];
    RecordProperty("absorbed", std::to_string(o.absorbed));
    RecordProperty("expected", std::to_string(6 * mean_up));
    EXPECT_NEAR(o.absorbed, 6 * mean_up, o.absorbed_ci95);
    EXPECT_LT(o.absorbed_ci95, 0.01 * 6 * mean_up);
    EXPECT_EQ(o.incident_back, 0);
}

// The sky with its sun at the zenith over a black rectangle: what it absorbs is the sky's
// radiance times |cos| integrated over the sphere (over pi), the sun's disk taken whole:
// the sun's stated irradiance (SkyEnvironment.SunDiskDeliversTheStatedIrradiance) plus
// the dome's and the ground's.
TEST(LightSources, SkyAndSunDeliverTheirIrradiance)
{
    SkyParameters p;
    p.sun_direction = {0, 1, 0};
    p.turbidity = 3;
    auto sky = std::make_shared<Environment>(make_sky_environment(p));
    const float cos_sun = std::cos(0.2665f * float(pi) / 180);
    const double sun_solid_angle = 2 * pi * (1 - double(cos_sun));
    auto mean = [](Vec3f c) { return (double(c.x) + c.y + c.z) / 3; };
    // the sun's own irradiance, and the rest by a fine midpoint rule outside its disk
    const double sun =
        (mean(sky->radiance({0, 1, 0})) - mean(sky->radiance(normalize({0.01f, 1, 0})))) *
        sun_solid_angle / pi;
    double rest_up = 0, rest_down = 0;
    const int nc = 2000, nphi = 256;
    for (int i = 0; i < nc; ++i)
        for (int j = 0; j < nphi; ++j) {
            const double c = -1 + 2 * (i + 0.5) / nc, phi = 2 * pi * (j + 0.5) / nphi;
            const double s = std::sqrt(1 - c * c);
            const Vec3f d{float(s * std::cos(phi)), float(c), float(s * std::sin(phi))};
            // inside the sun's disk the dome's radiance at its rim
            const Vec3f at = c > cos_sun ? normalize(Vec3f{0.01f, 1, 0}) : d;
            (c > 0 ? rest_up : rest_down) +=
                mean(sky->radiance(at)) * std::abs(c) * (2.0 / nc) * (2 * pi / nphi) / pi;
        }
    geom::Scene scene = dark_scene();
    add_floor(scene, 2, 3);
    LightReport r = trace_light(scene, lit_by(sky, 400'000));
    ASSERT_EQ(r.organs.size(), 1u);
    const OrganLight& o = r.organs[0];
    const double expected = 6 * (sun + rest_up + rest_down);
    RecordProperty("absorbed", std::to_string(o.absorbed));
    RecordProperty("expected", std::to_string(expected));
    RecordProperty("sun_share", std::to_string(sun / (sun + rest_up + rest_down)));
    EXPECT_GT(sun, 0.5 * (sun + rest_up + rest_down));  // the sun is most of it
    EXPECT_NEAR(o.absorbed, expected, o.absorbed_ci95);
    EXPECT_LT(o.absorbed_ci95, 0.01 * expected);
    EXPECT_NEAR(o.incident_front, 6 * (sun + rest_up), 0.01 * expected);
    // the sun's part of the upper side: its stated irradiance
    RecordProperty("sun_measured", std::to_string(o.incident_front / 6 - rest_up));
    RecordProperty("sun_stated", std::to_string(sun));
    EXPECT_NEAR(o.incident_front / 6 - rest_up, sun, 0.02 * sun);
}

// A black sphere of radius r at distance D from a point light whose fall-off is 1/d^2 and
// colour white absorbs the solid angle it subtends: 2 pi (1 - sqrt(1 - r^2/D^2)).
TEST(LightSources, PointLightOnASphere)
{
    geom::Scene scene = dark_scene();
    scene.geometry.spheres.centres.push_back({1, 2, 3, 0.5f});
    scene.geometry.spheres.material.push_back(black);
    scene.geometry.spheres.texture.push_back(-1);
    scene.geometry.spheres.module.push_back(0);
    scene.geometry.modules.records.push_back({0, 0, 0});
    geom::Light light;
    light.kind = geom::Light::Kind::point;
    light.position = {1, 2, 3 + 2};  // D = 2
    light.attenuation_constant = 0;
    light.attenuation_quadratic = 1;
    scene.lights = {light};
    LightReportSettings s;
    s.rays = 200'000;
    LightReport r = trace_light(scene, s);
    ASSERT_EQ(r.organs.size(), 1u);
    EXPECT_TRUE(r.skipped_lights.empty());
    const double expected = 2 * pi * (1 - std::sqrt(1 - 0.25 / 4));
    RecordProperty("absorbed", std::to_string(r.organs[0].absorbed));
    RecordProperty("expected", std::to_string(expected));
    EXPECT_NEAR(r.organs[0].absorbed, expected, 2e-3 * expected);
}

// A spot light with an exponent, a cutoff and all three attenuation terms over a black
// square: the report's flux is the renderer's irradiance (sample_light) over pi,
// integrated over the square, within the confidence interval.
TEST(LightSources, SpotLightAgreesWithTheRenderer)
{
    geom::Scene scene = dark_scene();
    add_floor(scene, 2, 2);
    geom::Light light;
    light.kind = geom::Light::Kind::spot;
    light.position = {0.7f, 0.8f, 1.1f};
    light.spot_direction = {0.2f, -1, -0.1f};
    light.spot_exponent = 3;
    light.spot_cutoff_deg = 40;
    light.attenuation_constant = 0.5f;
    light.attenuation_linear = 0.3f;
    light.attenuation_quadratic = 0.8f;
    light.diffuse = {0.9f, 0.7f, 0.5f};
    scene.lights = {light};
    const RenderLight rl = make_lights(scene.lights).at(0);
    double expected = 0;
    const int n = 800;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const Vec3f p{2 * (i + 0.5f) / n, 0, 2 * (j + 0.5f) / n};
            const LightSample ls = sample_light(rl, p);
            const double e = (double(ls.irradiance.x) + ls.irradiance.y + ls.irradiance.z) / 3 / pi;
            expected += e * std::max(0.0f, ls.wi.y) * (4.0 / (double(n) * n));
        }
    LightReportSettings s;
    s.rays = 400'000;
    LightReport r = trace_light(scene, s);
    ASSERT_EQ(r.organs.size(), 1u);
    RecordProperty("absorbed", std::to_string(r.organs[0].absorbed));
    RecordProperty("expected", std::to_string(expected));
    EXPECT_NEAR(r.organs[0].absorbed, expected,
                std::max(r.organs[0].absorbed_ci95, 2e-3 * expected));
    EXPECT_LT(r.organs[0].absorbed_ci95, 0.01 * expected);
    EXPECT_TRUE(r.skipped_lights.empty());
}

namespace {

/// `count` black triangles of equal area at uniformly random places in the unit cube,
/// their normals uniform over the sphere; returns their total area over the area of
/// their x-z bounds (the leaf area index of the tile).
double random_canopy(geom::Scene& scene, int count, double leaf_area, std::uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    // an equilateral triangle of that area: circumradius R
    const double R = std::sqrt(4 * leaf_area / (3 * std::sqrt(3.0)));
    double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
    for (int k = 0; k < count; ++k) {
        const double cz = 2 * u(rng) - 1, phi = 2 * pi * u(rng);
        const double sz = std::sqrt(1 - cz * cz);
        const double n[3] = {sz * std::cos(phi), cz, sz * std::sin(phi)};
        const double other[3] = {std::abs(n[0]) < 0.9 ? 1.0 : 0.0, std::abs(n[0]) < 0.9 ? 0.0 : 1.0,
                                 0};
        double t[3] = {other[1] * n[2] - other[2] * n[1], other[2] * n[0] - other[0] * n[2],
                       other[0] * n[1] - other[1] * n[0]};
        const double tl = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        for (double& c : t) c /= tl;
        const double b[3] = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2],
                             n[0] * t[1] - n[1] * t[0]};
        const double centre[3] = {u(rng), u(rng), u(rng)}, turn = 2 * pi * u(rng);
        Float3 v[3];
        for (int i = 0; i < 3; ++i) {
            const double a = turn + 2 * pi * i / 3;
            for (int c = 0; c < 3; ++c)
                v[i][c] = float(centre[c] + R * (std::cos(a) * t[c] + std::sin(a) * b[c]));
            lo[0] = std::min(lo[0], double(v[i][0]));
            hi[0] = std::max(hi[0], double(v[i][0]));
            lo[1] = std::min(lo[1], double(v[i][2]));
            hi[1] = std::max(hi[1], double(v[i][2]));
        }
        add_triangle(scene, std::uint32_t(k), v[0], v[1], v[2]);
        scene.geometry.modules.records.push_back({std::uint32_t(k), 0, 0});
    }
    return count * leaf_area / ((hi[0] - lo[0]) * (hi[1] - lo[1]));
}

/// A white directional light at zenith angle theta (radians), half a radian round from +x.
geom::Light sun_at(double theta)
{
    const double azimuth = 0.5;
    geom::Light light;
    light.kind = geom::Light::Kind::directional;
    light.direction = {std::sin(theta) * std::cos(azimuth), std::cos(theta),
                       std::sin(theta) * std::sin(azimuth)};
    return light;
}

using Polygon = std::vector<std::array<double, 3>>;

/// The part of a convex polygon where coordinate `axis` lies in [lo, hi].
Polygon clip(const Polygon& polygon, int axis, double lo, double hi)
{
    Polygon out = polygon;
    for (const auto& [bound, sign] : {std::pair{lo, 1.0}, std::pair{hi, -1.0}}) {
        Polygon in = std::move(out);
        out.clear();
        for (std::size_t i = 0; i < in.size(); ++i) {
            const auto& a = in[i];
            const auto& b = in[(i + 1) % in.size()];
            const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
            if (da >= 0) out.push_back(a);
            if ((da < 0) != (db < 0)) {
                const double t = da / (da - db);
                out.push_back({a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]),
                               a[2] + t * (b[2] - a[2])});
            }
        }
    }
    return out;
}

/// `count` black triangles of equal area, uniformly placed and spherically oriented, in
/// a unit layer made periodic: a leaf crossing the unit square's side is cut there and
/// its outer piece moved in by one, so the leaf area density is the same everywhere in
/// the tile and the tile's leaf area index is count x leaf_area.
void periodic_canopy(geom::Scene& scene, int count, double leaf_area, std::uint32_t seed)
{
    geom::Scene loose = dark_scene();
    random_canopy(loose, count, leaf_area, seed);
    const auto& positions = loose.geometry.mesh.positions;
    for (int k = 0; k < count; ++k) {
        Polygon leaf;
        for (int i = 0; i < 3; ++i) {
            const Float3& p = positions[std::size_t(3 * k + i)];
            leaf.push_back({p[0], p[1], p[2]});
        }
        for (int cx = -1; cx <= 1; ++cx)
            for (int cz = -1; cz <= 1; ++cz) {
                Polygon piece = clip(clip(leaf, 0, cx, cx + 1), 2, cz, cz + 1);
                for (std::size_t i = 1; i + 1 < piece.size(); ++i) {
                    Float3 v[3];
                    for (int j = 0; j < 3; ++j) {
                        const auto& q = piece[j == 0 ? 0 : i + std::size_t(j) - 1];
                        v[j] = {float(q[0] - cx), float(q[1]), float(q[2] - cz)};
                    }
                    add_triangle(scene, std::uint32_t(k), v[0], v[1], v[2]);
                }
            }
        scene.geometry.modules.records.push_back({std::uint32_t(k), 0, 0});
    }
}

}  // namespace

// Beer-Lambert: through a canopy of small black leaves, randomly placed and spherically
// oriented (G = 0.5), of leaf area index LAI, a beam at zenith angle theta reaches the
// ground in the fraction exp(-G LAI / cos theta). With the canopy repeated sideways the
// tile matches it; alone, light slips in and out through its sides.
TEST(LightSources, InfiniteCanopyFollowsBeerLambert)
{
    geom::Scene scene = dark_scene();
    const double lai = random_canopy(scene, 6000, 2.0 / 6000, 11);
    const double theta = 60 * pi / 180;
    scene.lights = {sun_at(theta)};
    LightReportSettings s;
    s.rays = 200'000;
    s.infinite_canopy = true;
    const LightReport stand = trace_light(scene, s);
    s.infinite_canopy = false;
    const LightReport alone = trace_light(scene, s);
    const double expected = std::exp(-0.5 * lai / std::cos(theta));
    const double with = stand.escaped_down / stand.emitted,
                 without = alone.escaped_down / alone.emitted;
    RecordProperty("lai", std::to_string(lai));
    RecordProperty("expected", std::to_string(expected));
    RecordProperty("canopy", std::to_string(with));
    RecordProperty("alone", std::to_string(without));
    EXPECT_NEAR(with, expected, 0.06 * expected);
    EXPECT_GT(without, 2 * expected);
    EXPECT_NEAR(stand.absorbed + stand.escaped + stand.truncated, stand.emitted,
                1e-9 * stand.emitted);
}

// The same law across leaf area indices 1 to 5, on what a periodic canopy intercepts:
// 1 - exp(-G LAI / cos theta) within 1%, from the zenith and at 60 degrees. Many small
// leaves keep one canopy's own randomness (the union of their shadows) well inside that.
TEST(LightSources, InfiniteCanopyInterceptsAsBeerLambertForLai1To5)
{
    const int count = 40'000;
    for (const double theta : {0.0, pi / 3})
        for (int lai = 1; lai <= 5; ++lai) {
            geom::Scene scene = dark_scene();
            periodic_canopy(scene, count, double(lai) / count, std::uint32_t(20 + lai));
            scene.lights = {sun_at(theta)};
            LightReportSettings s;
            s.rays = 400'000;
            s.infinite_canopy = true;
            const LightReport r = trace_light(scene, s);
            const double expected = 1 - std::exp(-0.5 * lai / std::cos(theta));
            EXPECT_NEAR(r.absorbed / r.emitted, expected, 0.01 * expected)
                << "LAI " << lai << ", zenith angle " << theta;
        }
}

// A stated tile twice as wide as the leaves' bounds: half of it bare. A beam whose
// horizontal travel across the leaves' unit-high layer is one tile width spends the same
// share of its path among leaves wherever it enters, so Beer-Lambert holds with the leaf
// area index of the whole tile. A tile that does not hold the bounds is an error.
TEST(LightSources, CanopyTileSetsTheSpacing)
{
    geom::Scene scene = dark_scene();
    const int count = 3000;
    const double leaf_area = 2.0 / count;
    random_canopy(scene, count, leaf_area, 12);
    double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
    for (const Float3& q : scene.geometry.mesh.positions) {
        lo[0] = std::min(lo[0], double(q[0]));
        hi[0] = std::max(hi[0], double(q[0]));
        lo[1] = std::min(lo[1], double(q[2]));
        hi[1] = std::max(hi[1], double(q[2]));
    }
    const double period = 2 * (hi[0] - lo[0]);
    const double lai = count * leaf_area / (period * (hi[1] - lo[1]));
    geom::Light light;
    light.kind = geom::Light::Kind::directional;
    light.direction = {period, 1, 0};  // tan(zenith angle) = period / the layer's height
    scene.lights = {light};
    LightReportSettings s;
    s.rays = 200'000;
    s.canopy_tile = std::array<double, 4>{lo[0], lo[1], lo[0] + period, hi[1]};
    const LightReport r = trace_light(scene, s);
    const double expected = std::exp(-0.5 * lai * std::sqrt(1 + period * period));
    RecordProperty("expected", std::to_string(expected));
    RecordProperty("measured", std::to_string(r.escaped_down / r.emitted));
    EXPECT_NEAR(r.escaped_down / r.emitted, expected, 0.06 * expected);
    s.canopy_tile = std::array<double, 4>{lo[0] + 0.1, lo[1], lo[0] + period, hi[1]};
    EXPECT_THROW(trace_light(scene, s), cambium::Error);
}

// The sky, a point light and the canopy together: the same numbers, bit for bit, on one
// thread and on two.
TEST(LightSources, SameNumbersOnAnyThreads)
{
    geom::Scene scene = dark_scene();
    scene.materials[black].diffuse = {0.5f, 0.6f, 0.4f};  // scattering too
    scene.materials[black].translucency = 0.3f;
    random_canopy(scene, 300, 0.002, 4);
    geom::Light light;
    light.kind = geom::Light::Kind::point;
    light.position = {0.5f, 0.5f, 0.5f};
    scene.lights = {light};
    LightReportSettings s = lit_by(std::make_shared<Environment>(make_sky_environment()), 40'000);
    s.infinite_canopy = true;
    s.threads = 1;
    const LightReport one = trace_light(scene, s);
    s.threads = 2;
    const LightReport two = trace_light(scene, s);
    EXPECT_EQ(one.lights.size(), 3u);  // the canopy's tile, the point light, the sky
    EXPECT_TRUE(one.skipped_lights.empty());
    EXPECT_GT(one.absorbed, 0);
    EXPECT_EQ(one.absorbed, two.absorbed);
    EXPECT_EQ(one.escaped_down, two.escaped_down);
    ASSERT_EQ(one.organs.size(), two.organs.size());
    for (std::size_t i = 0; i < one.organs.size(); ++i)
        EXPECT_EQ(one.organs[i].absorbed, two.organs[i].absorbed);
}
