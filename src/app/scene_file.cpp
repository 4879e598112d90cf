// SPDX-License-Identifier: Apache-2.0
// Reading scene files (docs/scenes.md): every value is checked where it is read, and a
// failure names the file and the value's JSON path.
#include "app/scene_file.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/shot_options.h"
#include "base/confinement.h"
#include "base/diagnostics.h"
#include "geom/text_input.h"

namespace cambium::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

/// A value of the document with its JSON path, for messages.
class Node {
public:
    Node(const std::string& file, const json& value, std::string path)
        : m_file(&file), m_value(&value), m_path(std::move(path))
    {
    }

    const json& value() const { return *m_value; }
    const std::string& path() const { return m_path; }

    [[noreturn]] void fail(const std::string& message) const
    {
        throw Error(*m_file + ": " + (m_path.empty() ? "the document" : m_path) + ": " + message);
    }

    Node operator[](const char* key) const
    {
        return Node(*m_file, m_value->at(key), join(key));
    }
    Node operator[](std::size_t i) const
    {
        return Node(*m_file, m_value->at(i), m_path + "[" + std::to_string(i) + "]");
    }
    bool has(const char* key) const { return m_value->contains(key); }

    /// An object whose keys are all among `known` (a misspelt key is an error, not a
    /// silently ignored setting).
    const Node& object(std::initializer_list<const char*> known) const
    {
        if (!m_value->is_object())
            fail("must be an object");
        for (const auto& item : m_value->items()) {
            // not a structured binding: clang before 16 cannot capture one in a lambda
            const std::string& key = item.key();
            if (std::none_of(known.begin(), known.end(), [&](const char* k) { return key == k; })) {
                std::string list;
                for (const char* k : known)
                    list += (list.empty() ? "" : ", ") + std::string(k);
                Node(*m_file, item.value(), join(key.c_str()))
                    .fail("unknown key (expected one of " + list + ")");
            }
        }
        return *this;
    }

    double number(double low = -HUGE_VAL, double high = HUGE_VAL) const
    {
        if (!m_value->is_number())
            fail("must be a number");
        double x = m_value->get<double>();
        if (!std::isfinite(x) || x < low || x > high)
            fail(range_text("a number", low, high));
        return x;
    }
    long long integer(long long low, long long high) const
    {
        if (!m_value->is_number_integer())
            fail(range_text("an integer", double(low), double(high)));
        // unsigned values above the signed range read as negative: compare as unsigned
        if (m_value->is_number_unsigned() &&
            m_value->get<std::uint64_t>() > std::uint64_t(std::numeric_limits<long long>::max()))
            fail(range_text("an integer", double(low), double(high)));
        long long x = m_value->get<long long>();
        if (x < low || x > high)
            fail(range_text("an integer", double(low), double(high)));
        return x;
    }
    bool boolean() const
    {
        if (!m_value->is_boolean())
            fail("must be true or false");
        return m_value->get<bool>();
    }
    std::string string() const
    {
        if (!m_value->is_string())
            fail("must be a string");
        return m_value->get<std::string>();
    }
    template <std::size_t N>
    std::array<double, N> numbers(double low = -HUGE_VAL, double high = HUGE_VAL) const
    {
        if (!m_value->is_array() || m_value->size() != N)
            fail("must be an array of " + std::to_string(N) + " numbers");
        std::array<double, N> out{};
        for (std::size_t i = 0; i < N; ++i)
            out[i] = (*this)[i].number(low, high);
        return out;
    }
    geom::Vec3 vec3() const
    {
        auto a = numbers<3>(-1e9, 1e9);
        return {a[0], a[1], a[2]};
    }

private:
    std::string join(const char* key) const { return m_path.empty() ? key : m_path + "." + key; }
    static std::string range_text(const char* what, double low, double high)
    {
        std::ostringstream s;
        s << "must be " << what;
        if (low > -HUGE_VAL && high < HUGE_VAL)
            s << " from " << low << " to " << high;
        else if (low > -HUGE_VAL)
            s << " of at least " << low;
        return s.str();
    }

    const std::string* m_file;
    const json* m_value;
    std::string m_path;
};

/// A positive whole number: the common case of counts.
std::size_t positive(const Node& n, std::size_t high)
{
    if (!n.value().is_number_integer() || n.value().get<long long>() < 1 ||
        n.value().get<unsigned long long>() > high)
        n.fail("must be a positive integer (at most " + std::to_string(high) + ")");
    return static_cast<std::size_t>(n.value().get<unsigned long long>());
}

