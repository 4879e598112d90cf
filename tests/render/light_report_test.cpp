// SPDX-License-Identifier: Apache-2.0
// Tests of the light report against cases with known answers: a leaf facing the light,
// the union of many leaves' shadows, energy closure, and the same numbers on any threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "base/diagnostics.h"
#include "render/light_report.h"

using namespace cambium;
using namespace cambium::render;

namespace {

using geom::Float3;

constexpr std::uint16_t black = 1, grey = 2;

geom::Scene empty_scene(geom::Vec3 to_light)
{
    geom::Scene scene;
    scene.materials[black].diffuse = {0, 0, 0};
    scene.materials[grey].diffuse = {0.6f, 0.6f, 0.6f};
    scene.materials[grey].translucency = 0.3f;
    geom::Light light;
    light.kind = geom::Light::Kind::directional;
    light.direction = to_light;
    scene.lights = {light};
    scene.geometry.modules.names = {"L"};
    return scene;
}

/// A quad a, b, c, d (two triangles) drawn by module `module`.
void add_quad(geom::Scene& scene, std::uint32_t module, Float3 a, Float3 b, Float3 c, Float3 d,
              std::uint16_t material)
{
    geom::TriangleMesh& m = scene.geometry.mesh;
    auto base = static_cast<std::uint32_t>(m.positions.size());
    for (const Float3& p : {a, b, c, d}) {
        m.positions.push_back(p);
        m.normals.push_back({0, 0, 0});
    }
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
    for (int k = 0; k < 2; ++k) {
        m.material.push_back(material);
        m.back_material.push_back(material);
        m.module.push_back(module);
    }
    scene.geometry.modules.records.push_back({module, 0, 3});
}

Float3 add(Float3 a, Float3 b, double s = 1)
{
    return {float(a[0] + s * b[0]), float(a[1] + s * b[1]), float(a[2] + s * b[2])};
}

LightReportSettings rays(std::uint64_t n, int threads = 0)
{
    LightReportSettings s;
    s.rays = n;
    s.threads = threads;
    return s;
}

}  // namespace

