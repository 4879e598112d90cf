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

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include "app/shot_options.h"
#include "app/video.h"
#include "base/diagnostics.h"
#include "base/output_format.h"
#include "base/subprocess.h"
#include "geom/view_file.h"
#include "geom/view_volume.h"
#include "lsys/inbetween.h"
#include "lsys/string_io.h"
#include "render/denoise.h"
#include "render/organ_masks.h"
#include "render/framing.h"
#include "render/vector_writer.h"
#include "geom/tessellate.h"
#include "geom/inventor_export.h"
#include "base/limits.h"
#include "render/ground.h"
#include "base/input_file.h"
#include "geom/mesh_export.h"
#include "render/color.h"
#include "render/image_codec.h"
#include "render/image_io.h"

namespace cambium::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start)
{
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// --stats for a sequence: each frame's derivation and interpretation, gathered until it
/// is rendered (RunStats::add_frame). Work for frames rendered elsewhere (another MPI
/// rank) or not at all counts in the run's totals only.
class FrameLedger {
public:
    FrameLedger(RunStats* stats, Clock::time_point command_start)
        : m_stats(stats), m_command_start(command_start)
    {
    }
    void derived(int number, double seconds) { work(number).derive_s += seconds; }
    void interpreted(int number, double seconds) { work(number).interpret_s += seconds; }
    /// Derivation or interpretation that belongs to no rendered frame (-vv's own pass).
    void shared(double derive_s, double interpret_s)
    {
        if (m_stats) {
            m_stats->derive_s += derive_s;
            m_stats->interpret_s += interpret_s;
        }
    }
    double now() const { return seconds_since(m_command_start); }
    void rendered(int number, const geom::Scene& scene, const render::RenderReport& report,
                  double render_start_s, const render::RenderSettings& s)
    {
        if (m_stats)
            m_stats->add_frame(take(number), scene, report, render_start_s, s.width, s.height);
    }
    void rendered_elsewhere(int number)
    {
        FrameStats f = take(number);
        shared(f.derive_s, f.interpret_s);
    }

private:
    FrameStats& work(int number)
    {
        FrameStats& f = m_pending[number];
        f.number = number;
        return f;
    }
    FrameStats take(int number)
    {
        FrameStats f = work(number);
        m_pending.erase(number);
        return f;
    }
    RunStats* m_stats;
    Clock::time_point m_command_start;
    std::map<int, FrameStats> m_pending;
};

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
    if (options.rayshade)
        check(*options.rayshade, "-ray");
    if (options.postscript)
        check(*options.postscript, "-ps");
    if (options.inventor)
        check(*options.inventor, "-iv");
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
    /// `kept`: the caller keeps every frame's image (SequenceOutputs::frame_images), so
    /// frames render without files too.
    FrameFilter(const ShotOptions& shot, const std::vector<fs::path>& images, bool kept)
        : m_resume(shot.resume), m_images(images), m_kept(kept)
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
        if (!selected(number) || (m_images.empty() && !m_kept))
            return false;
        if (!m_resume || m_images.empty())
            return true;
        if (m_written)
            return m_written->count(number) == 0;
        for (const fs::path& image : m_images)
            if (!fs::exists(frame_file(image, number)))
                return true;
        return false;
    }

    /// --mpi: which of `numbers` --resume finds written is rank 0's to say, for every
    /// rank (the others may not see its files, or may see them appear as it writes).
    void agree(Mpi& mpi, const std::vector<int>& numbers)
    {
        if (!m_resume)
            return;
        std::string written;
        if (mpi.rank() == 0)
            for (int n : numbers)
                if (selected(n) && !to_render(n))
                    written += std::to_string(n) + " ";
        std::istringstream in(mpi.from_rank0(written));
        m_written.emplace();
        for (int n = 0; in >> n;)
            m_written->insert(n);
    }

private:
    std::optional<std::pair<int, int>> m_range;
    std::optional<std::set<int>> m_written;  ///< agreed among MPI ranks (agree())
    bool m_resume;
    const std::vector<fs::path>& m_images;
    bool m_kept = false;
};

