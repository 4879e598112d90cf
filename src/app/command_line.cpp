// SPDX-License-Identifier: Apache-2.0
// The `cambium` command line: cpfg's options that make sense offline, plus modern ones.
#include "app/command_line.h"

#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <regex>

#include "app/shot_options.h"
#include "base/diagnostics.h"

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

/// `-w W H`: cpfg's window size, the image size here.
void set_image_size(Options& options, const std::string& width, const std::string& height)
{
    auto pixels = [](const std::string& word) {
        std::size_t used = 0;
        int value = 0;
        try {
            value = std::stoi(word, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != word.size() || value < 1 || value > 32768)
            throw Error("-w: the image size must be two whole numbers from 1 to 32768, not '" +
                        word + "'");
        return value;
    };
    options.width = pixels(width);
    options.height = pixels(height);
}

const std::map<std::string, CpfgOption>& cpfg_options()
{
    static const std::map<std::string, CpfgOption> table = {
        {"-v", {0, [](Options& o, auto&) { o.verbosity = Verbosity::warnings; }}},
        {"-V", {0, [](Options& o, auto&) { o.verbosity = Verbosity::verbose; }}},
        {"-homo", {0, [](Options& o, auto&) { o.homomorphism_in_string = true; }}},
        {"-e", {1, [](Options& o, auto&) { o.environment_requested = true; }}},
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
        {"-ray", {1, unsupported_output("rayshade")}},
        {"-ps", {1, unsupported_output("PostScript")}},
        {"-iv", {1, unsupported_output("Inventor")}},
        {"-gls", {1, unsupported_output("gls")}},
        {"-glsl", {1, unsupported_output("gls")}},
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
            int block = m[2].length() ? std::stoi(m[2]) : 1;
            if (block > 15)
                throw Error("option " + a + ": colour map numbers go from 0 to 15");
            options.colour_files.push_back({block, m[1] == "M", args[++i]});
        } else if (std::regex_match(a, m, colour_block)) {
            options.colour_block = m[1].length() < 3 ? std::stoi(m[1]) : 99;
            if (options.colour_block > 15)
                throw Error("option " + a + ": colour map numbers go from 0 to 15");
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

std::optional<Options> parse_command_line(const std::vector<std::string>& words)
{
    Options options;
    std::vector<std::string> args = take_cpfg_options(words, options);

    CLI::App cli{"cambium: renders cpfg plant models physically.\n"
                 "cpfg options: -w W H (image size, default 640 480), -m[n] file.map, -M[n] file.mat, -c<n>, -w W H, -str file,\n"
                 "-strb file, -homo, -vv file, -rgb file, -tga file, -v, -V, -P cpp, -e file,\n"
                 "-a (every frame of the animation file); window options (-g -wp -wt -mb -pm -sb -s<n>)\n"
                 "are accepted and ignored."};
    cli.set_version_flag("--version", "cambium 0.1.0");
    cli.add_option("-o", options.outputs,
                   "Output image (.png .exr .tif .jpg); may be given more than once")
        ->take_all()
        ->allow_extra_args(false);
    cli.add_option("--spp", options.samples_per_pixel, "Samples per pixel (default 64)")
        ->check(CLI::Range(1, 1 << 20));
    cli.add_option("--max-depth", options.max_depth, "Maximum path length (default 6)")
        ->check(CLI::Range(1, 64));
    cli.add_option("--threads", options.threads, "Render threads (default: all cores)")
        ->check(CLI::Range(0, 1024));
    cli.add_option("--seed", options.seed, "Sampling seed (default 0)");
    cli.add_option("--max-modules", options.max_modules,
                   "Stop a derivation whose string grows past this many modules (default 1e8)")
        ->check(CLI::Range(std::size_t{1}, std::size_t{1'000'000'000}));
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
    cli.add_option("--exposure", options.exposure, "Exposure in stops for PNG/TIFF/JPEG")
        ->check(CLI::Range(-20.0f, 20.0f));
    cli.add_flag("--transparent", options.transparent,
                 "Transparent background: alpha is the plant's coverage");
    cli.add_option("--ambient", options.ambient,
                   "Radiance of the uniform environment (default 0.05)")
        ->check(CLI::Range(0.0f, 1e6f));
    cli.add_flag("--sky", options.sky, "Light with Preetham's daylight sky and sun");
    cli.add_option("--sun", options.sun_direction, "Direction toward the sun (with --sky)")
        ->expected(3);
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
    cli.add_flag("--allow-system-calls", options.allow_system_calls,
                 "Run the commands of @S modules (never done by default)");
    cli.add_flag("-q,--quiet", options.quiet, "Print nothing but errors");
    add_shot_options(cli, options.shot);
    std::vector<std::string> files;
    cli.add_option("files", files, "plant.l plant.v [plant.a]")->required()->expected(2, 3);

    std::vector<std::string> reversed(args.rbegin(), args.rend());
    try {
        cli.parse(reversed);
    } catch (const CLI::CallForHelp&) {
        std::printf("%s", cli.help().c_str());
        return std::nullopt;
    } catch (const CLI::CallForVersion&) {
        std::printf("cambium 0.1.0\n");
        return std::nullopt;
    } catch (const CLI::ParseError& e) {
        throw Error(std::string(e.what()) + " (see cambium --help)");
    }
    // A budget or a noise target decides when to stop; --spp, when given, still caps it.
    if (cli.count("--spp") == 0 && options.time_budget_s > 0)
        options.samples_per_pixel = 1 << 16;
    else if (cli.count("--spp") == 0 && options.noise_target > 0)
        options.samples_per_pixel = 4096;
    if (options.sky && options.environment_map)
        throw Error("--sky and --env both set what surrounds the plant; give one");
    if (cli.count("--turbidity") > 0 && !options.sky)
        throw Error("--turbidity sets the haze of the --sky; give --sky too");
    if (cli.count("--env-rotate") > 0 && !options.sky && !options.environment_map)
        throw Error("--env-rotate turns the --env map or the --sky; give one of them");
    check_shot_options(options);
    options.lsystem = files[0];
    options.view = files[1];
    if (files.size() == 3)
        options.animation = files[2];
    return options;
}

}  // namespace cambium::app
