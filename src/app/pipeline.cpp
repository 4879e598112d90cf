// SPDX-License-Identifier: Apache-2.0
// A model as cpfg loads it (view file, colours, functions, L-system), derived and
// interpreted.
#include "app/pipeline.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "base/confinement.h"
#include "base/diagnostics.h"
#include "base/output_format.h"
#include "base/subprocess.h"
#include "app/light_environment.h"
#include "app/light_report.h"
#include "env/environmental_step.h"
#include "env/light_spec.h"
#include "geom/background_scene.h"
#include "geom/colour_index_lighting.h"
#include "geom/flatten.h"
#include "geom/curve.h"
#include "geom/function.h"
#include "geom/gencyl.h"
#include "geom/interpreter.h"
#include "geom/query.h"
#include "geom/scene_limits.h"
#include "geom/wireframe.h"
#include "lsys/program.h"
#include "render/image_codec.h"

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

/// The materials of the selected colours, as cpfg's window has them: opaque unless
/// --material-transparency, with the view file's translucency.
void set_model_materials(geom::Scene& scene, const geom::Palette& palette, const geom::ViewFile& view,
                         const Options& options)
{
    scene.materials = palette.entries(options.colour_block);
    scene.background = palette.background(options.colour_block);
    // cpfg's window draws every object of the L-system opaque (manual 9.4); only the
    // background scene keeps its transparency.
    if (!options.material_transparency)
        for (geom::Material& m : scene.materials)
            m.transparency = 0;
    for (const geom::TranslucencySetting& t : view.translucency)
        for (int i = t.first; i <= t.last; ++i)
            scene.materials.at(static_cast<std::size_t>(i)).translucency = t.amount;
}

/// A pass's plant as the light environment traces it: the turtle's geometry, each
/// primitive with its module in the derived string, and the model's materials.
geom::Scene light_pass_scene(const env::PassPlant& plant, const geom::Palette& palette, const Options& options)
{
    geom::InterpretOptions turtle;
    turtle.max_memory_bytes = options.max_memory_bytes;
    turtle.origins = plant.string.origins;
    if (!plant.string.origins.empty())
        turtle.derived = &plant.string.derived;
    geom::Scene scene = geom::interpret(plant.string.modules, plant.symbols, plant.view, turtle);
    set_model_materials(scene, palette, plant.view, options);
    geom::drop_unrenderable(scene);
    return scene;
}

/// QuasiMC's `.e` line: Cambium's light environment, its specification read now so that
/// its errors come before any work.
env::Connection light_connection(const env::CommSpec& spec, const env::Context& context, const Options& options)
{
    const std::vector<std::string> args(spec.executable.begin() + 1, spec.executable.end());
    auto light = std::make_shared<const env::LightSpec>(env::read_light_spec(args, context));
    auto palette = std::make_shared<const geom::Palette>(load_palette(options));
    env::Connection c;
    c.make = [light, palette, options] {
        return make_light_environment(
            *light, [palette, options](const env::PassPlant& plant) { return light_pass_scene(plant, *palette, options); },
            options.threads, light_report_ground(options));
    };
    c.description = std::filesystem::path(spec.executable.front()).filename().string() +
                    " (built in: Cambium's light environment traces the plant; no program is started)";
    return c;
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

/// Sides of a background cylinder drawn as triangles (as its ellipsoids' 32 slices).
constexpr int background_cylinder_sides = 32;

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

/// An image a built-in environment reads (clover's light map), as 8-bit RGB rows from
/// the top, through the image module.
env::RgbImage read_environment_image(const std::filesystem::path& file, std::uint64_t max_memory_bytes)
{
    std::string why;
    std::optional<render::TexturePixels> pixels =
        render::image_codec().read_texture(file, max_memory_bytes, why);
    if (!pixels)
        throw Error(FileLoc{file.string()}, "cannot read the environment's image: " + why);
    env::RgbImage image;
    image.width = pixels->width;
    image.height = pixels->height;
    const std::size_t n = static_cast<std::size_t>(pixels->width) * static_cast<std::size_t>(pixels->height);
    const int c = pixels->channels;
    image.rgb.resize(n * 3);
    for (std::size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            const std::size_t from = i * static_cast<std::size_t>(c) + static_cast<std::size_t>(std::min(k, c - 1));
            image.rgb[i * 3 + static_cast<std::size_t>(k)] =
                pixels->bytes.empty()
                    ? static_cast<std::uint8_t>(std::lround(std::clamp(pixels->floats[from], 0.0f, 1.0f) * 255))
                    : pixels->bytes[from];
        }
    return image;
}

}  // namespace

