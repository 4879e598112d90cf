// SPDX-License-Identifier: Apache-2.0
// A model as cpfg loads it (view file, colours, functions, L-system), derived and
// interpreted.
#include "app/pipeline.h"

#include "base/diagnostics.h"
#include <algorithm>
#include <sstream>

#include "geom/background_scene.h"
#include "geom/contour.h"
#include "geom/interpreter.h"
#include "geom/query.h"
#include "lsys/program.h"

namespace cambium::app {
namespace {

geom::Palette load_palette(const Options& options)
{
    geom::Palette palette;
    for (const ColourFile& f : options.colour_files) {
        if (f.materials)
            palette.load_materials(f.block, f.file);
        else
            palette.load_colormap(f.block, f.file);
    }
    return palette;
}

/// The view file's `curve:` contours (ids from 1, in order) for curveX/Y/Z and
/// curveGAL: each resampled finely at equal arc length, so a parameter t in [0, 1] is
/// the fraction of the curve's length (the L-systems walk curves by arc length).
class CurveSet {
public:
    explicit CurveSet(const geom::ViewFile& view)
    {
        for (const geom::ViewCommand& c : view.deferred) {
            if (c.name != "curve")
                continue;
            std::string file;
            std::istringstream(c.value) >> file;
            try {
                m_curves.push_back(geom::resample(
                    geom::read_contour(view.path.parent_path() / file), samples));
            } catch (const Error& e) {
                // The `version: 1.4` B-spline curve format is not read yet.
                warn(c.loc, std::string("curve not read, its coordinates are 0: ") + e.what());
                m_curves.emplace_back();
            }
        }
    }

    bool empty() const { return m_curves.empty(); }

    double evaluate(char which, int id, double t) const
    {
        if (id < 1 || id > static_cast<int>(m_curves.size())) {
            warn("curve id " + std::to_string(id) + " is not defined by the view file; using 0");
            return 0;
        }
        const geom::ContourSamples& c = m_curves[static_cast<std::size_t>(id - 1)];
        if (which == 'l' || c.vertices.size() < 2)
            return which == 'l' ? c.length : 0.0;
        const std::vector<geom::Vec3>& v = c.vertices;
        std::size_t edges = c.closed ? v.size() : v.size() - 1;
        double at = std::clamp(t, 0.0, 1.0) * static_cast<double>(edges);
        std::size_t i = std::min(static_cast<std::size_t>(at), edges - 1);
        double f = at - static_cast<double>(i);
        geom::Vec3 p = v[i] * (1 - f) + v[(i + 1) % v.size()] * f;
        return which == 'x' ? p.x : which == 'y' ? p.y : p.z;
    }

private:
    static constexpr int samples = 2048;
    std::vector<geom::ContourSamples> m_curves;
};

/// The symbol table the query pass needs exists only once the L-system is loaded,
/// after the hook is made; the hook finds it here.
struct QueryContext {
    std::shared_ptr<const geom::ViewFile> view;
    const lsys::SymbolTable* symbols = nullptr;
};

}  // namespace

Model load_model(const Options& options)
{
    geom::Palette palette = load_palette(options);
    auto view = std::make_shared<const geom::ViewFile>(geom::read_view_file(options.view));
    auto functions =
        std::make_shared<const geom::FunctionSet>(geom::FunctionSet::from_view_file(*view));

    lsys::LoadOptions load;
    load.max_modules = options.max_modules;
    load.preprocessor = options.preprocessor;
    load.defines = functions->define_names();
    if (!functions->empty())
        load.function = [functions](int id, double x) { return functions->evaluate(id, x); };
    auto curves = std::make_shared<const CurveSet>(*view);
    if (!curves->empty())
        load.curve = [curves](char which, int id, double t) {
            return curves->evaluate(which, id, t);
        };
    auto queries = std::make_shared<QueryContext>();
    queries->view = view;
    load.query = [queries](lsys::ModuleString& string) {
        if (queries->symbols)
            geom::answer_queries(string, *queries->symbols, *queries->view);
    };
    if (options.verbosity == Verbosity::verbose)
        load.on_step = [](int step, const lsys::ModuleString& s) {
            std::printf("step %d: %zu modules\n", step, s.size());
        };

    lsys::LSystem lsystem = lsys::LSystem::load(options.lsystem, load);
    // The program (and its symbol table) lives behind a pointer: moving the LSystem
    // into the Model keeps this address.
    queries->symbols = &lsystem.symbols();
    return Model{std::move(view), std::move(palette), std::move(functions), std::move(lsystem)};
}

lsys::ModuleString derive(const Model& model, const Options& options)
{
    lsys::ModuleString derived = model.lsystem.derive(options.steps);
    if (options.homomorphism_in_string)
        return model.lsystem.interpretation_string(derived);
    return derived;
}

geom::Scene interpret(const Model& model, const lsys::ModuleString& derived,
                      const Options& options)
{
    lsys::ModuleString string = options.homomorphism_in_string
                                    ? derived
                                    : model.lsystem.interpretation_string(derived);
    geom::InterpretOptions interpret_options;
    interpret_options.strings = model.lsystem.program().strings;
    geom::Scene scene =
        geom::interpret(string, model.lsystem.symbols(), *model.view, interpret_options);
    scene.materials = model.palette.entries(options.colour_block);
    scene.background = model.palette.background(options.colour_block);
    for (const geom::TranslucencySetting& t : model.view->translucency)
        for (int i = t.first; i <= t.last; ++i)
            scene.materials.at(static_cast<std::size_t>(i)).translucency = t.amount;

    geom::BackgroundScene background = geom::load_view_background(*model.view, scene.materials[0]);
    if (!background.geometry.empty()) {
        geom::offset_materials(background.geometry,
                               static_cast<std::uint16_t>(scene.materials.size()));
        scene.materials.insert(scene.materials.end(), background.materials.begin(),
                               background.materials.end());
        geom::append_geometry(scene.geometry, background.geometry);
    }
    return scene;
}

}  // namespace cambium::app
