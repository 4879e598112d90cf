// SPDX-License-Identifier: Apache-2.0
// Scene files (docs/scenes.md): reading good and bad files, placements, plants derived
// once, palettes kept apart, and instanced plants rendering as the same plants drawn
// inline.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <set>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "app/scene_assembly.h"
#include "app/scene_file.h"
#include "base/diagnostics.h"
#include "geom/scene_limits.h"
#include "render/camera.h"
#include "render/light_report.h"
#include "render/render.h"

using namespace cambium;
namespace fs = std::filesystem;

namespace {

/// A scratch folder holding a scene and its models; removed at the end of the test.
class SceneFolder {
public:
    explicit SceneFolder(const std::string& name)
        : m_dir(fs::temp_directory_path() /
                ("cambium_scene_" + name + "_" + std::to_string(::getpid())))
    {
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    ~SceneFolder() { fs::remove_all(m_dir); }

    const fs::path& dir() const { return m_dir; }

    void write(const fs::path& file, const std::string& text) const
    {
        fs::create_directories((m_dir / file).parent_path());
        std::ofstream(m_dir / file, std::ios::binary) << text;
    }

    /// A small plant whose flowers K are -o> objects: a stem of `nodes` internodes.
    void tiny_model(const fs::path& folder, const std::string& arrow = "-o>") const
    {
        write(folder / "p.l", "lsystem: 1\nderivation length: 3\naxiom: A\n"
                              "A --> F(1)[+(40)K]/(137)A\n"
                              "homomorphism\n"
                              "K " + arrow + " F(0.5)[;(2)@O(0.3)][&(30)F(0.3)]\n"
                              "endlsystem\n");
        write(folder / "p.v", "angle factor: 8\ninitial line width: 0.15\nline style: cylinder\n");
    }

    fs::path scene(const std::string& text, const std::string& name = "field.json") const
    {
        write(name, text);
        return m_dir / name;
    }

private:
    fs::path m_dir;
};

/// The message read_scene_file throws for `text`, or "" when it reads.
std::string error_of(const SceneFolder& folder, const std::string& text)
{
    try {
        app::read_scene_file(folder.scene(text), app::Options{});
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

/// A scene's text and a part of the message it must give.
struct ErrorCase {
    std::string text, message;
};

/// Each case's scene gives an error holding its message.
void expect_errors(const SceneFolder& folder, const std::vector<ErrorCase>& cases)
{
    for (const ErrorCase& c : cases) {
        std::string message = error_of(folder, c.text);
        EXPECT_NE(message.find(c.message), std::string::npos)
            << "scene: " << c.text.substr(0, 300) << "\nexpected: " << c.message
            << "\ngot: " << message;
    }
}

const char* tiny_plant = R"("model": "m", "command": "cpfg p.l p.v")";

std::string with_plant(const std::string& plant_rest, const std::string& rest = "")
{
    return std::string(R"({"plants": [{)") + tiny_plant + ", " + plant_rest + "}]" + rest + "}";
}

double distance_xz(const app::Transform& a, const app::Transform& b)
{
    return std::hypot(a[9] - b[9], a[11] - b[11]);
}

double mean_difference(const render::Image& a, const render::Image& b)
{
    double d = 0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i)
        d += std::fabs(a.rgba[i] - b.rgba[i]);
    return d / static_cast<double>(a.rgba.size());
}

}  // namespace

TEST(SceneFile, ReadsPlantsPlacementsAndSettings)
{
    SceneFolder f("good");
    f.tiny_model("models/a");
    fs::path file = f.scene(R"({
      // comments are allowed
      "plants": [
        {"model": "models/a", "command": "cpfg -w 300 300 p.l p.v", "steps": [1, 2], "seed": 7,
         "placements": [{"translate": [1, 0, 2], "rotate_y_deg": 90, "scale": 2},
                        {"matrix": [1,0,0, 0,1,0, 0,0,1, 5,6,7]}]},
        {"model": "models/a", "command": "cpfg p.l p.v",
         "placements": {"scatter": {"rectangle": [0, 0, 10, 10], "count": 5, "seed": 3}}}
      ],
      "ground": {"size": [20, 30], "colour": "#ff8000"},
      "camera": {"eye": [0, 5, 20], "look_at": [0, 1, 0], "fov_deg": 30, "width": 320, "height": 200},
      "lights": [{"direction": [0, 1, 0], "intensity": 2}],
      "sky": {"sun": [0, 1, 1]},
      "render": {"spp": 3, "noise_target": 0.1, "filter": "gaussian"}
    })");
    app::SceneFile s = app::read_scene_file(file, app::Options{});
    ASSERT_EQ(s.plants.size(), 2u);
    const app::ScenePlant& a = s.plants[0];
    EXPECT_EQ(a.path, "plants[0]");
    EXPECT_EQ(a.model.lsystem, fs::weakly_canonical(f.dir() / "models/a/p.l"));
    EXPECT_EQ(a.model.view, fs::weakly_canonical(f.dir() / "models/a/p.v"));
    ASSERT_EQ(a.steps.size(), 2u);
    EXPECT_EQ(a.steps[0], 1);
    EXPECT_EQ(a.steps[1], 2);
    EXPECT_EQ(a.seed, 7);
    ASSERT_EQ(a.placements.size(), 2u);
    // scale 2, turned 90 degrees about +y: x goes to -z, z to +x; then moved
    const app::Transform& t = a.placements[0];
    EXPECT_NEAR(t[0], 0, 1e-6);
    EXPECT_NEAR(t[2], -2, 1e-6);
    EXPECT_NEAR(t[4], 2, 1e-6);
    EXPECT_NEAR(t[6], 2, 1e-6);
    EXPECT_NEAR(t[8], 0, 1e-6);
    EXPECT_EQ(t[9], 1);
    EXPECT_EQ(t[11], 2);
    EXPECT_EQ(a.placements[1][10], 6);
    EXPECT_EQ(s.plants[1].placements.size(), 5u);
    EXPECT_FALSE(s.plants[1].steps[0].has_value());  // the L-system's derivation length
    ASSERT_TRUE(s.ground && s.ground->size);
    EXPECT_EQ((*s.ground->size)[1], 30);
    EXPECT_FLOAT_EQ(s.ground->colour.g, 128 / 255.0f);
    ASSERT_TRUE(s.camera);
    EXPECT_EQ(s.camera->fov_deg, 30);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].kind, geom::Light::Kind::directional);
    EXPECT_GT(s.lights[0].diffuse.r, 1.0f);  // intensity 2
    ASSERT_TRUE(s.sky);

    // The command line wins where it speaks; the file fills in the rest.
    app::Options given = *app::parse_command_line({"--spp", "9", "x.json"});
    app::apply_scene_settings(s, given);
    EXPECT_EQ(given.samples_per_pixel, 9);
    EXPECT_EQ(given.width, 320);
    EXPECT_FLOAT_EQ(given.noise_target, 0.1f);
    EXPECT_EQ(given.filter, "gaussian");
    EXPECT_TRUE(given.sky);
    app::Options plain = *app::parse_command_line({"-w", "64", "48", "x.json"});
    app::apply_scene_settings(s, plain);
    EXPECT_EQ(plain.samples_per_pixel, 3);
    EXPECT_EQ(plain.width, 64);
    EXPECT_EQ(plain.height, 48);
}