env::Connection model_environment(const Options& options, const env::CommSpec& spec)
{
    env::Context context;
    context.folder = model_folder(options);
    context.allow_file_access = options.allow_file_access;
    context.read_image = [limit = options.max_memory_bytes](const std::filesystem::path& f) {
        return read_environment_image(f, limit);
    };
    env::ProgramPermission programs;
    programs.allowed = options.allow_environment_program;
    if (options.environment_messages) {
        env::prepare_message_folder(*options.environment_messages);
        programs.limits.message_folder = std::filesystem::absolute(*options.environment_messages);
    }
    env::Connection connection = env::names_light_environment(spec.executable.front())
                                     ? light_connection(spec, context, options)
                                     : env::connect(spec, context, programs);
    if (!options.quiet)
        std::fprintf(stderr, "environment: %s\n", connection.description.c_str());
    return connection;
}

namespace {

/// Connects the `-e` file's environment to the derivation (manual 7): the environmental
/// step runs where the query pass runs, on the same string.
void connect_environment(const Options& options, lsys::LoadOptions& load,
                         const std::shared_ptr<QueryContext>& queries, const EnvironmentSeat* seat)
{
    if (!options.environment_file)
        return;
    env::CommSpec spec = env::read_comm_spec(*options.environment_file);
    env::Connection connection;
    if (seat) {
        connection.make = [environment = seat->environment, plant = seat->plant] {
            return environment->participant(plant);
        };
        connection.placement = seat->placement;
    } else {
        connection = model_environment(options, spec);
    }
    load.environment = [queries, spec = std::move(spec), connection = std::move(connection)] {
        auto step = std::make_shared<env::EnvironmentalStep>(spec, connection);
        return [queries, step](const lsys::TurtleString& string, int n) {
            if (queries->symbols)
                step->run(string, *queries->symbols, *queries->view, n);
        };
    };
}

}  // namespace

std::filesystem::path model_folder(const Options& options)
{
    return std::filesystem::weakly_canonical(std::filesystem::absolute(options.lsystem).parent_path());
}

std::shared_ptr<const geom::ViewFile> read_view(const Options& options)
{
    auto view = std::make_shared<const geom::ViewFile>(geom::read_view_file(options.view));
    if (options.allow_file_access)
        return view;
    namespace fs = std::filesystem;
    const fs::path folder = model_folder(options);
    auto refuse_outside = [&](const fs::path& named, const std::string& what, const FileLoc& loc) {
        if (!lies_within(named, folder))
            throw Error(loc, what + " '" + named.string() + "' lies outside the model's folder " +
                                 folder.string() + " (--allow-file-access lifts this)");
    };
    for (const geom::TextureDef& t : view->textures)
        refuse_outside(t.file, "texture", FileLoc{options.view.string()});
    // Every other file the view file names (surfaces, contours, functions, background
    // scenes...) that exists (or is a link), read as the readers read it, must lie inside
    // the model's folder. Names of nothing are left to the readers, which fail on them.
    for (const auto& [named, loc] : geom::named_files(*view)) {
        std::error_code ec;
        const fs::file_status status = fs::status(named, ec);
        if (fs::is_symlink(fs::symlink_status(named, ec)) ||
            (fs::exists(status) && !fs::is_directory(status)))
            refuse_outside(named, "file", loc);
    }
    return view;
}

Model load_model(const Options& options, const EnvironmentSeat* seat)
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
    connect_environment(options, load, queries, seat);
    // Fragmentation (manual 5.1.9): the turtles saved at `%(par)` before each step are
    // the model's, for drawing `%(par, index)`; each derivation run starts them afresh.
    auto fragments = std::make_shared<std::vector<geom::Turtle>>();
    const std::string lsystem_file = options.lsystem.string();
    load.fragment_pass = [queries, fragments, lsystem_file,
                          limit = load.max_saved_turtles](const lsys::ModuleString& string,
                                                          std::uint32_t first) {
        if (!queries->symbols)
            return std::vector<std::uint32_t>{};
        try {
            return geom::save_fragment_turtles(string, *queries->symbols, *queries->view,
                                               *fragments, first, limit);
        } catch (const Error& e) {
            throw Error(FileLoc{lsystem_file, 0, 0}, e.what());
        }
    };
    if (options.verbosity == Verbosity::verbose)
        load.on_step = [](int step, const lsys::ModuleString& s) {
            std::printf("step %d: %zu modules\n", step, s.size());
        };

    lsys::LSystem lsystem = lsys::LSystem::load(options.lsystem, load);
    // The program (and its symbol table) lives behind a pointer: moving the LSystem
    // into the Model keeps this address.
    queries->symbols = &lsystem.symbols();
    return Model{std::move(view), std::move(palette), std::move(functions), std::move(lsystem),
                 std::move(fragments)};
}

