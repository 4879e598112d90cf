// SPDX-License-Identifier: Apache-2.0
// Denoising: the denoised few-sample still against the raw many-sample one, on staged
// stills of the benchmark plants (docs/denoise.md). Each plant is loaded through the app
// pipeline (its model.json command line) and staged as `--sky --background sky --ground
// --perspective --fit --orbit 30 10` stages it; then rendered
//   - at --spp (16) with the denoiser: the denoised image and, beside it, the raw one;
//   - at --raw-spp (256) without it;
//   - at --reference-spp (1024; the acceptance figure asks 4096, too slow for the shared
//     2-core machine) with another seed: the reference, cached under the build folder.
// and compared with the reference: relative MSE (mean over pixels and RGB of
// (x - ref)^2 / (ref^2 + 0.01), as Rousselle et al. measure), the same over the band
// within 2 pixels of the plant's silhouette (the plant: pixels whose nearest hit is an
// organ, not the ground or the sky, in the reference), and SSIM (Wang et al. 2004: 11x11
// Gaussian window, sigma 1.5, on sRGB-encoded values clamped to [0, 1], mean over RGB).
// Times: the 16-spp render's wall seconds with and without its set-up (BVH build,
// textures), the denoiser's, and the denoiser's share of each. Prints one JSON object per
// plant.
//
//   build/benchmarks/denoise [--plant NAME]... [--size WxH] [--threads N] [--spp N]
//       [--raw-spp N] [--reference-spp N] [--search-radius N] [--patch-radius N]
//       [--save FOLDER] [--turntable N]
//
// --turntable N measures flicker instead: an N-frame turntable of the staged plant (10
// degrees above the horizontal, as `--turntable N --turntable-elevation 10`) at --spp
// denoised and raw, and at --raw-spp raw; for each renderer and each pair of consecutive
// frames, the mean absolute difference over RGB relative to the open ground's level, on
// the ground's pixels that the plant does not shade (below). The sun stays put while the
// camera turns, so the plant's shadow moves across the image: a pixel counts only where
// both frames' --raw-spp renders see the ground (organ ground, and no other organ within
// 3 pixels) within 5% of that frame's median ground luminance. Ground that is neither
// shaded nor hidden has the same radiance in every frame, so what differs there is noise
// that moves from frame to frame: flicker.
//
// --save writes each plant's images as PNG for a person to look at: NAME-noisy.png (the
// raw --spp render), NAME-denoised.png, NAME-raw-256.png (the --raw-spp one) and
// NAME-reference.png. Without the corpus (../shared/corpus, or $CAMBIUM_CORPUS) it
// prints {"skipped": ...} and exits 0.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/command_line.h"
#include "app/pipeline.h"
#include "app/sequence.h"
#include "render/color.h"
#include "render/denoise.h"
#include "render/environment.h"
#include "render/framing.h"
#include "render/render.h"

namespace fs = std::filesystem;
namespace render = cambium::render;