/// `name` (a relative path from the scene or model file) as a file under `folder`.
/// Absolute paths and `..` escapes are refused unless file access is allowed.
fs::path resolve_under(const Node& n, const fs::path& folder, const std::string& name,
                       bool allow_file_access)
{
    if (name.empty())
        n.fail("must name a file or folder");
    if (name.find('\0') != std::string::npos)
        n.fail("a file name cannot contain a NUL character");
    fs::path p(name);
    if (allow_file_access)
        return p.is_absolute() ? p : folder / p;
    if (p.is_absolute())
        n.fail("'" + name + "' is an absolute path; files must lie in the scene's folder "
               "(or give --allow-file-access)");
    // a link loop (a folder linked to itself) is a message at the JSON path, not a raw
    // filesystem exception
    std::error_code ec;
    fs::path base = fs::weakly_canonical(folder, ec);
    fs::path full = ec ? fs::path() : fs::weakly_canonical(base / p, ec);
    if (ec)
        n.fail("'" + name + "' cannot be resolved: " + ec.message());
    if (!is_within(base, full))
        n.fail("'" + name + "' lies outside the folder " + folder.string() +
               " (give --allow-file-access to allow it)");
    return full;
}

/// A colour as display values: "#rrggbb" or [r, g, b] in 0..1.
geom::Rgb colour(const Node& n)
{
    if (n.value().is_string()) {
        std::string text = n.string();
        if (text.size() != 7 || text[0] != '#')
            n.fail("must be #rrggbb or [r, g, b] from 0 to 1");
        try {
            auto rgb = background_colour(text);
            return {rgb[0], rgb[1], rgb[2]};
        } catch (const Error&) {
            n.fail("must be #rrggbb or [r, g, b] from 0 to 1");
        }
    }
    if (!n.value().is_array())
        n.fail("must be #rrggbb or [r, g, b] from 0 to 1");
    auto c = n.numbers<3>(0, 1);
    return {float(c[0]), float(c[1]), float(c[2])};
}

// ---- plants -----------------------------------------------------------------------

/// The words of a cpfg command line (no shell: quotes and metacharacters are refused).
std::vector<std::string> command_words(const Node& n)
{
    std::string text = n.string();
    if (text.find_first_of("\"'`$;|&<>()\\*?~{}\n") != std::string::npos)
        n.fail("a cpfg command line of words only (no quotes, variables or shell syntax)");
    std::istringstream in(text);
    std::vector<std::string> words;
    for (std::string w; in >> w;)
        words.push_back(w);
    if (words.empty() || words[0] != "cpfg")
        n.fail("must start with 'cpfg', as model.json's command");
    words.erase(words.begin());
    return words;
}

/// Which cpfg options a scene's command may hold: those naming the model's files and
/// the interactive ones cambium ignores. Nothing that writes, runs a program (-P) or
/// overrides the scene's render settings.
void check_command_options(const Node& n, const std::vector<std::string>& words)
{
    static const std::regex takes_file(R"(-[mM][0-9]*|-e)");
    static const std::regex glued(R"(-c[0-9]+|-s[0-9]+)");
    static const std::set<std::string> no_value = {"-a", "-v", "-V", "-g", "-d", "-mb", "-pm", "-sb"};
    static const std::set<std::string> one_value = {"-wt", "-S", "-C", "-f"};
    static const std::set<std::string> two_values = {"-w", "-wp"};
    // cpfg keeps the last of a repeated option, where a reviewer of the scene reads the first
    std::set<std::string> seen;
    for (std::size_t i = 0; i < words.size(); ++i) {
        const std::string& w = words[i];
        if (w.empty() || w[0] != '-')
            continue;
        std::string key = w == "-m" || w == "-M" ? w + "1" : w;  // no number: colour map 1
        if (std::regex_match(w, glued))
            key = w.substr(0, 2);
        if (!seen.insert(key).second)
            n.fail("option " + w + " is given twice (cpfg would keep the last, a reader sees "
                                   "the first)");
        if (std::regex_match(w, takes_file) || one_value.count(w))
            ++i;
        else if (two_values.count(w))
            i += 2;
        else if (!std::regex_match(w, glued) && !no_value.count(w))
            n.fail("option " + w + " is not allowed in a scene (only the model's file options "
                                   "-m -M -c -e and cpfg's window options)");
    }
}