TEST(SceneFile, ErrorsNameTheFileAndTheJsonPath)
{
    SceneFolder f("bad");
    f.tiny_model("m");
    expect_errors(f, {
        {R"({"plants": []})", "field.json: plants: must be a non-empty list"},
        {R"({"plant": []})", "field.json: plant: unknown key"},
        {with_plant(R"("placements": {"scatter": {"rectangle": [0,0,1,1], "count": 0}})"),
         "field.json: plants[0].placements.scatter.count: must be a positive integer"},
        {with_plant(R"("placements": {"scatter": {"rectangle": [0,0,1,1], "count": 2.5}})"),
         "field.json: plants[0].placements.scatter.count: must be a positive integer"},
        {with_plant(R"("placements": {"scatter": {"rectangle": [1,0,0,1], "count": 2}})"),
         "plants[0].placements.scatter.rectangle: must be [xmin, zmin, xmax, zmax]"},
        {with_plant(R"("placements": {"scatter": {"count": 2}})"),
         "plants[0].placements.scatter: give one of rectangle"},
        {with_plant(R"("stesp": 3, "placements": [])"), "plants[0].stesp: unknown key"},
        {with_plant(R"("steps": [], "placements": [])"), "plants[0].steps: must list 1 to 100"},
        {with_plant(R"("steps": [2, 2], "placements": [])"), "plants[0].steps[1]: repeats"},
        {with_plant(R"("steps": -1, "placements": [])"), "plants[0].steps: must be an integer"},
        {with_plant(R"("placements": [{}, {"matrix": [1,2,3]}])"),
         "plants[0].placements[1].matrix: must be 12 numbers"},
        {with_plant(R"("placements": [{"translate": [0, "x", 0]}])"),
         "plants[0].placements[0].translate[1]: must be a number"},
        {R"({"plants": [{"model": "../elsewhere", "command": "cpfg p.l p.v", "placements": []}]})",
         "plants[0].model: '../elsewhere' lies outside the folder"},
        {R"({"plants": [{"model": "/tmp", "command": "cpfg p.l p.v", "placements": []}]})",
         "plants[0].model: '/tmp' is an absolute path"},
        {R"({"plants": [{"model": "m", "command": "cpfg ../../p.l p.v", "placements": []}]})",
         "plants[0].command: '../../p.l' lies outside the folder"},
        {R"({"plants": [{"model": "m", "command": "cpfg -P sh p.l p.v", "placements": []}]})",
         "plants[0].command: option -P is not allowed in a scene"},
        {R"({"plants": [{"model": "m", "command": "cpfg -str out p.l p.v", "placements": []}]})",
         "plants[0].command: option -str is not allowed"},
        {R"({"plants": [{"model": "m", "command": "cpfg -m1 a.map -m1 b.map p.l p.v", "placements": []}]})",
         "plants[0].command: option -m1 is given twice"},
        {R"({"plants": [{"model": "m", "command": "cpfg -m a.map -m1 b.map p.l p.v", "placements": []}]})",
         "plants[0].command: option -m1 is given twice"},
        {R"({"plants": [{"model": "m", "command": "cpfg -e a.e -e b.e p.l p.v", "placements": []}]})",
         "plants[0].command: option -e is given twice"},
        {R"({"plants": [{"model": "m", "command": "cpfg -c2 -c3 p.l p.v", "placements": []}]})",
         "plants[0].command: option -c3 is given twice"},
        {R"({"plants": [{"model": "m", "command": "cpfg p.l p.v; rm x", "placements": []}]})",
         "plants[0].command: a cpfg command line of words only"},
        {R"({"plants": [{"model": "m", "command": "sh p.l p.v", "placements": []}]})",
         "plants[0].command: must start with 'cpfg'"},
        {R"({"plants": [{"model": "m", "command": "cpfg p.l", "placements": []}]})",
         "plants[0].command: files: At least 2 required"},
        {R"({"plants": [{"model": "nowhere", "command": "cpfg p.l p.v", "placements": []}]})",
         "plants[0].model: 'nowhere' is not a folder"},
        {R"({"plants": [{"model": "m", "command": "cpfg p.l p.v"}]})", "plants[0]: needs a placements"},
        {with_plant(R"("placements": [])", R"(, "camera": {"fov_deg": 0})"),
         "field.json: camera.fov_deg: must be a number from 0.01 to 179"},
        {with_plant(R"("placements": [])", R"(, "camera": {"projection": "fisheye"})"),
         "camera.projection: must be \"perspective\" or \"parallel\""},
        {with_plant(R"("placements": [])", R"(, "lights": [{"direction": [0, 0, 0]}])"),
         "lights[0].direction: must not be zero"},
        {with_plant(R"("placements": [])", R"(, "ground": {"size": [1, 1], "colour": "green"})"),
         "ground.colour: must be #rrggbb"},
        {with_plant(R"("placements": [])", R"(, "sky": {}, "environment": {"map": "x.exr"})"),
         "field.json: the document: give sky or environment, not both"},
        {with_plant(R"("placements": [])", R"(, "render": {"spp": 0})"),
         "render.spp: must be an integer from 1 to"},
        {with_plant(R"("placements": {"scatter": {"mesh": "none.obj", "count": 3}})"),
         "plants[0].placements.scatter.mesh: "},
    });
    // Syntax errors keep nlohmann's position as line and column.
    std::string syntax = error_of(f, "{\n  \"plants\": [\n    {\"model\": }\n  ]\n}\n");
    EXPECT_NE(syntax.find("field.json:3:15:"), std::string::npos) << syntax;
    // The total of placed plants is bounded before any is placed.
    app::SceneLimits small;
    small.max_instances = 10;
    try {
        app::read_scene_file(
            f.scene(with_plant(R"("placements": {"scatter": {"rectangle": [0,0,9,9], "count": 11}})")),
            app::Options{}, small);
        ADD_FAILURE() << "11 plants passed a limit of 10";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("plants[0].placements.scatter.count"), std::string::npos)
            << e.what();
    }
}