lsys::ModuleString derive(const Model& model, const Options& options)
{
    lsys::ModuleString derived = model.lsystem.derive(options.steps);
    if (options.homomorphism_in_string)
        return model.lsystem.interpretation_string(derived);
    return derived;
}

lsys::ModuleString derive(const Model& model, const Options& options, bool with_ages,
                          std::vector<std::uint16_t>& ages)
{
    if (!with_ages || options.homomorphism_in_string)
        return derive(model, options);
    return model.lsystem.derive_with_ages(options.steps, ages);
}

geom::Scene interpret_with_provenance(const Model& model, const lsys::ModuleString& derived,
                                      const Options& options, StringOrigins& provenance)
{
    if (turtle_reads_derived_string(model, options))
        return interpret_turtle_string(model, derived, options, &provenance);
    provenance.derived = &derived;  // the turtle string's modules name the derived ones
    lsys::ModuleString turtle = turtle_string(model, derived, options, provenance.origins);
    return interpret_turtle_string(model, turtle, options, &provenance);
}

namespace {
/// The scene's own lines: with no texture on any of them, the per-key texture v and the
/// per-segment texture index say nothing (scene.h lets both be empty), so they go, and
/// the other buffers give back their growth slack (a quarter of tree10m's Scene memory,
/// build/benchmarks/render --stats). Prototypes keep theirs: an instance's texture falls on their
/// untextured primitives.
void release_unused_line_buffers(geom::LinearCurves& l)
{
    if (std::all_of(l.texture.begin(), l.texture.end(),
                    [](std::int16_t t) { return t == geom::no_texture; })) {
        l.texture = {};
        l.v = {};
    }
    l.keys.shrink_to_fit();
    l.v.shrink_to_fit();
    l.segments.shrink_to_fit();
    l.flags.shrink_to_fit();
    l.material.shrink_to_fit();
    l.texture.shrink_to_fit();
    l.module.shrink_to_fit();
}

}  // namespace

geom::Scene interpret(const Model& model, const lsys::ModuleString& derived,
                      const Options& options)
{
    if (turtle_reads_derived_string(model, options))
        return interpret_turtle_string(model, derived, options);
    return interpret_turtle_string(model, turtle_string(model, derived, options), options);
}