/// The model's files from the command line, resolved in its folder.
Options model_options(const Node& n, const fs::path& folder, bool allow_file_access)
{
    std::vector<std::string> words = command_words(n);
    check_command_options(n, words);
    std::optional<Options> parsed;
    try {
        parsed = parse_command_line(words);
    } catch (const Error& e) {
        n.fail(nested_message(e));
    }
    if (!parsed)
        n.fail("is not a command line that renders");
    Options model;
    auto in_folder = [&](const fs::path& p) {
        return resolve_under(n, folder, p.string(), allow_file_access);
    };
    model.lsystem = in_folder(parsed->lsystem);
    model.view = in_folder(parsed->view);
    for (ColourFile c : parsed->colour_files) {
        c.file = in_folder(c.file);
        model.colour_files.push_back(c);
    }
    model.colour_block = parsed->colour_block;
    if (parsed->environment_file)
        model.environment_file = in_folder(*parsed->environment_file);
    return model;
}

std::vector<std::optional<int>> step_variants(const Node& n)
{
    constexpr long long max_steps = 1'000'000;
    std::vector<std::optional<int>> steps;
    if (n.value().is_array()) {
        if (n.value().empty() || n.value().size() > 100)
            n.fail("must list 1 to 100 step counts");
        for (std::size_t i = 0; i < n.value().size(); ++i) {
            int s = static_cast<int>(n[i].integer(0, max_steps));
            if (std::find(steps.begin(), steps.end(), std::optional<int>(s)) != steps.end())
                n[i].fail("repeats the step count " + std::to_string(s));
            steps.emplace_back(s);
        }
    } else {
        steps.emplace_back(static_cast<int>(n.integer(0, max_steps)));
    }
    return steps;
}

Transform explicit_placement(const Node& n)
{
    n.object({"translate", "rotate_y_deg", "scale", "matrix"});
    if (n.has("matrix")) {
        if (n.has("translate") || n.has("rotate_y_deg") || n.has("scale"))
            n.fail("give either matrix or translate / rotate_y_deg / scale");
        Node m = n["matrix"];
        if (!m.value().is_array() || m.value().size() != 12)
            m.fail("must be 12 numbers: a 3x4 matrix, column-major (x, y, z axes, translation)");
        Transform t{};
        for (std::size_t i = 0; i < 12; ++i)
            t[i] = static_cast<float>(m[i].number(-1e9, 1e9));
        return t;
    }
    geom::Vec3 translate = n.has("translate") ? n["translate"].vec3() : geom::Vec3{};
    double angle = n.has("rotate_y_deg") ? n["rotate_y_deg"].number(-3600, 3600) : 0;
    double scale = n.has("scale") ? n["scale"].number(1e-6, 1e6) : 1;
    return placement_transform(translate, angle, scale);
}

struct Context {
    const std::string& name;   ///< the scene file as given, for messages
    fs::path folder;           ///< the scene file's folder
    const Options& options;
    const SceneLimits& limits;
    std::size_t instances = 0; ///< placed so far
};

ScatterSpec scatter_spec(const Node& n, Context& c)
{
    n.object({"rectangle", "mesh", "count", "seed", "min_spacing", "rotate_y", "scale"});
    ScatterSpec s;
    if (n.has("rectangle") == n.has("mesh"))
        n.fail("give one of rectangle [xmin, zmin, xmax, zmax] or mesh \"ground.obj\"");
    if (n.has("rectangle")) {
        s.rectangle = n["rectangle"].numbers<4>(-1e7, 1e7);
        if (!(s.rectangle[0] < s.rectangle[2] && s.rectangle[1] < s.rectangle[3]))
            n["rectangle"].fail("must be [xmin, zmin, xmax, zmax] with xmin < xmax and zmin < zmax");
    } else {
        s.mesh = resolve_under(n["mesh"], c.folder, n["mesh"].string(),
                               c.options.allow_file_access);
    }
    if (!n.has("count"))
        n.fail("needs a count");
    s.count = positive(n["count"], c.limits.max_instances);
    if (n.has("seed"))
        s.seed = static_cast<std::uint64_t>(n["seed"].integer(0, std::numeric_limits<long long>::max()));
    if (n.has("min_spacing"))
        s.min_spacing = n["min_spacing"].number(0, 1e6);
    if (n.has("rotate_y"))
        s.rotate_y = n["rotate_y"].boolean();
    if (n.has("scale")) {
        auto r = n["scale"].numbers<2>(1e-6, 1e6);
        if (r[0] > r[1])
            n["scale"].fail("must be [low, high] with low <= high");
        s.scale = r;
    }
    return s;
}