// What the JSON parser would accept silently, build without bound or report without a
// place is an error at file:line:column before it parses.
TEST(SceneFile, DuplicateKeysDeepNestingAndHugeNumbersAreErrorsWithPlaces)
{
    SceneFolder f("json");
    f.tiny_model("m");
    expect_errors(f, {
        // a reviewer reading the first "plants" would not see the folder the second names
        {"{\"plants\": [],\n \"plants\": []}",
         "field.json:2:2: error: the key \"plants\" appears twice in one object"},
        {R"({"plants": [], /* "plants": */ "pl\u0061nts": []})",
         "field.json:1:32: error: the key \"plants\" appears twice"},
        {with_plant(R"("placements": [{"scale": 1, "translate": [0, 0, 0], "scale": 2}])"),
         "field.json:1:107: error: the key \"scale\" appears twice"},
        {R"({"plants": [{"model": "m", "seed": 1e999}]})",
         "field.json:1:36: error: the number 1e999 is out of range"},
        {"{\"plants\": " + std::string(200000, '[') + std::string(200000, ']') + "}",
         "field.json:1:75: error: JSON nested more than 64 levels deep"},
    });
    // the same key in different objects, and in strings and comments, is no duplicate
    std::string fine = error_of(
        f, R"({"plants": [{"model": "m", "command": "cpfg p.l p.v", "placements": [{"scale": 1}, {"scale": 2}]}],
              // "plants": 
              "render": {"spp": 1}})");
    EXPECT_EQ(fine, "");
}

// A model folder that is a link to itself is an error at its JSON path.
TEST(SceneFile, SelfLinkedModelFolderNamesTheJsonPath)
{
    SceneFolder f("self_link");
    fs::create_directory_symlink("loop", f.dir() / "loop");
    std::string message =
        error_of(f, R"({"plants": [{"model": "loop", "command": "cpfg p.l p.v", "placements": [{}]}]})");
    EXPECT_NE(message.find("field.json: plants[0].model: 'loop'"), std::string::npos) << message;
}

TEST(SceneFile, FilesOutsideTheFolderNeedFileAccess)
{
    SceneFolder f("access");
    f.tiny_model("outside/m");
    f.write("inner/.keep", "");
    fs::path file = f.scene(
        R"({"plants": [{"model": "../outside/m", "command": "cpfg p.l p.v", "placements": [{}]}]})",
        "inner/field.json");
    EXPECT_THROW(app::read_scene_file(file, app::Options{}), Error);
    app::Options allowed;
    allowed.allow_file_access = true;
    EXPECT_EQ(app::read_scene_file(file, allowed).plants.size(), 1u);
}

