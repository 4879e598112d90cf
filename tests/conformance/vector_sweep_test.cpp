// SPDX-License-Identifier: Apache-2.0
// Every self-contained corpus model drawn as PostScript (-ps) and SVG in a small window:
// no error, the page is the window, and the SVG holds one path per projected shape.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/pipeline.h"
#include "base/output_format.h"
#include "corpus_model.h"
#include "geom/tessellate.h"
#include "render/camera.h"
#include "render/vector_drawing.h"
#include "render/vector_writer.h"

namespace cambium::test {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::size_t occurrences(const std::string& text, const std::string& what)
{
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
        ++n;
    return n;
}

TEST(VectorSweep, EverySelfContainedModelDrawsAsPostScriptAndSvg)
{
    const auto start = std::chrono::steady_clock::now();
    const fs::path out = process_folder("vector_sweep");
    std::size_t drawn = 0, with_shapes = 0;
    const std::optional<int> models = sweep_self_contained_models([&](const CorpusModel& model,
                                                                      app::Options options) {
        options.width = 96;  // a small window keeps the files and the sweep small
        options.height = 72;
        const fs::path ps = out / (std::to_string(drawn) + ".ps");
        const fs::path svg = out / (std::to_string(drawn) + ".svg");
        options.outputs = {svg};
        app::Model loaded = app::load_model(options);
        geom::Scene scene = app::interpret(loaded, app::derive(loaded, options), options);
        // the drawing -ps and -o .svg make (the command's camera options are none here)
        const render::Camera camera =
            render::make_camera(scene.view, scene.bounds, options.width, options.height);
        const render::VectorDrawing drawing =
            render::project_drawing(scene, geom::tessellate(scene, geom::drawing_tessellation), camera);
        render::write_vector(drawing, ps, VectorFormat::ps);
        const std::string ps_text = bytes_of(ps);
        EXPECT_EQ(ps_text.rfind("%!PS", 0), 0u) << model.id;
        EXPECT_NE(ps_text.find("\n%%BoundingBox: 0 0 96 72\n"), std::string::npos) << model.id;
        render::write_vector(drawing, svg, VectorFormat::svg);
        const std::string svg_text = bytes_of(svg);
        EXPECT_NE(svg_text.find("viewBox=\"0 0 96 72\""), std::string::npos) << model.id;
        // one path a shape; cairo may still leave out a sliver whose extents round to nothing
        const std::size_t paths = occurrences(svg_text, "<path ");
        EXPECT_LE(paths, drawing.shapes.size()) << model.id;
        EXPECT_GE(paths, drawing.shapes.size() * 999 / 1000) << model.id;
        with_shapes += !drawing.shapes.empty();
        ++drawn;
        fs::remove(ps);
        fs::remove(svg);
    });
    fs::remove_all(out);
    if (!models)
        GTEST_SKIP() << "corpus not found";
    EXPECT_GE(drawn, 79u);
    EXPECT_GE(with_shapes, drawn - 2);  // a model may draw outside its own window, not many
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    RecordProperty("seconds", std::to_string(seconds));
    std::printf("vector sweep: %zu models in %.1f s\n", drawn, seconds);
}

}  // namespace
}  // namespace cambium::test
