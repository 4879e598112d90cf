// SPDX-License-Identifier: Apache-2.0
// The render layer's entry points: render a Scene to an Image, write it to a file.
#include "render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <string>

#include "base/diagnostics.h"
#include "render/accel.h"
#include "render/color.h"
#include "render/integrator.h"

namespace cambium::render {

namespace {

constexpr int tile_size = 16;

void check_settings(const RenderSettings& s)
{
    if (s.width <= 0 || s.height <= 0)
        throw Error("render: image size " + std::to_string(s.width) + "x" +
                    std::to_string(s.height) + " is empty");
    if (s.samples_per_pixel <= 0)
        throw Error("render: samples per pixel must be positive, not " +
                    std::to_string(s.samples_per_pixel));
    if (s.max_depth <= 0)
        throw Error("render: maximum path depth must be positive, not " +
                    std::to_string(s.max_depth));
    if (s.threads < 0)
        throw Error("render: thread count must not be negative");
}

/// One pixel: jittered samples over its area (a box filter), averaged.
void render_pixel(const PathContext& ctx, const Camera& camera, const RenderSettings& s, int x,
                  int y, Image& image)
{
    Vec3f sum;
    int hits = 0;
    for (int i = 0; i < s.samples_per_pixel; ++i) {
        Sampler sampler(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                        static_cast<std::uint32_t>(i), s.seed);
        float jx = sampler.next(), jy = sampler.next();
        CameraRay ray = camera.generate_ray(x + jx, y + jy);
        PathResult r = trace_path(ctx, Vec3f(ray.org), Vec3f(ray.dir), sampler);
        sum += r.radiance;
        hits += r.hit ? 1 : 0;
    }
    float inv = 1.0f / static_cast<float>(s.samples_per_pixel);
    image.at(x, y, 0) = sum.x * inv;
    image.at(x, y, 1) = sum.y * inv;
    image.at(x, y, 2) = sum.z * inv;
    image.at(x, y, 3) = static_cast<float>(hits) * inv;
}

void render_tile(const PathContext& ctx, const Camera& camera, const RenderSettings& s, int tile,
                 Image& image)
{
    int tiles_x = (s.width + tile_size - 1) / tile_size;
    int x0 = (tile % tiles_x) * tile_size, y0 = (tile / tiles_x) * tile_size;
    for (int y = y0; y < std::min(y0 + tile_size, s.height); ++y)
        for (int x = x0; x < std::min(x0 + tile_size, s.width); ++x)
            render_pixel(ctx, camera, s, x, y, image);
}

}  // namespace

Image render(const geom::Scene& scene, const RenderSettings& settings)
{
    check_settings(settings);
    Camera camera = make_camera(scene.view, scene.bounds, settings.width, settings.height);
    return render(scene, camera, settings);
}

Image render(const geom::Scene& scene, const Camera& camera, const RenderSettings& settings)
{
    check_settings(settings);
    if (camera.width() != settings.width || camera.height() != settings.height)
        throw Error("render: the camera's image size differs from the settings'");
    tbb::task_arena arena(settings.threads > 0 ? settings.threads
                                               : tbb::task_arena::automatic);
    Image image{settings.width, settings.height,
                std::vector<float>(std::size_t(settings.width) * settings.height * 4)};
    arena.execute([&] {
        // Embree builds with TBB too, so the build also stays within the arena.
        EmbreeScene accel(scene, camera);
        PathContext ctx;
        ctx.accel = &accel;
        ctx.materials = make_materials(scene.materials);
        ctx.lights = make_lights(scene.lights);
        ctx.background = decode_display(scene.background);
        ctx.environment = {settings.ambient.r, settings.ambient.g, settings.ambient.b};
        ctx.max_depth = settings.max_depth;
        ctx.roulette_depth = settings.roulette_depth;

        int tiles_x = (settings.width + tile_size - 1) / tile_size;
        int tiles_y = (settings.height + tile_size - 1) / tile_size;
        // Each tile writes only its own pixels; no exception leaves a task.
        tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y, 1),
                          [&](const tbb::blocked_range<int>& r) {
                              for (int t = r.begin(); t != r.end(); ++t)
                                  render_tile(ctx, camera, settings, t, image);
                          });
    });
    return image;
}

}  // namespace cambium::render