TEST(Scatter, SameSeedSamePlacementsAndSpacingHolds)
{
    app::ScatterSpec spec;
    spec.rectangle = {-10, -5, 10, 5};
    spec.count = 100;
    spec.seed = 42;
    spec.min_spacing = 1.0;
    spec.rotate_y = true;
    spec.scale = {0.5, 1.5};
    std::vector<app::Transform> a = app::scatter(spec), b = app::scatter(spec);
    ASSERT_EQ(a.size(), 100u);
    EXPECT_EQ(a, b);
    spec.seed = 43;
    EXPECT_NE(app::scatter(spec), a);
    for (std::size_t i = 0; i < a.size(); ++i) {
        const app::Transform& t = a[i];
        EXPECT_GE(t[9], -10);
        EXPECT_LE(t[9], 10);
        EXPECT_GE(t[11], -5);
        EXPECT_LE(t[11], 5);
        EXPECT_EQ(t[10], 0);  // standing on the ground
        // a turn about +y times a uniform scale: y axis stays up, x axis horizontal
        EXPECT_EQ(t[3], 0);
        EXPECT_EQ(t[5], 0);
        EXPECT_EQ(t[1], 0);
        EXPECT_GE(t[4], 0.5f - 1e-6f);
        EXPECT_LE(t[4], 1.5f + 1e-6f);
        EXPECT_NEAR(std::hypot(t[0], t[2]), t[4], 1e-5);
        for (std::size_t j = 0; j < i; ++j)
            ASSERT_GE(distance_xz(t, a[j]), 1.0 - 1e-6) << i << " " << j;
    }
    // A full area gives fewer plants, still spaced (a 2 x 2 square holds few at 1.0).
    spec.rectangle = {0, 0, 2, 2};
    spec.count = 100;
    std::vector<app::Transform> crowded = app::scatter(spec);
    EXPECT_GT(crowded.size(), 3u);
    EXPECT_LT(crowded.size(), 20u);
    for (std::size_t i = 0; i < crowded.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            EXPECT_GE(distance_xz(crowded[i], crowded[j]), 1.0 - 1e-6);
}

// A spacing far below the area's size (cell indices past long long's range before)
// neither overflows nor puts every point in one cell (200 000 points, 2·10¹⁰ distance
// tests in one cell).
TEST(Scatter, TinySpacingOverAHugeRectangle)
{
    app::ScatterSpec spec;
    spec.rectangle = {-1e7, -1e7, 1e7, 1e7};
    spec.count = 200'000;
    spec.seed = 3;
    spec.min_spacing = 1e-300;
    EXPECT_EQ(app::scatter(spec).size(), 200'000u);
}

TEST(Scatter, OverAMeshPointsLieOnItsTriangles)
{
    SceneFolder f("mesh");
    // a slope: y = 0.5 x over x in [0, 4], z in [0, 2]; a quad written as one face
    f.write("slope.obj", "# a slope\nv 0 0 0\nv 4 2 0\nv 4 2 2\nv 0 0 2\nvn 0 1 0\nf 1//1 2//1 3//1 4//1\n");
    app::SceneLimits small;
    small.max_mesh_triangles = 100;
    app::GroundMesh mesh = app::read_obj_mesh(f.dir() / "slope.obj", small);
    ASSERT_EQ(mesh.triangles.size(), 2u);
    app::ScatterSpec spec;
    spec.mesh = f.dir() / "slope.obj";
    spec.count = 200;
    spec.seed = 5;
    std::vector<app::Transform> placed = app::scatter(spec, &mesh);
    ASSERT_EQ(placed.size(), 200u);
    double mean_x = 0;
    for (const app::Transform& t : placed) {
        EXPECT_NEAR(t[10], 0.5 * t[9], 1e-4);
        EXPECT_GE(t[11], -1e-6);
        EXPECT_LE(t[11], 2 + 1e-6);
        mean_x += t[9] / 200.0;
    }
    EXPECT_NEAR(mean_x, 2.0, 0.3);  // uniform over the area, not bunched on one triangle
    EXPECT_THROW(app::read_obj_mesh(f.dir() / "missing.obj", small), Error);
    f.write("bad.obj", "v 0 0 0\nf 1 2 3\n");
    EXPECT_THROW(app::read_obj_mesh(f.dir() / "bad.obj", small), Error);
}

/// The message of the error reading `file` as a mesh.
std::string mesh_error(const fs::path& file, const app::SceneLimits& limits)
{
    try {
        app::read_obj_mesh(file, limits);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

// A mesh is a regular file within its size and line limits, checked before reading:
// a FIFO would block forever, a huge file or line would be held whole.
TEST(Scatter, MeshFilesAreRegularAndBounded)
{
    SceneFolder f("mesh_bounds");
    ASSERT_EQ(::mkfifo((f.dir() / "fifo.obj").c_str(), 0600), 0);
    app::SceneLimits limits;
    EXPECT_NE(mesh_error(f.dir() / "fifo.obj", limits).find("not a regular file"),
              std::string::npos);
    EXPECT_NE(mesh_error(f.dir(), limits).find("not a regular file"), std::string::npos);
    std::string quad = "v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n";
    f.write("long.obj", quad + "# " + std::string(200, 'x') + "\n");
    limits.max_mesh_line_bytes = 100;
    EXPECT_NE(mesh_error(f.dir() / "long.obj", limits).find("long.obj:5:101: error: the line is longer than 100 bytes"),
              std::string::npos)
        << mesh_error(f.dir() / "long.obj", limits);
    limits.max_mesh_line_bytes = 202;  // the comment line just fits
    EXPECT_EQ(app::read_obj_mesh(f.dir() / "long.obj", limits).triangles.size(), 1u);
    limits.max_mesh_bytes = 20;
    EXPECT_NE(mesh_error(f.dir() / "long.obj", limits).find("too large"), std::string::npos);
}

TEST(SceneAssembly, EachDistinctVariantIsDerivedOnce)
{
    SceneFolder f("once");
    f.tiny_model("m");
    f.tiny_model("n");
    auto report_of = [&](const std::string& plants) {
        app::SceneFile s = app::read_scene_file(f.scene("{\"plants\": [" + plants + "]}"), app::Options{});
        app::AssemblyReport r;
        app::AssemblyOptions compose{app::OrganPlacement::compose, false};
        geom::Scene scene = app::assemble_scene(s, app::Options{}, compose, &r);
        return std::make_pair(r, scene.instances.size());
    };
    const std::string m = R"("model": "m", "command": "cpfg p.l p.v", )";
    const std::string three = R"("placements": [{}, {"translate": [2, 0, 0]}, {"translate": [4, 0, 0]}])";
    // two entries of one model and steps: one load, one derivation, six plants
    // (the second's command differs in spaces only)
    auto [r1, instances1] = report_of("{" + m + "\"steps\": 2, " + three + "}, {\"model\": \"m\", " +
                                      "\"command\": \"cpfg  p.l   p.v\", \"steps\": 2, " + three + "}");
    EXPECT_EQ(r1.models_loaded, 1u);
    EXPECT_EQ(r1.derivations, 1u);
    EXPECT_EQ(r1.plant_instances, 6u);
    // steps [1, 2] and [2]: two variants of one model, both from one derivation of two
    // steps; placements alternate variants
    auto [r2, instances2] = report_of("{" + m + "\"steps\": [1, 2], " + three + "}, {" + m +
                                      "\"steps\": 2, " + three + "}");
    EXPECT_EQ(r2.models_loaded, 1u);
    EXPECT_EQ(r2.derivations, 1u);
    EXPECT_EQ(r2.variants, 2u);
    EXPECT_EQ(r2.derivation_steps, 2u);
    // another model, or another seed, is another load
    auto [r3, instances3] = report_of("{" + m + three + "}, {" + m + "\"seed\": 3, " + three +
                                      "}, {\"model\": \"n\", \"command\": \"cpfg p.l p.v\", " +
                                      three + "}");
    EXPECT_EQ(r3.models_loaded, 3u);
    EXPECT_EQ(r3.derivations, 3u);
    EXPECT_EQ(r3.variants, 3u);
    EXPECT_EQ(r3.plant_instances, 9u);
    // each plant of 3 steps has 3 flowers (objects): composed, one instance each
    EXPECT_EQ(r3.organ_instances, 27u);
    EXPECT_EQ(instances3, 36u);
}

// Every instance names the placement it belongs to, counted over the file's plants in
// order: a plant's own instance and its flowers' alike (exports name plants by it).
TEST(SceneAssembly, EachInstanceNamesItsPlacement)
{
    SceneFolder f("placement_ids");
    f.tiny_model("m");
    const std::string m = R"("model": "m", "command": "cpfg p.l p.v", )";
    app::SceneFile s = app::read_scene_file(
        f.scene(std::string("{\"plants\": [{") + m + R"("placements": [{}, {"translate": [2, 0, 0]}]}, {)" + m +
                R"("seed": 3, "placements": [{"translate": [4, 0, 0]}]}]})"),
        app::Options{});
    geom::Scene scene = app::assemble_scene(s, app::Options{}, {app::OrganPlacement::compose, false});
    std::map<std::uint32_t, int> per_placement;
    for (const geom::Instance& i : scene.instances) {
        ASSERT_NE(i.plant, geom::Instance::no_plant);
        const float x = i.transform[9];
        // each placement's instances lie about its translation (flowers a little off it)
        EXPECT_NEAR(x, 2.0f * float(i.plant), 1.5f) << "placement " << i.plant;
        ++per_placement[i.plant];
    }
    EXPECT_EQ(per_placement.size(), 3u);
    EXPECT_EQ(per_placement[0], per_placement[1]);  // the same variant: the same instances
}

TEST(SceneAssembly, SeedOverrideChangesAStochasticPlantReproducibly)
{
    SceneFolder f("seed");
    // a stochastic L-system: each step, A grows straight or turns, chosen at random
    f.write("m/p.l", "lsystem: 1\nseed: 1\nderivation length: 12\naxiom: A\n"
                     "A --> F(1)A : 1\nA --> +(60)F(1)A : 1\nendlsystem\n");
    f.write("m/p.v", "angle factor: 8\ninitial line width: 0.1\nline style: cylinder\n");
    auto bounds_with = [&](const std::string& seed) {
        app::SceneFile s = app::read_scene_file(
            f.scene(R"({"plants": [{"model": "m", "command": "cpfg p.l p.v", )" + seed +
                    R"("placements": [{}]}]})"),
            app::Options{});
        geom::Scene scene = app::assemble_scene(s, app::Options{});
        return std::array<double, 4>{scene.bounds.lo.x, scene.bounds.hi.x, scene.bounds.lo.y,
                                     scene.bounds.hi.y};
    };
    auto plain = bounds_with(""), seven = bounds_with("\"seed\": 7, "),
         again = bounds_with("\"seed\": 7, ");
    EXPECT_EQ(seven, again);
    // among a few seeds, some plant differs from the unseeded one and from seed 7
    bool differs_from_plain = seven != plain, differs_from_seven = false;
    for (int s = 8; s < 12; ++s) {
        auto other = bounds_with("\"seed\": " + std::to_string(s) + ", ");
        differs_from_plain |= other != plain;
        differs_from_seven |= other != seven;
    }
    EXPECT_TRUE(differs_from_plain);
    EXPECT_TRUE(differs_from_seven);
}

TEST(SceneAssembly, PlantsKeepTheirOwnPalettes)
{
    SceneFolder f("palette");
    // two one-segment plants in colour 1 of colormaps that differ there
    for (const char* name : {"red", "blue"}) {
        f.write(std::string(name) + "/p.l", "lsystem: 1\nderivation length: 0\naxiom: ;(1)F(1)\nendlsystem\n");
        f.write(std::string(name) + "/p.v", std::string("initial line width: 0.1\nline style: cylinder\n") +
                                                (name[0] == 'r' ? "texture: F: bark.png\n" : ""));
        std::string map(768, '\0');
        map[3] = name[0] == 'r' ? char(255) : 0;
        map[5] = name[0] == 'b' ? char(255) : 0;
        f.write(std::string(name) + "/p.map", map);
    }
    app::SceneFile s = app::read_scene_file(f.scene(R"({"plants": [
        {"model": "red", "command": "cpfg -m p.map p.l p.v", "placements": [{}]},
        {"model": "blue", "command": "cpfg -m p.map p.l p.v", "placements": [{"translate": [3, 0, 0]}]}]})"),
                                            app::Options{});
    for (app::AssemblyOptions how : {app::AssemblyOptions{}, app::AssemblyOptions{app::OrganPlacement::compose, true}}) {
        geom::Scene scene = app::assemble_scene(s, app::Options{}, how);
        std::vector<geom::Rgb> colours;
        auto colour_of_segments = [&](const geom::Geometry& g) {
            for (std::uint16_t m : g.lines.material)
                colours.push_back(scene.materials.at(m).diffuse);
        };
        colour_of_segments(scene.geometry);
        for (const geom::Instance& i : scene.instances)
            colour_of_segments(scene.prototypes.at(i.prototype).geometry);
        ASSERT_EQ(colours.size(), 2u);
        EXPECT_EQ(colours[0], (geom::Rgb{1, 0, 0}));
        EXPECT_EQ(colours[1], (geom::Rgb{0, 0, 1}));
        // the red plant's texture is read from its own folder, wherever cambium runs
        ASSERT_EQ(scene.textures.size(), 1u);
        EXPECT_EQ(scene.textures[0].file, fs::weakly_canonical(f.dir() / "red") / "bark.png");
    }
}

TEST(SceneAssembly, CameraUpIsHonoured)
{
    SceneFolder f("camera");
    f.tiny_model("m");
    app::SceneFile s = app::read_scene_file(
        f.scene(with_plant(R"("placements": [{}])",
                           R"(, "camera": {"eye": [0, 2, 10], "look_at": [0, 2, 0], "up": [1, 1, 0]})")),
        app::Options{});
    geom::Scene scene = app::assemble_scene(s, app::Options{});
    render::Camera camera = render::make_camera(scene.view, scene.bounds, 64, 64);
    geom::Vec3 up = camera.up();
    EXPECT_NEAR(up.x, std::sqrt(0.5), 1e-6);
    EXPECT_NEAR(up.y, std::sqrt(0.5), 1e-6);
    EXPECT_NEAR(up.z, 0, 1e-6);
}

// Placements times the organs each one composes are counted against the memory budget
// before any instance is made (the scene file bounds the placements alone).
TEST(SceneAssembly, PlacementsTimesOrgansAreWithinTheMemoryBudget)
{
    SceneFolder f("organs_budget");
    f.tiny_model("m");
    app::SceneFile s = app::read_scene_file(
        f.scene(with_plant(R"("steps": 3, "placements": {"scatter": {"rectangle": [0, 0, 100, 100], "count": 1000}})")),
        app::Options{});
    // 1000 plants with 3 flowers each: 4000 instances of about 150 B, 600 kB
    app::Options budget;
    budget.max_memory_bytes = 400'000;
    try {
        app::assemble_scene(s, budget, {app::OrganPlacement::compose, false});
        ADD_FAILURE() << "4000 instances passed a budget of 400 kB";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("field.json: plants: the placements with their organs (-o>) need about"),
                  std::string::npos)
            << e.what();
    }
    budget.max_memory_bytes = 800'000;
    EXPECT_EQ(app::assemble_scene(s, budget, {app::OrganPlacement::compose, false}).instances.size(),
              4000u);
    // drawn inline, every copy's primitives count (7 a plant: 100 B each)
    budget.max_memory_bytes = 400'000;
    EXPECT_THROW(app::assemble_scene(s, budget, {app::OrganPlacement::compose, true}), Error);
}

// Each variant's derivation and interpretation keeps to the budget on its own; the
// variants held together until the scene is combined must too.
TEST(SceneAssembly, VariantsHeldTogetherAreWithinTheMemoryBudget)
{
    SceneFolder f("variants_budget");
    f.tiny_model("m");
    app::Options one;
    one.lsystem = f.dir() / "m/p.l";
    one.view = f.dir() / "m/p.v";
    app::Model model = app::load_model(one);
    const std::uint64_t variant_bytes = geom::scene_buffer_bytes(app::interpret(model, app::derive(model, one), one));
    ASSERT_GT(variant_bytes, 0u);
    std::string plants;  // 10 seeds: 10 groups, each one variant held until combined
    for (int seed = 0; seed < 10; ++seed)
        plants += std::string(seed ? ", " : "") + R"({"model": "m", "command": "cpfg p.l p.v", "seed": )" +
                  std::to_string(seed) + R"(, "placements": [{}]})";
    app::SceneFile s = app::read_scene_file(f.scene("{\"plants\": [" + plants + "]}"), app::Options{});
    app::Options budget;
    budget.max_memory_bytes = 5 * variant_bytes;
    try {
        app::assemble_scene(s, budget, {app::OrganPlacement::compose, false});
        ADD_FAILURE() << "10 variants of " << variant_bytes << " B passed a budget of 5 of them";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("variants) hold"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("(--max-memory)"), std::string::npos) << e.what();
    }
    budget.max_memory_bytes = 15 * variant_bytes;
    app::AssemblyReport report;
    app::assemble_scene(s, budget, {app::OrganPlacement::compose, false}, &report);
    EXPECT_EQ(report.variants, 10u);
}

TEST(SceneAssembly, InstancedFieldRendersAsTheSamePlantsInline)
{
    SceneFolder f("inline");
    f.tiny_model("m");
    app::SceneFile s = app::read_scene_file(f.scene(R"({
      "plants": [{"model": "m", "command": "cpfg p.l p.v", "steps": [2, 3],
                  "placements": [{"translate": [-2, 0, 0], "rotate_y_deg": 30},
                                 {"translate": [1, 0, 1], "scale": 0.8},
                                 {"translate": [2.5, 0, -1], "rotate_y_deg": -70, "scale": 1.1}]}],
      "ground": {"size": [10, 10]},
      "camera": {"eye": [0, 3, 9], "look_at": [0, 1.2, 0], "fov_deg": 40}
    })"),
                                            app::Options{});
    render::RenderSettings settings;
    settings.width = 64;
    settings.height = 64;
    settings.samples_per_pixel = 16;
    settings.max_depth = 2;
    auto render_with = [&](app::AssemblyOptions how, std::size_t instances) {
        geom::Scene scene = app::assemble_scene(s, app::Options{}, how);
        EXPECT_EQ(scene.instances.size(), instances);
        return render::render(scene, settings);
    };
    // 3 plants, 2 + 3 + 2 flowers: composed 3 + 7 instances; flattened 3; inline none
    render::Image composed = render_with({app::OrganPlacement::compose, false}, 10);
    render::Image flattened = render_with({app::OrganPlacement::flatten, false}, 3);
    render::Image drawn_inline = render_with({app::OrganPlacement::compose, true}, 0);
    // automatic: the variant of 2 steps, placed twice, has its 2 flowers drawn in (2 x 3
    // primitives cost no more than 2 x 2 instances); the one of 3 steps, placed once,
    // keeps its 3 flowers as instances
    render::Image automatic = render_with({app::OrganPlacement::automatic, false}, 6);
    // the same picture up to float rounding of the placements
    EXPECT_LT(mean_difference(composed, drawn_inline), 1e-3);
    EXPECT_LT(mean_difference(flattened, drawn_inline), 1e-3);
    EXPECT_LT(mean_difference(automatic, drawn_inline), 1e-3);
    // ... and not by accident: a plant moved is another picture
    app::SceneFile moved = s;
    moved.plants[0].placements[0][9] += 1.0f;
    render::Image other = render::render(app::assemble_scene(moved, app::Options{}), settings);
    EXPECT_GT(mean_difference(other, drawn_inline), 1e-3);
}

