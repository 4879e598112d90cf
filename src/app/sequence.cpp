// SPDX-License-Identifier: Apache-2.0
// Sequences of frames: cpfg's animation mode (-a with the .a file) and turntables.
//
// An animation derives incrementally: each frame continues from the previous frame's
// string, so every derivation step is computed once. With `scale between frames: off`
// (cpfg's default) the camera stays fixed for the whole animation, framed so that every
// frame fits: the frames are derived and interpreted first (their turtle strings kept),
// then rendered with the camera fitted to the union of their bounds. A turntable derives
// and interprets once and renders every view from one BVH (render::render_views).
#include "app/sequence.h"

#include <chrono>
#include <optional>

#include <fmt/format.h>

#include "app/shot_options.h"
#include "app/video.h"
#include "base/diagnostics.h"
#include "geom/view_file.h"
#include "geom/view_volume.h"
#include "lsys/string_io.h"
#include "render/framing.h"

namespace cambium::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

fs::path frame_file(const fs::path& pattern, int number)
{
    return lsys::format_frame_name(pattern.string(), number);
}

/// Several frames need a number field in every output name (cpfg would append one;
/// a silent overwrite of one file by every frame helps nobody).
void require_numbered_names(const Options& options, const std::vector<fs::path>& images,
                            std::size_t frames)
{
    if (frames <= 1)
        return;
    auto check = [&](const fs::path& name, const char* option) {
        if (!lsys::is_frame_pattern(name.string()))
            throw Error(FileLoc{name.string()},
                        fmt::format("{} names one file for {} frames: put a number field in "
                                    "the name, e.g. plant%03d{}",
                                    option, frames, name.extension().string()));
    };
    for (const fs::path& image : images)
        check(image, "-o");
    if (options.string_text)
        check(*options.string_text, "-str");
    if (options.string_binary)
        check(*options.string_binary, "-strb");
    if (options.view_volume)
        check(*options.view_volume, "-vv");
}

render::ViewOverrides view_overrides(const ShotOptions& shot)
{
    render::ViewOverrides o;
    if (shot.orbit.size() == 2) {
        o.orbit_azimuth_deg = shot.orbit[0];
        o.orbit_elevation_deg = shot.orbit[1];
    }
    o.zoom = shot.zoom;
    o.fit = shot.fit;
    o.fov_deg = shot.fov;
    if (shot.perspective || shot.parallel)
        o.perspective = shot.perspective;
    return o;
}

/// Which frame numbers to render: --frames, and --resume's frames already written.
class FrameFilter {
public:
    FrameFilter(const ShotOptions& shot, const std::vector<fs::path>& images)
        : m_resume(shot.resume), m_images(images)
    {
        if (shot.frames)
            m_range = frame_range(*shot.frames);
    }
    /// In the --frames range (all outputs of other frames are left alone).
    bool selected(int number) const
    {
        return !m_range || (number >= m_range->first && number <= m_range->second);
    }
    /// Selected and, with --resume, not every image of it written yet.
    bool to_render(int number) const
    {
        if (!selected(number) || m_images.empty())
            return false;
        if (!m_resume)
            return true;
        for (const fs::path& image : m_images)
            if (!fs::exists(frame_file(image, number)))
                return true;
        return false;
    }

private:
    std::optional<std::pair<int, int>> m_range;
    bool m_resume;
    const std::vector<fs::path>& m_images;
};

/// "frame 12: 3 of 40 done, 37 left, about 1:05 to go" after each rendered frame.
class SequenceProgress {
public:
    SequenceProgress(std::size_t total, std::function<void(const std::string&)> say)
        : m_total(total), m_say(std::move(say)), m_start(Clock::now())
    {
    }
    void frame_done(int number, double seconds)
    {
        ++m_done;
        double elapsed = std::chrono::duration<double>(Clock::now() - m_start).count();
        std::size_t left = m_total - std::min(m_done, m_total);
        double eta = m_done > 0 ? elapsed / double(m_done) * double(left) : 0;
        m_say(fmt::format("frame {}: rendered in {:.2f} s; {} of {} done, {} left, about {} to go",
                          number, seconds, m_done, m_total, left, clock_time(eta)));
    }

private:
    static std::string clock_time(double s)
    {
        long t = static_cast<long>(s + 0.5);
        if (t >= 3600)
            return fmt::format("{}:{:02}:{:02}", t / 3600, t / 60 % 60, t % 60);
        return fmt::format("{}:{:02}", t / 60, t % 60);
    }
    std::size_t m_total, m_done = 0;
    std::function<void(const std::string&)> m_say;
    Clock::time_point m_start;
};

void write_frame_images(render::Image& image, int number, const Options& options,
                        const SequenceOutputs& out)
{
    render::WriteOptions write = write_options(options);
    for (const fs::path& pattern : out.images) {
        fs::path file = frame_file(pattern, number);
        render::write_image(image, file, write);
        out.say("wrote " + file.string());
    }
}

