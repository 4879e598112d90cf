// SPDX-License-Identifier: Apache-2.0
// The film: adaptive sampling's convergence test over the pixels' sums, and the sums
// resolved into an Image.
#include "render/film.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace cambium::render {

namespace {

constexpr int min_adaptive_samples = 16;  // fewer give no useful variance estimate

/// The squared relative standard error of a pixel's mean luminance (infinite when too
/// few samples): the replicas' estimate (render.cpp's replica_index), but never below the samples'
/// variance over n^2 (their spread over n, the error of independent samples, times a
/// stratification gain of 1/sqrt(n), more than nets achieve on an edge). From a few
/// samples the replicas often agree exactly on an edge (each net's coverage count is an
/// integer): an estimate of zero, which without the floor would stop the pixel at once.
double relative_error_squared(const PixelState& st, const PixelExtras& ex)
{
    if (st.samples < std::uint32_t(min_adaptive_samples))
        return std::numeric_limits<double>::infinity();
    double n = st.samples, n_even = (st.samples + 1) / 2, n_odd = st.samples / 2;
    double sum = ex.replica_luminance[0] + ex.replica_luminance[1], mean = sum / n;
    double replica_error = (ex.replica_luminance[0] / n_even - ex.replica_luminance[1] / n_odd) / 2;
    double variance = std::max(0.0, (ex.luminance_sq - sum * mean) / (n - 1));
    double error_sq = std::max(replica_error * replica_error, variance / (n * n));
    return error_sq / std::max(mean * mean, 1e-4);
}

/// A shadow catcher's share of a pixel's coverage, in samples: its samples that met the
/// catcher (those with light) times the fraction of the light the plant takes away, as a
/// ratio of the sums (Cycles' catcher): 0 where nothing is in the way.
float shadow_coverage(const PixelExtras& ex)
{
    if (!(ex.lit_without > 0) || ex.lit_with >= ex.lit_without)
        return 0;
    float missing = static_cast<float>(1 - ex.lit_with / ex.lit_without);
    return missing * static_cast<float>(ex.caught);
}

}  // namespace

/// A pixel's replica estimate has one degree of freedom, so a lucky pair of replicas could
/// stop it early: it stops only when every pixel of its neighbourhood meets the target.
void mark_converged(Film& film, int w, int h, double target)
{
    std::vector<PixelState>& px = film.px;
    std::vector<double> err(px.size());
    for (std::size_t i = 0; i < px.size(); ++i)
        err[i] = relative_error_squared(px[i], film.extras[i]);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double pooled = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int nx = std::clamp(x + dx, 0, w - 1), ny = std::clamp(y + dy, 0, h - 1);
                    pooled = std::max(pooled, err[std::size_t(ny) * w + nx]);
                }
            if (pooled <= target * target)
                px[std::size_t(y) * w + x].done = true;
        }
}

/// Each output row is a run of a sampled row.
Image resolve(const Film& film, const PixelRect& sampled, const PixelRect& out,
              const ImageLayers& layers, const geom::Scene& scene)
{
    const std::size_t width = std::size_t(out.width), count = width * std::size_t(out.height);
    Image img{out.width, out.height, std::vector<float>(count * 4)};
    img.transparent = layers.transparent;
    const bool aovs = layers.aovs, denoise = layers.denoise;
    if (aovs) {
        img.albedo.assign(count * 3, 0.0f);
        img.normal.assign(count * 3, 0.0f);
        img.depth.assign(count, std::numeric_limits<float>::infinity());
    }
    if (denoise) {
        img.variance.assign(count * 3, 0.0f);
        img.feature_variance.assign(count * 2, 0.0f);
        img.organ.assign(count, organ_background);
    }
    const bool extras = !film.extras.empty();  // (without them no pixel has a catcher's light)
    std::optional<OrganMaskBuilder> masks;
    if (!film.organs.empty())
        masks.emplace(scene, count, layers.organ_mask_depth);
    for (std::size_t row = 0; row < std::size_t(out.height); ++row) {
        const std::size_t from = (std::size_t(out.y - sampled.y) + row) * std::size_t(sampled.width) +
                                 std::size_t(out.x - sampled.x);
        for (std::size_t x = 0, i = row * width; x < width; ++x, ++i) {
            const PixelState& st = film.px[from + x];
            if (st.samples == 0)
                continue;
            float inv = 1.0f / static_cast<float>(st.samples);
            float coverage = extras ? shadow_coverage(film.extras[from + x]) : 0.0f;
            img.rgba[i * 4 + 0] = st.radiance.x * inv;
            img.rgba[i * 4 + 1] = st.radiance.y * inv;
            img.rgba[i * 4 + 2] = st.radiance.z * inv;
            img.rgba[i * 4 + 3] = (static_cast<float>(st.hits) + coverage) * inv;
            if (masks)
                masks->pixel(i, film.organs[from + x], st.samples);
            if (denoise) {
                // A quarter of the squared difference of the two replicas' means: the
                // variance of the pixel's mean, without bias (1 degree of freedom).
                const PixelExtras& ex = film.extras[from + x];
                const std::uint32_t odd = st.samples / 2, even = st.samples - odd;
                if (odd > 0) {
                    const Vec3f a = (st.radiance - ex.odd_radiance) * (1.0f / float(even));
                    const Vec3f b = ex.odd_radiance * (1.0f / float(odd));
                    const Vec3f d = a - b;
                    img.variance[i * 3 + 0] = 0.25f * d.x * d.x;
                    img.variance[i * 3 + 1] = 0.25f * d.y * d.y;
                    img.variance[i * 3 + 2] = 0.25f * d.z * d.z;
                    // The same for the albedo and the normal, summed over their channels.
                    auto half_variance = [&](const Vec3f& sum, const Vec3f& odd_sum) {
                        const Vec3f e = (sum - odd_sum) * (1.0f / float(even)) - odd_sum * (1.0f / float(odd));
                        return 0.25f * (e.x * e.x + e.y * e.y + e.z * e.z);
                    };
                    img.feature_variance[i * 2 + 0] = half_variance(ex.albedo, ex.odd_albedo);
                    img.feature_variance[i * 2 + 1] = half_variance(ex.normal, ex.odd_normal);
                }
                img.organ[i] = ex.organ;
            }
            if (aovs) {
                const PixelExtras& ex = film.extras[from + x];
                Vec3f a = ex.albedo * inv, n = ex.normal * inv;
                img.albedo[i * 3 + 0] = a.x;
                img.albedo[i * 3 + 1] = a.y;
                img.albedo[i * 3 + 2] = a.z;
                img.normal[i * 3 + 0] = n.x;
                img.normal[i * 3 + 1] = n.y;
                img.normal[i * 3 + 2] = n.z;
                img.depth[i] = ex.depth;
            }
        }
    }
    if (masks)
        img.organ_masks = masks->finish();
    return img;
}

}  // namespace cambium::render