namespace {

/// Drawn segments of every prototype and of the scene's own geometry.
std::size_t segments(const geom::Scene& scene)
{
    std::size_t n = scene.geometry.lines.segments.size();
    for (const geom::Prototype& p : scene.prototypes)
        n += p.geometry.lines.segments.size();
    return n;
}

/// The manual's L-system 3 (section 7.1) as model m, with honda81 answering 1 (free)
/// or 0 (blocked): only free ends branch again.
void open_sierpinski(const SceneFolder& f)
{
    f.write("m/p.l", "lsystem: 1\nderivation length: 3\naxiom: ?E(1)\n"
                     "?E(c) : c == 1 --> [+F/(180)?E(1)]F?E(1)\nendlsystem\n");
    f.write("m/p.v", "angle increment: 60\nline style: cylinder\ninitial line width: 0.1\n");
    f.write("m/p.e", "executable: honda81 density.spec\nturtle position:P:%.4f %.4f %.0f\n");
    f.write("m/density.spec", "radius: 0.01\n3d case: on\n");
}

/// The segments a scene of model m with `command` and `placements` draws, every plant
/// drawn inline.
std::size_t segments_drawn(const SceneFolder& f, const std::string& command, const std::string& placements)
{
    app::SceneFile s = app::read_scene_file(
        f.scene(R"({"plants": [{"model": "m", "command": ")" + command + R"(", "placements": )" +
                placements + "}]}"),
        app::Options{});
    Diagnostics quiet(Diagnostics::Output::quiet);
    ScopedDiagnostics scope(quiet);
    app::Options options;
    options.quiet = true;
    return segments(app::assemble_scene(s, options, {app::OrganPlacement::compose, true}, nullptr));
}

}  // namespace