// A black leaf of area 6 facing a directional light of the default white colour, tilted
// off every axis: it absorbs 6, all on its front, irradiance 1.
TEST(LightReport, BlackLeafFacingTheLightAbsorbsItsArea)
{
    const geom::Vec3 n = geom::normalize(geom::Vec3{1, 2, 0.5});
    geom::Scene scene = empty_scene(n);
    // an orthonormal pair across n: the leaf is 2 x 3
    const geom::Vec3 e1 = geom::normalize(geom::Vec3{2, -1, 0});
    const geom::Vec3 e2 = geom::Vec3{n.y * e1.z - n.z * e1.y, n.z * e1.x - n.x * e1.z, n.x * e1.y - n.y * e1.x};
    const Float3 o{0.3f, -0.2f, 0.1f};
    const Float3 u{float(2 * e1.x), float(2 * e1.y), float(2 * e1.z)};
    const Float3 v{float(3 * e2.x), float(3 * e2.y), float(3 * e2.z)};
    add_quad(scene, 4, o, add(o, u), add(add(o, u), v), add(o, v), black);
    LightReport r = trace_light(scene, rays(200'000));
    ASSERT_EQ(r.organs.size(), 1u);
    const OrganLight& leaf = r.organs[0];
    EXPECT_EQ(leaf.module, 4u);
    EXPECT_EQ(leaf.symbol, "L");
    EXPECT_EQ(leaf.age, 3);
    EXPECT_NEAR(leaf.area, 6, 1e-5);
    RecordProperty("absorbed", std::to_string(leaf.absorbed));
    EXPECT_NEAR(leaf.absorbed, 6, 6e-3);  // 0.1%
    EXPECT_NEAR(leaf.incident_front + leaf.incident_back, 6, 6e-3);
    EXPECT_NEAR(r.absorbed, r.emitted - r.escaped, 1e-9 * r.emitted);
    EXPECT_GT(leaf.absorbed_ci95, 0);
    EXPECT_LT(leaf.absorbed_ci95, 0.05);
}

// Many small black horizontal leaves at random heights under a vertical light absorb the
// area of the union of their projections. Corners on a 1/500 grid make a raster of that
// pitch exact.
TEST(LightReport, RandomLeavesAbsorbTheUnionOfTheirShadows)
{
    geom::Scene scene = empty_scene({0, 1, 0});
    constexpr int pitch = 500, side = 40;  // leaves 0.08 wide
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> cell(0, pitch - side);
    std::uniform_real_distribution<float> height(0, 1);
    std::vector<char> covered(pitch * pitch, 0);
    for (std::uint32_t k = 0; k < 150; ++k) {
        const int x = cell(rng), z = cell(rng);
        const float y = height(rng);
        const float x0 = float(x) / pitch, z0 = float(z) / pitch, s = float(side) / pitch;
        add_quad(scene, k, {x0, y, z0}, {x0, y, z0 + s}, {x0 + s, y, z0 + s}, {x0 + s, y, z0}, black);
        for (int i = x; i < x + side; ++i)
            for (int j = z; j < z + side; ++j)
                covered[i * pitch + j] = 1;
    }
    double union_area = 0;
    for (char c : covered)
        union_area += c;
    union_area /= double(pitch) * pitch;
    LightReport r = trace_light(scene, rays(1'000'000));
    double sum = 0;
    for (const OrganLight& o : r.organs)
        sum += o.absorbed;
    RecordProperty("absorbed", std::to_string(r.absorbed));
    RecordProperty("union", std::to_string(union_area));
    EXPECT_NEAR(r.absorbed, union_area, 2e-3 * union_area);
    EXPECT_NEAR(sum, r.absorbed, 1e-9);
    EXPECT_LT(union_area, 150 * 0.08 * 0.08);  // they do overlap
}

// Grey translucent leaves: what is absorbed, escapes or is cut short is what the light
// emitted, to 1e-6; each organ's share adds up to the total.
TEST(LightReport, EnergyCloses)
{
    geom::Scene scene = empty_scene(geom::normalize(geom::Vec3{0.3, 1, 0.2}));
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> at(0, 1);
    for (std::uint32_t k = 0; k < 200; ++k) {
        const Float3 o{at(rng), at(rng), at(rng)};
        const Float3 u{0.1f * at(rng), 0.1f * at(rng) - 0.05f, 0.1f * at(rng)};
        const Float3 v{0.1f * at(rng) - 0.05f, 0.1f * at(rng), 0.05f - 0.1f * at(rng)};
        add_quad(scene, 2 * k, o, add(o, u), add(add(o, u), v), add(o, v), grey);
    }
    LightReport r = trace_light(scene, rays(200'000));
    char closure[64];
    std::snprintf(closure, sizeof closure, "%.3g", (r.absorbed + r.escaped + r.truncated) / r.emitted - 1);
    RecordProperty("relative_closure_error", closure);
    EXPECT_NEAR(r.absorbed + r.escaped + r.truncated, r.emitted, 1e-6 * r.emitted);
    EXPECT_GT(r.absorbed, 0);
    EXPECT_GT(r.escaped, 0);
    double sum = 0, back = 0;
    for (const OrganLight& o : r.organs) {
        sum += o.absorbed;
        back += o.incident_back;
    }
    EXPECT_NEAR(sum + r.unattributed, r.absorbed, 1e-9 * r.absorbed);
    EXPECT_GT(back, 0);  // light through the leaves reaches their undersides
}

// The same report, bit for bit, on one thread and on two.
TEST(LightReport, SameNumbersOnAnyThreads)
{
    geom::Scene scene = empty_scene(geom::normalize(geom::Vec3{0.3, 1, 0.2}));
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> at(0, 1);
    for (std::uint32_t k = 0; k < 100; ++k) {
        const Float3 o{at(rng), at(rng), at(rng)};
        add_quad(scene, k, o, add(o, {0.1f, 0, 0}), add(o, {0.1f, 0.02f, 0.1f}), add(o, {0, 0.02f, 0.1f}), grey);
    }
    LightReport one = trace_light(scene, rays(50'000, 1));
    LightReport two = trace_light(scene, rays(50'000, 2));
    ASSERT_EQ(one.organs.size(), two.organs.size());
    EXPECT_EQ(one.absorbed, two.absorbed);
    EXPECT_EQ(one.escaped, two.escaped);
    for (std::size_t i = 0; i < one.organs.size(); ++i) {
        EXPECT_EQ(one.organs[i].absorbed, two.organs[i].absorbed);
        EXPECT_EQ(one.organs[i].absorbed_ci95, two.organs[i].absorbed_ci95);
        EXPECT_EQ(one.organs[i].incident_back, two.organs[i].incident_back);
    }
    // and another seed gives other numbers (the streams are seeded)
    LightReportSettings other = rays(50'000, 2);
    other.seed = 1;
    EXPECT_NE(trace_light(scene, other).absorbed, one.absorbed);
}

// An instance's primitives are its module's organ, its area as placed (scaled by 2).
TEST(LightReport, InstancesAreTheirModulesOrgans)
{
    geom::Scene scene = empty_scene({0, 1, 0});
    geom::Prototype leaf;
    geom::TriangleMesh& m = leaf.geometry.mesh;
    m.positions = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}};
    m.normals.assign(4, {0, 0, 0});
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    m.material = {black, black};
    m.back_material = {black, black};
    scene.prototypes.push_back(leaf);
    geom::Instance in;
    in.transform = {2, 0, 0, 0, 2, 0, 0, 0, 2, 5, 0, 0};
    in.module = 9;
    in.material = black;
    in.back_material = black;
    scene.instances.push_back(in);
    in.transform = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    in.module = 12;
    scene.instances.push_back(in);
    scene.geometry.modules.records = {{9, 0, 1}, {12, 0, 2}};
    LightReport r = trace_light(scene, rays(100'000));
    ASSERT_EQ(r.organs.size(), 2u);
    EXPECT_EQ(r.organs[0].module, 9u);
    EXPECT_NEAR(r.organs[0].area, 4, 1e-6);
    EXPECT_NEAR(r.organs[0].absorbed, 4, 0.012);
    EXPECT_EQ(r.organs[1].module, 12u);
    EXPECT_EQ(r.organs[1].age, 2);
    EXPECT_NEAR(r.organs[1].absorbed, 1, 0.005);
}

// The files: JSON with total_absorbed and organs[].absorbed, CSV with a header; another
// extension is refused and leaves nothing.
TEST(LightReport, WritesJsonAndCsv)
{
    geom::Scene scene = empty_scene({0, 1, 0});
    add_quad(scene, 3, {0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}, black);
    LightReport r = trace_light(scene, rays(10'000));
    auto dir = std::filesystem::temp_directory_path() / ("cambium_light_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    write_light_report(r, dir / "r.json");
    write_light_report(r, dir / "r.csv");
    auto read = [](const std::filesystem::path& f) {
        std::ifstream in(f);
        std::stringstream s;
        s << in.rdbuf();
        return s.str();
    };
    const std::string json = read(dir / "r.json");
    EXPECT_NE(json.find("\"total_absorbed\": "), std::string::npos) << json;
    EXPECT_NE(json.find("\"organs\": ["), std::string::npos);
    EXPECT_NE(json.find("{\"module\": \"L\", \"index\": 3, \"plant\": null, \"age\": 3"), std::string::npos) << json;
    EXPECT_NE(json.find("\"absorbed\": "), std::string::npos);
    EXPECT_NE(json.find("\"units\""), std::string::npos);
    const std::string csv = read(dir / "r.csv");
    EXPECT_NE(csv.find("module,index,plant,age,area,absorbed,absorbed_ci95,irradiance_front,irradiance_back\nL,3,,3,1,"),
              std::string::npos)
        << csv;
    EXPECT_THROW(write_light_report(r, dir / "r.txt"), Error);
    EXPECT_FALSE(std::filesystem::exists(dir / "r.txt"));
    std::filesystem::remove_all(dir);
}
