// SPDX-License-Identifier: Apache-2.0
// The screen mask: pixels no primitive's projection reaches, whose camera rays are not
// traced. Checked against Embree itself (no ray of a skipped pixel meets anything) and
// against renders with every ray traced (the same bytes).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "geom_scenes.h"
#include "render/accel.h"
#include "render/render.h"
#include "render/screen_mask.h"
#include "test_scenes.h"

namespace cambium::render {
namespace {

using testing::add_disc;
using testing::add_hermite;
using testing::add_quad;
using testing::add_segment;
using testing::add_sphere;
using testing::directional;
using testing::small;

Camera perspective_camera(int w, int h)
{
    return Camera::perspective({2, 3, 12}, {0, 0, 0}, {0, 1, 0}, 40, w, h);
}

/// Small primitives of every kind scattered over part of the view, and two instances of
/// a rotated, scaled prototype.
geom::Scene mixed_scene()
{
    geom::Scene s;
    add_segment(s, {-3, -1, 0}, {-1.5f, 1.5, 0.5}, 0.15f);
    add_segment(s, {-1.5f, 1.5, 0.5}, {-0.5, 2, -1}, 0.1f);
    add_hermite(s.geometry, {2, -2, 0, 0.2f}, {2, 3, 0, 0}, {3, 0, 1, 0.1f}, {0, 3, -2, -0.1f});
    add_sphere(s.geometry, {0.5, -2.5, 2}, 0.4f);
    add_disc(s.geometry, {-2.5, 2.5, -1}, 0.5f, {0, 0, 1}, 1, 1);
    add_quad(s.geometry, 1, 1.5f, 1.6f, 2.2f, 0.3f, 1, 1);
    geom::Prototype leaf;
    add_quad(leaf.geometry, 0, 0, 1, 0.4f, 0, 1, 1);
    s.prototypes.push_back(leaf);
    for (float x : {-3.0f, 3.5f}) {
        geom::Instance inst;
        inst.transform = testing::transform({0, -0.6f, 0, 0.6f, 0, 0, 0, 0, 0.6f}, {x, -3, 0});
        inst.material = inst.back_material = 1;
        s.instances.push_back(inst);
    }
    s.bounds.extend({-4, -4, -2});
    s.bounds.extend({4, 4, 2});
    s.lights.push_back(directional({0.3, 1, 0.5}));
    return s;
}

/// For each pixel the mask skips, 9 rays over the area its samples reach (`reach` pixels
/// about the centre): none may meet the scene. Returns the pixels skipped.
int expect_skipped_pixels_unhit(const geom::Scene& s, const Camera& camera, double reach)
{
    const ScreenMask mask(s, camera, reach);
    const EmbreeScene accel(s, camera);
    int skipped = 0;
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
            if (mask.may_hit(x, y))
                continue;
            ++skipped;
            for (double dy : {-reach, 0.0, reach})
                for (double dx : {-reach, 0.0, reach}) {
                    CameraRay r = camera.generate_ray(x + 0.5 + dx, y + 0.5 + dy);
                    EXPECT_FALSE(accel.intersect(Vec3f(r.org), Vec3f(r.dir), 0,
                                                 std::numeric_limits<float>::infinity()))
                        << "pixel " << x << ", " << y;
                }
        }
    return skipped;
}

TEST(ScreenMask, NoSkippedPixelHasAHitInPerspective)
{
    const Camera camera = perspective_camera(80, 60);
    int skipped = expect_skipped_pixels_unhit(mixed_scene(), camera, 0.5);
    // Not vacuous: most of the frame is empty, and some of it is not.
    EXPECT_GT(skipped, 80 * 60 / 3);
    EXPECT_LT(skipped, 80 * 60);
}

TEST(ScreenMask, NoSkippedPixelHasAHitInParallelWithAWideFilter)
{
    // Looking down and to the side, with an orthonormal frame (as make_camera's).
    const geom::Vec3 forward = geom::normalize(geom::Vec3{-0.2, -0.3, -1});
    const geom::Vec3 up = geom::normalize(geom::Vec3{0, 1, 0} - forward * forward.y);
    const Camera camera = Camera::parallel({0, 0, 0}, forward, up, 10.0 / 80, 50, 80, 60);
    int skipped = expect_skipped_pixels_unhit(mixed_scene(), camera, 2.0);
    EXPECT_GT(skipped, 80 * 60 / 4);
    EXPECT_LT(skipped, 80 * 60);
}

// Instances alone: each is bounded by its prototype's box, placed (rotated, scaled),
// so most of the frame is skipped and nothing skipped is hit.
TEST(ScreenMask, InstancesAreBoundedByTheirPlacedPrototype)
{
    geom::Scene s;
    geom::Prototype leaf;
    add_quad(leaf.geometry, 0, 0, 1, 0.4f, 0, 1, 1);
    add_sphere(leaf.geometry, {0.5, 0.8, 0}, 0.1f);
    s.prototypes.push_back(leaf);
    for (float x : {-2.0f, 0.5f, 2.5f}) {
        geom::Instance inst;
        inst.transform = testing::transform({0, -0.8f, 0, 0.8f, 0, 0, 0, 0, 0.8f}, {x, 1, 0});
        inst.material = inst.back_material = 1;
        s.instances.push_back(inst);
    }
    const Camera camera = perspective_camera(80, 60);
    int skipped = expect_skipped_pixels_unhit(s, camera, 0.5);
    EXPECT_GT(skipped, 80 * 60 * 3 / 4);
    EXPECT_LT(skipped, 80 * 60);
}

// A sphere of radius 0.5 at the focus of a parallel camera with 0.1 units a pixel: a disc
// 5 pixels in radius about the image centre (40, 30). Pixels within it are kept; pixels
// beyond it, the samples' reach and the safety margin (with a pixel for rounding up to
// whole pixels) are skipped.
TEST(ScreenMask, KeepsWhatASphereCoversAndSkipsWhatIsFarFromIt)
{
    geom::Scene s;
    add_sphere(s.geometry, {0, 0, 0}, 0.5f);
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.1, 50, 80, 60);
    const ScreenMask mask(s, camera, 0.5);
    const double keep = 5, skip_beyond = 5 + 0.5 + ScreenMask::safety_px + 1.5;
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 80; ++x) {
            double dx = std::max(std::fabs(x + 0.5 - 40) - 0.5, 0.0);
            double dy = std::max(std::fabs(y + 0.5 - 30) - 0.5, 0.0);
            if (std::hypot(dx, dy) < keep) {
                EXPECT_TRUE(mask.may_hit(x, y)) << x << ", " << y;
            }
            if (std::max(dx, dy) > skip_beyond) {
                EXPECT_FALSE(mask.may_hit(x, y)) << x << ", " << y;
            }
        }
    EXPECT_GT(mask.empty_share(), 0.9);
}