namespace {

/// The benchmark plants (corpus folders): leaves, thin twigs, instanced flowers.
const std::map<std::string, std::string> plants = {
    {"FernLeaf", "cpfg/10-manuals/15-VlabTools/FernLeaf"},
    {"WeepingBirch", "cpfg/10-manuals/11-CPFG/WeepingBirch"},
    {"Lilac", "cpfg/10-manuals/11-CPFG/Lilac"},
};

struct Settings {
    std::vector<std::string> plants;
    int width = 640, height = 480, threads = 2, spp = 16, raw_spp = 256, reference_spp = 1024;
    render::NlMeansParameters denoiser;  ///< --search-radius, --patch-radius
    fs::path save;
    int turntable = 0;  ///< --turntable N: measure flicker over N frames
};

/// The plant staged: its scene (camera options applied) and its render settings.
struct Staged {
    cambium::geom::Scene scene;
    render::RenderSettings settings;
};

/// The plant's scene through the same path as `cambium <model.json's command> <staging>`;
/// the current folder becomes the model's.
Staged load_staged(const fs::path& folder, const Settings& s)
{
    std::ifstream in(folder / "model.json");
    std::istringstream words(nlohmann::json::parse(in).at("command").get<std::string>());
    std::vector<std::string> args;
    std::string word;
    words >> word;  // "cpfg"
    while (words >> word)
        args.push_back(word);
    for (const char* a : {"--sky", "--background", "sky", "--ground", "--perspective", "--fit",
                          "--orbit", "30", "10", "-q"})
        args.emplace_back(a);
    fs::current_path(folder);
    cambium::app::Options options = *cambium::app::parse_command_line(args);
    options.width = s.width;
    options.height = s.height;
    cambium::app::Model model = cambium::app::load_model(options);
    Staged staged{cambium::app::interpret(model, cambium::app::derive(model, options), options), {}};
    cambium::app::apply_camera_options(staged.scene, options);
    render::RenderSettings& rs = staged.settings;
    rs.width = s.width;
    rs.height = s.height;
    rs.threads = s.threads;
    rs.environment = std::make_shared<const render::Environment>(
        render::make_sky_environment(render::SkyParameters{}));
    cambium::app::apply_staging(rs, options);
    rs.aovs = false;
    return staged;
}

struct Run {
    render::Image image;
    render::RenderReport report;
};

Run render_at(const Staged& staged, int spp, std::uint64_t seed, bool denoise,
              const render::NlMeansParameters& parameters = {})
{
    render::RenderSettings rs = staged.settings;
    rs.samples_per_pixel = spp;
    rs.seed = seed;
    if (denoise)
        rs.denoiser = std::make_shared<render::NlMeansDenoiser>(parameters);
    Run run;
    run.image = render::render(staged.scene, rs, &run.report);
    return run;
}

/// The reference (raw RGBA and organ ids), cached as raw bytes in `file`.
struct Reference {
    std::vector<float> rgba;
    std::vector<std::uint32_t> organ;
};

Reference reference(const Staged& staged, const Settings& s, const fs::path& file)
{
    const std::size_t n = std::size_t(s.width) * s.height;
    Reference r{std::vector<float>(n * 4), std::vector<std::uint32_t>(n)};
    std::ifstream in(file, std::ios::binary);
    if (in.read(reinterpret_cast<char*>(r.rgba.data()), std::streamsize(n * 4 * sizeof(float))) &&
        in.read(reinterpret_cast<char*>(r.organ.data()), std::streamsize(n * sizeof(std::uint32_t))) &&
        in.peek() == std::char_traits<char>::eof())
        return r;
    // With the denoiser for its organ layer (the plant's mask); its raw frame is the
    // reference. A seed of its own: its noise is independent of the measured renders'.
    Run run = render_at(staged, s.reference_spp, 0x5eed, true);
    r.rgba = std::move(run.image.noisy);
    r.organ = std::move(run.image.organ);
    fs::create_directories(file.parent_path());
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(r.rgba.data()), std::streamsize(n * 4 * sizeof(float)));
    out.write(reinterpret_cast<const char*>(r.organ.data()), std::streamsize(n * sizeof(std::uint32_t)));
    return r;
}

bool is_plant(std::uint32_t organ)
{
    return organ != render::organ_background && organ != render::organ_ground;
}

/// Pixels within 2 of the plant's silhouette (a plant pixel beside a non-plant one).
std::vector<bool> silhouette_band(const std::vector<std::uint32_t>& organ, int w, int h)
{
    std::vector<bool> edge(organ.size(), false), band(organ.size(), false);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool plant = is_plant(organ[std::size_t(y) * w + x]);
            for (auto [dx, dy] : std::array<std::pair<int, int>, 4>{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}}) {
                const int nx = x + dx, ny = y + dy;
                if (nx >= 0 && ny >= 0 && nx < w && ny < h &&
                    is_plant(organ[std::size_t(ny) * w + nx]) != plant)
                    edge[std::size_t(y) * w + x] = true;
            }
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!edge[std::size_t(y) * w + x])
                continue;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    const int nx = x + dx, ny = y + dy;
                    if (nx >= 0 && ny >= 0 && nx < w && ny < h)
                        band[std::size_t(ny) * w + nx] = true;
                }
        }
    return band;
}

