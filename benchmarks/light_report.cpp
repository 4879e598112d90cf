// SPDX-License-Identifier: Apache-2.0
// The light report's speed (docs/light.md): rays from the lights per second, traced
// through a model's organs with multiple scattering. Prints one JSON line.
//
//   build/benchmarks/light_report plant.l plant.v [rays] [--allow-file-access]
//   build/benchmarks/light_report --synthetic ORGANS [rays]
//
// Either may end with --sky (the default sky and sun too), --infinite-canopy and --ground
// (mid grey, under the lowest point).
//
// The synthetic plant: ORGANS / 2 grey translucent leaves and as many internodes
// (cylinders) at random in a crown of radius 1, each its own module.
#include <sys/resource.h>
#include <tbb/info.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/pipeline.h"
#include "render/light_report.h"

namespace {

using Clock = std::chrono::steady_clock;
namespace geom = cambium::geom;
namespace render = cambium::render;

double seconds_since(Clock::time_point t)
{
    return std::chrono::duration<double>(Clock::now() - t).count();
}

std::size_t primitives(const geom::Scene& s)
{
    std::size_t n = 0;
    auto count = [](const geom::Geometry& g) {
        return g.lines.segment_count() + g.curves.segment_count() + g.spheres.size() +
               g.discs.size() + g.mesh.size();
    };
    n += count(s.geometry);
    for (const geom::Instance& i : s.instances)
        n += count(s.prototypes[i.prototype].geometry);
    return n;
}

geom::Scene synthetic(std::uint32_t organs)
{
    geom::Scene scene;
    scene.materials[1].diffuse = {0.5f, 0.6f, 0.4f};
    scene.materials[1].translucency = 0.4f;
    scene.materials[2].diffuse = {0.4f, 0.3f, 0.2f};
    geom::Light light;
    light.kind = geom::Light::Kind::directional;
    light.direction = geom::normalize(geom::Vec3{0.3, 1, 0.2});
    scene.lights = {light};
    scene.geometry.modules.names = {"F", "L"};
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1, 1);
    auto in_crown = [&] {
        for (;;) {
            geom::Float3 p{u(rng), u(rng), u(rng)};
            if (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] <= 1)
                return p;
        }
    };
    geom::TriangleMesh& m = scene.geometry.mesh;
    geom::LinearCurves& l = scene.geometry.lines;
    for (std::uint32_t k = 0; k < organs; ++k) {
        const geom::Float3 p = in_crown();
        if (k % 2 == 0) {  // an internode
            auto key = static_cast<std::uint32_t>(l.keys.size());
            l.keys.push_back({p[0], p[1], p[2], 0.005f});
            l.keys.push_back({p[0] + 0.05f * u(rng), p[1] + 0.05f * u(rng), p[2] + 0.05f * u(rng), 0.005f});
            l.segments.push_back(key);
            l.flags.push_back(0);
            l.material.push_back(2);
            l.texture.push_back(geom::no_texture);
            l.module.push_back(k);
            scene.geometry.modules.records.push_back({k, 0, geom::unknown_age});
        } else {  // a leaf: a quad 0.06 across at a random slant
            auto base = static_cast<std::uint32_t>(m.positions.size());
            const geom::Float3 a{0.06f * u(rng), 0.03f * u(rng), 0.06f * u(rng)};
            const geom::Float3 b{-a[2], 0.03f * u(rng), a[0]};
            for (float s : {0.0f, 1.0f})
                for (float t : {0.0f, 1.0f})
                    m.positions.push_back({p[0] + s * a[0] + t * b[0], p[1] + s * a[1] + t * b[1],
                                           p[2] + s * a[2] + t * b[2]});
            m.normals.insert(m.normals.end(), 4, geom::Float3{0, 0, 0});
            m.triangles.push_back({base, base + 1, base + 3});
            m.triangles.push_back({base, base + 3, base + 2});
            for (int t = 0; t < 2; ++t) {
                m.material.push_back(1);
                m.back_material.push_back(1);
                m.module.push_back(k);
            }
            scene.geometry.modules.records.push_back({k, 1, geom::unknown_age});
        }
    }
    return scene;
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: light_report plant.l plant.v [rays] [--allow-file-access]\n"
                             "       light_report --synthetic ORGANS [rays]\n");
        return 2;
    }
    try {
        std::uint64_t rays = 1'000'000;
        std::string name;
        geom::Scene scene;
        double interpret_s = 0;
        auto t = Clock::now();
        bool sky = false, canopy = false, ground = false;
        for (;; --argc) {
            const char* last = argv[argc - 1];
            bool* flag = std::strcmp(last, "--sky") == 0               ? &sky
                         : std::strcmp(last, "--infinite-canopy") == 0 ? &canopy
                         : std::strcmp(last, "--ground") == 0          ? &ground
                                                                       : nullptr;
            if (argc <= 3 || !flag)
                break;
            *flag = true;
        }
        if (std::strcmp(argv[1], "--synthetic") == 0) {
            const auto organs = static_cast<std::uint32_t>(std::stoul(argv[2]));
            if (argc > 3)
                rays = std::stoull(argv[3]);
            name = "synthetic-" + std::to_string(organs);
            scene = synthetic(organs);
        } else {
            std::vector<std::string> args{argv[1], argv[2]};
            for (int i = 3; i < argc; ++i) {
                if (std::strcmp(argv[i], "--allow-file-access") == 0)
                    args.emplace_back(argv[i]);
                else
                    rays = std::stoull(argv[i]);
            }
            args.emplace_back("-q");
            auto options = cambium::app::parse_command_line(args);
            if (!options)
                return 2;
            name = argv[1];
            cambium::app::Model model = cambium::app::load_model(*options);
            cambium::app::StringOrigins provenance;
            cambium::lsys::ModuleString derived =
                model.lsystem.derive_with_ages(options->steps, provenance.ages);
            provenance.derived = &derived;
            cambium::lsys::ModuleString turtle =
                cambium::app::turtle_string(model, derived, *options, provenance.origins);
            scene = cambium::app::interpret_turtle_string(model, turtle, *options, &provenance);
        }
        interpret_s = seconds_since(t);
        render::LightReportSettings settings;
        settings.rays = rays;
        if (sky)
            settings.environment = std::make_shared<const render::Environment>(render::make_sky_environment());
        settings.infinite_canopy = canopy;
        if (ground)
            settings.ground = render::LightReportSettings::Ground{};
        auto cpu_seconds = [] {
            struct rusage u {};
            getrusage(RUSAGE_SELF, &u);
            return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
                   1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
        };
        const double cpu_before = cpu_seconds();
        t = Clock::now();
        render::LightReport report = render::trace_light(scene, settings);
        const double trace_s = seconds_since(t);
        // CPU seconds too: on a loaded machine wall time says little
        const double trace_cpu_s = cpu_seconds() - cpu_before;
        struct rusage usage {};
        getrusage(RUSAGE_SELF, &usage);
        std::printf("{\"model\": \"%s\", \"primitives\": %zu, \"organs\": %zu, \"rays\": %llu, "
                    "\"threads\": %d, \"prepare_s\": %.3f, \"trace_s\": %.3f, \"trace_cpu_s\": %.3f, "
                    "\"rays_per_s\": %.0f, \"rays_per_cpu_s\": %.0f, "
                    "\"emitted\": %.6g, \"absorbed\": %.6g, \"escaped\": %.6g, \"peak_rss_mib\": %.1f}\n",
                    name.c_str(), primitives(scene), report.organs.size(),
                    static_cast<unsigned long long>(report.rays), tbb::info::default_concurrency(),
                    interpret_s, trace_s, trace_cpu_s, double(report.rays) / trace_s,
                    double(report.rays) / trace_cpu_s, report.emitted,
                    report.absorbed, report.escaped, double(usage.ru_maxrss) / 1024);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "light_report: %s\n", e.what());
        return 1;
    }
}
