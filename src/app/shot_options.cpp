// SPDX-License-Identifier: Apache-2.0
// The command-line options of sequences and of the camera (ShotOptions).
#include "app/shot_options.h"

#include <algorithm>
#include <charconv>
#include <filesystem>

#include "app/video.h"
#include "base/diagnostics.h"

namespace cambium::app {

void add_shot_options(CLI::App& cli, ShotOptions& shot)
{
    cli.add_option("--turntable", shot.turntable,
                   "Render N frames orbiting the plant about the vertical axis, framed once")
        ->check(CLI::Range(1, 100000));
    cli.add_option("--turntable-elevation", shot.turntable_elevation,
                   "Angle of the turntable's view above the horizontal, degrees")
        ->check(CLI::Range(-89.0, 89.0));
    cli.add_option("--orbit", shot.orbit,
                   "Turn the viewpoint AZ degrees about the vertical and EL degrees up, "
                   "about the view reference point")
        ->expected(2);
    cli.add_option("--zoom", shot.zoom, "Multiply the view's scale factor by K")
        ->check(CLI::Range(1e-6, 1e6));
    cli.add_flag("--fit", shot.fit, "Frame the plant's bounds (ignores box: and scale factor:)");
    cli.add_option("--fov", shot.fov, "Vertical field of view in degrees (perspective)")
        ->check(CLI::Range(0.1, 179.0));
    cli.add_flag("--perspective", shot.perspective, "Perspective projection");
    cli.add_flag("--parallel", shot.parallel, "Parallel projection");
    cli.add_option("--frames", shot.frames,
                   "Render only frames A-B of a sequence (frame numbers as in the file names)");
    cli.add_flag("--resume", shot.resume, "Skip frames whose output files exist already");
    cli.add_flag("--video", shot.video,
                 "Encode the sequence as <plant>.mp4 with ffmpeg (or give -o name.mp4)");
    cli.add_option("--tonemap", shot.tonemap,
                   "Tone curve of PNG/TIFF/JPEG: none (clip, default) or filmic (ACES fit)")
        ->check(CLI::IsMember({"none", "filmic"}));
    cli.add_option("--background", shot.background,
                   "What the camera sees behind the plant: a colour (#rrggbb or R,G,B in 0..1), "
                   "sky (with --sky) or env (with --env), in both projections");
    cli.add_flag("--shadow-catcher", shot.shadow_catcher,
                 "The ground only darkens: alpha carries the plant's shadow for compositing");
    cli.add_option("--inbetween", shot.inbetween,
                   "With -a: K frames interpolated between derivation steps (growth)")
        ->check(CLI::Range(0, 1000));
    cli.add_option("--fps", shot.fps, "Frames per second of video outputs (default 24)")
        ->check(CLI::Range(1, 240));
}

namespace {

bool is_colour_word(const std::string& word)
{
    return (word.size() == 7 && word[0] == '#') ||
           std::count(word.begin(), word.end(), ',') == 2;
}

}  // namespace

bool is_ground_texture(const std::string& value)
{
    static const std::array<std::string_view, 12> images = {
        ".png", ".jpg", ".jpeg", ".exr", ".tif", ".tiff", ".hdr", ".tga", ".rgb", ".bmp",
        ".sgi", ".tx"};
    std::string ext = std::filesystem::path(value).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
        return static_cast<char>(std::tolower(c));
    });
    return std::find(images.begin(), images.end(), ext) != images.end();
}

std::vector<std::string> take_ground_option(const std::vector<std::string>& args,
                                            ShotOptions& shot)
{
    std::vector<std::string> rest;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a.rfind("--ground=", 0) == 0) {
            shot.ground = a.substr(9);
        } else if (a == "--ground") {
            bool valued = i + 1 < args.size() &&
                          (is_colour_word(args[i + 1]) || is_ground_texture(args[i + 1]));
            shot.ground = valued ? args[++i] : std::string();
        } else {
            rest.push_back(a);
        }
    }
    return rest;
}