/// Relative MSE over the pixels `mask` admits (all where empty).
double relative_mse(const std::vector<float>& image, const std::vector<float>& ref,
                    const std::vector<bool>& mask = {})
{
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < ref.size() / 4; ++i) {
        if (!mask.empty() && !mask[i])
            continue;
        for (std::size_t c = 0; c < 3; ++c) {
            const double r = ref[i * 4 + c], d = double(image[i * 4 + c]) - r;
            sum += d * d / (r * r + 0.01);
            ++count;
        }
    }
    return count > 0 ? sum / double(count) : 0;
}

/// SSIM (see the top of the file).
double ssim(const std::vector<float>& image, const std::vector<float>& ref, int w, int h)
{
    constexpr int radius = 5;
    constexpr double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    std::array<double, 2 * radius + 1> g{};
    double gsum = 0;
    for (int k = -radius; k <= radius; ++k)
        gsum += g[std::size_t(k + radius)] = std::exp(-k * k / (2 * 1.5 * 1.5));
    for (double& v : g)
        v /= gsum;
    double total = 0;
    std::size_t count = 0;
    for (int c = 0; c < 3; ++c) {
        auto encode = [&](const std::vector<float>& img) {
            std::vector<double> out(std::size_t(w) * h);
            for (std::size_t i = 0; i < out.size(); ++i)
                out[i] = render::linear_to_srgb(std::clamp(img[i * 4 + std::size_t(c)], 0.0f, 1.0f));
            return out;
        };
        const std::vector<double> a = encode(image), b = encode(ref);
        // Separable Gaussian blur of a, b, a^2, b^2, ab.
        auto blur = [&](auto value) {
            std::vector<double> tmp(a.size()), out(a.size());
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    double s = 0;
                    for (int k = -radius; k <= radius; ++k) {
                        const int xx = std::clamp(x + k, 0, w - 1);
                        s += g[std::size_t(k + radius)] * value(std::size_t(y) * w + xx);
                    }
                    tmp[std::size_t(y) * w + x] = s;
                }
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    double s = 0;
                    for (int k = -radius; k <= radius; ++k) {
                        const int yy = std::clamp(y + k, 0, h - 1);
                        s += g[std::size_t(k + radius)] * tmp[std::size_t(yy) * w + x];
                    }
                    out[std::size_t(y) * w + x] = s;
                }
            return out;
        };
        const auto ma = blur([&](std::size_t i) { return a[i]; });
        const auto mb = blur([&](std::size_t i) { return b[i]; });
        const auto aa = blur([&](std::size_t i) { return a[i] * a[i]; });
        const auto bb = blur([&](std::size_t i) { return b[i] * b[i]; });
        const auto ab = blur([&](std::size_t i) { return a[i] * b[i]; });
        for (std::size_t i = 0; i < a.size(); ++i) {
            const double va = aa[i] - ma[i] * ma[i], vb = bb[i] - mb[i] * mb[i];
            const double cov = ab[i] - ma[i] * mb[i];
            total += ((2 * ma[i] * mb[i] + c1) * (2 * cov + c2)) /
                     ((ma[i] * ma[i] + mb[i] * mb[i] + c1) * (va + vb + c2));
            ++count;
        }
    }
    return total / double(count);
}

void save_png(const std::vector<float>& rgba, int w, int h, const fs::path& file);

/// The turntable's frames: RGBA (denoised when the run denoises), the raw RGBA beside
/// them when denoised, and each frame's organ ids.
struct Frames {
    std::vector<std::vector<float>> rgba, noisy;
    std::vector<std::vector<std::uint32_t>> organ;
};

