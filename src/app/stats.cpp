// SPDX-License-Identifier: Apache-2.0
// --stats and --stats-json.
#include "app/stats.h"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/diagnostics.h"
#include "geom/scene_limits.h"

namespace cambium::app {

PrimitiveCounts& PrimitiveCounts::operator+=(const PrimitiveCounts& o)
{
    cylinders += o.cylinders;
    lines += o.lines;
    curve_segments += o.curve_segments;
    spheres += o.spheres;
    discs += o.discs;
    triangles += o.triangles;
    return *this;
}

PrimitiveCounts count_primitives(const geom::Geometry& g, bool pixel_lines)
{
    PrimitiveCounts c;
    (pixel_lines ? c.lines : c.cylinders) = g.lines.segment_count();
    c.curve_segments = g.curves.segment_count();
    c.spheres = g.spheres.size();
    c.discs = g.discs.size();
    c.triangles = g.mesh.size();
    return c;
}

void RunStats::add_assembly(double load, double derive, double interpret, double wall)
{
    load_s = load;
    derive_s = derive;
    interpret_s = interpret;
    assemble_s = wall;
}

void RunStats::add_scene(const geom::Scene& scene)
{
    interpreted = true;
    primitives = count_primitives(scene.geometry, scene.line_radius_in_pixels);
    placed_primitives = primitives;
    std::vector<PrimitiveCounts> per_prototype;
    for (const geom::Prototype& p : scene.prototypes) {
        per_prototype.push_back(count_primitives(p.geometry, scene.line_radius_in_pixels));
        primitives += per_prototype.back();
    }
    for (const geom::Instance& i : scene.instances)
        if (i.prototype < per_prototype.size())
            placed_primitives += per_prototype[i.prototype];
    instances = scene.instances.size();
    prototypes = scene.prototypes.size();
    cambium_bytes = geom::scene_buffer_bytes(scene);
}

void RunStats::add_render(const render::RenderReport& report, double render_start_s, int w, int h)
{
    rendered = true;
    build_s = report.build_seconds;
    first_pixel_s = render_start_s + report.setup_seconds;
    render_s = report.seconds - report.setup_seconds;
    denoise_s = report.denoise_seconds;
    width = w;
    height = h;
    samples = report.samples;
    rays = report.rays;
    background_only_samples = report.background_only_samples;
    embree_bytes = report.embree_bytes;
    embree_peak_bytes = report.embree_peak_bytes;
    render_buffer_bytes = report.render_buffer_bytes;
    embree_shared_bytes = report.embree_shared_bytes;
    embree_unmonitored_bytes = report.embree_unmonitored_bytes;
}

void RunStats::add_frame(FrameStats f, const geom::Scene& scene,
                         const render::RenderReport& report, double render_start_s, int w, int h)
{
    if (!rendered)
        first_pixel_s = render_start_s + report.setup_seconds;
    sequence = rendered = interpreted = true;
    width = w;
    height = h;
    f.build_s = report.build_seconds;
    f.render_s = report.seconds - report.setup_seconds;
    f.samples = report.samples;
    f.rays = report.rays;
    f.background_only_samples = report.background_only_samples;
    f.embree_bytes = report.embree_bytes;
    RunStats counted;
    counted.add_scene(scene);
    f.primitives = counted.placed_primitives.total();
    if (frames.empty() || f.primitives > placed_primitives.total()) {  // the largest frame
        primitives = counted.primitives;
        placed_primitives = counted.placed_primitives;
        instances = counted.instances;
        prototypes = counted.prototypes;
        cambium_bytes = counted.cambium_bytes;
    }
    derive_s += f.derive_s;
    interpret_s += f.interpret_s;
    build_s += f.build_s;
    render_s += f.render_s;
    denoise_s += report.denoise_seconds;
    samples += f.samples;
    rays += f.rays;
    background_only_samples += f.background_only_samples;
    embree_bytes = std::max(embree_bytes, report.embree_bytes);
    embree_peak_bytes = std::max(embree_peak_bytes, report.embree_peak_bytes);
    f.peak_process_bytes = app::peak_process_bytes();
    frames.push_back(f);
}

namespace {

std::uint64_t read_peak_process_bytes()
{
    // VmHWM is the kernel's high-water mark of the resident set, in kB.
    std::ifstream status("/proc/self/status");
    std::string key;
    while (status >> key) {
        if (key == "VmHWM:") {
            std::uint64_t kb = 0;
            status >> kb;
            return kb * 1024;
        }
        status.ignore(1 << 16, '\n');
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // KiB on Linux
}

}  // namespace

std::uint64_t peak_process_bytes()
{
    // The kernel sums the resident set from per-CPU counters that it reads without
    // folding them together, so VmHWM read twice can go down by a few pages (seen: 88 KiB
    // between two frames). A peak so far never goes down: the highest value read.
    static std::atomic<std::uint64_t> highest{0};
    std::uint64_t now = read_peak_process_bytes();
    std::uint64_t seen = highest.load(std::memory_order_relaxed);
    while (now > seen && !highest.compare_exchange_weak(seen, now, std::memory_order_relaxed)) {
    }
    return std::max(now, seen);
}

namespace {

double per_second(double count, double seconds) { return seconds > 0 ? count / seconds : 0; }

double per_primitive(std::uint64_t bytes, std::uint64_t primitives)
{
    return primitives > 0 ? double(bytes) / double(primitives) : 0;
}

std::string mib(std::uint64_t bytes) { return fmt::format("{:.1f} MiB", double(bytes) / (1 << 20)); }

nlohmann::json counts_json(const PrimitiveCounts& c)
{
    return {{"cylinders", c.cylinders}, {"lines", c.lines},
            {"curve_segments", c.curve_segments}, {"spheres", c.spheres},
            {"discs", c.discs}, {"triangles", c.triangles}, {"total", c.total()}};
}

std::string counts_line(const PrimitiveCounts& c)
{
    return fmt::format(
        "{} ({} cylinders, {} pixel-width lines, {} curve segments, {} spheres, {} discs, "
        "{} triangles)",
        c.total(), c.cylinders, c.lines, c.curve_segments, c.spheres, c.discs, c.triangles);
}

/// Primitives Embree holds: each built once, plus one per instance.
std::uint64_t embree_primitives(const RunStats& s) { return s.primitives.total() + s.instances; }

/// All of Cambium's geometry buffers: the Scene's and the renderer's.
std::uint64_t cambium_total(const RunStats& s) { return s.cambium_bytes + s.render_buffer_bytes; }

/// Memory per primitive against what Embree itself needs (docs/benchmarks.md): what
/// Embree needs is its own allocations (those its memory monitor reports, and its instance
/// geometries, which it does not) plus the buffers it reads in place (keys, indices: with
/// rtcSetNewGeometryBuffer it would allocate them itself); what is used is Embree's
/// allocations plus all of Cambium's buffers. 1 would be a renderer that keeps nothing
/// beside the buffers Embree reads.
double ratio_to_embree_need(const RunStats& s)
{
    std::uint64_t embree = s.embree_bytes + s.embree_unmonitored_bytes;
    std::uint64_t need = embree + s.embree_shared_bytes;
    return need > 0 ? double(embree + cambium_total(s)) / double(need) : 0.0;
}

/// The same with Embree's allocations as its memory monitor reports them alone: it
/// leaves out Embree's instance geometries, about 300 B each.
double ratio_to_embree_monitor(const RunStats& s)
{
    std::uint64_t need = s.embree_bytes + s.embree_shared_bytes;
    return need > 0 ? double(s.embree_bytes + cambium_total(s)) / double(need) : 0.0;
}

/// The earlier measure, (Embree + Cambium) / Embree's allocations alone: it counts the
/// keys Embree reads as overhead, and it falls when Embree wastes memory.
double ratio_to_embree_allocations(const RunStats& s)
{
    return s.embree_bytes > 0 ? double(s.embree_bytes + cambium_total(s)) / double(s.embree_bytes)
                              : 0.0;
}

}  // namespace

namespace {

/// The sequence's lines: how many frames, and the spread of their render times.
std::string sequence_lines(const RunStats& s)
{
    std::string out = fmt::format("  sequence of {} frames, {} rendered here; times below are "
                                  "sums over them\n",
                                  s.sequence_frames, s.frames.size());
    if (s.frames.empty())
        return out;
    auto slowest = std::max_element(s.frames.begin(), s.frames.end(),
                                    [](const FrameStats& a, const FrameStats& b) {
                                        return a.render_s < b.render_s;
                                    });
    out += fmt::format("  per frame: render {:.3f} s on average, slowest frame {} ({:.3f} s); "
                       "interpret {:.3f} s on average\n",
                       s.render_s / double(s.frames.size()), slowest->number, slowest->render_s,
                       s.interpret_s / double(s.frames.size()));
    return out;
}

}  // namespace

std::string format_stats(const RunStats& s)
{
    std::string out = "statistics\n";
    if (s.sequence)
        out += sequence_lines(s);
    out += fmt::format("  load {:.3f} s, derive {:.3f} s, interpret {:.3f} s (together {:.3f} s), "
                       "build {:.3f} s\n",
                       s.load_s, s.derive_s, s.interpret_s, s.assemble_s, s.build_s);
    if (s.rendered)
        out += fmt::format("  time to first pixel {:.3f} s, rendering {:.3f} s{}\n", s.first_pixel_s,
                           s.render_s,
                           s.denoise_s > 0 ? fmt::format(" (denoising {:.3f} s)", s.denoise_s)
                                           : std::string());
    if (s.interpreted) {
        out += std::string(s.sequence ? "  largest frame: " : "  ") + "primitives " +
               counts_line(s.primitives) + "\n";
        out += fmt::format("  {} instances of {} prototypes; placed primitives {}\n", s.instances,
                           s.prototypes, s.placed_primitives.total());
    } else {
        out += "  not interpreted (string outputs only)\n";
    }
    std::uint64_t n = embree_primitives(s);
    if (s.rendered)
        out += fmt::format("  memory: Embree {} (peak {}, {:.1f} B per primitive), Cambium {} "
                           "({:.1f} B per primitive; {} of it read by Embree in place); "
                           "{:.2f}x what Embree needs\n",
                           mib(s.embree_bytes), mib(s.embree_peak_bytes),
                           per_primitive(s.embree_bytes, n), mib(cambium_total(s)),
                           per_primitive(cambium_total(s), n), mib(s.embree_shared_bytes),
                           ratio_to_embree_need(s));
    else if (s.interpreted)
        out += "  memory: Cambium " + mib(s.cambium_bytes) + "\n";
    out += "  peak process memory " + mib(s.peak_process_bytes) + "\n";
    if (s.rendered)
        out += fmt::format("  {}x{}: {} samples ({} of empty pixels, without a ray), {} rays; "
                           "{:.3g} samples/s, {:.3g} rays/s\n",
                           s.width, s.height, s.samples, s.background_only_samples, s.rays,
                           per_second(double(s.samples), s.render_s),
                           per_second(double(s.rays), s.render_s));
    return out;
}

nlohmann::json stats_json(const RunStats& s)
{
    std::uint64_t n = embree_primitives(s);
    nlohmann::json j;
    j["interpreted"] = s.interpreted;
    j["rendered"] = s.rendered;
    j["times_s"] = {{"load", s.load_s},
                    {"derive", s.derive_s},
                    {"interpret", s.interpret_s},
                    {"assemble", s.assemble_s},
                    {"build", s.build_s},
                    {"first_pixel", s.rendered ? nlohmann::json(s.first_pixel_s) : nullptr},
                    {"render", s.render_s},
                    {"denoise", s.denoise_s}};
    j["primitives"] = counts_json(s.primitives);
    j["placed_primitives"] = counts_json(s.placed_primitives);
    j["instances"] = s.instances;
    j["prototypes"] = s.prototypes;
    j["memory_bytes"] = {{"embree", s.embree_bytes},
                         {"embree_peak", s.embree_peak_bytes},
                         {"cambium", cambium_total(s)},
                         {"scene_buffers", s.cambium_bytes},
                         {"render_buffers", s.render_buffer_bytes},
                         {"embree_shared", s.embree_shared_bytes},
                         {"embree_unmonitored", s.embree_unmonitored_bytes},
                         {"peak_process", s.peak_process_bytes}};
    j["bytes_per_primitive"] = {
        {"embree", per_primitive(s.embree_bytes, n)},
        {"cambium", per_primitive(cambium_total(s), n)},
        {"peak_process", per_primitive(s.peak_process_bytes, n)},
        {"ratio_to_embree", ratio_to_embree_need(s)},
        {"ratio_to_embree_monitor", ratio_to_embree_monitor(s)},
        {"ratio_to_embree_allocations", ratio_to_embree_allocations(s)}};
    j["render"] = {{"width", s.width},
                   {"height", s.height},
                   {"samples", s.samples},
                   {"rays", s.rays},
                   {"background_only_samples", s.background_only_samples},
                   {"samples_per_s", per_second(double(s.samples), s.render_s)},
                   {"rays_per_s", per_second(double(s.rays), s.render_s)}};
    j["sequence"] = s.sequence;
    if (s.sequence) {
        j["sequence_frames"] = s.sequence_frames;
        nlohmann::json frames = nlohmann::json::array();
        for (const FrameStats& f : s.frames)
            frames.push_back({{"number", f.number},
                              {"times_s", {{"derive", f.derive_s},
                                           {"interpret", f.interpret_s},
                                           {"build", f.build_s},
                                           {"render", f.render_s}}},
                              {"placed_primitives", f.primitives},
                              {"samples", f.samples},
                              {"rays", f.rays},
                              {"background_only_samples", f.background_only_samples},
                              {"embree_bytes", f.embree_bytes},
                              {"peak_process_bytes", f.peak_process_bytes}});
        j["frames"] = std::move(frames);
    }
    return j;
}

void write_stats_json(const RunStats& stats, const std::filesystem::path& file)
{
    std::string text = stats_json(stats).dump(2) + "\n";
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out << text;
        out.close();
        if (!out)
            throw Error(FileLoc{file.string()}, "cannot be written");
    });
}

}  // namespace cambium::app