/// The camera of one animation frame: the fixed one, else fitted to this frame; then
/// turned and scaled by the frame intervals' rotate / scale.
render::Camera frame_camera(const geom::Scene& scene, const std::optional<render::Camera>& fixed,
                            const geom::AnimationFrame& frame, const render::RenderSettings& s)
{
    render::Camera camera =
        fixed ? *fixed : render::make_camera(scene.view, scene.bounds, s.width, s.height);
    bool moved = frame.rotation_deg.x != 0 || frame.rotation_deg.y != 0 ||
                 frame.rotation_deg.z != 0 || frame.scale.x != 1 || frame.scale.y != 1 ||
                 frame.scale.z != 1;
    if (moved)
        camera = render::transform_object_view(camera, frame.rotation_deg, frame.scale,
                                               scene.bounds);
    if (s.aperture_radius > 0)
        camera = camera.with_lens(s.aperture_radius, s.focus_distance);
    return camera;
}

int run_animation(const Options& options, const SequenceOutputs& out)
{
    Model model = load_model(options);
    std::vector<geom::AnimationFrame> frames = animation_frames(model, options);
    require_numbered_names(options, out.images, frames.size());
    FrameFilter filter(options.shot, out.images);
    std::optional<geom::AnimationFile> animation;
    if (options.animation)
        animation = geom::read_animation_file(*options.animation);
    const bool refit = animation && (animation->scale_between_frames ||
                                     animation->new_view_between_frames);
    std::size_t to_render = 0;
    for (const geom::AnimationFrame& f : frames)
        to_render += filter.to_render(f.number) ? 1 : 0;
    out.say(fmt::format("{} frames, {} to render", frames.size(), to_render));

    render::ViewOverrides overrides = view_overrides(options.shot);
    SequenceProgress progress(to_render, out.say);
    int status = 0;
    auto render_frame = [&](const geom::Scene& scene, const std::optional<render::Camera>& fixed,
                            const geom::AnimationFrame& f) {
        render::RenderReport report;
        render::Image image =
            render::render(scene, frame_camera(scene, fixed, f, out.settings), out.settings,
                           &report);
        write_frame_images(image, f.number, options, out);
        progress.frame_done(f.number, report.seconds);
        if (report.cancelled)
            status = 130;
    };

    // Derive every frame once; render now (refitting per frame, or a perspective view),
    // or keep the turtle strings to render with one camera fitted to all of them.
    struct Kept {
        geom::AnimationFrame frame;
        lsys::ModuleString turtle;
    };
    std::vector<Kept> kept;
    geom::Bounds3 all_bounds;
    std::optional<geom::View> fixed_view;
    int derived = derive_frames(model, frames, [&](const geom::AnimationFrame& f,
                                                   const lsys::ModuleString& string) {
        if (!filter.selected(f.number) || status != 0)
            return;
        // -homo: strings after the homomorphism, which the turtle then reads as they are
        lsys::ModuleString homomorphic;
        if (options.homomorphism_in_string)
            homomorphic = model.lsystem.interpretation_string(string);
        const lsys::ModuleString& written = options.homomorphism_in_string ? homomorphic : string;
        out.write_strings(model, written, f.number);
        if (!options.view_volume && !filter.to_render(f.number))
            return;
        if (refit && animation->new_view_between_frames)
            model.view = std::make_shared<const geom::ViewFile>(geom::read_view_file(options.view));
        lsys::ModuleString turtle = turtle_string(model, written, options);
        geom::Scene scene = interpret_turtle_string(model, turtle, options);
        scene.view = render::apply_overrides(scene.view, overrides, scene.bounds);
        if (options.view_volume) {
            fs::path file = frame_file(*options.view_volume, f.number);
            geom::write_view_volume(scene.view.box.value_or(scene.bounds), file);
            out.say("wrote " + file.string());
        }
        if (!filter.to_render(f.number))
            return;
        if (refit || scene.view.perspective) {
            render_frame(scene, std::nullopt, f);
            return;
        }
        fixed_view = scene.view;
        all_bounds.extend(scene.bounds);
        kept.push_back({f, std::move(turtle)});
    });
    out.say(fmt::format("derived {} steps once for {} frames", derived, frames.size()));
    if (!kept.empty()) {
        const render::RenderSettings& s = out.settings;
        render::Camera camera = render::make_camera(*fixed_view, all_bounds, s.width, s.height);
        for (const Kept& k : kept) {
            if (status != 0)
                break;
            geom::Scene scene = interpret_turtle_string(model, k.turtle, options);
            scene.view = *fixed_view;
            render_frame(scene, camera, k.frame);
        }
    }
    return status;
}