TEST(SceneAssembly, OpenLSystemPlantsTalkToTheirEnvironment)
{
    // two ends meet after two steps and stop
    SceneFolder f("open");
    open_sierpinski(f);
    EXPECT_EQ(segments_drawn(f, "cpfg p.l p.v", "[{}]"), 14u);  // 2 + 4 + 8: every end branches
    EXPECT_EQ(segments_drawn(f, "cpfg -e p.e p.l p.v", "[{}]"), 10u);  // the two blocked do not
}

TEST(SceneAssembly, PlantsOfOneEnvironmentCompete)
{
    // Two placements of that plant share honda81: far apart each grows as alone; on one
    // spot every end of one meets the same end of the other (equal vigor blocks both),
    // so neither grows at all
    SceneFolder f("field");
    open_sierpinski(f);
    const std::string open = "cpfg -e p.e p.l p.v";
    EXPECT_EQ(segments_drawn(f, open, R"([{}, {"translate": [100, 0, 0]}])"), 20u);
    EXPECT_EQ(segments_drawn(f, open, "[{}, {}]"), 0u);
}

/// Model m: a bud before a leaf ball, which grows a segment only when the light
/// environment (QuasiMC's `.e` line) finds the ball lit.
void light_bud(const SceneFolder& f)
{
    f.write("m/p.l", "lsystem: 1\nderivation length: 1\naxiom: B?E(0)@O(2)\n"
                     "B > ?E(l) : l > 0.1 --> F(1)B\nendlsystem\n");
    f.write("m/p.v", "line style: cylinder\ninitial line width: 0.1\n");
    f.write("m/p.e", "executable: QuasiMC -e p.e light.spec\n");
    f.write("m/light.spec", "light source: 0 -1 0 1\nleaf material (top): 0 10 0 10 1\nnumber of rays: 20000\n");
}