std::vector<Transform> placements(const Node& n, Context& c)
{
    std::vector<Transform> out;
    if (n.value().is_array()) {
        if (n.value().size() > c.limits.max_instances)
            n.fail("has more than " + std::to_string(c.limits.max_instances) + " placements");
        for (std::size_t i = 0; i < n.value().size(); ++i)
            out.push_back(explicit_placement(n[i]));
    } else if (n.value().is_object()) {
        n.object({"scatter"});
        if (!n.has("scatter"))
            n.fail("must be a list of placements or {\"scatter\": {...}}");
        Node sn = n["scatter"];
        ScatterSpec spec = scatter_spec(sn, c);
        if (c.instances + spec.count > c.limits.max_instances)
            sn["count"].fail("places more than the scene's limit of " +
                             std::to_string(c.limits.max_instances) + " plants in all");
        std::optional<GroundMesh> mesh;
        if (spec.mesh) {
            try {
                mesh = read_obj_mesh(*spec.mesh, c.limits);
            } catch (const Error& e) {
                sn["mesh"].fail(nested_message(e));
            }
        }
        out = scatter(spec, mesh ? &*mesh : nullptr);
    } else {
        n.fail("must be a list of placements or {\"scatter\": {...}}");
    }
    c.instances += out.size();
    if (c.instances > c.limits.max_instances)
        n.fail("places more than the scene's limit of " + std::to_string(c.limits.max_instances) +
               " plants in all");
    return out;
}

ScenePlant plant(const Node& n, Context& c)
{
    n.object({"model", "command", "steps", "seed", "placements"});
    for (const char* key : {"model", "command", "placements"})
        if (!n.has(key))
            n.fail(std::string("needs a ") + key);
    ScenePlant p;
    p.path = n.path();
    p.folder = resolve_under(n["model"], c.folder, n["model"].string(), c.options.allow_file_access);
    std::error_code ec;
    if (!fs::is_directory(p.folder, ec))
        n["model"].fail("'" + n["model"].string() + "' is not a folder");
    p.command = n["command"].string();
    p.model = model_options(n["command"], p.folder, c.options.allow_file_access);
    p.steps = n.has("steps") ? step_variants(n["steps"]) : std::vector<std::optional<int>>{std::nullopt};
    if (n.has("seed"))
        p.seed = static_cast<long>(n["seed"].integer(0, 0xffffffffLL));
    p.placements = placements(n["placements"], c);
    return p;
}

SceneMesh mesh_entry(const Node& n, Context& c)
{
    n.object({"file", "placements"});
    for (const char* key : {"file", "placements"})
        if (!n.has(key))
            n.fail(std::string("needs a ") + key);
    SceneMesh m;
    m.path = n.path();
    m.file = resolve_under(n["file"], c.folder, n["file"].string(), c.options.allow_file_access);
    if (!fs::is_regular_file(m.file))
        n["file"].fail("'" + n["file"].string() + "' is not a file");
    m.placements = placements(n["placements"], c);
    return m;
}

// ---- the rest ---------------------------------------------------------------------

SceneGround ground(const Node& n, Context& c)
{
    n.object({"size", "mesh", "colour", "texture", "texture_repeat"});
    SceneGround g;
    if (n.has("size") == n.has("mesh"))
        n.fail("give one of size [w, d] or mesh \"ground.obj\"");
    if (n.has("size"))
        g.size = n["size"].numbers<2>(1e-6, 1e7);
    else
        g.mesh = resolve_under(n["mesh"], c.folder, n["mesh"].string(), c.options.allow_file_access);
    if (n.has("colour") && n.has("texture"))
        n.fail("give colour or texture, not both");
    if (n.has("colour"))
        g.colour = colour(n["colour"]);
    if (n.has("texture")) {
        g.texture = resolve_under(n["texture"], c.folder, n["texture"].string(),
                                  c.options.allow_file_access);
        if (!fs::is_regular_file(*g.texture))
            n["texture"].fail("'" + n["texture"].string() + "' is not a file");
    }
    if (n.has("texture_repeat"))
        g.texture_repeat = n["texture_repeat"].number(1e-3, 1e6);
    return g;
}