std::pair<int, int> frame_range(const std::string& text)
{
    auto number = [&](std::string_view word) {
        int value = 0;
        auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
        if (ec != std::errc() || end != word.data() + word.size() || value < 0)
            throw Error("--frames: expected A-B with frame numbers A <= B, not '" + text + "'");
        return value;
    };
    std::string_view all = text;
    std::size_t dash = all.find('-');
    int first = number(all.substr(0, dash));
    int last = dash == std::string_view::npos ? first : number(all.substr(dash + 1));
    if (last < first)
        throw Error("--frames: expected A-B with frame numbers A <= B, not '" + text + "'");
    return {first, last};
}

std::array<float, 3> background_colour(const std::string& text, const char* option)
{
    std::array<float, 3> rgb{};
    auto fail = [&]() -> std::array<float, 3> {
        throw Error(std::string(option) + ": expected " +
                    (std::string_view(option) == "--background" ? "sky, env, "
                                                                : "an image file, ") +
                    "#rrggbb or R,G,B (0 to 1), not '" + text + "'");
    };
    if (text.size() == 7 && text[0] == '#') {
        for (int c = 0; c < 3; ++c) {
            unsigned value = 0;
            auto [end, ec] = std::from_chars(text.data() + 1 + 2 * c, text.data() + 3 + 2 * c,
                                             value, 16);
            if (ec != std::errc() || end != text.data() + 3 + 2 * c)
                return fail();
            rgb[std::size_t(c)] = static_cast<float>(value) / 255.0f;
        }
        return rgb;
    }
    std::size_t start = 0;
    for (int c = 0; c < 3; ++c) {
        std::size_t end = c < 2 ? text.find(',', start) : text.size();
        if (end == std::string::npos)
            return fail();
        float value = -1;
        auto [ptr, ec] = std::from_chars(text.data() + start, text.data() + end, value);
        if (ec != std::errc() || ptr != text.data() + end || !(value >= 0 && value <= 1))
            return fail();
        rgb[std::size_t(c)] = value;
        start = end + 1;
    }
    return rgb;
}

void check_shot_options(const Options& options)
{
    const ShotOptions& shot = options.shot;
    if (shot.perspective && shot.parallel)
        throw Error("--perspective and --parallel contradict each other; give one");
    if (shot.turntable > 0 && shot.animate)
        throw Error("--turntable and -a (animation) are two kinds of sequence; give one");
    if (shot.turntable_elevation && shot.turntable == 0)
        throw Error("--turntable-elevation tilts a --turntable; give --turntable N too");
    if (shot.turntable > 0 && (!shot.orbit.empty() || shot.fit))
        throw Error("--turntable frames the plant itself; --orbit and --fit do not apply");
    if ((shot.frames || shot.resume) && shot.turntable == 0 && !shot.animate)
        throw Error("--frames and --resume select frames of a sequence (-a or --turntable)");
    if (shot.frames)
        frame_range(*shot.frames);
    if (shot.background == "sky" && !options.sky)
        throw Error("--background sky shows the --sky behind the plant, not the --env map");
    if (shot.background == "env" && !options.environment_map)
        throw Error("--background env shows the --env map behind the plant; give --env too");
    if (shot.background && *shot.background != "sky" && *shot.background != "env")
        background_colour(*shot.background);
    if (shot.ground && !shot.ground->empty() && !is_ground_texture(*shot.ground))
        background_colour(*shot.ground, "--ground");
    if (shot.ground && is_ground_texture(*shot.ground) &&
        !std::filesystem::is_regular_file(*shot.ground))
        throw Error(FileLoc{*shot.ground}, "--ground: no such texture file");
    if (shot.inbetween > 0 && !shot.animate)
        throw Error("--inbetween interpolates the frames of a growth animation; give -a too");
    bool video = shot.video || std::any_of(options.outputs.begin(), options.outputs.end(),
                                           [](const auto& f) { return is_video(f); });
    if (video && shot.turntable == 0 && !shot.animate)
        throw Error("a video needs a sequence: give -a or --turntable N");
    if (video && shot.frames)
        throw Error("--frames renders part of a sequence and a video needs all of it; write "
                    "frames with -o frame%03d.png and encode them yourself");
}

}  // namespace cambium::app