Frames render_turntable(const Staged& staged, std::span<const render::Camera> cameras, int spp,
                        bool denoise, const render::NlMeansParameters& parameters = {})
{
    render::RenderSettings rs = staged.settings;
    rs.samples_per_pixel = spp;
    rs.seed = 1;
    // The organ layer comes with the denoiser; the raw runs need it for the ground mask.
    rs.denoiser = std::make_shared<render::NlMeansDenoiser>(parameters);
    Frames f;
    render::render_views(staged.scene, cameras, rs,
                         [&](std::size_t, render::Image& image, const render::RenderReport&) {
                             f.rgba.push_back(denoise ? std::move(image.rgba) : std::move(image.noisy));
                             if (denoise)
                                 f.noisy.push_back(std::move(image.noisy));
                             f.organ.push_back(std::move(image.organ));
                             return true;
                         });
    return f;
}

/// Open, unshaded ground in a frame (see the top of the file), from a clean render of it.
std::vector<bool> open_ground(const std::vector<float>& rgba, const std::vector<std::uint32_t>& organ,
                              int w, int h)
{
    std::vector<float> ground;
    for (std::size_t i = 0; i < organ.size(); ++i)
        if (organ[i] == render::organ_ground)
            ground.push_back(render::luminance(render::Vec3f(rgba[i * 4], rgba[i * 4 + 1], rgba[i * 4 + 2])));
    std::vector<bool> open(organ.size(), false);
    if (ground.empty())
        return open;
    std::nth_element(ground.begin(), ground.begin() + std::ptrdiff_t(ground.size() / 2), ground.end());
    const float median = ground[ground.size() / 2];
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            bool ok = organ[i] == render::organ_ground &&
                      std::abs(render::luminance(render::Vec3f(rgba[i * 4], rgba[i * 4 + 1],
                                                               rgba[i * 4 + 2])) - median) <= 0.05f * median;
            for (int dy = -3; ok && dy <= 3; ++dy)
                for (int dx = -3; ok && dx <= 3; ++dx) {
                    const int nx = std::clamp(x + dx, 0, w - 1), ny = std::clamp(y + dy, 0, h - 1);
                    ok = organ[std::size_t(ny) * w + nx] == render::organ_ground;
                }
            open[i] = ok;
        }
    return open;
}

/// Mean over consecutive frame pairs of the mean |a - b| over RGB and the pairs' open
/// ground, relative to the clean frames' mean ground level there.
double flicker(const std::vector<std::vector<float>>& frames, const Frames& clean,
               const std::vector<std::vector<bool>>& open)
{
    double total = 0;
    std::size_t pairs = 0;
    for (std::size_t k = 0; k + 1 < frames.size(); ++k) {
        double diff = 0, level = 0;
        std::size_t n = 0;
        for (std::size_t i = 0; i < open[k].size(); ++i) {
            if (!open[k][i] || !open[k + 1][i])
                continue;
            for (std::size_t c = 0; c < 3; ++c) {
                diff += std::abs(double(frames[k][i * 4 + c]) - frames[k + 1][i * 4 + c]);
                level += 0.5 * (double(clean.rgba[k][i * 4 + c]) + clean.rgba[k + 1][i * 4 + c]);
            }
            ++n;
        }
        if (n > 0 && level > 0) {
            total += diff / level;
            ++pairs;
        }
    }
    return pairs > 0 ? total / double(pairs) : 0;
}