int run_turntable(const Options& options, const SequenceOutputs& out)
{
    const int n = options.shot.turntable;
    require_numbered_names(Options{}, out.images, static_cast<std::size_t>(n));
    geom::Scene scene;
    if (out.make_scene) {
        scene = out.make_scene();
    } else {
        Model model = load_model(options);
        lsys::ModuleString derived = derive(model, options);
        out.write_strings(model, derived,
                          options.steps.value_or(model.lsystem.derivation_length()));
        scene = interpret(model, derived, options);
    }
    scene.view = render::apply_overrides(scene.view, view_overrides(options.shot), scene.bounds);
    if (options.view_volume)
        geom::write_view_volume(scene.view.box.value_or(scene.bounds), *options.view_volume);

    const render::RenderSettings& s = out.settings;
    std::vector<render::Camera> orbit = render::turntable_cameras(
        scene.view, scene.bounds, n, options.shot.turntable_elevation, s.width, s.height);
    // Frames are numbered 1..N; the first looks from the view file's side.
    FrameFilter filter(options.shot, out.images);
    std::vector<render::Camera> cameras;
    std::vector<int> numbers;
    for (int k = 0; k < n; ++k)
        if (filter.to_render(k + 1)) {
            cameras.push_back(s.aperture_radius > 0
                                  ? orbit[std::size_t(k)].with_lens(s.aperture_radius,
                                                                    s.focus_distance)
                                  : orbit[std::size_t(k)]);
            numbers.push_back(k + 1);
        }
    out.say(fmt::format("turntable of {} frames, {} to render", n, cameras.size()));
    SequenceProgress progress(cameras.size(), out.say);
    int status = 0;
    render::render_views(scene, cameras, s,
                         [&](std::size_t view, render::Image& image, const render::RenderReport& r) {
        write_frame_images(image, numbers[view], options, out);
        progress.frame_done(numbers[view], r.seconds);
        if (r.cancelled)
            status = 130;
        return true;
    });
    return status;
}

}  // namespace

bool is_sequence(const Options& options)
{
    return options.shot.animate || options.shot.turntable > 0;
}

std::vector<geom::AnimationFrame> animation_frames(const Model& model, const Options& options)
{
    geom::AnimationFile animation = options.animation
                                        ? geom::read_animation_file(*options.animation)
                                        : geom::default_animation();
    return geom::select_frames(animation,
                               options.steps.value_or(model.lsystem.derivation_length()));
}

int derive_frames(const Model& model, const std::vector<geom::AnimationFrame>& frames,
                  const std::function<void(const geom::AnimationFrame&,
                                           const lsys::ModuleString&)>& on_frame)
{
    lsys::Derivation derivation = model.lsystem.start();
    for (std::size_t i = 0; i < frames.size(); ++i) {
        derivation.advance(frames[i].derive_steps);
        // cpfg runs the End block once the last frame is reached, or on stop()
        bool last = i + 1 == frames.size() || derivation.stopped();
        if (last && (!derivation.stopped() || derivation.stop_runs_end()))
            derivation.finish();
        on_frame(frames[i], derivation.string());
        if (derivation.stopped())
            break;  // stop() ends the animation (manual 5.1)
    }
    return derivation.steps_done();
}

void apply_staging(render::RenderSettings& settings, const Options& options)
{
    const std::optional<std::string>& background = options.shot.background;
    if (!background)
        return;
    if (*background == "sky" || *background == "env") {
        settings.backdrop = render::RenderSettings::Backdrop::environment;
        return;
    }
    auto rgb = background_colour(*background);
    settings.backdrop = render::RenderSettings::Backdrop::colour;
    settings.backdrop_colour = {rgb[0], rgb[1], rgb[2]};
}

render::WriteOptions write_options(const Options& options)
{
    render::WriteOptions write;
    write.exposure = options.exposure;
    write.tonemap =
        options.shot.tonemap == "filmic" ? render::ToneMap::filmic : render::ToneMap::none;
    return write;
}

void apply_camera_options(geom::Scene& scene, const Options& options)
{
    scene.view = render::apply_overrides(scene.view, view_overrides(options.shot), scene.bounds);
}

int run_sequence(const Options& options, const SequenceOutputs& outputs)
{
    // Videos: frames go to a folder per video first, then ffmpeg encodes them.
    SequenceOutputs frames = outputs;
    std::vector<fs::path> videos;
    frames.images.clear();
    for (const fs::path& out : outputs.images)
        (is_video(out) ? videos : frames.images).push_back(out);
    if (options.shot.video && videos.empty()) {
        videos.push_back((options.scene ? options.scene->stem() : options.lsystem.stem()).string() +
                         ".mp4");
        if (options.outputs.empty())
            frames.images.clear();  // not the default still's name
    }
    fs::path ffmpeg;
    if (!videos.empty())
        ffmpeg = require_ffmpeg(videos.front());  // before any work
    for (const fs::path& video : videos) {
        fs::create_directories(video_frames_folder(video));
        frames.images.push_back(video_frames_folder(video) / "%06d.png");
    }
    int status = options.shot.turntable > 0 ? run_turntable(options, frames)
                                            : run_animation(options, frames);
    if (status != 0)
        return status;
    for (const fs::path& video : videos) {
        encode_video(ffmpeg, video_frames_folder(video), options.shot.fps, video);
        outputs.say("wrote " + video.string());
    }
    return 0;
}

}  // namespace cambium::app