TEST(ScreenMask, GeometryBehindTheEyeIsNeverSeen)
{
    geom::Scene s;
    add_sphere(s.geometry, {0, 0, 20}, 1);  // the eye is at z = 12, looking toward -z
    const ScreenMask mask(s, perspective_camera(40, 30), 0.5);
    EXPECT_EQ(mask.empty_share(), 1.0);
    EXPECT_FALSE(mask.may_hit(20, 15));
}

TEST(ScreenMask, GeometryThroughTheEyesPlaneSkipsNothing)
{
    geom::Scene s;
    add_segment(s, {0, 0, 0}, {2, 3, 30}, 0.1f);  // from in front of the eye to behind it
    const ScreenMask mask(s, perspective_camera(40, 30), 0.5);
    EXPECT_EQ(mask.empty_share(), 0.0);
    for (int y = 0; y < 30; ++y)
        for (int x = 0; x < 40; ++x)
            EXPECT_TRUE(mask.may_hit(x, y));
}

TEST(ScreenMask, CoordinatesThatAreNotFiniteSkipNothing)
{
    geom::Scene s;
    add_sphere(s.geometry, {0, 0, 0}, 0.1f);
    add_sphere(s.geometry, {std::nan(""), 0, 0}, 0.1f);
    const ScreenMask mask(s, perspective_camera(40, 30), 0.5);
    EXPECT_EQ(mask.empty_share(), 0.0);
}

// `line style: pixel`: a line's radius is in pixels at any depth. A line of radius 4
// pixels along the image's middle row keeps rows 4 pixels above and below it.
TEST(ScreenMask, PixelWideLinesKeepTheirWidthInPixels)
{
    geom::Scene s;
    s.line_radius_in_pixels = true;
    add_segment(s, {-1, 0, 0}, {1, 0, 0}, 4.0f);
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.05, 50, 80, 60);
    const ScreenMask mask(s, camera, 0.5);
    for (int y = 26; y <= 33; ++y)
        EXPECT_TRUE(mask.may_hit(40, y)) << y;
    EXPECT_FALSE(mask.may_hit(40, 2));
    EXPECT_FALSE(mask.may_hit(2, 30));  // beyond the line's end (x = -1 is column 20)
}

