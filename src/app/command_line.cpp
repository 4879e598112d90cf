// SPDX-License-Identifier: Apache-2.0
// The `cambium` command line: cpfg's options that make sense offline, plus modern ones.
#include "app/command_line.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <regex>

#include "app/shot_options.h"
#include "base/diagnostics.h"
#include "render/render.h"
#include "render/sun_position.h"

namespace cambium::app {
namespace {

/// A cpfg option spelled with one dash and several letters (-str, -wp, -m2...), which
/// CLI11 cannot express: how many words it takes and what it does with them.
struct CpfgOption {
    int arguments = 0;
    std::function<void(Options&, const std::vector<std::string>&)> apply;
};

void ignore(Options&, const std::vector<std::string>&) {}

std::function<void(Options&, const std::vector<std::string>&)> unsupported_output(
    std::string what)
{
    return [what](Options&, const std::vector<std::string>& a) {
        warn("cambium does not write " + what + " files; " + a[0] + " is not written");
    };
}

/// cpfg's -gls: the geometry as graphics library statements, an output like -o's whose
/// format Cambium reads from the name.
void gls_output(Options& o, const std::vector<std::string>& a)
{
    if (std::filesystem::path(a[0]).extension() != ".gls")
        throw Error("-gls " + a[0] + ": name the file with .gls (Cambium chooses every output's "
                    "format by its extension)");
    o.outputs.emplace_back(a[0]);
}

/// A whole number from `low` to `high` spelled as `word`, or an Error naming `option`.
int whole_number(const std::string& option, const std::string& word, int low, int high)
{
    int value = 0;
    const char* end = word.data() + word.size();
    auto [ptr, ec] = std::from_chars(word.data(), end, value);
    if (word.empty() || ec != std::errc() || ptr != end || value < low || value > high)
        throw Error(option + ": expected a whole number from " + std::to_string(low) + " to " +
                    std::to_string(high) + ", not '" + word + "'");
    return value;
}

/// `-w W H`: cpfg's window size, the image size here; checked before any work.
void set_image_size(Options& options, const std::string& width, const std::string& height)
{
    options.width = whole_number("-w", width, 1, max_image_side);
    options.height = whole_number("-w", height, 1, max_image_side);
    if (std::int64_t(options.width) * options.height > render::max_image_pixels)
        throw Error("-w: " + width + " x " + height + " is more than " +
                    std::to_string(render::max_image_pixels) + " pixels (8192 x 8192)");
}

const std::map<std::string, CpfgOption>& cpfg_options()
{
    static const std::map<std::string, CpfgOption> table = {
        {"-v", {0, [](Options& o, auto&) { o.verbosity = Verbosity::warnings; }}},
        {"-V", {0, [](Options& o, auto&) { o.verbosity = Verbosity::verbose; }}},
        {"-homo", {0, [](Options& o, auto&) { o.homomorphism_in_string = true; }}},
        {"-e", {1, [](Options& o, auto& a) { o.environment_file = a[0]; }}},
        {"-P", {1, [](Options& o, auto& a) { o.preprocessor = a[0]; }}},
        {"-w", {2, [](Options& o, auto& a) { set_image_size(o, a[0], a[1]); }}},
        {"-str", {1, [](Options& o, auto& a) { o.string_text = a[0]; }}},
        {"-strb", {1, [](Options& o, auto& a) { o.string_binary = a[0]; }}},
        {"-vv", {1, [](Options& o, auto& a) { o.view_volume = a[0]; }}},
        // OpenImageIO writes SGI and Targa images, so these are plain image outputs.
        {"-rgb", {1, [](Options& o, auto& a) { o.outputs.emplace_back(a[0]); }}},
        {"-tga", {1, [](Options& o, auto& a) { o.outputs.emplace_back(a[0]); }}},
        {"-ras", {1, unsupported_output("colour-index SGI raster")}},
        {"-rle", {1, unsupported_output("Utah RLE")}},
        {"-ray", {1, [](Options& o, auto& a) { o.rayshade = a[0]; }}},
        {"-ps", {1, [](Options& o, auto& a) { o.postscript = a[0]; }}},
        {"-iv", {1, [](Options& o, auto& a) { o.inventor = a[0]; }}},
        {"-gls", {1, gls_output}},
        {"-glsl", {1, gls_output}},
        // cpfg's animate mode: every frame of the animation file (or its defaults).
        {"-a", {0, [](Options& o, auto&) { o.shot.animate = true; }}},
        // Window-system and interactive options of cpfg: meaningless offline.
        {"-g", {0, ignore}},  {"-d", {0, ignore}},
        {"-mb", {0, ignore}}, {"-pm", {0, ignore}}, {"-sb", {0, ignore}},
        {"-wt", {1, ignore}}, {"-S", {1, ignore}},  {"-C", {1, ignore}},
        {"-f", {1, ignore}},  {"-wp", {2, ignore}},
    };
    return table;
}

/// The n of -m<n>, -M<n>, -c<n>.
int colour_map_number(const std::string& option, const std::string& digits)
{
    return whole_number("option " + option + ": the colour map number", digits, 0, 15);
}

/// Removes cpfg's own options (glued -m2 file, -M file, -c3, -s150000, and the
/// single-dash words of cpfg_options) from `args`, recording them in `options`.
std::vector<std::string> take_cpfg_options(const std::vector<std::string>& args, Options& options)
{
    static const std::regex colour_file(R"(-([mM])([0-9]*))");
    static const std::regex colour_block(R"(-c([0-9]+))");
    static const std::regex string_size(R"(-s([0-9]+))");
    std::vector<std::string> rest;
    std::smatch m;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (std::regex_match(a, m, colour_file)) {
            if (i + 1 >= args.size())
                throw Error("option " + a + " needs a file name");
            int block = m[2].length() ? colour_map_number(a, m[2]) : 1;
            options.colour_files.push_back({block, m[1] == "M", args[++i]});
        } else if (std::regex_match(a, m, colour_block)) {
            options.colour_block = colour_map_number(a, m[1]);
        } else if (std::regex_match(a, m, string_size)) {
            // cpfg's initial string allocation; Cambium's strings grow as needed.
        } else if (a == "-pipestrb") {
            throw Error("-pipestrb (strings on standard input) is not supported");
        } else if (auto it = cpfg_options().find(a); it != cpfg_options().end()) {
            const CpfgOption& option = it->second;
            if (i + option.arguments >= args.size())
                throw Error("option " + a + " needs " + std::to_string(option.arguments) +
                            (option.arguments == 1 ? " value" : " values"));
            std::vector<std::string> values(args.begin() + static_cast<long>(i) + 1,
                                            args.begin() + static_cast<long>(i) + 1 + option.arguments);
            option.apply(options, values);
            options.given.push_back(a);
            i += static_cast<std::size_t>(option.arguments);
        } else {
            rest.push_back(a);
        }
    }
    return rest;
}

}  // namespace