/// "frame 12: 3 of 40 done, 37 left, about 1:05 to go" after each rendered frame.
class SequenceProgress {
public:
    SequenceProgress(std::size_t total, std::function<void(const std::string&)> say)
        : m_total(total), m_say(std::move(say)), m_start(Clock::now())
    {
    }
    /// `seconds` < 0: rendered by another MPI rank, time unknown here.
    void frame_done(int number, double seconds)
    {
        ++m_done;
        double elapsed = std::chrono::duration<double>(Clock::now() - m_start).count();
        std::size_t left = m_total - std::min(m_done, m_total);
        double eta = m_done > 0 ? elapsed / double(m_done) * double(left) : 0;
        std::string how = seconds < 0 ? "rendered by another rank"
                                      : fmt::format("rendered in {:.2f} s", seconds);
        m_say(fmt::format("frame {}: {}; {} of {} done, {} left, about {} to go", number, how,
                          m_done, m_total, left, clock_time(eta)));
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
    if (out.frame_images)
        out.frame_images(image, number);
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

/// The textures of a sequence's frames, opened once (render::load_textures) and opened
/// again only when a frame's view file names other textures (new view between frames).
class SequenceTextures {
public:
    void share(const geom::Scene& scene, render::RenderSettings& settings)
    {
        if (scene.textures.empty() && settings.ground.texture.empty())
            return;
        if (settings.textures && same_definitions(scene.textures))
            return;
        settings.textures = render::load_textures(scene, settings);
        m_definitions = scene.textures;
    }

private:
    bool same_definitions(const std::vector<geom::TextureDef>& defs) const
    {
        return std::equal(defs.begin(), defs.end(), m_definitions.begin(), m_definitions.end(),
                          [](const geom::TextureDef& a, const geom::TextureDef& b) {
                              return a.file == b.file && a.decal == b.decal &&
                                     a.linear_filter == b.linear_filter && a.mipmap == b.mipmap;
                          });
    }
    std::vector<geom::TextureDef> m_definitions;
};

/// The symbols whose parameters are lengths or widths: a module of them that appears in
/// a step grows from nothing over the in-between frames before it (--inbetween). The
/// turtle's steps F f G g without a parameter are steps of 1.
std::vector<lsys::Growth> grown_symbols(const lsys::LSystem& lsystem)
{
    std::vector<lsys::Growth> growth(lsystem.symbols().size());
    auto set = [&](const char* name, float implied) {
        if (int id = lsystem.symbols().find(name); id >= 0)
            growth[std::size_t(id)] = {true, implied};
    };
    for (const char* step : {"F", "f", "G", "g"})
        set(step, 1);
    for (const char* size : {"!", "@O", "@o", "@c"})
        set(size, 0);
    return growth;
}

/// The image numbers of an animation: the derivation step of each frame (cpfg), or with
/// K in-betweens, 1, 2, 3 ... through every frame, the in-betweens before the frame
/// they lead to (frame i of the selection is number i (K + 1) + 1).
struct FrameNumbering {
    int inbetween = 0;
    int anchor(const geom::AnimationFrame& f, std::size_t index) const
    {
        return inbetween == 0 ? f.number : int(index) * (inbetween + 1) + 1;
    }
    /// The k-th (1..K) in-between before frame `index` (>= 1).
    int between(std::size_t index, int k) const
    {
        return int(index - 1) * (inbetween + 1) + 1 + k;
    }
};

/// An in-between frame's object motion: the frame intervals' rotate / scale
/// interpolated between the two frames.
geom::AnimationFrame between_frame(const geom::AnimationFrame& a, const geom::AnimationFrame& b,
                                   float t, int number)
{
    geom::AnimationFrame f = b;
    f.number = number;
    f.rotation_deg = a.rotation_deg * (1 - t) + b.rotation_deg * t;
    f.scale = a.scale * (1 - t) + b.scale * t;
    return f;
}

int run_animation(const Options& options, const SequenceOutputs& out)
{
    FrameLedger ledger(out.stats, out.command_start);
    auto load_start = Clock::now();
    Model model = load_model(options);
    if (out.stats)
        out.stats->load_s = seconds_since(load_start);
    std::vector<geom::AnimationFrame> frames = animation_frames(model, options);
    const FrameNumbering numbering{options.shot.inbetween};
    const std::size_t images_total =
        frames.empty() ? 0
                       : frames.size() + std::size_t(numbering.inbetween) * (frames.size() - 1);
    require_numbered_names(options, out.images, images_total);
    require_numbered_names(Options{}, out.geometry, images_total);
    FrameFilter filter(options.shot, out.images, bool(out.frame_images));
    std::optional<geom::AnimationFile> animation;
    if (options.animation)
        animation = geom::read_animation_file(*options.animation);
    const bool refit = animation && (animation->scale_between_frames ||
                                     animation->new_view_between_frames);
    std::vector<int> image_numbers;  // every image of the sequence, anchors and in-betweens
    for (std::size_t i = 0; i < frames.size(); ++i) {
        image_numbers.push_back(numbering.anchor(frames[i], i));
        for (int k = 1; i > 0 && k <= numbering.inbetween; ++k)
            image_numbers.push_back(numbering.between(i, k));
    }
    if (out.mpi) {
        out.mpi->checkpoint();
        filter.agree(*out.mpi, image_numbers);
    }
    const std::size_t to_render = std::size_t(
        std::count_if(image_numbers.begin(), image_numbers.end(),
                      [&](int number) { return filter.to_render(number); }));
    out.say(fmt::format("{} frames, {} to render", images_total, to_render));
    if (out.stats)
        out.stats->sequence_frames = images_total;
    std::vector<int> numbers;  // image numbers of the frames rendered, in call order

    render::ViewOverrides overrides = view_overrides(options.shot);
    render::RenderSettings settings = out.settings;
    SequenceTextures textures;
    SequenceProgress progress(to_render, out.say);
    int status = 0;
    std::map<std::size_t, double> seconds_here;  // render times of the frames rendered here
    auto write = [&](std::size_t k, render::Image& image) {
        write_frame_images(image, numbers[k], options, out);
        auto here = seconds_here.find(k);
        progress.frame_done(numbers[k], here == seconds_here.end() ? -1 : here->second);
    };
    // --mpi: frames on demand (app/distributed.h)
    std::optional<FrameQueue> queue;
    if (out.mpi)
        queue.emplace(*out.mpi, to_render, write);
    const bool writes = !queue || queue->writes();
    std::size_t reached = 0;  // frames to render reached so far, on every rank alike
    auto render_frame = [&](const geom::Scene& scene, const std::optional<render::Camera>& fixed,
                            const geom::AnimationFrame& f) {
        std::size_t k = reached++;
        numbers.push_back(f.number);
        if (queue && !queue->renders(k)) {
            ledger.rendered_elsewhere(f.number);
            return;
        }
        textures.share(scene, settings);
        render::RenderReport report;
        double render_start_s = ledger.now();
        auto render_it = [&] {
            return render::render(scene, frame_camera(scene, fixed, f, settings), settings,
                                  &report);
        };
        render::Image image = queue ? queue->render_serving(render_it) : render_it();
        ledger.rendered(f.number, scene, report, render_start_s, settings);
        seconds_here[k] = report.seconds;
        if (queue)
            queue->rendered(k, std::move(image));
        else
            write(k, image);
        if (report.cancelled)
            status = 130;
    };

    // Derive every frame once; render now (refitting per frame, or a perspective view),
    // or keep the turtle strings to render with one camera fitted to all of them. With a
    // ground every frame is kept: the ground's height is the lowest point of them all.
    const bool keep_all = settings.ground.enabled;
    struct Kept {
        geom::AnimationFrame frame;  ///< numbered as its images
        lsys::ModuleString turtle;
        std::optional<geom::View> own_view;  ///< refitted per frame (else the fixed camera)
        StringOrigins origins;  ///< organ masks: ages and births (else empty)
        /// Organ masks: the frame's derived string, whose symbols name the organs.
        std::shared_ptr<const lsys::ModuleString> derived;
    };
    std::vector<Kept> kept;
    geom::Bounds3 all_bounds, fixed_bounds;
    double lowest = std::numeric_limits<double>::infinity();
    std::optional<geom::View> fixed_view;
    // One frame's turtle string (and image number in `frame`): rendered or kept.
    auto take = [&](lsys::ModuleString turtle, const geom::AnimationFrame& frame,
                    StringOrigins origins = {}) {
        auto interpret_start = Clock::now();
        // (origins.derived, when set, lives only as long as this call)
        geom::Scene scene = interpret_turtle_string(model, turtle, options,
                                                    origins.ages.empty() ? nullptr : &origins);
        ledger.interpreted(frame.number, seconds_since(interpret_start));
        scene.view = render::apply_overrides(scene.view, overrides, scene.bounds);
        bool own_camera = refit || scene.view.perspective;
        if (own_camera && !keep_all) {
            render_frame(scene, std::nullopt, frame);
            return;
        }
        all_bounds.extend(scene.bounds);
        if (keep_all)
            lowest = std::min(lowest, render::lowest_point(scene));
        if (!own_camera) {
            fixed_view = scene.view;
            fixed_bounds.extend(scene.bounds);
        }
        std::shared_ptr<const lsys::ModuleString> derived;
        if (origins.derived) {  // copied: the derivation goes on before the frame is rendered
            derived = std::make_shared<const lsys::ModuleString>(*origins.derived);
            origins.derived = derived.get();
        }
        kept.push_back({frame, std::move(turtle),
                        own_camera ? std::optional<geom::View>(scene.view) : std::nullopt,
                        std::move(origins), std::move(derived)});
    };
    // -homo: the strings written are the homomorphism's output, which the turtle then
    // reads as it is; otherwise the derived string is written as it stands (not copied)
    // and the turtle reads turtle_string()'s.
    auto after_homomorphism = [&](const lsys::ModuleString& derived) {
        return options.homomorphism_in_string
                   ? std::optional(model.lsystem.interpretation_string(derived))
                   : std::nullopt;
    };
    const std::vector<lsys::Growth> grows = grown_symbols(model.lsystem);
    lsys::ModuleString before;  // the previous frame's string (--inbetween)
    const geom::AnimationFrame* previous = nullptr;
    auto derivation_start = Clock::now();  // of this frame's steps: since the last frame
    // Organ masks: each module's age (the derivation step of the frame where it appeared)
    // and its index in that frame's string, followed along the lineage from frame to
    // frame: together its name in every frame it lives in (docs/masks.md).
    std::vector<std::uint16_t> ages;
    std::vector<std::uint32_t> births;
    int steps_so_far = 0;
    // One frame's derived string to take(): the homomorphism's output as -homo writes it,
    // else the string the turtle reads, its organs named by birth for the masks.
    auto take_derived = [&](const lsys::ModuleString& derived, std::optional<lsys::ModuleString> homo,
                            const geom::AnimationFrame& frame) {
        if (homo)
            return take(std::move(*homo), frame);
        if (!options.organ_masks)
            return take(turtle_string(model, derived, options), frame);
        StringOrigins origins;
        origins.derived = &derived;
        origins.ages = ages;
        origins.births = births;
        lsys::ModuleString turtle = turtle_string(model, derived, options, origins.origins);
        take(std::move(turtle), frame, std::move(origins));
    };
    int derived = derive_frames_with_lineage(
        model, frames, numbering.inbetween > 0 || options.organ_masks,
        [&](const geom::AnimationFrame& f, const lsys::ModuleString& string,
            const std::vector<std::uint32_t>& lineage) {
        std::size_t index = std::size_t(&f - frames.data());
        steps_so_far += f.derive_steps;
        if (options.organ_masks) {
            constexpr std::uint16_t oldest = 0xfffe;
            const auto step = static_cast<std::uint16_t>(std::min(steps_so_far, int(oldest)));
            std::vector<std::uint16_t> next_ages(string.size(), step);
            std::vector<std::uint32_t> next_births(string.size());
            for (std::size_t i = 0; i < string.size(); ++i) {
                const std::uint32_t parent = i < lineage.size() ? lineage[i] : lsys::no_parent;
                next_births[i] = static_cast<std::uint32_t>(i);
                if (parent == lsys::no_parent)
                    continue;
                // the first frame's parents are the axiom's modules, born at step 0
                next_ages[i] = parent < ages.size() ? ages[parent] : 0;
                next_births[i] = parent < births.size() ? births[parent] : parent;
            }
            ages = std::move(next_ages);
            births = std::move(next_births);
        }
        int number = numbering.anchor(f, index);
        struct Restart {  // the next frame's derivation starts when this call returns
            Clock::time_point& start;
            ~Restart() { start = Clock::now(); }
        } restart{derivation_start};
        if (const int signal = SignalNote::signal())
            throw Interrupted(signal);  // a video's run: no further frame is derived
        if (status == 0 && settings.cancel && settings.cancel->load())
            throw Interrupted(SIGINT);  // Ctrl-C between renders, or with only files to write
        if (status != 0)
            return;
        if (filter.to_render(number))
            ledger.derived(number, seconds_since(derivation_start));
        else
            ledger.shared(seconds_since(derivation_start), 0);
        if (previous)  // the in-betweens leading to this frame
            for (int k = 1; k <= numbering.inbetween && status == 0; ++k) {
                geom::AnimationFrame g = between_frame(
                    *previous, f, float(k) / float(numbering.inbetween + 1),
                    numbering.between(index, k));
                if (!filter.to_render(g.number))
                    continue;
                auto blend_start = Clock::now();
                lsys::ModuleString grown = lsys::inbetween(
                    before, string, lineage, float(k) / float(numbering.inbetween + 1), grows);
                ledger.derived(g.number, seconds_since(blend_start));
                // the in-between has the frame's modules, in order: their names too
                take_derived(grown, after_homomorphism(grown), g);
            }
        if (numbering.inbetween > 0) {
            before = string;
            previous = &f;
        }
        if (!filter.selected(number))
            return;
        std::optional<lsys::ModuleString> homo = after_homomorphism(string);
        const lsys::ModuleString& written = homo ? *homo : string;
        if (writes)
            out.write_strings(model, written, f.number);
        const bool geometry_files = writes && (options.rayshade || options.postscript ||
                                               options.inventor || !out.geometry.empty());
        if (!options.view_volume && !geometry_files && !filter.to_render(number))
            return;
        if (refit && animation->new_view_between_frames)
            model.view = read_view(options);
        if (options.view_volume && writes) {
            auto vv_start = Clock::now();
            // --fit drops the view file's box (render::apply_overrides)
            geom::Bounds3 volume = view_volume(model, written, options, !options.shot.fit);
            ledger.shared(0, seconds_since(vv_start));
            fs::path file = frame_file(*options.view_volume, f.number);
            geom::write_view_volume(volume, file);
            out.say("wrote " + file.string());
        }
        if (geometry_files) {
            // The frame's own geometry, as a still derived to its step writes it: organs
            // named by the derived string's modules (glTF's nodes), vector drawings
            // framed as the still's.
            StringOrigins provenance;
            const geom::Scene frame =
                interpret_with_provenance(model, homo ? *homo : string, options, provenance);
            auto wrote = [&](const fs::path& file) {
                out.say("wrote " + file.string());
                if (out.geometry_written)
                    out.geometry_written(file);
            };
            if (options.rayshade) {
                fs::path file = frame_file(*options.rayshade, f.number);
                geom::write_rayshade(frame, file, rayshade_options(options, file, &model));
                wrote(file);
            }
            if (options.postscript) {
                fs::path file = frame_file(*options.postscript, f.number);
                write_vector_output(frame, options, file, VectorFormat::ps);
                wrote(file);
            }
            if (options.inventor) {
                fs::path file = frame_file(*options.inventor, f.number);
                write_inventor_output(frame, options, file);
                wrote(file);
            }
            for (const fs::path& pattern : out.geometry) {
                fs::path file = frame_file(pattern, f.number);
                write_geometry_output(frame, options, file);
                wrote(file);
            }
        }
        if (!filter.to_render(number))
            return;
        geom::AnimationFrame anchor = f;
        anchor.number = number;
        take_derived(string, std::move(homo), anchor);
    });
    out.say(fmt::format("derived {} steps once for {} frames", derived, images_total));
    if (keep_all && !kept.empty()) {
        // One ground for the whole sequence: at the lowest point of every frame, its
        // texture tiled by the size of the largest frame.
        settings.ground.height = lowest;
        if (!(settings.ground.tile > 0)) {
            geom::Vec3 e = all_bounds.extent();
            settings.ground.tile = std::max({e.x, e.y, e.z, 1e-3});
        }
    }
    std::optional<render::Camera> camera;
    if (fixed_view)
        camera = render::make_camera(*fixed_view, fixed_bounds, settings.width, settings.height);
    for (const Kept& k : kept) {
        if (status != 0)
            break;
        auto interpret_start = Clock::now();
        geom::Scene scene = interpret_turtle_string(model, k.turtle, options,
                                                    k.origins.ages.empty() ? nullptr : &k.origins);
        ledger.interpreted(k.frame.number, seconds_since(interpret_start));
        scene.view = k.own_view.value_or(*fixed_view);
        render_frame(scene, k.own_view ? std::nullopt : camera, k.frame);
    }
    if (queue)
        queue->finish(reached, status == 0);
    if (out.stats)
        out.stats->assemble_s = out.stats->load_s + out.stats->derive_s + out.stats->interpret_s;
    return status;
}

int run_turntable(const Options& options, const SequenceOutputs& out)
{
    const int n = options.shot.turntable;
    require_numbered_names(Options{}, out.images, static_cast<std::size_t>(n));
    const bool writes = !out.mpi || out.mpi->rank() == 0;
    geom::Scene scene;
    if (out.make_scene) {
        scene = out.make_scene();  // times its own assembly into out.stats
    } else {
        RunStats ignored;
        RunStats& stats = out.stats ? *out.stats : ignored;
        auto lap = Clock::now();
        Model model = load_model(options);
        stats.load_s = seconds_since(lap);
        lap = Clock::now();
        lsys::ModuleString derived = derive(model, options);
        stats.derive_s = seconds_since(lap);
        if (writes)
            out.write_strings(model, derived,
                              options.steps.value_or(model.lsystem.derivation_length()));
        lap = Clock::now();
        scene = interpret(model, derived, options);
        stats.interpret_s = seconds_since(lap);
        stats.assemble_s = stats.load_s + stats.derive_s + stats.interpret_s;
    }
    if (out.stats)
        out.stats->sequence_frames = std::size_t(n);
    FrameLedger ledger(out.stats, out.command_start);
    scene.view = render::apply_overrides(scene.view, view_overrides(options.shot), scene.bounds);
    if (out.mpi)
        out.mpi->checkpoint();
    if (options.view_volume && writes)
        geom::write_view_volume(scene.view.box.value_or(scene.bounds), *options.view_volume);

    const render::RenderSettings& s = out.settings;
    std::vector<render::Camera> orbit = render::turntable_cameras(
        scene.view, scene.bounds, n, options.shot.turntable_elevation, s.width, s.height);
    // Frames are numbered 1..N; the first looks from the view file's side.
    FrameFilter filter(options.shot, out.images, bool(out.frame_images));
    if (out.mpi) {
        std::vector<int> all(static_cast<std::size_t>(n));
        std::iota(all.begin(), all.end(), 1);
        filter.agree(*out.mpi, all);
    }
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
    // --mpi: this rank's share of the views; `ordinals` maps them back.
    std::optional<FrameExchange> exchange;
    if (out.mpi)
        exchange.emplace(*out.mpi);
    std::vector<render::Camera> mine;
    std::vector<std::size_t> ordinals;
    for (std::size_t k = 0; k < cameras.size(); ++k)
        if (!exchange || exchange->renders(k)) {
            mine.push_back(cameras[k]);
            ordinals.push_back(k);
        }
    auto write_received = [&](std::size_t k, render::Image& image) {
        write_frame_images(image, numbers[k], options, out);
        progress.frame_done(numbers[k], -1);
    };
    double render_start_s = ledger.now();
    render::render_views(scene, mine, s,
                         [&](std::size_t view, render::Image& image, const render::RenderReport& r) {
        std::size_t k = ordinals[view];
        ledger.rendered(numbers[k], scene, r, render_start_s, s);
        auto write = [&](std::size_t, render::Image& done) {
            write_frame_images(done, numbers[k], options, out);
            progress.frame_done(numbers[k], r.seconds);
        };
        if (!exchange) {
            write(k, image);
        } else {
            exchange->rendered(k, image, write);
            // The other ranks' views rendered meanwhile, up to rank 0's next one.
            exchange->receive_until(std::min(cameras.size(), k + std::size_t(out.mpi->size())),
                                    write_received);
        }
        if (r.cancelled)
            status = 130;
        return true;
    });
    if (exchange && status == 0)
        exchange->receive_until(cameras.size(), write_received);
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
    return derive_frames_with_lineage(
        model, frames, false,
        [&](const geom::AnimationFrame& f, const lsys::ModuleString& s,
            const std::vector<std::uint32_t>&) { on_frame(f, s); });
}

int derive_frames_with_lineage(const Model& model,
                               const std::vector<geom::AnimationFrame>& frames, bool lineage,
                               const FrameWithLineage& on_frame)
{
    lsys::Derivation derivation = model.lsystem.start();
    if (lineage)
        derivation.track_lineage();
    derivation.go_on_after_stop_one();
    for (std::size_t i = 0; i < frames.size(); ++i) {
        derivation.advance(frames[i].derive_steps);
        // cpfg runs the End block once the last frame is reached, or on stop()
        bool last = i + 1 == frames.size() || derivation.stopped();
        if (last && (!derivation.stopped() || derivation.stop_runs_end()))
            derivation.finish();
        on_frame(frames[i], derivation.string(), derivation.lineage());
        if (derivation.stopped())
            break;  // stop(n), n != 1, ends the animation (manual 5.1)
    }
    return derivation.steps_done();
}
void apply_staging(render::RenderSettings& settings, const Options& options)
{
    const ShotOptions& shot = options.shot;
    if (shot.ground || shot.shadow_catcher) {
        render::RenderSettings::Ground& ground = settings.ground;
        ground.enabled = true;
        ground.shadow_catcher = shot.shadow_catcher;
        const std::string value = shot.ground.value_or("");
        if (is_ground_texture(value)) {
            ground.texture = fs::absolute(value);
            ground.colour = {1, 1, 1};  // the texture's own colours
        } else if (!value.empty()) {
            auto rgb = background_colour(value, "--ground");
            ground.colour = {rgb[0], rgb[1], rgb[2]};
        }
    }
    const std::optional<std::string>& background = shot.background;
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

namespace {

render::PixelFilter pixel_filter(const std::string& name)
{
    if (name == "gaussian")
        return render::PixelFilter::gaussian;
    if (name == "blackman-harris")
        return render::PixelFilter::blackman_harris;
    return render::PixelFilter::box;
}

}  // namespace

std::shared_ptr<const render::Environment> make_environment(const Options& options)
{
    std::optional<render::Environment> environment;
    if (options.sky) {
        render::SkyParameters sky;
        if (!options.sun_direction.empty())
            sky.sun_direction = render::normalize(render::Vec3f(
                options.sun_direction[0], options.sun_direction[1], options.sun_direction[2]));
        sky.turbidity = options.turbidity;
        environment = render::make_sky_environment(sky);
    } else if (options.environment_map) {
        environment =
            render::make_map_environment(*options.environment_map, options.environment_scale);
    }
    if (!environment)
        return nullptr;
    return std::make_shared<const render::Environment>(
        std::move(*environment).rotated(options.environment_rotation));
}

render::RenderSettings render_settings(const Options& options,
                                       const std::vector<std::filesystem::path>& images)
{
    render::RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.samples_per_pixel = options.samples_per_pixel;
    settings.max_depth = options.max_depth;
    settings.seed = options.seed;
    settings.sampler = options.sampler == "white" ? render::SampleSequence::white
                                                  : render::SampleSequence::sobol;
    settings.threads = options.threads;
    settings.max_memory_bytes = options.max_memory_bytes;
    settings.filter = pixel_filter(options.filter);
    settings.filter_radius = options.filter_radius;
    settings.noise_target = options.noise_target;
    settings.time_budget_s = options.time_budget_s;
    settings.aperture_radius = options.aperture_radius;
    settings.focus_distance = options.focus_distance;
    settings.transparent_background = options.transparent;
    settings.ambient = {options.ambient, options.ambient, options.ambient};
    settings.view_lights = !options.no_view_lights;
    settings.environment = make_environment(options);
    // The albedo, normal and depth layers cost a camera-ray intersection: only for a
    // format that keeps them.
    settings.aovs = std::any_of(images.begin(), images.end(), [](const auto& f) {
        const OutputFormat* format = find_output_format(f);
        return format && format->keeps_layers;
    });
    if (options.denoise)
        settings.denoiser = render::make_default_denoiser();
    if (options.organ_masks)
        settings.organ_mask_depth = render::default_organ_mask_depth;
    apply_staging(settings, options);
    return settings;
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

namespace {

/// A texture file as PNG bytes (what glTF embeds), through the image codec: its pixels
/// decoded to linear values, alpha associated, written as the renderer writes a PNG
/// (sRGB, straight alpha) into a private folder and read back; empty when unreadable.
std::vector<unsigned char> texture_as_png(const fs::path& file, std::uint64_t max_memory_bytes)
{
    std::string why;
    std::optional<render::TexturePixels> pixels =
        render::image_codec().read_texture(file, max_memory_bytes, why);
    if (!pixels || pixels->channels < 1 || pixels->channels > 4)
        return {};
    const render::TexturePixels& t = *pixels;
    render::Image image;
    image.width = t.width;
    image.height = t.height;
    image.transparent = t.channels == 2 || t.channels == 4;
    image.rgba.resize(std::size_t(t.width) * std::size_t(t.height) * 4);
    const auto value = [&](std::size_t i) {
        return t.bytes.empty() ? t.floats[i] : float(t.bytes[i]) / 255.0f;
    };
    const auto decoded = [&](float v) { return t.srgb ? render::srgb_to_linear(v) : v; };
    for (std::size_t p = 0; p < std::size_t(t.width) * std::size_t(t.height); ++p) {
        const std::size_t in = p * std::size_t(t.channels);
        const bool grey = t.channels <= 2;
        const float alpha = image.transparent ? value(in + std::size_t(t.channels) - 1) : 1.0f;
        for (std::size_t c = 0; c < 3; ++c)
            image.rgba[p * 4 + c] = decoded(value(grey ? in : in + c)) * alpha;
        image.rgba[p * 4 + 3] = alpha;
    }
    std::string folder = (fs::temp_directory_path() / "cambium-texture-XXXXXX").string();
    if (!mkdtemp(folder.data()))
        return {};
    std::vector<unsigned char> bytes;
    try {
        const fs::path png = fs::path(folder) / "texture.png";
        render::write_image(image, png);
        bytes = read_binary_file(png, "the re-encoded texture", std::uintmax_t{1} << 30);
    } catch (const Error&) {
        bytes.clear();
    }
    std::error_code ec;
    fs::remove_all(folder, ec);
    return bytes;
}

}  // namespace

bool is_geometry_output(const std::filesystem::path& file)
{
    const OutputFormat* format = find_output_format(file);
    return format && (format->mesh != MeshFormat::none || format->vector != VectorFormat::none);
}

void write_geometry_output(const geom::Scene& scene, const Options& options,
                           const std::filesystem::path& file)
{
    const OutputFormat* format = find_output_format(file);
    if (format && format->vector != VectorFormat::none) {
        write_vector_output(scene, options, file, format->vector);
        return;
    }
    geom::MeshExportOptions mesh;
    mesh.texture_folder = options.scene ? options.scene->parent_path() : options.view.parent_path();
    mesh.max_memory_bytes = options.max_memory_bytes;
    mesh.png_of = [&](const fs::path& texture) {
        return texture_as_png(texture, options.max_memory_bytes);
    };
    geom::write_mesh(scene, file, format ? format->mesh : MeshFormat::none, mesh);
}

void write_inventor_output(const geom::Scene& scene, const Options& options,
                           const std::filesystem::path& file)
{
    geom::MeshExportOptions how;
    how.max_memory_bytes = options.max_memory_bytes;
    geom::write_inventor(scene, file, how);
}

void write_vector_output(const geom::Scene& scene, const Options& options,
                         const std::filesystem::path& file, VectorFormat format)
{
    const geom::Tessellation how = geom::drawing_tessellation;
    // the tessellated mesh and the drawing's shapes are held together
    constexpr std::uint64_t bytes_per_triangle =
        geom::exported_triangle_bytes + render::vector_shape_bytes;
    std::uint64_t shapes = geom::tessellated_triangles(scene, how);
    if (scene.line_radius_in_pixels) {
        shapes += scene.geometry.lines.segment_count();
        for (const geom::Instance& in : scene.instances)
            if (in.prototype < scene.prototypes.size())
                shapes += scene.prototypes[in.prototype].geometry.lines.segment_count();
    }
    if (shapes > options.max_memory_bytes / bytes_per_triangle)
        throw Error(file.string() + ": the drawing's " + std::to_string(shapes) +
                    " shapes need " + byte_size_text(shapes * bytes_per_triangle) +
                    ", more than the memory budget of " +
                    byte_size_text(options.max_memory_bytes) + " (--max-memory)");
    const geom::View view =
        render::apply_overrides(scene.view, view_overrides(options.shot), scene.bounds);
    const render::Camera camera =
        render::make_camera(view, scene.bounds, options.width, options.height);
    render::VectorDrawing drawing =
        render::project_drawing(scene, geom::tessellate(scene, how), camera);
    render::write_vector(drawing, file, format);
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
    // SIGINT, SIGTERM and SIGHUP, noted before the first folder exists, stop the renders
    // and end the run by this path, through the folders' destructors.
    std::optional<SignalNote> signals;
    if (!videos.empty()) {
        signals.emplace();
        frames.settings.cancel = signals->cancel();
    }
    // Each video's frames and encoding in a fresh private folder beside it, removed
    // however the run ends (nothing a model folder plants there can be reached).
    std::vector<PrivateFolder> work;
    work.reserve(videos.size());
    for (const fs::path& video : videos) {
        work.emplace_back(video);
        frames.images.push_back(video_frame_pattern(work.back()));
    }
    int status = options.shot.turntable > 0 ? run_turntable(options, frames)
                                            : run_animation(options, frames);
    if (signals && signals->signal() != 0)
        throw Interrupted(signals->signal());  // the folders go as this leaves
    if (status != 0 || (outputs.mpi && outputs.mpi->rank() != 0))
        return status;
    for (std::size_t i = 0; i < videos.size(); ++i) {
        encode_video(ffmpeg, work[i], options.shot.fps, videos[i]);
        outputs.say("wrote " + videos[i].string());
    }
    return 0;
}

}  // namespace cambium::app