// ---- Renders: skipping changes no byte, and happens only where a miss shows one colour.

std::vector<float> bytes_of(const Image& img)
{
    std::vector<float> all = img.rgba;
    for (const auto* layer : {&img.albedo, &img.normal, &img.depth})
        all.insert(all.end(), layer->begin(), layer->end());
    return all;
}

void expect_same_image_either_way(const geom::Scene& s, const Camera& camera,
                                  RenderSettings settings, bool expect_skipping)
{
    settings.skip_empty_pixels = false;
    RenderReport all_traced, skipping;
    std::vector<float> traced = bytes_of(render(s, camera, settings, &all_traced));
    settings.skip_empty_pixels = true;
    std::vector<float> skipped = bytes_of(render(s, camera, settings, &skipping));
    ASSERT_EQ(traced.size(), skipped.size());
    EXPECT_EQ(std::memcmp(traced.data(), skipped.data(), traced.size() * sizeof(float)), 0);
    EXPECT_EQ(all_traced.background_only_samples, 0u);
    EXPECT_EQ(skipping.samples, all_traced.samples);
    if (expect_skipping) {
        EXPECT_GT(skipping.background_only_samples, skipping.samples / 4);
        EXPECT_LT(skipping.rays, all_traced.rays);
        EXPECT_GT(skipping.empty_pixel_share, 0.25);
    } else {
        EXPECT_EQ(skipping.background_only_samples, 0u);
        EXPECT_EQ(skipping.rays, all_traced.rays);
    }
}

TEST(ScreenMask, RendersTheSameBytesWithAndWithoutSkipping)
{
    geom::Scene s = mixed_scene();
    s.background = {0.2f, 0.3f, 0.5f};
    RenderSettings settings = small(64, 48, 8, 3);
    expect_same_image_either_way(s, perspective_camera(64, 48), settings, true);
    settings.filter = PixelFilter::gaussian;
    settings.transparent_background = true;
    expect_same_image_either_way(s, perspective_camera(64, 48), settings, true);
}

TEST(ScreenMask, RendersTheSameBytesWithPixelLinesAndInstancesInParallel)
{
    geom::Scene s = mixed_scene();
    s.line_radius_in_pixels = true;
    for (geom::Float4& k : s.geometry.lines.keys)
        k[3] = 1.5f;
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 10.0 / 64, 50, 64, 48);
    RenderSettings settings = small(64, 48, 4, 2);
    settings.noise_target = 0.05f;  // adaptive: the skipped pixels converge at once
    expect_same_image_either_way(s, camera, settings, true);
}

// Skipped pixels reuse the background sums of the pixel skipped before them when they
// start from the same sum and take as many samples: in passes of unequal sizes (8, 8, 4
// samples; 6, 7, 7) with a background whose repeated sums round differently at every
// count, they must still equal the traced pixels' sums, made one miss at a time.
TEST(ScreenMask, SkippedPixelsSumTheirPassesAsTracedOnesDo)
{
    geom::Scene s = mixed_scene();
    s.background = {0.1f, 0.3f, 0.7f};
    const Camera camera = Camera::parallel({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 10.0 / 64, 50, 64, 48)
                              .with_clipping(-60, 60);
    RenderSettings settings = small(64, 48, 20, 2);
    expect_same_image_either_way(s, camera, settings, true);
    settings.passes = 3;
    expect_same_image_either_way(s, camera, settings, true);
}

TEST(ScreenMask, NothingIsSkippedWhereAMissDependsOnItsRay)
{
    geom::Scene s = mixed_scene();
    RenderSettings settings = small(48, 36, 4, 2);
    settings.ground.enabled = true;  // camera rays meet the ground beside the scene
    expect_same_image_either_way(s, perspective_camera(48, 36), settings, false);
    settings = small(48, 36, 4, 2);
    const Camera lens = perspective_camera(48, 36).with_lens(0.5, 10);
    expect_same_image_either_way(s, lens, settings, false);
}

}  // namespace
}  // namespace cambium::render