SceneCamera camera(const Node& n)
{
    n.object({"eye", "look_at", "up", "fov_deg", "projection", "width", "height"});
    SceneCamera cam;
    if (n.has("eye"))
        cam.eye = n["eye"].vec3();
    if (n.has("look_at"))
        cam.look_at = n["look_at"].vec3();
    if (n.has("up")) {
        cam.up = n["up"].vec3();
        if (geom::length(cam.up) == 0)
            n["up"].fail("must not be zero");
    }
    if (cam.eye && cam.look_at && geom::length(*cam.eye - *cam.look_at) == 0)
        n["look_at"].fail("must differ from eye");
    if (n.has("fov_deg"))
        cam.fov_deg = n["fov_deg"].number(0.01, 179);
    if (n.has("projection")) {
        std::string p = n["projection"].string();
        if (p != "perspective" && p != "parallel")
            n["projection"].fail("must be \"perspective\" or \"parallel\"");
        cam.perspective = p == "perspective";
    }
    if (n.has("width"))
        cam.width = static_cast<int>(n["width"].integer(1, max_image_side));
    if (n.has("height"))
        cam.height = static_cast<int>(n["height"].integer(1, max_image_side));
    return cam;
}

geom::Light light(const Node& n)
{
    n.object({"type", "direction", "position", "colour", "intensity"});
    geom::Light l;
    std::string type = n.has("type") ? n["type"].string() : "directional";
    if (type == "directional") {
        if (!n.has("direction"))
            n.fail("a directional light needs a direction (toward the light)");
        l.kind = geom::Light::Kind::directional;
        l.direction = n["direction"].vec3();
        if (geom::length(l.direction) == 0)
            n["direction"].fail("must not be zero");
    } else if (type == "point") {
        if (!n.has("position"))
            n.fail("a point light needs a position");
        l.kind = geom::Light::Kind::point;
        l.position = n["position"].vec3();
    } else {
        n["type"].fail("must be \"directional\" or \"point\"");
    }
    geom::Rgb c = n.has("colour") ? colour(n["colour"]) : geom::Rgb{1, 1, 1};
    float k = n.has("intensity") ? static_cast<float>(n["intensity"].number(0, 1e6)) : 1.0f;
    // Display values, as a view file's light: the intensity scales the decoded (linear)
    // colour, i.e. the display value by k^(1/2.2) in the power-law approximation.
    float display_k = std::pow(k, 1 / 2.2f);
    l.diffuse = {c.r * display_k, c.g * display_k, c.b * display_k};
    l.ambient = {0, 0, 0};
    l.specular = l.diffuse;
    return l;
}

SceneRender render_settings(const Node& n)
{
    n.object({"spp", "max_depth", "seed", "noise_target", "time_budget_s", "exposure", "ambient",
              "filter", "tonemap", "background"});
    SceneRender r;
    if (n.has("spp"))
        r.spp = static_cast<int>(n["spp"].integer(1, 1 << 20));
    if (n.has("max_depth"))
        r.max_depth = static_cast<int>(n["max_depth"].integer(1, 64));
    if (n.has("seed"))
        r.seed = static_cast<std::uint64_t>(n["seed"].integer(0, std::numeric_limits<long long>::max()));
    if (n.has("noise_target"))
        r.noise_target = static_cast<float>(n["noise_target"].number(0, 1));
    if (n.has("time_budget_s"))
        r.time_budget_s = n["time_budget_s"].number(0, 1e7);
    if (n.has("exposure"))
        r.exposure = static_cast<float>(n["exposure"].number(-20, 20));
    if (n.has("ambient"))
        r.ambient = static_cast<float>(n["ambient"].number(0, 1e6));
    if (n.has("filter")) {
        r.filter = n["filter"].string();
        if (*r.filter != "box" && *r.filter != "gaussian" && *r.filter != "blackman-harris")
            n["filter"].fail("must be \"box\", \"gaussian\" or \"blackman-harris\"");
    }
    if (n.has("tonemap")) {
        r.tonemap = n["tonemap"].string();
        if (*r.tonemap != "none" && *r.tonemap != "filmic")
            n["tonemap"].fail("must be \"none\" or \"filmic\"");
    }
    if (n.has("background")) {
        r.background = n["background"].string();
        try {
            if (*r.background != "sky" && *r.background != "env")
                background_colour(*r.background);
        } catch (const Error&) {
            n["background"].fail("must be \"sky\", \"env\", \"#rrggbb\" or \"R,G,B\"");
        }
    }
    return r;
}

