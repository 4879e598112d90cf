// SPDX-License-Identifier: Apache-2.0
// The `cambium` Python module (docs/python.md): a cpfg model loaded, derived, its string
// read and edited as arrays, interpreted and rendered into images numpy reads in place,
// written by the command's own writer. Every step goes through the libraries the command
// is made of (src/app), with the options the command parses, so a model is confined and
// bounded as under the command.
#include <pybind11/numpy.h>  // arrays are made on demand: numpy is imported on first use
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <unistd.h>

#include "app/command_line.h"
#include "app/light_report.h"
#include "app/pipeline.h"
#include "app/scene_assembly.h"
#include "app/scene_file.h"
#include "app/sequence.h"
#include "base/diagnostics.h"
#include "base/subprocess.h"
#include "geom/rayshade_export.h"
#include "lsys/string_io.h"
#include "render/framing.h"
#include "render/render.h"

namespace py = pybind11;

namespace cambium::python {
namespace {

// ---- Options: keyword arguments as the command's words ----

/// A keyword's value as one command-line word: paths through os.fspath, numbers and
/// strings as Python prints them.
std::string word(const py::handle& value)
{
    if (py::isinstance<py::str>(value))
        return value.cast<std::string>();
    if (py::hasattr(value, "__fspath__"))
        return py::str(value.attr("__fspath__")()).cast<std::string>();
    return py::str(value).cast<std::string>();
}

/// cpfg's single-dash options by their keyword names.
const char* cpfg_flag(const std::string& key)
{
    static const std::pair<const char*, const char*> table[] = {
        {"animate", "-a"},       {"homomorphism", "-homo"}, {"warnings", "-v"},
        {"verbose", "-V"},       {"environment", "-e"},     {"preprocessor", "-P"},
        {"string_text", "-str"}, {"string_binary", "-strb"}, {"view_volume", "-vv"},
        {"rayshade", "-ray"},
    };
    for (const auto& [name, flag] : table)
        if (key == name)
            return flag;
    return nullptr;
}

/// The command's words for keyword options: `colormap=` and `materials=` (a file, or a
/// dict of colour block to file) are -m / -M, `colour_block=n` is -c<n>, `width=` and
/// `height=` are -w, the cpfg_flag() names are cpfg's options, and any other keyword
/// `max_depth=6` is `--max-depth 6`: True gives the bare flag, False and None nothing,
/// a list or tuple its items.
std::vector<std::string> option_words(const py::dict& options)
{
    std::vector<std::string> words;
    std::optional<std::string> width, height;
    for (const auto& [k, value] : options) {
        std::string key = k.cast<std::string>();
        if (value.is_none())
            continue;
        if (key == "o" || key == "output" || key == "outputs")
            throw Error("keyword '" + key +
                        "': the module returns images; write them with Image.write(path)");
        if (key == "video")  // a sequence's video is a file and an ffmpeg run: the command's
            throw Error("keyword 'video': the module returns a Sequence; write its frames with "
                        "Sequence.write(pattern)");
        if (key == "mpi" || key == "tile" || key == "assemble")
            throw Error("keyword '" + key + "': a distributed render is the command's "
                        "(docs/distributed.md)");
        if (key == "colormap" || key == "materials" || key == "colourmap" ||
            key == "colormaps") {
            const std::string flag = key == "materials" ? "-M" : "-m";
            if (py::isinstance<py::dict>(value)) {
                for (const auto& [block, file] : value.cast<py::dict>()) {
                    words.push_back(flag + word(block));
                    words.push_back(word(file));
                }
            } else {
                words.push_back(flag);
                words.push_back(word(value));
            }
            continue;
        }
        if (key == "colour_block" || key == "color_block") {
            words.push_back("-c" + word(value));
            continue;
        }
        if (key == "width") {
            width = word(value);
            continue;
        }
        if (key == "height") {
            height = word(value);
            continue;
        }
        std::string flag;
        if (const char* cpfg = cpfg_flag(key)) {
            flag = cpfg;
        } else {
            flag = "--" + key;
            for (char& c : flag)
                if (c == '_')
                    c = '-';
        }
        if (py::isinstance<py::bool_>(value)) {
            if (value.cast<bool>())
                words.push_back(flag);
            continue;
        }
        words.push_back(flag);
        if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
            for (const auto& item : value)
                words.push_back(word(item));
        } else {
            words.push_back(word(value));
        }
    }
    if (width || height) {
        words.push_back("-w");
        words.push_back(width.value_or("640"));
        words.push_back(height.value_or("480"));
    }
    return words;
}

// ---- Running the work without the GIL ----

/// What a running call tells the Python thread: stages and pass previews for the
/// progress callback.
struct Events {
    std::mutex mutex;
    std::vector<std::pair<std::string, std::shared_ptr<render::Image>>> queue;
    void push(std::string stage, std::shared_ptr<render::Image> image = nullptr)
    {
        std::lock_guard lock(mutex);
        queue.emplace_back(std::move(stage), std::move(image));
    }
    auto take()
    {
        std::lock_guard lock(mutex);
        return std::exchange(queue, {});
    }
};

struct ImageObject;
py::object image_object(render::Image image, render::WriteOptions write);

/// The module's calls run one at a time, whichever Python thread makes them: each one
/// already uses every core, installs the process's warning sink, and reads symbol tables
/// that a string edit may grow.
std::mutex& call_mutex()
{
    static std::mutex calls;
    return calls;
}

/// Holds call_mutex() for a call that runs with the GIL held (a string edit): the GIL is
/// released while waiting, so the call under way can finish.
class HeldCall {
public:
    HeldCall() : m_lock(call_mutex(), std::defer_lock)
    {
        py::gil_scoped_release release;
        m_lock.lock();
    }

private:
    std::unique_lock<std::mutex> m_lock;
};

/// Runs `work` on a thread of its own while the calling (Python) thread, the GIL
/// released, waits for it and checks for signals every 50 ms: Ctrl-C (or any handler
/// that raises) sets `cancel`, which a render checks every tile row, and the exception
/// is raised once the work has stopped. The progress callback, when given, is called
/// on the Python thread with each stage's name and, for a render pass, the image so far.
/// Warnings the work reports are given to Python's warnings module (unless quiet).
void run_released(const std::function<void(std::atomic<bool>& cancel, Events& events)>& work,
                  const py::object& progress, bool quiet, const render::WriteOptions& write = {})
{
    std::atomic<bool> cancel{false};
    Events events;
    Diagnostics diagnostics(Diagnostics::Output::quiet);
    std::exception_ptr failure;
    std::atomic<bool> done{false};
    std::thread worker([&] {
        try {
            std::lock_guard one_at_a_time(call_mutex());
            if (cancel.load())
                return;
            ScopedDiagnostics install(diagnostics, ScopedDiagnostics::Reach::process);
            work(cancel, events);
        } catch (...) {
            failure = std::current_exception();
        }
        done.store(true);
    });
    std::optional<py::error_already_set> raised;
    auto deliver = [&] {
        if (progress.is_none() || raised)
            return;
        for (auto& [stage, image] : events.take()) {
            try {
                if (image)
                    progress(stage, image_object(std::move(*image), write));
                else
                    progress(stage, py::none());
            } catch (py::error_already_set& e) {
                raised.emplace(std::move(e));
                cancel.store(true);
                return;
            }
        }
    };
    while (!done.load()) {
        {
            py::gil_scoped_release release;
            for (int i = 0; i < 10 && !done.load(); ++i)
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        if (!raised && PyErr_CheckSignals() != 0) {
            raised.emplace();  // fetches the KeyboardInterrupt
            cancel.store(true);
        }
        deliver();
    }
    {
        py::gil_scoped_release release;
        worker.join();
    }
    deliver();
    if (!quiet)
        for (const Diagnostic& d : diagnostics.collected())
            if (d.severity == Severity::warning &&
                PyErr_WarnEx(PyExc_UserWarning, d.to_string().c_str(), 1) != 0)
                throw py::error_already_set();
    if (raised)
        throw std::move(*raised);
    if (failure)
        std::rethrow_exception(failure);
}

// ---- Objects ----

/// The files and keywords of a load: the options of each call are the load's keywords
/// with that call's over them, parsed as the command parses them.
struct Loaded {
    std::vector<std::string> files;  // plant.l plant.v [plant.a], or scene.json
    py::dict keywords;
    app::Options options;

    app::Options options_with(const py::dict& more) const
    {
        py::dict merged;
        for (const auto& [k, v] : keywords)
            merged[k] = v;
        for (const auto& [k, v] : more)
            merged[k] = v;
        std::vector<std::string> words = option_words(merged);
        words.insert(words.end(), files.begin(), files.end());
        std::optional<app::Options> parsed = app::parse_command_line(words);
        if (!parsed)
            throw Error("the options asked for help or the version, not a model");
        return *parsed;
    }
};

/// A loaded model: its files read once.
struct ModelObject : Loaded {
    std::shared_ptr<app::Model> model;
};

/// A loaded scene file of many plants (docs/scenes.md), read and checked once.
struct SceneObject : Loaded {
    std::shared_ptr<const app::SceneFile> scene;
};

/// A derived string: the model's symbols, its modules' parameters editable in place.
struct StringObject {
    std::shared_ptr<app::Model> model;
    lsys::ModuleString string;

    std::size_t index(long i) const
    {
        long n = long(string.size());
        if (i < 0)
            i += n;
        if (i < 0 || i >= n)
            throw py::index_error("module index out of range");
        return std::size_t(i);
    }
    std::vector<std::int64_t> offsets() const
    {
        std::vector<std::int64_t> out(string.size());
        std::int64_t at = 0;
        for (std::size_t i = 0; i < string.size(); ++i) {
            out[i] = at;
            at += string.param_count(i);
        }
        return out;
    }
    std::string name(std::size_t i) const
    {
        return std::string(model->lsystem.symbols().name(string.symbol(i)));
    }
    /// The position for an insertion before module i (i == size() appends).
    std::size_t gap(long i) const
    {
        long n = long(string.size());
        if (i < 0)
            i += n;
        if (i < 0 || i > n)
            throw py::index_error("insertion point out of range");
        return std::size_t(i);
    }
    /// Modules [first, last) replaced by those cpfg's string text `text` reads as; names
    /// the model never used are added to its symbols (the turtle reads them by name).
    void splice(std::size_t first, std::size_t last, const std::string& text)
    {
        HeldCall held;
        std::istringstream in(text);
        const lsys::ModuleString middle = lsys::read_string_text(
            in, model->lsystem.symbols(), "<string text>", {.max_modules = max_modules});
        const std::size_t size = string.size() - (last - first) + middle.size();
        if (size > max_modules)
            throw Error("the edited string would have " + std::to_string(size) +
                        " modules, more than the limit of " + std::to_string(max_modules) +
                        " (max_modules=)");
        const std::vector<std::int64_t> at = offsets();
        const auto param_at = [&](std::size_t i) {
            return i < at.size() ? std::size_t(at[i]) : string.param_total();
        };
        lsys::ModuleString out;
        out.reserve(size, string.param_total() + middle.param_total());
        out.append_range(string, 0, first, 0);
        out.append(middle);
        out.append_range(string, last, string.size(), param_at(last));
        string = std::move(out);
    }

    std::size_t max_modules = lsys::StringReadLimits{}.max_modules;
};

/// A rendered image: rows top to bottom, RGBA floats (linear; the buffer numpy reads),
/// with the albedo, normal and depth layers when computed.
struct ImageObject {
    render::Image image;
    render::WriteOptions write;
};

py::object image_object(render::Image image, render::WriteOptions write)
{
    return py::cast(ImageObject{std::move(image), write});
}

/// A layer of `self` as a numpy array over its memory (None when not computed).
py::object layer(py::object self, std::vector<float> render::Image::*member, int channels)
{
    ImageObject& o = self.cast<ImageObject&>();
    const std::vector<float>& data = o.image.*member;
    if (data.empty())
        return py::none();
    std::vector<py::ssize_t> shape{o.image.height, o.image.width};
    std::vector<py::ssize_t> strides{py::ssize_t(sizeof(float)) * o.image.width * channels,
                                     py::ssize_t(sizeof(float)) * channels};
    if (channels > 1) {
        shape.push_back(channels);
        strides.push_back(sizeof(float));
    }
    return py::array(py::dtype::of<float>(), shape, strides, data.data(), self);
}

void write_image(const ImageObject& o, const std::filesystem::path& file)
{
    py::gil_scoped_release release;
    render::write_image(o.image, file, o.write);
}

/// PNG bytes for notebooks, written by write_image into a private temporary folder.
py::bytes png_bytes(const ImageObject& o)
{
    std::string bytes;
    {
        py::gil_scoped_release release;
        std::string pattern = (std::filesystem::temp_directory_path() / "cambium-XXXXXX").string();
        if (!mkdtemp(pattern.data()))
            throw Error("cannot make a temporary folder for the PNG");
        std::filesystem::path folder = pattern;
        try {
            std::filesystem::path file = folder / "image.png";
            render::write_image(o.image, file, o.write);
            std::ifstream in(file, std::ios::binary);
            std::ostringstream text;
            text << in.rdbuf();
            bytes = text.str();
        } catch (...) {
            std::error_code ec;
            std::filesystem::remove_all(folder, ec);
            throw;
        }
        std::error_code ec;
        std::filesystem::remove_all(folder, ec);
    }
    return py::bytes(bytes);
}

py::dict view_settings(const geom::ViewFile& v)
{
    auto vec = [](const geom::Vec3& p) { return py::make_tuple(p.x, p.y, p.z); };
    py::dict d;
    d["file"] = v.path.string();
    d["angle_increment"] = v.angle_increment_deg;
    d["initial_line_width"] = v.initial_line_width;
    d["line_width_increment"] = v.line_width_increment;
    d["line_style"] = v.line_style == geom::LineStyle::pixel     ? "pixel"
                      : v.line_style == geom::LineStyle::polygon ? "polygon"
                                                                 : "cylinder";
    d["initial_color"] = v.initial_color;
    d["color_increment"] = v.color_increment;
    d["initial_scale"] = v.initial_scale;
    d["scale_multiplier"] = v.scale_multiplier;
    d["tapered_lines"] = v.tapered_lines;
    d["viewpoint"] = vec(v.view.viewpoint);
    d["view_reference_point"] = vec(v.view.reference_point);
    d["twist"] = v.view.twist_deg;
    d["projection"] = v.view.perspective ? "perspective" : "parallel";
    d["viewing_angle"] = v.view.viewing_angle_deg;
    d["scale_factor"] = v.view.scale_factor;
    if (v.view.box)
        d["box"] = py::make_tuple(vec(v.view.box->lo), vec(v.view.box->hi));
    else
        d["box"] = py::none();
    d["front_distance"] = v.view.front_distance ? py::cast(*v.view.front_distance) : py::none();
    d["back_distance"] = v.view.back_distance ? py::cast(*v.view.back_distance) : py::none();
    const geom::Shading mode = v.render_mode.shading;
    d["render_mode"] = mode == geom::Shading::shaded   ? "shaded"
                       : mode == geom::Shading::flat   ? "flat"
                       : mode == geom::Shading::filled ? "filled"
                                                       : "wireframe";
    d["lights"] = v.lights.size();
    d["textures"] = v.textures.size();
    d["contours"] = v.cylinders.contours.size();
    d["surfaces"] = v.surfaces.size();
    d["functions"] = v.functions.size();
    d["curves"] = v.curves.size();
    d["background_scenes"] = v.background_scenes.size();
    return d;
}

ModelObject load(const py::object& lsystem, const py::object& view, const py::object& animation,
                 const py::object& progress, const py::kwargs& keywords)
{
    ModelObject m;
    m.files.push_back(word(lsystem));
    if (view.is_none()) {
        m.files.push_back(std::filesystem::path(m.files[0]).replace_extension(".v").string());
    } else {
        m.files.push_back(word(view));
    }
    if (!animation.is_none())
        m.files.push_back(word(animation));
    for (const auto& [k, v] : keywords)
        m.keywords[k] = v;
    m.options = m.options_with(py::dict());
    if (m.options.scene)
        throw Error("a scene file is loaded with cambium.load_scene()");
    const app::Options& options = m.options;
    run_released(
        [&](std::atomic<bool>&, Events& events) {
            events.push("load");
            m.model = std::make_shared<app::Model>(app::load_model(options));
        },
        progress, options.quiet);
    return m;
}

/// The string to render: `string` (a String of this model) or none, to derive.
std::optional<lsys::ModuleString> given_string(const ModelObject& m, const py::object& string)
{
    if (string.is_none())
        return std::nullopt;
    StringObject& s = string.cast<StringObject&>();
    if (s.model != m.model)
        throw Error("the string was derived from another model");
    return s.string;
}

/// Derives (unless given a string), interprets and applies the camera options.
geom::Scene model_scene(const ModelObject& m, std::optional<lsys::ModuleString>& given,
                        const app::Options& options, Events& events)
{
    if (!given) {
        events.push("derive");
        given = app::derive(*m.model, options);
    }
    events.push("interpret");
    app::StringOrigins provenance;  // organs named by the derived string's modules, as the command's
    geom::Scene scene = app::interpret_with_provenance(*m.model, *given, options, provenance);
    given.reset();
    app::apply_camera_options(scene, options);
    return scene;
}

py::dict keyword_dict(const py::kwargs& keywords)
{
    py::dict more;
    for (const auto& [k, v] : keywords)
        more[k] = v;
    return more;
}

py::object render_model(ModelObject& m, const py::object& string, bool layers,
                        const py::object& progress, const py::kwargs& keywords)
{
    const app::Options options = m.options_with(keyword_dict(keywords));
    if (app::is_sequence(options))
        throw Error("a sequence is not one image: use Model.animate() or Model.turntable()");
    std::optional<lsys::ModuleString> given = given_string(m, string);
    render::RenderSettings settings = app::render_settings(options, {});
    settings.aovs = layers;
    const render::WriteOptions write = app::write_options(options);
    render::Image image;
    render::RenderReport report;
    run_released(
        [&](std::atomic<bool>& cancel, Events& events) {
            geom::Scene scene = model_scene(m, given, options, events);
            settings.cancel = &cancel;
            if (!progress.is_none())
                settings.on_pass = [&](const render::Image& so_far) {
                    events.push("pass", std::make_shared<render::Image>(so_far));
                };
            events.push("render");
            image = render::render(scene, settings, &report);
        },
        progress, options.quiet, write);
    return image_object(std::move(image), write);
}

SceneObject load_scene(const py::object& file, const py::object& progress,
                       const py::kwargs& keywords)
{
    SceneObject o;
    o.files.push_back(word(file));
    o.keywords = keyword_dict(keywords);
    o.options = o.options_with(py::dict());
    if (!o.options.scene)
        throw Error(o.files[0] + ": a scene file is a .json file (docs/scenes.md)");
    app::refuse_single_model_options(o.options);
    run_released(
        [&](std::atomic<bool>&, Events& events) {
            events.push("load");
            o.scene = std::make_shared<const app::SceneFile>(
                app::read_scene_file(*o.options.scene, o.options));
        },
        progress, o.options.quiet);
    return o;
}

/// The scene's plants derived, interpreted and placed (each time: a render's options
/// may change their steps or limits), then rendered as the command renders a still.
/// The plant's geometry, each primitive knowing its module, as the command interprets a
/// still: the `given` string (moved from), else a derivation (with its ages when
/// `with_ages`). Runs on the worker thread of run_released.
geom::Scene plant_with_provenance(ModelObject& m, const app::Options& options,
                                  std::optional<lsys::ModuleString>& given, bool with_ages,
                                  Events& events)
{
    app::StringOrigins provenance;
    lsys::ModuleString derived;
    if (given) {
        derived = std::move(*given);
    } else {
        events.push("derive");
        derived = app::derive(*m.model, options, with_ages, provenance.ages);
    }
    events.push("interpret");
    return app::interpret_with_provenance(*m.model, derived, options, provenance);
}

/// Where light_report() writes: the caller's file (checked by the command line's rules),
/// or a private temporary one read back and removed.
class ReportFile {
public:
    explicit ReportFile(const py::object& path)
    {
        if (!path.is_none()) {
            m_file = word(path);
            return;
        }
        std::string pattern = (std::filesystem::temp_directory_path() / "cambium-XXXXXX").string();
        if (!mkdtemp(pattern.data()))
            throw Error("cannot make a temporary folder for the light report");
        m_folder = pattern;
        m_file = m_folder / "light.json";
    }
    ReportFile(const ReportFile&) = delete;
    ReportFile& operator=(const ReportFile&) = delete;
    ~ReportFile()
    {
        std::error_code ec;
        if (!m_folder.empty())
            std::filesystem::remove_all(m_folder, ec);
    }
    const std::filesystem::path& file() const { return m_file; }
    /// The JSON report as Python values; None for a .csv file.
    py::object json() const
    {
        if (m_file.extension() != ".json")
            return py::none();
        std::ifstream in(m_file, std::ios::binary);
        std::ostringstream text;
        text << in.rdbuf();
        return py::module_::import("json").attr("loads")(text.str());
    }

private:
    std::filesystem::path m_folder;
    std::filesystem::path m_file;
};

void check_still_light_report(const app::Options& options)
{
    if (app::is_sequence(options))
        throw Error("--light-report measures a still; not with -a, --turntable or --inbetween");
}

/// --light-report: the light each organ absorbs (docs/light.md), traced as the command
/// traces it (the derivation's ages and the modules' provenance included) and written by
/// its writer to `path` (.json or .csv); returns the JSON report as Python values.
py::object light_report(ModelObject& m, const py::object& path, const py::object& string,
                        const py::object& progress, const py::kwargs& keywords)
{
    const ReportFile report(path);
    py::dict more = keyword_dict(keywords);
    more["light_report"] = report.file().string();
    const app::Options options = m.options_with(more);
    check_still_light_report(options);
    std::optional<lsys::ModuleString> given = given_string(m, string);
    run_released(
        [&](std::atomic<bool>&, Events& events) {
            const geom::Scene scene = plant_with_provenance(m, options, given, true, events);
            events.push("trace");
            app::write_light_report(scene, options);
        },
        progress, options.quiet);
    return report.json();
}

/// Refuses an export name whose extension names no geometry or drawing output.
void check_export_name(const std::filesystem::path& file)
{
    const std::string extension = file.extension().string();
    if (extension != ".ray" && extension != ".iv" && !app::is_geometry_output(file))
        throw Error(file.string() + ": export writes .obj, .ply, .glb, .gls, .ps, .svg, .pdf, "
                                    ".ray or .iv; images come from render()");
}

/// Writes `scene` to `file` by its extension, as the command's -o, -ray and -iv do;
/// `model` (a plant's, or null for a scene file's plants) gives -ray its predefined surfaces.
void write_export(const geom::Scene& scene, const app::Options& options,
                  const std::filesystem::path& file, const app::Model* model)
{
    const std::string extension = file.extension().string();
    if (extension == ".ray")
        geom::write_rayshade(scene, file, app::rayshade_options(options, file, model));
    else if (extension == ".iv")
        app::write_inventor_output(scene, options, file);
    else
        app::write_geometry_output(scene, options, file);
}

/// The command's sequence code stopped early (a render cancelled with no Python exception
/// to raise) is an error rather than a short sequence.
void require_last_frame(int status)
{
    if (status != 0)
        throw Error("the sequence stopped before its last frame (exit status " +
                    std::to_string(status) + ")");
}

/// -a with a geometry output: each frame's file written by the command's sequence code
/// (`pattern`'s number field given the frame's step, checked as the command checks it),
/// nothing rendered. Returns the names written, frame after frame.
py::list export_frames(const std::filesystem::path& pattern, app::Options options,
                       const py::object& progress)
{
    app::SequenceOutputs out;
    const std::string extension = pattern.extension().string();
    if (extension == ".ray")
        options.rayshade = pattern;
    else if (extension == ".iv")
        options.inventor = pattern;
    else
        out.geometry = {pattern};
    std::vector<std::filesystem::path> written;
    int status = 0;
    run_released(
        [&](std::atomic<bool>& cancel, Events& events) {
            out.settings = app::render_settings(options, {});
            out.settings.cancel = &cancel;  // checked between frames
            out.write_strings = [](const app::Model&, const lsys::ModuleString&, int) {};
            out.say = [](const std::string&) {};
            out.geometry_written = [&](const std::filesystem::path& file) {
                written.push_back(file);
                events.push("frame");
            };
            events.push("derive");
            status = app::run_sequence(options, out);
        },
        progress, options.quiet);
    require_last_frame(status);
    py::list names;
    for (const std::filesystem::path& file : written)
        names.append(file.string());
    return names;
}

/// The plant's geometry written to `path` as the command writes it: a mesh or drawing by
/// the extension (`-o`: .obj, .ply, .glb, .gls, .ps, .svg, .pdf), cpfg's rayshade scene
/// for .ray (`-ray`) and its Inventor scene for .iv (`-iv`). With animate=True, as `-a`:
/// a file per frame, whose names are returned.
py::object export_geometry(ModelObject& m, const py::object& path, const py::object& string,
                           const py::object& progress, const py::kwargs& keywords)
{
    const std::filesystem::path file = word(path);
    check_export_name(file);
    const app::Options options = m.options_with(keyword_dict(keywords));
    if (options.shot.turntable > 0)
        throw Error(file.string() + ": a turntable turns one geometry: export the still "
                                    "(without turntable=)");
    if (options.shot.animate) {
        if (!string.is_none())
            throw Error("animate=True derives each frame's string; export a given string as "
                        "a still");
        return export_frames(file, options, progress);
    }
    std::optional<lsys::ModuleString> given = given_string(m, string);
    run_released(
        [&](std::atomic<bool>&, Events& events) {
            const geom::Scene scene = plant_with_provenance(m, options, given, false, events);
            write_export(scene, options, file, m.model.get());
        },
        progress, options.quiet);
    return py::none();
}

/// A scene call's file and options: the load's keywords with the call's over them, and
/// both over the scene file's settings, as the command applies them.
struct SceneCall {
    app::SceneFile file;
    app::Options options;
};

SceneCall scene_call(const SceneObject& o, const py::dict& more)
{
    SceneCall call{*o.scene, o.options_with(more)};
    app::apply_scene_settings(call.file, call.options);
    if (call.options.steps)  // steps= derives every plant that many steps
        for (app::ScenePlant& plant : call.file.plants)
            plant.steps = {call.options.steps};
    return call;
}

py::object render_scene(SceneObject& o, bool layers, const py::object& progress,
                        const py::kwargs& keywords)
{
    const SceneCall call = scene_call(o, keyword_dict(keywords));
    const app::Options& options = call.options;
    if (app::is_sequence(options))
        throw Error("a sequence is not one image: use Scene.turntable()");
    render::RenderSettings settings = app::render_settings(options, {});
    settings.aovs = layers;
    const render::WriteOptions write = app::write_options(options);
    render::Image image;
    run_released(
        [&](std::atomic<bool>& cancel, Events& events) {
            events.push("assemble");
            geom::Scene scene = app::assemble_scene(call.file, options);
            app::apply_camera_options(scene, options);
            settings.cancel = &cancel;
            if (!progress.is_none())
                settings.on_pass = [&](const render::Image& so_far) {
                    events.push("pass", std::make_shared<render::Image>(so_far));
                };
            events.push("render");
            image = render::render(scene, settings);
        },
        progress, options.quiet, write);
    return image_object(std::move(image), write);
}

/// The scene's plants, each organ of each placement, written as the command's -o, -ray
/// and -iv write a scene file's still (instanced plants kept as instances where the
/// format can).
void export_scene(SceneObject& o, const py::object& path, const py::object& progress,
                  const py::kwargs& keywords)
{
    const std::filesystem::path file = word(path);
    check_export_name(file);
    const SceneCall call = scene_call(o, keyword_dict(keywords));
    if (app::is_sequence(call.options))
        throw Error(file.string() + ": export writes a still's geometry; not with --turntable");
    run_released(
        [&](std::atomic<bool>&, Events& events) {
            events.push("assemble");
            const geom::Scene scene = app::assemble_scene(call.file, call.options);
            write_export(scene, call.options, file, nullptr);
        },
        progress, call.options.quiet);
}

/// --light-report over a scene file's plants: each organ of each placement.
py::object scene_light_report(SceneObject& o, const py::object& path, const py::object& progress,
                              const py::kwargs& keywords)
{
    const ReportFile report(path);
    py::dict more = keyword_dict(keywords);
    more["light_report"] = report.file().string();
    const SceneCall call = scene_call(o, more);
    check_still_light_report(call.options);
    run_released(
        [&](std::atomic<bool>&, Events& events) {
            events.push("assemble");
            const geom::Scene scene = app::assemble_scene(call.file, call.options);
            events.push("trace");
            app::write_light_report(scene, call.options);
        },
        progress, call.options.quiet);
    return report.json();
}

/// A derivation in progress, one step (or a few) at a time.
struct DerivationObject {
    std::shared_ptr<app::Model> model;
    std::unique_ptr<lsys::Derivation> derivation;
    bool quiet = false;

    StringObject string() const { return StringObject{model, derivation->string()}; }
    StringObject advance(int steps, const py::object& progress)
    {
        if (steps < 0)
            throw Error("advance: steps must be 0 or more");
        run_released(
            [&](std::atomic<bool>&, Events& events) {
                events.push("derive");
                derivation->advance(steps);
            },
            progress, quiet);
        return string();
    }
};

/// Frames of a sequence, numbered from 1 as the command numbers them.
struct SequenceObject {
    py::list frames;
    int fps = 24;
};

/// A turntable's keywords: the call's with --turntable and --turntable-elevation.
py::dict turntable_keywords(const py::kwargs& keywords, int frames, std::optional<double> elevation)
{
    py::dict more = keyword_dict(keywords);
    more["turntable"] = frames;
    if (elevation)
        more["turntable_elevation"] = *elevation;
    return more;
}

/// A turntable as the command's --turntable renders it: derived and interpreted once,
/// `frames` views orbiting the vertical axis through the plant, one BVH for all.
SequenceObject turntable_model(ModelObject& m, int frames, std::optional<double> elevation,
                               const py::object& string, bool layers, const py::object& progress,
                               const py::kwargs& keywords)
{
    const app::Options options = m.options_with(turntable_keywords(keywords, frames, elevation));
    std::optional<lsys::ModuleString> given = given_string(m, string);
    render::RenderSettings settings = app::render_settings(options, {});
    settings.aovs = layers;
    const render::WriteOptions write = app::write_options(options);
    std::vector<render::Image> images;
    run_released(
        [&](std::atomic<bool>& cancel, Events& events) {
            geom::Scene scene = model_scene(m, given, options, events);
            std::vector<render::Camera> cameras = render::turntable_cameras(
                scene.view, scene.bounds, options.shot.turntable, options.shot.turntable_elevation,
                settings.width, settings.height);
            if (settings.aperture_radius > 0)
                for (render::Camera& c : cameras)
                    c = c.with_lens(settings.aperture_radius, settings.focus_distance);
            settings.cancel = &cancel;
            events.push("render");
            render::render_views(scene, cameras, settings,
                                 [&](std::size_t, render::Image& image, const render::RenderReport& r) {
                                     images.push_back(std::move(image));
                                     events.push("frame");
                                     return !r.cancelled;
                                 });
        },
        progress, options.quiet, write);
    SequenceObject sequence;
    sequence.fps = options.shot.fps;
    for (render::Image& image : images)
        sequence.frames.append(image_object(std::move(image), write));
    return sequence;
}

/// Runs the command's own sequence code (app::run_sequence) with each frame's image kept
/// instead of written, and returns the frames in the order of their numbers. With
/// `scene_file`, the turntable turns that scene file's plants, assembled once.
SequenceObject kept_sequence(const app::Options& options, bool layers, const py::object& progress,
                             const app::SceneFile* scene_file = nullptr)
{
    const render::WriteOptions write = app::write_options(options);
    std::vector<std::pair<int, render::Image>> images;
    int status = 0;
    run_released(
        [&](std::atomic<bool>& cancel, Events& events) {
            app::SequenceOutputs out;
            out.settings = app::render_settings(options, {});
            out.settings.aovs = layers;
            out.settings.cancel = &cancel;
            out.write_strings = [](const app::Model&, const lsys::ModuleString&, int) {};
            out.say = [](const std::string&) {};
            out.frame_images = [&](const render::Image& image, int number) {
                images.emplace_back(number, image);
                events.push("frame");
            };
            if (scene_file)
                out.make_scene = [&] {
                    events.push("assemble");
                    geom::Scene scene = app::assemble_scene(*scene_file, options);
                    events.push("render");  // the orbit's frames follow
                    return scene;
                };
            else
                events.push("render");
            status = app::run_sequence(options, out);
        },
        progress, options.quiet, write);
    require_last_frame(status);
    std::stable_sort(images.begin(), images.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    SequenceObject sequence;
    sequence.fps = options.shot.fps;
    for (auto& [number, image] : images)
        sequence.frames.append(image_object(std::move(image), write));
    return sequence;
}

/// cpfg's animation mode (-a, with the load's animation file or cpfg's default frames)
/// as the command renders it, every frame kept in a Sequence in the order of its number:
/// the same frames, cameras and in-betweens, through the command's own sequence code.
SequenceObject animate_model(ModelObject& m, bool layers, const py::object& progress, const py::kwargs& keywords)
{
    py::dict more = keyword_dict(keywords);
    more["animate"] = true;
    const app::Options options = m.options_with(more);
    if (options.shot.turntable > 0)
        throw Error("animate() renders -a frames; use Model.turntable() for a turntable");
    return kept_sequence(options, layers, progress);
}

/// A scene file's turntable as `cambium field.json --turntable N` renders it: the plants
/// assembled once, `frames` views orbiting them, through the command's turntable code.
SequenceObject turntable_scene(SceneObject& o, int frames, std::optional<double> elevation,
                               bool layers, const py::object& progress, const py::kwargs& keywords)
{
    const SceneCall call = scene_call(o, turntable_keywords(keywords, frames, elevation));
    if (call.options.light_report)
        check_still_light_report(call.options);
    return kept_sequence(call.options, layers, progress, &call.file);
}

/// The frames as an HTML animation (PNG frames shown in turn by a small script), for
/// notebooks: no video encoder needed.
std::string sequence_html(const SequenceObject& s)
{
    py::object b64 = py::module_::import("base64").attr("b64encode");
    std::string id = "cambium" + std::to_string(reinterpret_cast<std::uintptr_t>(&s));
    std::string frames;
    for (const auto& f : s.frames) {
        py::bytes png = png_bytes(f.cast<const ImageObject&>());
        frames += (frames.empty() ? "\"" : ",\"") + std::string("data:image/png;base64,") +
                  b64(png).attr("decode")().cast<std::string>() + "\"";
    }
    if (frames.empty())
        return "<p>(no frames)</p>";
    return "<img id=\"" + id + "\"><script>(function(){var f=[" + frames +
           "],i=0,e=document.getElementById(\"" + id + "\");function n(){e.src=f[i];i=(i+1)%f.length;}"
           "n();setInterval(n," + std::to_string(1000 / std::max(1, s.fps)) + ");})();</script>";
}

}  // namespace
}  // namespace cambium::python

PYBIND11_MODULE(cambium, m)
{
    using namespace cambium;
    using namespace cambium::python;
    m.doc() = "Cambium: derive, interpret and path-trace cpfg plant models (docs/python.md).";

    static py::exception<Error> error_type(m, "Error", PyExc_Exception);
    error_type.doc() = "An error in a model's files or in the options: the message names the "
                       "file, line and column; so do the attributes file, line and column.";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p)
                std::rethrow_exception(p);
        } catch (const Interrupted& e) {
            PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
        } catch (const Error& e) {
            py::object error = py::handle(error_type.ptr())(e.what());
            const FileLoc& loc = e.loc();
            error.attr("file") = loc.file.empty() ? py::object(py::none()) : py::str(loc.file);
            error.attr("line") = loc.line > 0 ? py::object(py::int_(loc.line)) : py::none();
            error.attr("column") = loc.column > 0 ? py::object(py::int_(loc.column)) : py::none();
            PyErr_SetObject(error_type.ptr(), error.ptr());
        }
    });

    py::class_<ImageObject>(m, "Image", py::buffer_protocol(),
                            "A rendered image: numpy.asarray(image) is its height x width x 4 "
                            "float32 RGBA (linear) without a copy.")
        .def_buffer([](ImageObject& o) {
            const py::ssize_t w = o.image.width, h = o.image.height;
            return py::buffer_info(o.image.rgba.data(), sizeof(float),
                                   py::format_descriptor<float>::format(), 3, {h, w, py::ssize_t(4)},
                                   {py::ssize_t(sizeof(float)) * w * 4,
                                    py::ssize_t(sizeof(float)) * 4, py::ssize_t(sizeof(float))});
        })
        .def_property_readonly("width", [](const ImageObject& o) { return o.image.width; })
        .def_property_readonly("height", [](const ImageObject& o) { return o.image.height; })
        .def_property_readonly("transparent",
                               [](const ImageObject& o) { return o.image.transparent; })
        .def_property_readonly(
            "albedo", [](py::object self) { return layer(self, &render::Image::albedo, 3); },
            "First-hit diffuse colour, height x width x 3 (None unless rendered with layers)")
        .def_property_readonly(
            "normal", [](py::object self) { return layer(self, &render::Image::normal, 3); },
            "First-hit shading normal, height x width x 3 (None unless rendered with layers)")
        .def_property_readonly(
            "depth", [](py::object self) { return layer(self, &render::Image::depth, 1); },
            "Nearest hit distance, height x width (None unless rendered with layers)")
        .def("write", &write_image, py::arg("path"),
             "Writes the image by its extension (.png .exr .tif .jpg .rgb .tga) as the "
             "command writes it, with the render's --exposure and --tonemap")
        .def("_repr_png_", &png_bytes)
        .def("__repr__", [](const ImageObject& o) {
            return "<cambium.Image " + std::to_string(o.image.width) + "x" +
                   std::to_string(o.image.height) + ">";
        });

    py::class_<StringObject>(m, "String",
                             "A derived L-system string: symbols and parameters as arrays; "
                             "parameters can be edited in place before rendering.")
        .def("__len__", [](const StringObject& s) { return s.string.size(); })
        .def("__str__",
             [](const StringObject& s) {
                 std::ostringstream out;
                 lsys::write_string_text(s.string, s.model->lsystem.symbols(), out);
                 return out.str();
             })
        .def("__repr__",
             [](const StringObject& s) {
                 return "<cambium.String of " + std::to_string(s.string.size()) + " modules>";
             })
        .def("__getitem__",
             [](const StringObject& s, long i) {
                 std::size_t k = s.index(i);
                 std::int64_t at = s.offsets()[k];
                 py::list params;
                 for (std::size_t p = 0; p < s.string.param_count(k); ++p)
                     params.append(s.string.param_data()[at + std::int64_t(p)]);
                 return py::make_tuple(s.name(k), py::tuple(params));
             })
        .def_property_readonly(
            "symbols",
            [](const StringObject& s) {
                py::array_t<std::uint16_t> out(py::ssize_t(s.string.size()));
                auto w = out.mutable_unchecked<1>();
                for (std::size_t i = 0; i < s.string.size(); ++i)
                    w(py::ssize_t(i)) = s.string.symbol(i);
                return out;
            },
            "Each module's symbol id (uint16, an index into names)")
        .def_property_readonly(
            "names",
            [](const StringObject& s) {
                py::list names;
                const lsys::SymbolTable& t = s.model->lsystem.symbols();
                for (std::size_t i = 0; i < t.size(); ++i)
                    names.append(std::string(t.name(lsys::SymbolId(i))));
                return names;
            },
            "The model's symbol names by id")
        .def_property_readonly(
            "counts",
            [](const StringObject& s) {
                return py::array_t<std::uint8_t>(py::ssize_t(s.string.size()),
                                                 s.string.count_data());
            },
            "Each module's number of parameters (uint8)")
        .def_property_readonly(
            "offsets",
            [](const StringObject& s) {
                std::vector<std::int64_t> o = s.offsets();
                return py::array_t<std::int64_t>(py::ssize_t(o.size()), o.data());
            },
            "Where each module's parameters start in parameters (int64)")
        .def_property_readonly(
            "parameters",
            [](py::object self) {
                StringObject& s = self.cast<StringObject&>();
                std::span<float> p = s.string.mutable_params();
                return py::array_t<float>(py::ssize_t(p.size()), p.data(), self);
            },
            "All parameters, module after module (float32, writable, without a copy)")
        .def(
            "find",
            [](const StringObject& s, const std::string& name) {
                std::vector<std::int64_t> found;
                int id = s.model->lsystem.symbols().find(name);
                if (id >= 0)
                    for (std::size_t i = 0; i < s.string.size(); ++i)
                        if (s.string.symbol(i) == id)
                            found.push_back(std::int64_t(i));
                return py::array_t<std::int64_t>(py::ssize_t(found.size()), found.data());
            },
            py::arg("name"), "The indices of the modules named `name`")
        .def(
            "set_parameter",
            [](StringObject& s, long i, int k, float value) {
                std::size_t m = s.index(i);
                if (k < 0 || std::size_t(k) >= s.string.param_count(m))
                    throw py::index_error("module " + std::to_string(m) + " (" + s.name(m) +
                                          ") has " + std::to_string(s.string.param_count(m)) +
                                          " parameters");
                s.string.mutable_params()[std::size_t(s.offsets()[m]) + std::size_t(k)] = value;
            },
            py::arg("module"), py::arg("parameter"), py::arg("value"),
            "Sets parameter k of module i")
        .def(
            "insert",
            [](StringObject& s, long i, const std::string& text) {
                const std::size_t at = s.gap(i);
                s.splice(at, at, text);
            },
            py::arg("index"), py::arg("text"),
            "Inserts the modules of cpfg's string text (as -str writes it: \"[+F(1.5)]\") "
            "before module `index` (len(string) appends)")
        .def(
            "replace",
            [](StringObject& s, long start, long stop, const std::string& text) {
                const std::size_t first = s.gap(start), last = s.gap(stop);
                if (last < first)
                    throw py::index_error("replace: stop before start");
                s.splice(first, last, text);
            },
            py::arg("start"), py::arg("stop"), py::arg("text"),
            "Replaces modules start to stop (stop excluded) by those of cpfg's string text")
        .def("__delitem__",
             [](StringObject& s, long i) {
                 const std::size_t at = s.index(i);
                 s.splice(at, at + 1, "");
             })
        .def("__delitem__", [](StringObject& s, const py::slice& range) {
            py::ssize_t start = 0, stop = 0, step = 0, length = 0;
            if (!range.compute(py::ssize_t(s.string.size()), &start, &stop, &step, &length))
                throw py::error_already_set();
            if (step != 1)
                throw py::value_error("deleting modules takes a slice with step 1");
            if (length > 0)
                s.splice(std::size_t(start), std::size_t(stop), "");
        });

    py::class_<DerivationObject>(m, "Derivation",
                                 "A derivation from the axiom, advanced step by step")
        .def("advance", &DerivationObject::advance, py::arg("steps") = 1,
             py::arg("progress") = py::none(),
             "Derives `steps` more steps (the query pass before each, as derive() does; past "
             "the derivation length if asked) and returns the string")
        .def_property_readonly("string", &DerivationObject::string, "The string so far (a copy)")
        .def_property_readonly("steps_done",
                               [](const DerivationObject& d) { return d.derivation->steps_done(); })
        .def_property_readonly(
            "derivation_length",
            [](const DerivationObject& d) { return d.derivation->derivation_length(); })
        .def_property_readonly("stopped",
                               [](const DerivationObject& d) { return d.derivation->stopped(); },
                               "stop() was called in a step")
        .def(
            "finish", [](DerivationObject& d) { d.derivation->finish(); },
            "Runs the End block (once)");

    py::class_<SequenceObject>(m, "Sequence",
                               "Frames of a sequence (Images), numbered from 1 as the command's")
        .def("__len__", [](const SequenceObject& s) { return py::len(s.frames); })
        .def("__getitem__", [](const SequenceObject& s, long i) {
            long n = long(py::len(s.frames));
            if (i < 0)
                i += n;
            if (i < 0 || i >= n)
                throw py::index_error("frame index out of range");
            return s.frames[py::size_t(i)];
        })
        .def("__iter__", [](const SequenceObject& s) { return py::iter(s.frames); })
        .def_readwrite("fps", &SequenceObject::fps)
        .def(
            "write",
            [](const SequenceObject& s, const std::string& pattern) {
                py::list written;
                int number = 1;
                for (const auto& f : s.frames) {
                    std::filesystem::path file = lsys::format_frame_name(pattern, number++);
                    write_image(f.cast<const ImageObject&>(), file);
                    written.append(file.string());
                }
                return written;
            },
            py::arg("pattern"),
            "Writes frame k to pattern with its number field (e.g. turn%03d.png) given k, from "
            "1, as the command names a sequence's files; returns the names")
        .def("_repr_html_", &sequence_html)
        .def("__repr__", [](const SequenceObject& s) {
            return "<cambium.Sequence of " + std::to_string(py::len(s.frames)) + " frames>";
        });

    py::class_<ModelObject>(m, "Model", "A cpfg model loaded by cambium.load()")
        .def(
            "derive",
            [](ModelObject& self, std::optional<int> steps, const py::object& progress) {
                py::dict more;
                if (steps)
                    more["steps"] = *steps;
                const app::Options options = self.options_with(more);
                StringObject s{self.model, {}, options.max_modules};
                run_released(
                    [&](std::atomic<bool>&, Events& events) {
                        events.push("derive");
                        s.string = app::derive(*self.model, options);
                    },
                    progress, options.quiet);
                return s;
            },
            py::arg("steps") = py::none(), py::arg("progress") = py::none(),
            "Derives the L-system (its derivation length, or `steps`) and returns the string, "
            "as -str writes it")
        .def(
            "parse",
            [](ModelObject& self, const std::string& text) {
                StringObject s{self.model, {}, self.options.max_modules};
                s.splice(0, 0, text);
                return s;
            },
            py::arg("text"),
            "A String of this model from cpfg's string text (as -str writes it), to edit and "
            "render; names the L-system never used are added to its symbols")
        .def(
            "render", &render_model, py::arg("string") = py::none(), py::arg("layers") = true,
            py::arg("progress") = py::none(),
            "Interprets and renders the model (or a given string of it) into an Image; keywords "
            "are the command's options (width=, height=, spp=, ...) over the load's")
        .def(
            "derivation",
            [](ModelObject& self) {
                DerivationObject d{self.model, nullptr, self.options.quiet};
                run_released(
                    [&](std::atomic<bool>&, Events&) {
                        d.derivation =
                            std::make_unique<lsys::Derivation>(self.model->lsystem.start());
                    },
                    py::none(), self.options.quiet);
                return d;
            },
            "Starts a derivation from the axiom (the Start block run): advance() it step by "
            "step")
        .def("animate", &animate_model, py::arg("layers") = false, py::arg("progress") = py::none(),
             "Renders cpfg's animation mode (-a: the load's animation file, or frames 1 to the "
             "derivation length) into a Sequence, frame for frame as the command's -a "
             "(inbetween= and the other keywords as render()'s)")
        .def("turntable", &turntable_model, py::arg("frames"), py::arg("elevation") = py::none(),
             py::arg("string") = py::none(), py::arg("layers") = false,
             py::arg("progress") = py::none(),
             "Renders `frames` views orbiting the plant (--turntable, --turntable-elevation) "
             "into a Sequence; keywords as render()'s")
        .def("light_report", &light_report, py::arg("path") = py::none(),
             py::arg("string") = py::none(), py::arg("progress") = py::none(),
             "The light each organ absorbs (--light-report; docs/light.md): written to `path` "
             "(.json or .csv) as the command writes it when given; returns the JSON report "
             "(None for a .csv path). Keywords as render()'s (light_rays=, ...)")
        .def("export", &export_geometry, py::arg("path"), py::arg("string") = py::none(),
             py::arg("progress") = py::none(),
             "Writes the plant's geometry as the command does: a mesh or drawing by the "
             "extension (.obj, .ply, .glb, .gls, .ps, .svg, .pdf, as -o), cpfg's rayshade "
             "scene (.ray, as -ray) or Inventor scene (.iv, as -iv); keywords as render()'s. "
             "With animate=True, a file per frame as -a writes them (a number field in `path`, "
             "e.g. plant%03d.glb): returns their names")
        .def_property_readonly("view",
                               [](const ModelObject& self) { return view_settings(*self.model->view); })
        .def_property_readonly(
            "derivation_length",
            [](const ModelObject& self) { return self.model->lsystem.derivation_length(); })
        .def_property_readonly("files", [](const ModelObject& self) { return self.files; })
        .def("__repr__", [](const ModelObject& self) {
            return "<cambium.Model " + self.files[0] + ">";
        });

    py::class_<SceneObject>(m, "Scene", "A scene file of many plants loaded by cambium.load_scene()")
        .def("render", &render_scene, py::arg("layers") = true, py::arg("progress") = py::none(),
             "Derives, places and renders the scene's plants into an Image; keywords are the "
             "command's options over the load's, and both over the scene file's settings")
        .def("export", &export_scene, py::arg("path"), py::arg("progress") = py::none(),
             "Writes the scene's plants as the command does for a scene file: a mesh or "
             "drawing by the extension (.obj, .ply, .glb, .gls, .ps, .svg, .pdf), .ray or .iv; "
             "keywords as render()'s")
        .def("turntable", &turntable_scene, py::arg("frames"), py::arg("elevation") = py::none(),
             py::arg("layers") = false, py::arg("progress") = py::none(),
             "Renders `frames` views orbiting the scene's plants (cambium field.json "
             "--turntable, --turntable-elevation) into a Sequence; keywords as render()'s")
        .def("light_report", &scene_light_report, py::arg("path") = py::none(),
             py::arg("progress") = py::none(),
             "The light each organ of each plant absorbs (--light-report): written to `path` "
             "(.json or .csv) when given; returns the JSON report (None for a .csv path)")
        .def_property_readonly("files", [](const SceneObject& self) { return self.files; })
        .def("__repr__", [](const SceneObject& self) {
            return "<cambium.Scene " + self.files[0] + ">";
        });

    m.def("load_scene", &load_scene, py::arg("file"), py::kw_only(),
          py::arg("progress") = py::none(),
          "Loads a scene file (docs/scenes.md); keywords are the command's options. Raises "
          "cambium.Error naming the file and the JSON path or line and column.");
    m.def("load", &load, py::arg("lsystem"), py::arg("view") = py::none(),
          py::arg("animation") = py::none(), py::kw_only(), py::arg("progress") = py::none(),
          "Loads a cpfg model: the L-system, the view file (default: the L-system's name with "
          ".v) and an animation file; keywords are cpfg's and the command's options "
          "(colormap=, materials=, steps=, ...). Raises cambium.Error naming file, line and "
          "column.");
    m.attr("__version__") = CAMBIUM_VERSION;
}