bool turtle_reads_derived_string(const Model& model, const Options& options)
{
    if (options.homomorphism_in_string)
        return true;
    const lsys::Program& program = model.lsystem.program();
    if (!program.split_commands.empty())
        return false;
    for (const auto& ls : program.lsystems)
        if (!ls.homomorphism.productions.empty())
            return false;
    return true;
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

lsys::ModuleString turtle_string(const Model& model, const lsys::ModuleString& derived,
                                 const Options& options, std::vector<std::uint32_t>& origins)
{
    if (options.homomorphism_in_string) {
        origins.resize(derived.size());
        for (std::size_t i = 0; i < origins.size(); ++i)
            origins[i] = static_cast<std::uint32_t>(i);
        return derived;
    }
    return model.lsystem.interpretation_string(derived,
                                               instanced_objects(model, options).empty()
                                                   ? lsys::ObjectHandling::expand
                                                   : lsys::ObjectHandling::keep,
                                               origins);
}

namespace {

/// cpfg's wireframe: its edge width (from the view volume and the window's width), its
/// cylinders' sides, and spheres as quadrics with a material file, octahedra without.
geom::WireframeStyle wireframe_style(const Model& model, const geom::Scene& scene, const Options& options)
{
    geom::WireframeStyle style;
    style.edge_width_px = geom::wireframe_edge_width(scene.view.box.value_or(scene.bounds), options.width);
    style.sides = model.view->cylinders.sides;
    style.quadric_spheres = model.palette.mode() == geom::Palette::Mode::materials;
    return style;
}

/// The turtle's hooks and limits for this model and command line.
geom::InterpretOptions interpret_options(const Model& model, const Options& options)
{
    geom::InterpretOptions turtle;
    turtle.strings = model.lsystem.program().strings;
    if (geom::lit_by_colour_index(*model.view, model.palette)) {
        turtle.surface_material_offset = geom::colour_indices;
        turtle.next_colormap_material_offset = 2 * geom::colour_indices;
    }
    turtle.max_memory_bytes = options.max_memory_bytes;
    turtle.branch_orders = options.organ_masks;
    if (model.fragment_turtles)
        turtle.fragment_turtles = *model.fragment_turtles;
    std::vector<char> objects = instanced_objects(model, options);
    if (!objects.empty()) {
        const lsys::LSystem& lsystem = model.lsystem;
        turtle.is_object = [objects](lsys::SymbolId s) {
            return s < objects.size() && objects[s] != 0;
        };
        turtle.expand_object = [&lsystem](lsys::ModuleRef m) { return lsystem.expand_object(m); };
    }
    if (options.allow_system_calls) {
        std::filesystem::path folder = options.lsystem.parent_path();
        turtle.system_call = [folder](const std::string& command) {
            run_system_call(command, folder);
        };
    }
    return turtle;
}

}  // namespace

geom::Bounds3 view_volume(const Model& model, const lsys::ModuleString& derived,
                          const Options& options, bool box_wins)
{
    geom::InterpretOptions bounds_only = interpret_options(model, options);
    bounds_only.bounds_only = true;
    // the derived string itself where the turtle reads it unchanged (no copy of it)
    geom::Scene scene =
        turtle_reads_derived_string(model, options)
            ? geom::interpret(derived, model.lsystem.symbols(), *model.view, bounds_only)
            : geom::interpret(turtle_string(model, derived, options), model.lsystem.symbols(),
                              *model.view, bounds_only);
    geom::drop_unrenderable(scene);  // its check of the view volume's range
    return box_wins ? scene.view.box.value_or(scene.bounds) : scene.bounds;
}

geom::Scene interpret_turtle_string(const Model& model, const lsys::ModuleString& string,
                                    const Options& options, const StringOrigins* origins)
{
    geom::InterpretOptions turtle = interpret_options(model, options);
    if (origins) {
        turtle.derived = origins->derived;
        turtle.origins = origins->origins;
        turtle.ages = origins->ages;
        turtle.births = origins->births;
    }
    geom::Scene scene = geom::interpret(string, model.lsystem.symbols(), *model.view, turtle);
    const bool index_lit = geom::lit_by_colour_index(*model.view, model.palette);
    scene.shading = model.view->render_mode.shading;
    set_model_materials(scene, model.palette, *model.view, options);
    if (index_lit)
        geom::light_by_colour_index(scene, *model.view, model.palette, options.colour_block);

    geom::BackgroundScene background = geom::load_view_background(
        *model.view, scene.materials[0],
        options.allow_file_access ? std::nullopt : std::optional(model_folder(options)));
    if (!background.geometry.empty()) {
        geom::offset_materials(background.geometry,
                               static_cast<std::uint16_t>(scene.materials.size()));
        // every line of the Scene is read in pixels under `line style: pixel`; the
        // background's cylinders keep their world radius as triangles
        if (scene.line_radius_in_pixels)
            geom::cylinders_as_mesh(background.geometry, background_cylinder_sides);
        scene.materials.insert(scene.materials.end(), background.materials.begin(),
                               background.materials.end());
        geom::append_geometry(scene.geometry, background.geometry);
    }
    if (scene.shading == geom::Shading::wireframe)
        geom::draw_as_wireframe(scene, wireframe_style(model, scene, options));
    // Small instanced surfaces (petals, leaves) drawn in place: one BVH for rays to
    // walk instead of two (docs/architecture.md), within a share of the memory budget;
    // not when a glTF output keeps the organs as shared meshes.
    const bool keeps_instances = std::any_of(options.outputs.begin(), options.outputs.end(), [](const auto& out) {
        const OutputFormat* format = find_output_format(out);
        return format && format->mesh == MeshFormat::glb;
    });
    geom::FlattenLimits flatten;
    flatten.max_bytes = keeps_instances ? 0 : options.max_memory_bytes / 8;
    geom::flatten_small_instances(scene, flatten);
    // Non-finite or huge numbers would abort inside Embree: dropped here with a warning.
    geom::drop_unrenderable(scene);
    release_unused_line_buffers(scene.geometry.lines);
    geom::fit_scene_buffers(scene);
    return scene;
}

geom::RayshadeOptions rayshade_options(const Options& options, const std::filesystem::path& file,
                                       const Model* model)
{
    geom::RayshadeOptions ray;
    ray.object_name = file.filename().string();
    // a rayshade name is one word
    std::replace_if(ray.object_name.begin(), ray.object_name.end(),
                    [](unsigned char c) { return std::isspace(c) != 0; }, '_');
    ray.colormap = std::none_of(options.colour_files.begin(), options.colour_files.end(),
                                [](const ColourFile& c) { return c.materials; });
    ray.width = options.width;
    ray.height = options.height;
    if (model) {
        ray.scale = model->view->rayshade_scale;
        for (const geom::Material& m : model->palette.entries(options.colour_block))
            ray.transparency.push_back(m.transparency);
    }
    return ray;
}

}  // namespace cambium::app