/// The line and column of byte `at` of `text`.
FileLoc location(const std::string& name, const std::string& text, std::size_t at)
{
    FileLoc loc{name, 1, 1};
    for (std::size_t i = 0; i < std::min(at, text.size()); ++i) {
        if (text[i] == '\n') {
            ++loc.line;
            loc.column = 1;
        } else {
            ++loc.column;
        }
    }
    return loc;
}

/// What the JSON parser accepts silently or reports without a place, checked first at
/// file:line:column: nesting deeper than limits.max_nesting (each level is a value the
/// parser builds: 63 MiB of '[' would be 66 million), a key twice in one object (the last
/// would win unseen), a number past double's range. Malformed text is left to the parser.
void check_structure(const std::string& text, const std::string& name, const SceneLimits& limits)
{
    struct Open {
        bool object;
        std::set<std::string> keys;
    };
    std::vector<Open> open;
    bool expect_key = false;  // a string here, in an object, is a key
    const std::size_t n = text.size();
    for (std::size_t i = 0; i < n;) {
        char c = text[i];
        if (c == '/' && i + 1 < n && (text[i + 1] == '/' || text[i + 1] == '*')) {
            std::size_t end = text[i + 1] == '/' ? text.find('\n', i) : text.find("*/", i + 2);
            if (end == std::string::npos)
                return;
            i = end + (text[i + 1] == '/' ? 1 : 2);
        } else if (c == '"') {
            std::size_t start = i++;
            for (; i < n && text[i] != '"'; ++i)
                if (text[i] == '\\')
                    ++i;
            if (i >= n)
                return;
            ++i;
            if (expect_key && !open.empty() && open.back().object) {
                std::string key = text.substr(start, i - start);
                try {
                    key = json::parse(key).get<std::string>();  // "\u0061" is "a"
                } catch (const json::exception&) {
                }
                if (!open.back().keys.insert(key).second)
                    throw Error(location(name, text, start),
                                "the key " + json(key).dump() +
                                    " appears twice in one object (the last would win unseen)");
                expect_key = false;
            }
        } else if (c == '{' || c == '[') {
            if (open.size() == limits.max_nesting)
                throw Error(
                    location(name, text, i),
                    "JSON nested more than " + std::to_string(limits.max_nesting) + " levels deep");
            open.push_back({c == '{', {}});
            expect_key = c == '{';
            ++i;
        } else if (c == '}' || c == ']') {
            if (!open.empty())
                open.pop_back();
            expect_key = false;
            ++i;
        } else if (c == ',') {
            expect_key = !open.empty() && open.back().object;
            ++i;
        } else if (c == '-' || (c >= '0' && c <= '9')) {
            std::size_t end = std::min(text.find_first_not_of("0123456789+-.eE", i), n);
            std::string number = text.substr(i, end - i);
            if (std::isinf(std::strtod(number.c_str(), nullptr)))
                throw Error(location(name, text, i),
                            "the number " + number.substr(0, 40) + " is out of range");
            i = end;
        } else {
            ++i;
        }
    }
}

json parse_document(const fs::path& file, const std::string& name, const SceneLimits& limits)
{
    std::string text = read_file(file, "the scene file", limits.max_file_bytes);
    check_structure(text, name, limits);
    try {
        // Comments are allowed: scenes are written by hand.
        return json::parse(text, nullptr, true, true);
    } catch (const json::parse_error& e) {
        // nlohmann gives the byte offset of the error: turn it into line and column.
        FileLoc at = location(name, text, e.byte > 0 ? e.byte - 1 : 0);
        std::string what = e.what();
        // "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error ..."
        std::size_t colon = what.find(": ");
        throw Error(at, "JSON " + (colon == std::string::npos ? what : what.substr(colon + 2)));
    } catch (const json::exception& e) {
        throw Error(FileLoc{name}, std::string("JSON ") + e.what());
    }
}

}  // namespace