TEST(SceneAssembly, PlantsSharingTheLightEnvironmentShadeEachOther)
{
    // Far apart, both buds are lit and grow; with the second plant 4 above the first, its
    // ball covers the first's from the light straight down, and only the upper one grows
    SceneFolder f("light_field");
    light_bud(f);
    const std::string open = "cpfg -e p.e p.l p.v";
    EXPECT_EQ(segments_drawn(f, open, R"([{}, {"translate": [100, 0, 0]}])"), 2u);
    EXPECT_EQ(segments_drawn(f, open, R"([{}, {"translate": [0, 4, 0]}])"), 1u);
    EXPECT_EQ(segments_drawn(f, open, R"([{}, {"translate": [0, -4, 0]}])"), 1u);
}

// --light-report: a .json or .csv file, refused before any work otherwise; without -o it
// renders no image; its value is never taken for a scene file.
// A scene's light report names each organ by its placement and by the derived string's
// module (a K the homomorphism draws as F and @O is one organ, K): two equal plants far
// apart under one sun absorb the same.
TEST(SceneAssembly, LightReportCountsEachPlacementsOrgans)
{
    SceneFolder f("light");
    f.tiny_model("m");
    app::SceneFile s = app::read_scene_file(
        f.scene(with_plant(R"("steps": 3, "placements": [{}, {"translate": [100, 0, 0]}])")), app::Options{});
    geom::Scene scene = app::assemble_scene(s, app::Options{}, {app::OrganPlacement::compose, false});
    render::LightReportSettings settings;
    settings.rays = 200'000;
    settings.threads = 2;
    const render::LightReport report = render::trace_light(scene, settings);
    std::map<std::uint32_t, double> absorbed;
    std::map<std::uint32_t, std::set<std::pair<std::uint32_t, std::string>>> organs;
    for (const render::OrganLight& o : report.organs) {
        absorbed[o.plant] += o.absorbed;
        organs[o.plant].insert({o.module, o.symbol});
    }
    ASSERT_EQ(absorbed.size(), 2u);
    ASSERT_TRUE(absorbed.count(0) && absorbed.count(1));
    EXPECT_EQ(organs[0], organs[1]);
    EXPECT_TRUE(std::any_of(organs[0].begin(), organs[0].end(), [](const auto& o) { return o.second == "K"; }));
    EXPECT_GT(absorbed[0], 0);
    EXPECT_NEAR(absorbed[0], absorbed[1], 0.05 * absorbed[0]);
    // the exports name organs placed whole by the same table: every flower is a K
    const geom::OrganModules organ_modules(scene);
    std::size_t flowers = 0;
    for (const geom::Instance& in : scene.instances)
        if (in.module != geom::no_module) {
            const geom::ModuleRecord* r = organ_modules.of(in).find(in.module);
            ASSERT_TRUE(r) << "module " << in.module << " of plant " << in.plant;
            EXPECT_EQ(organ_modules.of(in).name(*r), "K");
            ++flowers;
        }
    EXPECT_EQ(flowers, 6u);
}