std::optional<Options> parse_command_line(int argc, char** argv)
{
    return parse_command_line(std::vector<std::string>(argv + 1, argv + argc));
}

namespace {

/// --tile I/N: band I (from 0) of N.
/// A number of the whole word, or nullopt.
std::optional<double> number_of(const std::string& text)
{
    double v = 0;
    const char* end = text.data() + text.size();
    auto [p, ec] = std::from_chars(text.data(), end, v);
    if (ec != std::errc() || p != end || !std::isfinite(v))
        return std::nullopt;
    return v;
}

/// --sun-at's local time: YYYY-MM-DDTHH:MM[:SS] then Z or an offset +HH:MM / -HH:MM.
std::optional<render::LocalTime> local_time_of(const std::string& text)
{
    static const std::regex form(
        R"((\d{4})-(\d{2})-(\d{2})[T ](\d{2}):(\d{2})(?::(\d{2}(?:\.\d+)?))?(Z|([+-])(\d{2})(?::?(\d{2}))?))");
    std::smatch m;
    if (!std::regex_match(text, m, form))
        return std::nullopt;
    render::LocalTime t;
    t.year = std::stoi(m[1]);
    t.month = std::stoi(m[2]);
    t.day = std::stoi(m[3]);
    t.hour = std::stoi(m[4]);
    t.minute = std::stoi(m[5]);
    t.second = m[6].matched ? std::stod(m[6]) : 0;
    if (m[7] != "Z") {
        const int minutes = m[10].matched ? std::stoi(m[10]) : 0;
        if (minutes > 59)
            return std::nullopt;
        t.utc_offset_hours = (m[8] == "-" ? -1 : 1) * (std::stoi(m[9]) + minutes / 60.0);
    }
    if (!render::valid_local_time(t))
        return std::nullopt;
    return t;
}

/// The direction toward the sun of --sun-at LAT LON TIME.
std::vector<float> sun_at_option(const std::vector<std::string>& words)
{
    const std::optional<double> lat = number_of(words[0]), lon = number_of(words[1]);
    if (!lat || *lat < -90 || *lat > 90)
        throw Error("--sun-at: latitude '" + words[0] + "' is not a number of degrees in -90 .. 90");
    if (!lon || *lon < -180 || *lon > 180)
        throw Error("--sun-at: longitude '" + words[1] +
                    "' is not a number of degrees in -180 .. 180 (east positive)");
    const std::optional<render::LocalTime> t = local_time_of(words[2]);
    if (!t)
        throw Error("--sun-at: '" + words[2] +
                    "' is not a date and local time with its UTC offset such as "
                    "2024-06-21T14:30+02:00 (or Z for UTC)");
    const render::Vec3f d = render::sun_direction(render::sun_position(*lat, *lon, *t));
    return {d.x, d.y, d.z};
}

std::pair<int, int> tile_option(const std::string& text)
{
    std::size_t slash = text.find('/');
    auto fail = [&]() -> std::pair<int, int> {
        throw Error("--tile: expected I/N with 0 <= I < N (band I of N, from 0), not '" + text +
                    "'");
    };
    if (slash == std::string::npos)
        return fail();
    int index = 0, count = 0;
    auto a = std::from_chars(text.data(), text.data() + slash, index);
    auto b = std::from_chars(text.data() + slash + 1, text.data() + text.size(), count);
    if (a.ec != std::errc() || a.ptr != text.data() + slash || b.ec != std::errc() ||
        b.ptr != text.data() + text.size() || index < 0 || count < 1 || index >= count)
        return fail();
    return {index, count};
}

/// --tile, --assemble and --mpi: one at a time, and what each can split.
void check_distributed_options(const Options& options)
{
    int given = (options.tile ? 1 : 0) + (options.assemble ? 1 : 0) + (options.mpi ? 1 : 0);
    if (given > 1)
        throw Error("--tile, --assemble and --mpi are different ways to split a render; give one");
    bool sequence = options.shot.animate || options.shot.turntable > 0;
    if ((options.tile || options.assemble) && sequence)
        throw Error("--tile and --assemble split a still; split a sequence with --frames A-B "
                    "(docs/distributed.md)");
    if (options.denoise && (options.tile || options.assemble || (options.mpi && !sequence)))
        throw Error("--denoise needs the whole image: it cannot denoise the bands of --tile, "
                    "--assemble or an --mpi still (an --mpi sequence is denoised frame by frame)");
    if (options.organ_masks && (options.tile || options.assemble || options.mpi))
        throw Error("--organ-masks needs the whole image in one process: not with --tile, "
                    "--assemble or --mpi");
    int count = options.tile ? options.tile->second : options.assemble.value_or(1);
    if (count > options.height)
        throw Error(std::string(options.tile ? "--tile: " : "--assemble: ") +
                    std::to_string(count) + " bands of an image of " +
                    std::to_string(options.height) + " rows; give at most one band per row");
    if ((options.tile || options.assemble) && !options.renders())
        throw Error("--tile and --assemble need an image output (-o)");
}

/// Help as the command is called: the usage names the program and its two forms, where
/// CLI11's own would count the positional words ("files(2x)").
class HelpFormatter : public CLI::Formatter {
public:
    std::string make_usage(const CLI::App*, std::string) const override
    {
        return "Usage: cambium [OPTIONS] plant.l plant.v [plant.a]\n"
               "       cambium [OPTIONS] scene.json\n";
    }
};

}  // namespace