std::string nested_message(const std::exception& e)
{
    std::string text = e.what();
    return text.starts_with("error: ") ? text.substr(7) : text;
}

void refuse_single_model_options(const Options& options)
{
    if (options.shot.animate)
        throw Error("-a animates one L-system; a scene file has no animation (try --turntable)");
    if (options.string_text || options.string_binary)
        throw Error("-str and -strb write one L-system's string; not with a scene file");
    if (!options.colour_files.empty())
        throw Error("-m and -M name one model's colours; each plant of a scene names its own "
                    "in its command");
}

SceneFile read_scene_file(const fs::path& file, const Options& options, const SceneLimits& limits)
{
    const std::string name = file.string();
    json document = parse_document(file, name, limits);
    Context c{name, file.parent_path().empty() ? fs::path(".") : file.parent_path(), options,
              limits};
    Node root(name, document, "");
    root.object({"plants", "meshes", "ground", "camera", "lights", "sky", "environment", "render"});
    SceneFile scene;
    scene.file = file;
    if (!root.has("plants") && !root.has("meshes"))
        root.fail("needs a plants list (or a meshes list)");
    if (root.has("plants")) {
        Node plants = root["plants"];
        if (!plants.value().is_array() || plants.value().empty())
            plants.fail("must be a non-empty list of plants");
        if (plants.value().size() > limits.max_plants)
            plants.fail("lists more than " + std::to_string(limits.max_plants) + " plants");
        for (std::size_t i = 0; i < plants.value().size(); ++i)
            scene.plants.push_back(plant(plants[i], c));
    }
    if (root.has("meshes")) {
        Node meshes = root["meshes"];
        if (!meshes.value().is_array() || meshes.value().empty())
            meshes.fail("must be a non-empty list of meshes");
        if (meshes.value().size() > limits.max_meshes)
            meshes.fail("lists more than " + std::to_string(limits.max_meshes) + " meshes");
        for (std::size_t i = 0; i < meshes.value().size(); ++i)
            scene.meshes.push_back(mesh_entry(meshes[i], c));
    }
    Node plants = root.has("plants") ? root["plants"] : root["meshes"];
    std::size_t variants = 0;
    for (const ScenePlant& p : scene.plants)
        variants += p.steps.size();
    if (variants > limits.max_variants)
        plants.fail("asks for " + std::to_string(variants) + " plant variants (steps), more than " +
                    std::to_string(limits.max_variants));
    if (root.has("ground"))
        scene.ground = ground(root["ground"], c);
    if (root.has("camera"))
        scene.camera = camera(root["camera"]);
    if (root.has("lights")) {
        Node lights = root["lights"];
        if (!lights.value().is_array() || lights.value().size() > 64)
            lights.fail("must be a list of at most 64 lights");
        for (std::size_t i = 0; i < lights.value().size(); ++i)
            scene.lights.push_back(light(lights[i]));
    }
    if (root.has("sky") && root.has("environment"))
        root.fail("give sky or environment, not both");
    if (root.has("sky")) {
        Node n = root["sky"];
        n.object({"sun", "turbidity"});
        SceneSky sky;
        if (n.has("sun")) {
            auto s = n["sun"].numbers<3>(-1e6, 1e6);
            if (s[0] == 0 && s[1] == 0 && s[2] == 0)
                n["sun"].fail("must not be zero");
            sky.sun = std::array<float, 3>{float(s[0]), float(s[1]), float(s[2])};
        }
        if (n.has("turbidity"))
            sky.turbidity = static_cast<float>(n["turbidity"].number(1.7, 10));
        scene.sky = sky;
    }
    if (root.has("environment")) {
        Node n = root["environment"];
        n.object({"map", "scale", "rotate_deg"});
        if (!n.has("map"))
            n.fail("needs a map");
        SceneEnvironment env;
        env.map = resolve_under(n["map"], c.folder, n["map"].string(), options.allow_file_access);
        if (!fs::is_regular_file(env.map))
            n["map"].fail("'" + n["map"].string() + "' is not a file");
        if (n.has("scale"))
            env.scale = static_cast<float>(n["scale"].number(0, 1e6));
        if (n.has("rotate_deg"))
            env.rotate_deg = static_cast<float>(n["rotate_deg"].number(-3600, 3600));
        scene.environment = env;
    }
    if (root.has("render"))
        scene.render = render_settings(root["render"]);
    return scene;
}

}  // namespace cambium::app