void run_turntable(const std::string& name, const fs::path& folder, const Settings& s)
{
    const fs::path start = fs::current_path();
    Staged staged = load_staged(folder, s);
    fs::current_path(start);
    const std::vector<render::Camera> cameras = render::turntable_cameras(
        staged.scene.view, staged.scene.bounds, s.turntable, 10.0, s.width, s.height);
    const auto t0 = std::chrono::steady_clock::now();
    const Frames few = render_turntable(staged, cameras, s.spp, true, s.denoiser);
    const auto t1 = std::chrono::steady_clock::now();
    const Frames many = render_turntable(staged, cameras, s.raw_spp, false);
    const auto t2 = std::chrono::steady_clock::now();
    std::vector<std::vector<bool>> open;
    std::size_t open_pixels = 0;
    for (std::size_t k = 0; k < many.rgba.size(); ++k) {
        open.push_back(open_ground(many.rgba[k], many.organ[k], s.width, s.height));
        open_pixels += std::size_t(std::count(open.back().begin(), open.back().end(), true));
    }
    nlohmann::json j;
    j["plant"] = name;
    j["image"] = std::to_string(s.width) + "x" + std::to_string(s.height);
    j["threads"] = s.threads;
    j["frames"] = s.turntable;
    j["spp"] = s.spp;
    j["raw_spp"] = s.raw_spp;
    j["open_ground_pixels_per_frame"] = open_pixels / std::max<std::size_t>(1, open.size());
    j["flicker"] = {{"noisy", flicker(few.noisy, many, open)},
                    {"denoised", flicker(few.rgba, many, open)},
                    {"raw_many", flicker(many.rgba, many, open)}};
    j["seconds"] = {{"denoised_turntable", std::chrono::duration<double>(t1 - t0).count()},
                    {"raw_many_turntable", std::chrono::duration<double>(t2 - t1).count()}};
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
    if (!s.save.empty()) {
        fs::create_directories(s.save);
        for (std::size_t k : {std::size_t(0), few.rgba.size() / 2}) {
            const std::string tag = name + "-turntable-" + std::to_string(k + 1);
            save_png(few.rgba[k], s.width, s.height, s.save / (tag + "-denoised.png"));
            save_png(few.noisy[k], s.width, s.height, s.save / (tag + "-noisy.png"));
        }
    }
}

void save_png(const std::vector<float>& rgba, int w, int h, const fs::path& file)
{
    render::Image image{w, h, rgba};
    render::write_image(image, file);
}

void run_plant(const std::string& name, const fs::path& folder, const Settings& s,
               const fs::path& cache)
{
    const fs::path start = fs::current_path();
    Staged staged = load_staged(folder, s);
    fs::current_path(start);
    const Reference ref =
        reference(staged, s, cache / (name + "-" + std::to_string(s.width) + "x" +
                                      std::to_string(s.height) + "-" +
                                      std::to_string(s.reference_spp) + ".raw"));
    const Run few = render_at(staged, s.spp, 1, true, s.denoiser);
    const Run many = render_at(staged, s.raw_spp, 2, false);
    const std::vector<bool> band = silhouette_band(ref.organ, s.width, s.height);
    std::size_t band_pixels = 0, plant_pixels = 0;
    for (std::size_t i = 0; i < band.size(); ++i) {
        band_pixels += band[i] ? 1 : 0;
        plant_pixels += is_plant(ref.organ[i]) ? 1 : 0;
    }
    const std::vector<float>& noisy = few.image.noisy;
    const std::vector<float>& denoised = few.image.rgba;
    const std::vector<float>& raw = many.image.rgba;
    const double render_s = few.report.seconds - few.report.denoise_seconds;
    const double sampling_s = render_s - few.report.setup_seconds;
    nlohmann::json j;
    j["plant"] = name;
    j["image"] = std::to_string(s.width) + "x" + std::to_string(s.height);
    j["threads"] = s.threads;
    j["spp"] = s.spp;
    j["search_radius"] = s.denoiser.search_radius;
    j["patch_radius"] = s.denoiser.patch_radius;
    j["raw_spp"] = s.raw_spp;
    j["reference_spp"] = s.reference_spp;
    j["plant_pixels"] = plant_pixels;
    j["silhouette_band_pixels"] = band_pixels;
    j["rel_mse"] = {{"noisy", relative_mse(noisy, ref.rgba)},
                    {"denoised", relative_mse(denoised, ref.rgba)},
                    {"raw_many", relative_mse(raw, ref.rgba)}};
    j["rel_mse_silhouette"] = {{"noisy", relative_mse(noisy, ref.rgba, band)},
                               {"denoised", relative_mse(denoised, ref.rgba, band)},
                               {"raw_many", relative_mse(raw, ref.rgba, band)}};
    j["ssim"] = {{"noisy", ssim(noisy, ref.rgba, s.width, s.height)},
                 {"denoised", ssim(denoised, ref.rgba, s.width, s.height)},
                 {"raw_many", ssim(raw, ref.rgba, s.width, s.height)}};
    j["render_s"] = render_s;
    j["sampling_s"] = sampling_s;
    j["raw_many_render_s"] = many.report.seconds;
    j["denoise_s"] = few.report.denoise_seconds;
    j["denoise_share_of_render"] = few.report.denoise_seconds / render_s;
    j["denoise_share_of_sampling"] = few.report.denoise_seconds / sampling_s;
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
    if (!s.save.empty()) {
        fs::create_directories(s.save);
        save_png(noisy, s.width, s.height, s.save / (name + "-noisy.png"));
        save_png(denoised, s.width, s.height, s.save / (name + "-denoised.png"));
        save_png(raw, s.width, s.height, s.save / (name + "-raw-" + std::to_string(s.raw_spp) + ".png"));
        save_png(ref.rgba, s.width, s.height, s.save / (name + "-reference.png"));
    }
}