TEST(LightReportOption, ParsedAndChecked)
{
    app::Options o = *app::parse_command_line({"--light-report", "r.json", "--light-rays", "5000", "a.l", "a.v"});
    ASSERT_TRUE(o.light_report);
    EXPECT_EQ(*o.light_report, "r.json");
    EXPECT_EQ(o.light_rays, 5000u);
    EXPECT_FALSE(o.renders());
    EXPECT_FALSE(o.scene);
    EXPECT_TRUE(app::parse_command_line({"--light-report", "r.csv", "-o", "x.png", "a.l", "a.v"})->renders());
    EXPECT_THROW(app::parse_command_line({"--light-report", "r.txt", "a.l", "a.v"}), Error);
}

// --sun-at turns a place and a local time into the --sky's sun; bad values name the option.
TEST(SunAtOption, SetsTheSunAndChecksItsValues)
{
    app::Options o = *app::parse_command_line(
        {"--sky", "--sun-at", "0", "0", "2024-03-20T13:07+01:00", "a.l", "a.v"});
    ASSERT_EQ(o.sun_direction.size(), 3u);
    EXPECT_GT(o.sun_direction[1], 0.999f);  // the equinox noon sun over the equator
    o = *app::parse_command_line({"--sky", "--sun-at", "52", "5", "2024-06-21T07:00Z", "a.l", "a.v"});
    EXPECT_GT(o.sun_direction[0], 0.3f);  // the morning sun is in the east (+x)
    auto error = [](std::vector<std::string> words) {
        try {
            app::parse_command_line(words);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(error({"--sky", "--sun-at", "95", "0", "2024-03-20T12:00Z", "a.l", "a.v"}).find("--sun-at: latitude"),
              std::string::npos);
    EXPECT_NE(error({"--sky", "--sun-at", "0", "200", "2024-03-20T12:00Z", "a.l", "a.v"}).find("--sun-at: longitude"),
              std::string::npos);
    EXPECT_NE(error({"--sky", "--sun-at", "0", "0", "2023-02-29T12:00Z", "a.l", "a.v"}).find("--sun-at:"),
              std::string::npos);
    EXPECT_NE(error({"--sky", "--sun-at", "0", "0", "2023-02-20T12:00", "a.l", "a.v"}).find("UTC offset"),
              std::string::npos);
    EXPECT_NE(error({"--sun-at", "0", "0", "2023-02-20T12:00Z", "a.l", "a.v"}).find("give --sky"),
              std::string::npos);
    EXPECT_NE(error({"--sky", "--sun", "0", "1", "0", "--sun-at", "0", "0", "2023-02-20T12:00Z", "a.l", "a.v"})
                  .find("give one"),
              std::string::npos);
}

TEST(InfiniteCanopyOption, NeedsTheLightReport)
{
    EXPECT_TRUE(app::parse_command_line({"--light-report", "r.json", "--infinite-canopy", "a.l", "a.v"})->infinite_canopy);
    EXPECT_THROW(app::parse_command_line({"--infinite-canopy", "a.l", "a.v"}), Error);
    app::Options o = *app::parse_command_line(
        {"--light-report", "r.json", "--canopy-tile", "-1", "-2", "3", "4", "a.l", "a.v"});
    EXPECT_TRUE(o.infinite_canopy);
    EXPECT_EQ(o.canopy_tile, (std::vector<double>{-1, -2, 3, 4}));
    EXPECT_THROW(app::parse_command_line({"--light-report", "r.json", "--canopy-tile", "3", "0", "1", "4", "a.l", "a.v"}),
                 Error);
}
