// SPDX-License-Identifier: Apache-2.0
// Every self-contained corpus model exported as binary glTF: tinygltf's loader reads each
// file back with the triangles and lines the scene has, and the Khronos glTF-Validator (when
// node and npm's gltf-validator are installed: docs/export.md) finds no error or warning
// in any.
#include <gtest/gtest.h>

#include <tiny_gltf.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <tuple>

#include <nlohmann/json.hpp>

#include "app/pipeline.h"
#include "base/output_format.h"
#include "corpus_model.h"
#include "geom/gltf_export.h"
#include "geom/mesh_export.h"
#include "geom/tessellate.h"
#include "shell_output.h"

namespace cambium::test {
namespace {

namespace fs = std::filesystem;

/// The folder holding node_modules/gltf-validator ($CAMBIUM_GLTF_VALIDATOR, else the
/// build's gltf-validator folder), when it and node are there.
std::optional<fs::path> validator_folder()
{
    const char* env = std::getenv("CAMBIUM_GLTF_VALIDATOR");
    const fs::path dir = env ? fs::path(env) : fs::path(CAMBIUM_GLTF_VALIDATOR_DEFAULT);
    if (!fs::exists(dir / "node_modules" / "gltf-validator" / "package.json"))
        return std::nullopt;
    if (run_shell("node --version").status != 0)
        return std::nullopt;
    return dir;
}

/// The triangles and line segments a .glb holds, read by tinygltf's loader.
std::size_t primitives_in(const fs::path& file)
{
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string error, warning;
    if (!loader.LoadBinaryFromFile(&model, &error, &warning, file.string()))
        throw std::runtime_error(file.string() + ": " + error);
    std::size_t n = 0;
    for (const tinygltf::Mesh& mesh : model.meshes)
        for (const tinygltf::Primitive& p : mesh.primitives)
            n += p.mode == TINYGLTF_MODE_LINE
                     ? model.accessors.at(std::size_t(p.attributes.at("POSITION"))).count / 2
                     : model.accessors.at(std::size_t(p.indices)).count / 3;
    return n;
}

/// What the export should hold, counted from the scene: its own primitives as triangles
/// (pixel-wide lines as segments) and each prototype once per look it is placed with.
std::size_t expected_primitives(const geom::Scene& scene)
{
    const bool pixels = scene.line_radius_in_pixels;
    std::size_t n = geom::tessellate_geometry(scene.geometry, pixels, {}).size() +
                    (pixels ? scene.geometry.lines.segment_count() : 0);
    std::set<std::tuple<std::uint32_t, std::uint16_t, std::uint16_t, std::int16_t>> looks;
    for (const geom::Instance& i : scene.instances)
        if (looks.insert({i.prototype, i.material, i.back_material, i.texture}).second)
            n += geom::tessellate_geometry(scene.prototypes.at(i.prototype).geometry, pixels, {}).size();
    return n;
}

TEST(GltfSweep, EverySelfContainedModelExportsAValidGlb)
{
    const fs::path out = process_folder("gltf_sweep");
    std::vector<std::string> files;
    const std::optional<int> models = sweep_self_contained_models([&](const CorpusModel& model,
                                                                      app::Options options) {
        const std::string name = std::to_string(files.size()) + ".glb";
        options.outputs = {out / name};  // instances kept, as the command keeps them for .glb
        app::Model loaded = app::load_model(options);
        geom::Scene scene = app::interpret(loaded, app::derive(loaded, options), options);
        geom::MeshExportOptions how;
        how.texture_folder = options.view.parent_path();
        geom::write_mesh(scene, out / name, MeshFormat::glb, how);
        EXPECT_EQ(primitives_in(out / name), expected_primitives(scene)) << model.id;
        files.push_back(name);
    });
    if (!models) {
        fs::remove_all(out);
        GTEST_SKIP() << "corpus not found";
    }
    EXPECT_GE(files.size(), 79u);
    const std::optional<fs::path> validator = validator_folder();
    if (validator) {
        std::string command = "NODE_PATH='" + (*validator / "node_modules").string() + "' node '" +
                              CAMBIUM_GLTF_VALIDATE_SCRIPT + "'";
        for (const std::string& f : files)
            command += " " + f;
        const CommandResult r = run_shell(command, out);
        EXPECT_EQ(r.status, 0) << r.output;
        std::size_t reports = 0;
        for (std::size_t at = 0; at < r.output.size();) {
            const std::size_t end = r.output.find('\n', at);
            const std::string line = r.output.substr(at, end - at);
            at = end == std::string::npos ? r.output.size() : end + 1;
            if (line.empty() || line[0] != '{')
                continue;
            const nlohmann::json report = nlohmann::json::parse(line);
            ++reports;
            EXPECT_EQ(report["errors"].get<int>(), 0) << line;
            EXPECT_EQ(report["warnings"].get<int>(), 0) << line;
        }
        EXPECT_EQ(reports, files.size());
    }
    fs::remove_all(out);
    if (!validator)
        GTEST_SKIP() << "read back; the Khronos glTF-Validator is not installed (docs/export.md)";
}

}  // namespace
}  // namespace cambium::test