std::optional<Options> parse_command_line(const std::vector<std::string>& words)
{
    Options options;
    std::vector<std::string> args = take_ground_option(take_cpfg_options(words, options),
                                                       options.shot);
    // -rgb and -tga images join -o's, which CLI11 assigns whole
    std::vector<std::filesystem::path> cpfg_images = std::move(options.outputs);
    options.outputs.clear();

    CLI::App cli{"cambium: renders cpfg plant models physically.\n"
                 "cpfg options: -w W H (image size, default 640 480), -m[n] file.map, -M[n] file.mat, -c<n>, -str file,\n"
                 "-strb file, -homo, -vv file, -ray file, -ps file, -iv file, -rgb file, -tga file, -gls file, -v, -V, -P cpp, -e file,\n"
                 "-a (every frame of the animation file); window options (-g -wp -wt -mb -pm -sb -s<n>)\n"
                 "are accepted and ignored.\n"
                 "--ground [COLOUR|FILE]: a ground plane under the plant, grey (default), a colour\n"
                 "(#rrggbb or R,G,B) or a tiled texture image."};
    cli.name("cambium");
    cli.formatter(std::make_shared<HelpFormatter>());
    cli.set_version_flag("--version", "cambium " CAMBIUM_VERSION);
    cli.add_option("-o", options.outputs,
                   "Output: an image (.png .exr .tif .jpg .rgb .tga), a video (.mp4 .mov .mkv .webm) "
                   "or the still's geometry (.obj .ply .gls .glb) or drawing (.svg .pdf .ps); may be "
                   "given more than once")
        ->take_all()
        ->allow_extra_args(false);
    cli.add_option("--spp", options.samples_per_pixel, "Samples per pixel (default 64)")
        ->check(CLI::Range(1, 1 << 20));
    cli.add_option("--max-depth", options.max_depth, "Maximum path length (default 6)")
        ->check(CLI::Range(1, 64));
    cli.add_option("--threads", options.threads, "Render threads (default: all cores)")
        ->check(CLI::Range(0, 1024));
    std::string tile;
    cli.add_option("--tile", tile,
                   "Render band I of N bands of rows (I from 0) into a tile file for --assemble");
    cli.add_option("--assemble", options.assemble,
                   "Paste the N tile files of --tile I/N into the outputs (no rendering)")
        ->check(CLI::Range(1, max_image_side));
    cli.add_flag("--mpi", options.mpi,
                 "Share the render among the ranks of an MPI job: mpirun -np N cambium --mpi ...");
    cli.add_option("--seed", options.seed, "Sampling seed (default 0)")
        ->check(CLI::NonNegativeNumber);
    // Hidden (no group): the white-noise sampler is kept only for comparisons.
    cli.add_option("--sampler", options.sampler, "Sample sequence: sobol (default) or white")
        ->check(CLI::IsMember({"sobol", "white"}))
        ->group("");
    cli.add_flag("--stats", options.stats,
                 "Print where the time and memory went: load, derive, interpret, BVH build, "
                 "time to first pixel, primitives, instances, Embree's and Cambium's memory, "
                 "peak memory, rays/s and samples/s");
    cli.add_option("--stats-json", options.stats_json, "Write the --stats figures as JSON to FILE");
    cli.add_option("--light-report", options.light_report,
                   "Trace the lights (the view file's, the --sky or --env) onto every organ and write the "
                   "light each absorbs to FILE (.json or .csv; docs/light.md)")
        ->check([](const std::string& file) {  // refused before the work, not after
            const auto ext = std::filesystem::path(file).extension();
            return ext == ".json" || ext == ".csv" ? std::string()
                                                   : std::string("expected a .json or .csv file");
        });
    cli.add_flag("--infinite-canopy", options.infinite_canopy,
                 "--light-report repeats the scene sideways: rays leaving its x-z bounds "
                 "through a side come back through the opposite side (a stand)");
    cli.add_option("--canopy-tile", options.canopy_tile,
                   "The --infinite-canopy's tile X0 Z0 X1 Z1 (it must hold the scene's x-z "
                   "bounds) instead of those bounds: plants spaced wider than they are")
        ->expected(4)
        ->allow_extra_args(false);
    cli.add_option("--light-rays", options.light_rays,
                   "Rays from the lights for --light-report (default 1e6)")
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{10'000'000'000}));
    cli.add_option("--max-modules", options.max_modules,
                   "Stop a derivation whose string grows past this many modules (default 1e8)")
        ->check(CLI::Range(std::size_t{1}, std::size_t{1'000'000'000}));
    std::string max_memory;
    cli.add_option("--max-memory", max_memory,
                   "Memory budget for the derived strings, the scene's geometry and each "
                   "texture, e.g. 8G or 512M (default: half the physical memory, " +
                       byte_size_text(options.max_memory_bytes) + " here)");
    cli.add_option("--steps", options.steps,
                   "Derivation steps, instead of the L-system's derivation length")
        ->check(CLI::Range(0, 1'000'000));
    cli.add_option("--filter", options.filter, "Pixel filter: box (default), gaussian, blackman-harris")
        ->check(CLI::IsMember({"box", "gaussian", "blackman-harris"}));
    cli.add_option("--filter-radius", options.filter_radius, "Filter radius in pixels")
        ->check(CLI::Range(0.0f, 8.0f));
    cli.add_option("--noise-target", options.noise_target,
                   "Adaptive sampling: stop a pixel at this relative error (e.g. 0.02); "
                   "--spp is then the most samples a pixel gets")
        ->check(CLI::Range(0.0f, 1.0f));
    cli.add_option("--time-budget", options.time_budget_s,
                   "Stop rendering after about this many seconds")
        ->check(CLI::Range(0.0, 1e7));
    cli.add_option("--aperture", options.aperture_radius,
                   "Depth of field: lens radius in model units (perspective views)")
        ->check(CLI::Range(0.0, 1e9));
    cli.add_option("--focus-distance", options.focus_distance,
                   "Depth of field: distance in focus (default: to the view reference point)")
        ->check(CLI::Range(0.0, 1e12));
    cli.add_flag("--organ-masks", options.organ_masks,
                 "Add organ masks to EXR outputs: Cryptomatte layers CryptoOrgan (each organ) "
                 "and CryptoSymbol (each module symbol), and organ.index, .age, .order, "
                 ".plant channels (docs/masks.md)");
    cli.add_flag("--denoise", options.denoise,
                 "Denoise each frame from its albedo, normal, depth, organ and variance "
                 "(docs/denoise.md); an EXR keeps the raw frame as the noisy layer");
    cli.add_option("--exposure", options.exposure, "Exposure in stops for PNG/TIFF/JPEG")
        ->check(CLI::Range(-20.0f, 20.0f));
    cli.add_flag("--transparent", options.transparent,
                 "Transparent background: alpha is the plant's coverage");
    cli.add_flag("--material-transparency", options.material_transparency,
                 "Keep the materials' transparency on the plant (cpfg's window draws it opaque)");
    cli.add_option("--ambient", options.ambient,
                   "Radiance of the uniform environment (default 0.05)")
        ->check(CLI::Range(0.0f, 1e6f));
    cli.add_flag("--sky", options.sky, "Light with Preetham's daylight sky and sun");
    cli.add_option("--sun", options.sun_direction, "Direction toward the sun (with --sky)")
        ->expected(3)
        ->allow_extra_args(false);  // with a lone scene file allowed, files must not feed it
    cli.add_option("--sun-at", options.sun_at,
                   "The --sky's sun for a place and time: LAT LON (degrees, north and east "
                   "positive) and local time with UTC offset, e.g. 52.0 5.2 2024-06-21T14:30+02:00 "
                   "(north along -z, east along +x)")
        ->expected(3)
        ->allow_extra_args(false);
    cli.add_option("--turbidity", options.turbidity,
                   "Haze of the --sky, 1.7 (very clear) .. 10 (hazy); default 3")
        ->check(CLI::Range(1.7f, 10.0f));
    cli.add_option("--env", options.environment_map,
                   "Light with a latitude-longitude HDR map (.exr, .hdr)");
    cli.add_option("--env-scale", options.environment_scale, "Multiplies the --env map")
        ->check(CLI::Range(0.0f, 1e6f));
    cli.add_option("--env-rotate", options.environment_rotation,
                   "Turn the --env map (or --sky) by DEG about the up axis +y")
        ->check(CLI::Range(-3600.0f, 3600.0f));
    cli.add_flag("--no-view-lights", options.no_view_lights,
                 "Leave out the view file's lights (and cpfg's default light): light with "
                 "the --sky or --env alone");
    cli.add_flag("--allow-system-calls", options.allow_system_calls,
                 "Run the commands of @S modules (never done by default)");
    cli.add_flag("--allow-environment-program", options.allow_environment_program,
                 "Let the -e file start the environmental program it names, when it is not "
                 "one of the built-in environments (never done by default)");
    cli.add_option("--environment-messages", options.environment_messages,
                   "Write each environmental pass's messages to and from an external "
                   "program into DIR (created; an existing one must be empty)");
    cli.add_flag("--allow-file-access", options.allow_file_access,
                 "Let the L-system's fopen read and write files outside the model's folder, "
                 "its #include and the background scenes' read files there, and the view "
                 "file name textures, surfaces, contours, functions and background scenes "
                 "there (never done by default)");
    cli.add_flag("-q,--quiet", options.quiet, "Print nothing but errors");
    add_shot_options(cli, options.shot);
    std::vector<std::string> files;
    // CLI11 keeps the positionals' least count for them at the end of the line, so that
    // options of several values (--sun X Y Z) stop before them: one for a scene file.
    // A .json word is a scene file unless it is an option's own value (--stats-json F).
    bool scene = false;
    for (std::size_t i = 0; i < args.size(); ++i)
        if (args[i].rfind('-', 0) != 0 && std::filesystem::path(args[i]).extension() == ".json" &&
            !(i > 0 && (args[i - 1] == "--stats-json" || args[i - 1] == "--light-report")))
            scene = true;
    cli.add_option("files", files, "plant.l plant.v [plant.a], or scene.json (docs/scenes.md)")
        ->required()
        ->type_name("FILE")
        ->option_text("FILE ...")
        ->expected(scene ? 1 : 2, 3);

    std::vector<std::string> reversed(args.rbegin(), args.rend());
    try {
        cli.parse(reversed);
    } catch (const CLI::CallForHelp&) {
        std::printf("%s", cli.help().c_str());
        return std::nullopt;
    } catch (const CLI::CallForVersion&) {
        std::printf("cambium %s\n", CAMBIUM_VERSION);
        return std::nullopt;
    } catch (const CLI::ParseError& e) {
        throw Error(std::string(e.what()) + " (see cambium --help)");
    }
    options.outputs.insert(options.outputs.end(), cpfg_images.begin(), cpfg_images.end());
    // A budget or a noise target decides when to stop; --spp, when given, still caps it.
    if (cli.count("--spp") == 0 && options.time_budget_s > 0)
        options.samples_per_pixel = 1 << 16;
    else if (cli.count("--spp") == 0 && options.noise_target > 0)
        options.samples_per_pixel = 4096;
    if (!max_memory.empty()) {
        std::optional<std::uint64_t> bytes = parse_byte_size(max_memory);
        if (!bytes)
            throw Error("--max-memory: '" + max_memory +
                        "' is not a size such as 8G, 512M or 1000000 (bytes, at least 1)");
        options.max_memory_bytes = *bytes;
    }
    // `--background sky` shows the sky: without --env it brings the --sky itself.
    if (options.shot.background == "sky" && !options.sky && !options.environment_map)
        options.sky = true;
    if (options.sky && options.environment_map)
        throw Error("--sky and --env both set what surrounds the plant; give one");
    if (!options.sun_at.empty()) {
        if (!options.sun_direction.empty())
            throw Error("--sun and --sun-at both place the sun; give one");
        if (!options.sky)
            throw Error("--sun-at places the --sky's sun; give --sky too");
        options.sun_direction = sun_at_option(options.sun_at);
    }
    if (!options.canopy_tile.empty()) {
        const auto& t = options.canopy_tile;
        const bool finite = std::all_of(t.begin(), t.end(), [](double v) { return std::isfinite(v); });
        if (!finite || !(t[0] < t[2] && t[1] < t[3]))
            throw Error("--canopy-tile X0 Z0 X1 Z1: expected X0 < X1 and Z0 < Z1");
        options.infinite_canopy = true;
    }
    if (options.infinite_canopy && !options.light_report)
        throw Error("--infinite-canopy (--canopy-tile) repeats the scene for --light-report; give "
                    "--light-report too");
    if (cli.count("--turbidity") > 0 && !options.sky)
        throw Error("--turbidity sets the haze of the --sky; give --sky too");
    if (cli.count("--env-rotate") > 0 && !options.sky && !options.environment_map)
        throw Error("--env-rotate turns the --env map or the --sky; give one of them");
    check_shot_options(options);
    if (!tile.empty())
        options.tile = tile_option(tile);
    check_distributed_options(options);
    for (const CLI::Option* option : cli.get_options())
        if (option->count() > 0) {
            for (const std::string& name : option->get_lnames())
                options.given.push_back("--" + name);
            for (const std::string& name : option->get_snames())
                options.given.push_back("-" + name);
        }
    if (scene) {
        if (files.size() != 1 || std::filesystem::path(files[0]).extension() != ".json")
            throw Error("a scene file scene.json replaces plant.l plant.v; give one or the "
                        "other (see cambium --help)");
        options.scene = files[0];
        return options;
    }
    options.lsystem = files[0];
    options.view = files[1];
    if (files.size() == 3)
        options.animation = files[2];
    return options;
}

}  // namespace cambium::app
