// SPDX-License-Identifier: Apache-2.0
// The `cambium` command line: cpfg's options that make sense offline, plus modern ones.
#include "app/command_line.h"

#include <CLI/CLI.hpp>
#include <regex>

#include "base/diagnostics.h"

namespace cambium::app {
namespace {

/// Removes cpfg's glued options (-m2 file, -M file, -c3), which CLI11 cannot
/// express, from `args` and records them in `options`.
std::vector<std::string> take_cpfg_colour_options(std::vector<std::string> args, Options& options)
{
    static const std::regex colour_file(R"(-([mM])([0-9]*))");
    static const std::regex colour_block(R"(-c([0-9]+))");
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
            options.colour_block = std::stoi(m[1]);
            if (options.colour_block > 15)
                throw Error("option " + a + ": colour map numbers go from 0 to 15");
        } else {
            rest.push_back(a);
        }
    }
    return rest;
}

}  // namespace

std::optional<Options> parse_command_line(int argc, char** argv)
{
    Options options;
    std::vector<std::string> args(argv + 1, argv + argc);
    args = take_cpfg_colour_options(args, options);

    CLI::App cli{"cambium: renders cpfg plant models physically.\n"
                 "Colour options as in cpfg: -m[n] file.map, -M[n] file.mat, -c<n>."};
    cli.set_version_flag("--version", "cambium 0.1.0");
    std::vector<int> window;
    cli.add_option("-w", window, "Image size in pixels, as cpfg's window (default 640 480)")
        ->expected(2);
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
    cli.add_flag("-q,--quiet", options.quiet, "Print nothing but errors");
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
    if (!window.empty()) {
        if (window[0] < 1 || window[1] < 1 || window[0] > 32768 || window[1] > 32768)
            throw Error("-w: the image size must be between 1 and 32768 pixels per side");
        options.width = window[0];
        options.height = window[1];
    }
    options.lsystem = files[0];
    options.view = files[1];
    if (files.size() == 3)
        options.animation = files[2];
    return options;
}

}  // namespace cambium::app