int positive(const std::string& option, const char* text)
{
    int v = std::atoi(text);
    if (v <= 0) {
        std::fprintf(stderr, "%s: expected a positive number, not '%s'\n", option.c_str(), text);
        std::exit(2);
    }
    return v;
}

}  // namespace

int main(int argc, char** argv)
{
    Settings s;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "%s: expected a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--plant") {
            s.plants.push_back(value());
            if (!plants.count(s.plants.back())) {
                std::fprintf(stderr, "--plant: unknown plant '%s'\n", s.plants.back().c_str());
                return 2;
            }
        } else if (a == "--size") {
            const char* v = value();
            if (std::sscanf(v, "%dx%d", &s.width, &s.height) != 2 || s.width <= 0 || s.height <= 0) {
                std::fprintf(stderr, "--size: expected WxH, not '%s'\n", v);
                return 2;
            }
        } else if (a == "--threads") {
            s.threads = positive(a, value());
        } else if (a == "--spp") {
            s.spp = positive(a, value());
        } else if (a == "--raw-spp") {
            s.raw_spp = positive(a, value());
        } else if (a == "--reference-spp") {
            s.reference_spp = positive(a, value());
        } else if (a == "--search-radius") {
            s.denoiser.search_radius = positive(a, value());
        } else if (a == "--patch-radius") {
            s.denoiser.patch_radius = positive(a, value());
        } else if (a == "--save") {
            s.save = fs::absolute(value());
        } else if (a == "--turntable") {
            s.turntable = positive(a, value());
        } else {
            std::fprintf(stderr, "unknown option '%s'\n", a.c_str());
            return 2;
        }
    }
    if (s.plants.empty())
        for (const auto& [name, folder] : plants)
            s.plants.push_back(name);
    const char* env = std::getenv("CAMBIUM_CORPUS");
    const fs::path corpus = env ? fs::path(env) : fs::path(CAMBIUM_CORPUS_DEFAULT);
    if (!fs::is_directory(corpus)) {
        std::printf("{\"skipped\":\"no corpus at %s\"}\n", corpus.string().c_str());
        return 0;
    }
    const fs::path cache = fs::absolute("denoise-references");
    try {
        for (const std::string& name : s.plants)
            if (s.turntable > 0)
                run_turntable(name, corpus / plants.at(name), s);
            else
                run_plant(name, corpus / plants.at(name), s, cache);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "denoise: %s\n", e.what());
        return 1;
    }
    return 0;
}
