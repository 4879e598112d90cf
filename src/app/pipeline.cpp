// SPDX-License-Identifier: Apache-2.0
// A model as cpfg loads it (view file, colours, functions, L-system), derived and
// interpreted.
#include "app/pipeline.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "base/diagnostics.h"
#include "base/subprocess.h"
#include "geom/background_scene.h"
#include "geom/function.h"
#include "geom/interpreter.h"
#include "geom/query.h"
#include "geom/scene_limits.h"
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


/// The symbol table the query pass needs exists only once the L-system is loaded,
/// after the hook is made; the hook finds it here.
struct QueryContext {
    std::shared_ptr<const geom::ViewFile> view;
    const lsys::SymbolTable* symbols = nullptr;
};

/// Per symbol id: whether an -o> production makes it an object geom may instance.
std::vector<char> object_symbols(const lsys::LSystem& lsystem)
{
    std::vector<char> objects(lsystem.symbols().size(), 0);
    bool any = false;
    for (std::size_t s = 0; s < objects.size(); ++s)
        any |= (objects[s] = lsystem.is_object_symbol(static_cast<int>(s)) ? 1 : 0) != 0;
    return any ? objects : std::vector<char>{};
}

/// The longest an allowed @S command may run.
constexpr double max_system_call_seconds = 300;

/// Runs one allowed @S command with /bin/sh in the model's folder, its input from
/// /dev/null and its output on cambium's; a failure is a warning, as under cpfg.
void run_system_call(const std::string& command, const std::filesystem::path& folder)
{
    ProcessIo io;
    io.capture = false;
    ProcessLimits limits;
    limits.wall_seconds = max_system_call_seconds;
    limits.max_output_bytes = 0;
    limits.max_memory_bytes = 0;
    ProcessResult r = run_process({"/bin/sh", "-c", command}, folder, io, limits);
    if (r.end == ProcessResult::End::timed_out)
        warn("@S(\"" + command + "\") was stopped after " +
             std::to_string(int(max_system_call_seconds)) + " s");
    else if (r.end == ProcessResult::End::not_found)
        throw Error("@S: cannot run /bin/sh: " + r.messages);
    else if (r.exit_code != 0)
        warn("@S(\"" + command + "\") ended with status " + std::to_string(r.exit_code));
}

}  // namespace

std::shared_ptr<const geom::ViewFile> read_view(const Options& options)
{
    auto view = std::make_shared<const geom::ViewFile>(geom::read_view_file(options.view));
    if (options.allow_file_access)
        return view;
    namespace fs = std::filesystem;
    const fs::path folder = fs::weakly_canonical(fs::absolute(options.lsystem).parent_path());
    for (const geom::TextureDef& t : view->textures) {
        const fs::path file = fs::weakly_canonical(t.file);  // links and .. resolved
        auto [f, unused] = std::mismatch(folder.begin(), folder.end(), file.begin(), file.end());
        if (f != folder.end())
            throw Error(FileLoc{options.view.string()},
                        "texture '" + t.file.string() + "' lies outside the model's folder " +
                            folder.string() + " (--allow-file-access lifts this)");
    }
    return view;
}

Model load_model(const Options& options)
{
    geom::Palette palette = load_palette(options);
    std::shared_ptr<const geom::ViewFile> view = read_view(options);
    auto functions =
        std::make_shared<const geom::FunctionSet>(geom::FunctionSet::from_view_file(*view));

    lsys::LoadOptions load;
    load.max_modules = options.max_modules;
    load.max_memory_bytes = options.max_memory_bytes;
    load.allow_file_access = options.allow_file_access;
    load.preprocessor = options.preprocessor;
    load.seed = options.lsystem_seed;
    load.defines = functions->define_names();
    if (!functions->empty())
        load.function = [functions](int id, double x) { return functions->evaluate(id, x); };
    auto curves = std::make_shared<const geom::CurveSet>(geom::CurveSet::from_view_file(*view));
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

namespace {
/// The view file's `render mode:` or `shade mode:` (the last one given). `fast` is
/// filled (manual 5.2: filled with wireframe spheres); `interpolated` and `shadows` are
/// shaded (the former's colour blending is the generalized cylinders' concern). The
/// older `shade mode:` numbers as cpfg converts them: 1 simple fill (filled), 4 and 5
/// B-spline polygons and 7 wireframe (wireframe), the rest shaded (2 interpolated fill,
/// 3 Gouraud, 6 two-sided).
geom::Shading render_mode(const geom::ViewFile& view)
{
    geom::Shading mode = geom::Shading::shaded;
    for (const geom::ViewCommand& c : view.deferred) {
        std::istringstream in(c.value);
        std::string word;
        in >> word;
        if (c.name == "render mode")
            mode = word == "flat"        ? geom::Shading::flat
                   : word == "filled" || word == "fast" ? geom::Shading::filled
                   : word == "wireframe" ? geom::Shading::wireframe
                                         : geom::Shading::shaded;
        else if (c.name == "shade mode")
            mode = word == "1"                                ? geom::Shading::filled
                   : word == "4" || word == "5" || word == "7" ? geom::Shading::wireframe
                                                               : geom::Shading::shaded;
    }
    return mode;
}
}  // namespace

geom::Scene interpret(const Model& model, const lsys::ModuleString& derived,
                      const Options& options)
{
    return interpret_turtle_string(model, turtle_string(model, derived, options), options);
}

namespace {

/// -o> objects become prototypes and instances (docs: manual 8.1); with -homo the
/// string already holds their expansions.
std::vector<char> instanced_objects(const Model& model, const Options& options)
{
    return options.homomorphism_in_string ? std::vector<char>{} : object_symbols(model.lsystem);
}

}  // namespace

lsys::ModuleString turtle_string(const Model& model, const lsys::ModuleString& derived,
                                 const Options& options)
{
    if (options.homomorphism_in_string)
        return derived;
    return model.lsystem.interpretation_string(derived, instanced_objects(model, options).empty()
                                                            ? lsys::ObjectHandling::expand
                                                            : lsys::ObjectHandling::keep);
}

geom::Scene interpret_turtle_string(const Model& model, const lsys::ModuleString& string,
                                    const Options& options)
{
    geom::InterpretOptions interpret_options;
    interpret_options.strings = model.lsystem.program().strings;
    interpret_options.max_memory_bytes = options.max_memory_bytes;
    std::vector<char> objects = instanced_objects(model, options);
    if (!objects.empty()) {
        const lsys::LSystem& lsystem = model.lsystem;
        interpret_options.is_object = [objects](lsys::SymbolId s) {
            return s < objects.size() && objects[s] != 0;
        };
        interpret_options.expand_object = [&lsystem](lsys::ModuleRef m) { return lsystem.expand_object(m); };
    }
    if (options.allow_system_calls) {
        std::filesystem::path folder = options.lsystem.parent_path();
        interpret_options.system_call = [folder](const std::string& command) {
            run_system_call(command, folder);
        };
    }
    geom::Scene scene =
        geom::interpret(string, model.lsystem.symbols(), *model.view, interpret_options);
    scene.shading = render_mode(*model.view);
    scene.materials = model.palette.entries(options.colour_block);
    scene.background = model.palette.background(options.colour_block);
    // cpfg's window draws every object of the L-system opaque (manual 9.4); only the
    // background scene keeps its transparency.
    if (!options.material_transparency)
        for (geom::Material& m : scene.materials)
            m.transparency = 0;
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
    // Non-finite or huge numbers would abort inside Embree: dropped here with a warning.
    geom::drop_unrenderable(scene);
    return scene;
}

}  // namespace cambium::app
