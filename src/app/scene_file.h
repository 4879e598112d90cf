// SPDX-License-Identifier: Apache-2.0
// Scene files (docs/scenes.md): many cpfg plants placed by instances on a ground, with
// a camera, lights, a sky and render settings, in JSON. Reading one resolves and checks
// everything a render needs (files, placements) so that errors come before any work.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "geom/scene.h"

namespace cambium::app {

/// Limits on what a scene file may ask for (docs/scenes.md): the file itself, its plant
/// entries and the instances it places (the scatters' counts included).
struct SceneLimits {
    std::uintmax_t max_file_bytes = 64u << 20;
    std::size_t max_nesting = 64;  ///< JSON objects and arrays within one another
    std::size_t max_plants = 10'000;
    std::size_t max_variants = 1'000;       ///< distinct (model, command, steps, seed)
    std::size_t max_instances = 10'000'000; ///< placements of plants, all entries together
    std::size_t max_mesh_triangles = 10'000'000;  ///< a ground or scatter OBJ mesh
    std::uintmax_t max_mesh_bytes = 1u << 30;     ///< its file (a regular file)
    std::size_t max_mesh_line_bytes = 64u << 10;  ///< one line of it
    std::size_t max_mesh_materials = 65'534;      ///< MTL entries of a `meshes` OBJ
    std::size_t max_meshes = 10'000;              ///< `meshes` entries
};

/// A 3x4 column-major transform, as geom::Instance::transform.
using Transform = std::array<float, 12>;

/// A triangle mesh read from an OBJ file (positions and faces only; polygons are fanned).
struct GroundMesh {
    std::vector<geom::Float3> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Where a scatter places its plants.
struct ScatterSpec {
    std::array<double, 4> rectangle{0, 0, 0, 0};  ///< xmin, zmin, xmax, zmax (on y = 0)
    std::optional<std::filesystem::path> mesh;     ///< or over this mesh's area
    std::size_t count = 0;
    std::uint64_t seed = 0;
    double min_spacing = 0;
    bool rotate_y = false;
    std::array<double, 2> scale{1, 1};
};

/// One `plants` entry: a cpfg model and where its copies stand.
struct ScenePlant {
    std::string path;                    ///< its JSON path, "plants[3]", for messages
    std::filesystem::path folder;        ///< the model's folder, resolved
    std::string command;                 ///< the cpfg command line as written
    /// The command line's files (L-system, view, colour files, colour block), with
    /// paths resolved in `folder`; the rest of a plant's options are the command's.
    Options model;
    std::vector<std::optional<int>> steps;  ///< variants; nullopt: the derivation length
    std::optional<long> seed;            ///< the L-system's random streams' seed
    std::vector<Transform> placements;   ///< explicit ones and the scatter's, in order
};

struct SceneGround {
    std::optional<std::array<double, 2>> size;      ///< a w x d rectangle centred at 0
    std::optional<std::filesystem::path> mesh;      ///< or an OBJ mesh
    geom::Rgb colour{0.42f, 0.353f, 0.235f};        ///< display values (#6b5a3c)
    std::optional<std::filesystem::path> texture;   ///< image, stretched `texture_repeat` times
    double texture_repeat = 1;
};

/// One `meshes` entry: an OBJ file with its MTL materials (a plant Cambium exported)
/// and where its copies stand.
struct SceneMesh {
    std::string path;                   ///< its JSON path, "meshes[0]", for messages
    std::filesystem::path file;         ///< resolved
    std::vector<Transform> placements;
};

struct SceneCamera {
    std::optional<geom::Vec3> eye, look_at;
    geom::Vec3 up{0, 1, 0};
    double fov_deg = 40;
    bool perspective = true;
    std::optional<int> width, height;
};

struct SceneSky {
    std::optional<std::array<float, 3>> sun;
    float turbidity = 3;
};

struct SceneEnvironment {
    std::filesystem::path map;
    float scale = 1;
    float rotate_deg = 0;
};

/// The `render` object: each set value is a default the command line overrides.
struct SceneRender {
    std::optional<int> spp, max_depth;
    std::optional<std::uint64_t> seed;
    std::optional<float> noise_target, exposure, ambient;
    std::optional<double> time_budget_s;
    std::optional<std::string> filter, tonemap, background;
};

struct SceneFile {
    std::filesystem::path file;
    std::vector<ScenePlant> plants;
    std::vector<SceneMesh> meshes;
    std::optional<SceneGround> ground;
    std::optional<SceneCamera> camera;
    std::vector<geom::Light> lights;  ///< empty: a default sun (or the sky's)
    std::optional<SceneSky> sky;
    std::optional<SceneEnvironment> environment;
    SceneRender render;
};

/// Reads and checks a scene file: syntax (with line and column), every key and value
/// (messages name the JSON path: `forest.json: plants[3].steps: ...`), the files it
/// names (under the scene's folder unless options.allow_file_access), and computes
/// the scatters' placements. Throws cambium::Error.
SceneFile read_scene_file(const std::filesystem::path& file, const Options& options,
                          const SceneLimits& limits = {});

/// Refuses the options that belong to one L-system, not to a scene file of many plants
/// (-a, -str and -strb, -m and -M), with the command's messages. Throws cambium::Error.
void refuse_single_model_options(const Options& options);

/// The placements of a scatter: deterministic for its seed; up to `count` points at
/// least `min_spacing` apart (rejection sampling; fewer when the area is full, with a
/// warning), each turned about +y by a random angle when rotate_y and scaled uniformly
/// within `scale`. Over `mesh` (when given) points are uniform in area.
std::vector<Transform> scatter(const ScatterSpec& spec, const GroundMesh* mesh = nullptr);

/// Reads the vertices (`v`) and faces (`f`, fanned into triangles) of an OBJ file: a
/// regular file within limits.max_mesh_bytes, lines within max_mesh_line_bytes, at most
/// max_mesh_triangles triangles (errors at file:line otherwise).
GroundMesh read_obj_mesh(const std::filesystem::path& file, const SceneLimits& limits);

/// An OBJ file read as the surface it describes, in its MTL's materials.
struct ObjModel {
    /// smooth normals from `vn` (a face without them is flat), uvs from `vt`; material
    /// and texture index `materials` and `textures`
    geom::TriangleMesh mesh;
    std::vector<geom::Material> materials;  ///< one per MTL entry used (`usemtl`)
    std::vector<geom::TextureDef> textures; ///< `map_Kd` files, absolute
};

/// Reads an OBJ file, the MTL files its `mtllib` names and their `map_Kd` textures, each
/// of which must lie in `allowed` unless allow_file_access, within `limits` (the
/// ground's, plus max_mesh_materials): Cambium's MTL values map back to the cpfg
/// material they were written from (Ka, Kd, Ks, Ke, Ns, d = 1 - transparency). Errors
/// name the file and line (an MTL's error is nested in its mtllib line's).
ObjModel read_obj_model(const std::filesystem::path& file, const std::filesystem::path& allowed,
                        bool allow_file_access, const SceneLimits& limits);

/// The transform of an explicit placement: scale, then rotation about +y, then translation.
Transform placement_transform(const geom::Vec3& translate, double rotate_y_deg, double scale);

/// An error's text without the "error: " its unlocated form starts with, to nest it
/// in a message about the scene.
std::string nested_message(const std::exception& e);

/// a after b (x -> a(b(x))), both 3x4 column-major.
Transform compose(const Transform& a, const Transform& b);

}  // namespace cambium::app
