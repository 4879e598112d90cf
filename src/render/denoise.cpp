// SPDX-License-Identifier: Apache-2.0
// Cambium's denoiser: cross-bilateral non-local means on the film's buffers
// (docs/denoise.md).
//
// The image is cut into bands of rows; each band is filtered by one task, which walks
// the search window's offsets in a fixed order and, per offset, computes the colour
// distance of every pixel pair (p, p + offset), box-sums it over the patch (O(1) per
// pixel and offset), and adds the weighted neighbour to the band's sums. A pixel's
// result is a function of the input alone, summed in the same order whichever thread
// runs its band: byte-identical for any thread count.
#include "render/denoise.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "base/diagnostics.h"
#include "render/simd_clones.h"

namespace cambium::render {

namespace {

constexpr int band_rows = 16;
constexpr float epsilon = 1e-8f;  // keeps the colour distance finite where no noise is known

/// The smaller-magnitude one-sided difference (zero where they differ in sign): a
/// gradient that does not reach across a depth discontinuity.
float minmod(float a, float b)
{
    if (!(a * b > 0))
        return 0;
    return std::fabs(a) < std::fabs(b) ? a : b;
}

/// A one-sided difference of finite depths, or none.
bool difference(float from, float to, float& d)
{
    if (!std::isfinite(from) || !std::isfinite(to))
        return false;
    d = to - from;
    return true;
}

/// The depth's gradient at x along a row or column (values at x - 1, x, x + 1; a missing
/// neighbour is passed as infinity).
float depth_slope(float before, float here, float after)
{
    float a = 0, b = 0;
    bool has_a = difference(before, here, a), has_b = difference(here, after, b);
    if (has_a && has_b)
        return minmod(a, b);
    return has_a ? a : (has_b ? b : 0.0f);
}

/// exp(-x) for x >= 0, to about 2e-6 relative (at least 2^-100: callers zero what must
/// weigh nothing): 2^-t as an exponent built from bits times a polynomial of the
/// fraction. Branch-free, so the row loops below vectorise; the same bits on every thread.
inline float exp_neg(float x)
{
    constexpr float log2e = 1.44269504f, ln2 = 0.69314718f;
    const float t = std::min(x * log2e, 100.0f);
    const int whole = static_cast<int>(t);  // t >= 0: truncation is the floor
    const float g = (static_cast<float>(whole) - t) * ln2;  // in (-ln 2, 0]
    // e^g by its Taylor series to the 7th power (error below 2e-6 on the interval).
    float p = 1.0f / 5040;
    p = p * g + 1.0f / 720;
    p = p * g + 1.0f / 120;
    p = p * g + 1.0f / 24;
    p = p * g + 1.0f / 6;
    p = p * g + 0.5f;
    p = p * g + 1.0f;
    p = p * g + 1.0f;
    return p * std::bit_cast<float>((127 - whole) << 23);
}

/// The inputs prepared once per frame, one plane per channel (rows of contiguous floats
/// for the vectorised row loops), shared read-only by the bands.
struct Prepared {
    int w = 0, h = 0;
    bool albedo = false, normal = false, depth = false;
    std::array<std::vector<float>, 3> colour, variance, albedos, normals;
    /// The albedo's and the normal's variance (smoothed as `variance`; zero where unknown).
    std::vector<float> albedo_variance, normal_variance;
    /// Depth: the distance (0 where none), 1 / distance (0 where none) and whether there
    /// is one (1 or 0), and its gradient along x and y.
    std::vector<float> z, inv_z, has_z, slope_x, slope_y;
    std::vector<std::uint32_t> organ;

    std::size_t at(int x, int y) const { return std::size_t(y) * std::size_t(w) + std::size_t(x); }
};

void check_input(const DenoiseInput& in)
{
    if (in.width <= 0 || in.height <= 0)
        throw Error("denoise: the image is empty");
    const std::size_t n = std::size_t(in.width) * std::size_t(in.height);
    auto check = [&](std::size_t size, std::size_t per_pixel, const char* what) {
        if (size != 0 && size != n * per_pixel)
            throw Error(std::string("denoise: the ") + what + " layer has " + std::to_string(size) +
                        " values, not " + std::to_string(n * per_pixel));
    };
    if (in.beauty.size() != n * 4)
        throw Error("denoise: the beauty has " + std::to_string(in.beauty.size()) +
                    " values, not " + std::to_string(n * 4));
    check(in.variance.size(), 3, "variance");
    check(in.albedo.size(), 3, "albedo");
    check(in.normal.size(), 3, "normal");
    check(in.depth.size(), 1, "depth");
    check(in.organ.size(), 1, "organ");
    check(in.feature_variance.size(), 2, "feature variance");
}

/// The planes; the variance smoothed over each pixel's own organ within `radius`; the
/// depth's gradient.
Prepared prepare(const DenoiseInput& in, int radius)
{
    Prepared p;
    p.w = in.width;
    p.h = in.height;
    const std::size_t n = std::size_t(p.w) * std::size_t(p.h);
    p.albedo = !in.albedo.empty();
    p.normal = !in.normal.empty();
    p.depth = !in.depth.empty();
    p.organ.assign(n, 0);
    if (!in.organ.empty())
        std::copy(in.organ.begin(), in.organ.end(), p.organ.begin());
    p.albedo_variance.assign(n, 0.0f);
    p.normal_variance.assign(n, 0.0f);
    for (int c = 0; c < 3; ++c) {
        p.colour[c].resize(n);
        p.variance[c].assign(n, 0.0f);
        for (std::size_t i = 0; i < n; ++i)
            p.colour[c][i] = in.beauty[i * 4 + std::size_t(c)];
        if (p.albedo) {
            p.albedos[c].resize(n);
            for (std::size_t i = 0; i < n; ++i)
                p.albedos[c][i] = in.albedo[i * 3 + std::size_t(c)];
        }
        if (p.normal) {
            p.normals[c].resize(n);
            for (std::size_t i = 0; i < n; ++i)
                p.normals[c][i] = in.normal[i * 3 + std::size_t(c)];
        }
    }
    if (p.depth) {
        p.z.assign(n, 0.0f);
        p.inv_z.assign(n, 0.0f);
        p.has_z.assign(n, 0.0f);
        p.slope_x.assign(n, 0.0f);
        p.slope_y.assign(n, 0.0f);
        for (std::size_t i = 0; i < n; ++i)
            if (std::isfinite(in.depth[i]) && in.depth[i] > 0) {
                p.z[i] = in.depth[i];
                p.inv_z[i] = 1 / in.depth[i];
                p.has_z[i] = 1;
            }
    }
    tbb::parallel_for(tbb::blocked_range<int>(0, p.h, 8), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < p.w; ++x) {
                const std::size_t i = p.at(x, y);
                // Variance: the mean over the box's pixels of the same organ.
                if (!in.variance.empty()) {
                    double sum[3] = {0, 0, 0};
                    int count = 0;
                    const std::uint32_t organ = p.organ[i];
                    for (int yy = std::max(0, y - radius); yy <= std::min(p.h - 1, y + radius); ++yy)
                        for (int xx = std::max(0, x - radius); xx <= std::min(p.w - 1, x + radius); ++xx) {
                            const std::size_t j = p.at(xx, yy);
                            if (p.organ[j] != organ)
                                continue;
                            for (int c = 0; c < 3; ++c)
                                sum[c] += in.variance[j * 3 + std::size_t(c)];
                            ++count;
                        }
                    for (int c = 0; c < 3; ++c)
                        p.variance[c][i] = static_cast<float>(sum[c] / count);
                }
                if (!in.feature_variance.empty()) {
                    double sum[2] = {0, 0};
                    int count = 0;
                    const std::uint32_t organ = p.organ[i];
                    for (int yy = std::max(0, y - radius); yy <= std::min(p.h - 1, y + radius); ++yy)
                        for (int xx = std::max(0, x - radius); xx <= std::min(p.w - 1, x + radius); ++xx) {
                            const std::size_t j = p.at(xx, yy);
                            if (p.organ[j] != organ)
                                continue;
                            sum[0] += in.feature_variance[j * 2];
                            sum[1] += in.feature_variance[j * 2 + 1];
                            ++count;
                        }
                    p.albedo_variance[i] = static_cast<float>(sum[0] / count);
                    p.normal_variance[i] = static_cast<float>(sum[1] / count);
                }
                // Depth gradient, one-sided across discontinuities.
                if (p.depth) {
                    constexpr float none = std::numeric_limits<float>::infinity();
                    const float z = in.depth[i];
                    p.slope_x[i] = depth_slope(x > 0 ? in.depth[i - 1] : none, z,
                                               x + 1 < p.w ? in.depth[i + 1] : none);
                    p.slope_y[i] = depth_slope(y > 0 ? in.depth[i - std::size_t(p.w)] : none, z,
                                               y + 1 < p.h ? in.depth[i + std::size_t(p.w)] : none);
                }
            }
    });
    return p;
}

/// The row loops, built for each vector width (render/simd_clones.h; denoise.cpp is
/// compiled without FMA contraction, so every clone gives the same bits).
struct RowKernels {
    /// out[x] = the colour distance of pixels p + x and q + x (Rousselle et al. 2012: the
    /// squared difference less the noise's expected share, over the noise's variance),
    /// summed over RGB, for x < n.
    CAMBIUM_SIMD_CLONES
    static void colour(const Prepared& d, std::size_t p, std::size_t q, int n, float cancel,
                       float k2, float* out)
    {
        for (int x = 0; x < n; ++x)
            out[x] = 0;
        for (int c = 0; c < 3; ++c) {
            const float* up = &d.colour[c][p];
            const float* uq = &d.colour[c][q];
            const float* vp = &d.variance[c][p];
            const float* vq = &d.variance[c][q];
            for (int x = 0; x < n; ++x) {
                const float diff = up[x] - uq[x];
                const float noise = cancel * (vp[x] + std::min(vp[x], vq[x]));
                out[x] += (diff * diff - noise) / (epsilon + k2 * (vp[x] + vq[x]));
            }
        }
    }

    /// sums[x] (4 planes: R, G, B, weight) += the weight of neighbour q + x for centre
    /// p + x times its colour, for x < n; `patch` holds the patch distances summed.
    CAMBIUM_SIMD_CLONES
    static void accumulate(const Prepared& d, std::size_t p, std::size_t q, int n, float dx,
                           float dy, const float* patch, float inv_patch, float albedo_tolerance2,
                           float normal_tolerance2, float inv_depth, float* feature,
                           float* scratch, std::array<float*, 4> sums)
    {
        // The features' distance.
        for (int x = 0; x < n; ++x)
            feature[x] = std::max(0.0f, patch[x] * inv_patch);
        // Albedo and normal: the squared difference less what the two pixels' noise
        // explains, over the tolerance squared plus that noise's variance.
        auto vector_feature = [&](const std::array<std::vector<float>, 3>& f,
                                  const std::vector<float>& variance, float tolerance2) {
            for (int x = 0; x < n; ++x)
                scratch[x] = 0;
            for (int c = 0; c < 3; ++c) {
                const float* fp = &f[std::size_t(c)][p];
                const float* fq = &f[std::size_t(c)][q];
                for (int x = 0; x < n; ++x) {
                    const float e = fp[x] - fq[x];
                    scratch[x] += e * e;
                }
            }
            const float* vp = &variance[p];
            const float* vq = &variance[q];
            for (int x = 0; x < n; ++x) {
                const float excess = std::max(0.0f, scratch[x] - (vp[x] + std::min(vp[x], vq[x])));
                feature[x] += excess / (tolerance2 + vp[x] + vq[x]);
            }
        };
        if (d.albedo)
            vector_feature(d.albedos, d.albedo_variance, albedo_tolerance2);
        if (d.normal)
            vector_feature(d.normals, d.normal_variance, normal_tolerance2);
        if (d.depth) {
            // Against the centre's plane (its depth and gradient), relative to its depth;
            // 0 where either has no depth (then the organs differ anyway).
            const float* zp = &d.z[p];
            const float* zq = &d.z[q];
            const float* izp = &d.inv_z[p];
            const float* hq = &d.has_z[q];
            const float* sx = &d.slope_x[p];
            const float* sy = &d.slope_y[p];
            for (int x = 0; x < n; ++x) {
                const float e = (zq[x] - (zp[x] + sx[x] * dx + sy[x] * dy)) * izp[x] * hq[x];
                feature[x] += e * e * inv_depth;
            }
        }
        // Pixels of another organ weigh nothing.
        const std::uint32_t* op = &d.organ[p];
        const std::uint32_t* oq = &d.organ[q];
        for (int x = 0; x < n; ++x)
            feature[x] = exp_neg(feature[x]);
        for (int x = 0; x < n; ++x)
            feature[x] = op[x] == oq[x] ? feature[x] : 0.0f;
        // The weighted neighbours, plane by plane.
        for (int c = 0; c < 3; ++c) {
            const float* colour = &d.colour[std::size_t(c)][q];
            float* sum = sums[std::size_t(c)];
            for (int x = 0; x < n; ++x)
                sum[x] += feature[x] * colour[x];
        }
        for (int x = 0; x < n; ++x)
            sums[3][x] += feature[x];
    }
};

/// One band's filter: rows y0 .. y1 - 1 of `out`.
class Band {
public:
    Band(const Prepared& p, const NlMeansParameters& q, int y0, int y1)
        : m_p(p), m_q(q), m_y0(y0), m_y1(y1), m_ya(std::max(0, y0 - q.patch_radius)),
          m_yb(std::min(p.h, y1 + q.patch_radius)),
          m_distance(std::size_t(m_yb - m_ya) * std::size_t(p.w)),
          m_row_sum(m_distance.size()), m_patch(std::size_t(p.w)), m_feature(std::size_t(p.w)),
          m_scratch(std::size_t(p.w))
    {
        for (auto& plane : m_sums)
            plane.assign(std::size_t(y1 - y0) * std::size_t(p.w), 0.0f);
        m_inv_patch = 1.0f / float((2 * q.patch_radius + 1) * (2 * q.patch_radius + 1) * 3);
        m_k2 = q.colour_k * q.colour_k;
        m_albedo_tolerance2 = q.albedo_tolerance * q.albedo_tolerance;
        m_normal_tolerance2 = q.normal_tolerance * q.normal_tolerance;
        m_inv_depth = 1.0f / (q.depth_tolerance * q.depth_tolerance);
    }

    /// Adds the neighbours at offset (dx, dy) to the band's sums.
    void add_offset(int dx, int dy)
    {
        colour_distances(dx, dy);
        box_rows();
        accumulate(dx, dy);
    }

    /// The band's result into `out` (RGBA; alpha from the beauty).
    void write(std::span<const float> beauty, std::vector<float>& out) const
    {
        for (int y = m_y0; y < m_y1; ++y)
            for (int x = 0; x < m_p.w; ++x) {
                const std::size_t i = m_p.at(x, y);
                const std::size_t k = std::size_t(y - m_y0) * std::size_t(m_p.w) + std::size_t(x);
                const float inv = 1.0f / m_sums[3][k];  // the centre's own weight is 1: never 0
                for (int c = 0; c < 3; ++c)
                    out[i * 4 + std::size_t(c)] = m_sums[std::size_t(c)][k] * inv;
                out[i * 4 + 3] = beauty[i * 4 + 3];
            }
    }

private:
    /// The per-pixel colour distance of (s, s + offset) for the band's rows and the
    /// patch's margin, neighbours clamped to the image.
    void colour_distances(int dx, int dy)
    {
        const int w = m_p.w;
        const float cancel = m_q.variance_cancel;
        // Columns whose neighbour lies in the image: xa .. xb - 1.
        const int xa = std::clamp(-dx, 0, w), xb = std::clamp(w - dx, xa, w);
        for (int y = m_ya; y < m_yb; ++y) {
            const int qy = std::clamp(y + dy, 0, m_p.h - 1);
            float* row = &m_distance[std::size_t(y - m_ya) * std::size_t(w)];
            for (int x = 0; x < xa; ++x)
                RowKernels::colour(m_p, m_p.at(x, y), m_p.at(std::clamp(x + dx, 0, w - 1), qy), 1,
                                   cancel, m_k2, row + x);
            if (xb > xa)
                RowKernels::colour(m_p, m_p.at(xa, y), m_p.at(xa + dx, qy), xb - xa, cancel, m_k2,
                                   row + xa);
            for (int x = xb; x < w; ++x)
                RowKernels::colour(m_p, m_p.at(x, y), m_p.at(std::clamp(x + dx, 0, w - 1), qy), 1,
                                   cancel, m_k2, row + x);
        }
    }

    /// Each row's distances summed over the patch's width (clamped at the image's edge).
    void box_rows()
    {
        const int w = m_p.w, r = m_q.patch_radius;
        for (int y = m_ya; y < m_yb; ++y) {
            const float* d = &m_distance[std::size_t(y - m_ya) * std::size_t(w)];
            float* s = &m_row_sum[std::size_t(y - m_ya) * std::size_t(w)];
            // Inside: the 2r + 1 shifted rows added in order (a vectorised loop each);
            // at the ends, the same order with the columns clamped.
            const int x0 = std::min(r, w), x1 = std::max(x0, w - r);
            for (int x = x0; x < x1; ++x)
                s[x] = d[x - r];
            for (int k = -r + 1; k <= r; ++k)
                for (int x = x0; x < x1; ++x)
                    s[x] += d[x + k];
            auto clamped = [&](int x) {
                float sum = d[std::clamp(x - r, 0, w - 1)];
                for (int k = -r + 1; k <= r; ++k)
                    sum += d[std::clamp(x + k, 0, w - 1)];
                s[x] = sum;
            };
            for (int x = 0; x < x0; ++x)
                clamped(x);
            for (int x = x1; x < w; ++x)
                clamped(x);
        }
    }

    /// The neighbours at (dx, dy) weighted into the band's sums.
    void accumulate(int dx, int dy)
    {
        const int w = m_p.w, r = m_q.patch_radius;
        const int x0 = std::clamp(-dx, 0, w), x1 = std::clamp(w - dx, x0, w);
        if (x1 <= x0)
            return;
        for (int y = m_y0; y < m_y1; ++y) {
            const int qy = y + dy;
            if (qy < 0 || qy >= m_p.h)
                continue;
            // The patch distances: the row sums of the rows around y, added in order.
            float* patch = m_patch.data();
            for (int x = x0; x < x1; ++x)
                patch[x] = 0;
            for (int k = -r; k <= r; ++k) {
                const int yy = std::clamp(y + k, 0, m_p.h - 1);
                const float* s = &m_row_sum[std::size_t(yy - m_ya) * std::size_t(w)];
                for (int x = x0; x < x1; ++x)
                    patch[x] += s[x];
            }
            const std::size_t row = std::size_t(y - m_y0) * std::size_t(w) + std::size_t(x0);
            RowKernels::accumulate(m_p, m_p.at(x0, y), m_p.at(x0 + dx, qy), x1 - x0, float(dx),
                                   float(dy), patch + x0, m_inv_patch, m_albedo_tolerance2,
                                   m_normal_tolerance2, m_inv_depth, m_feature.data(), m_scratch.data(),
                                   {&m_sums[0][row], &m_sums[1][row], &m_sums[2][row], &m_sums[3][row]});
        }
    }

    const Prepared& m_p;
    const NlMeansParameters& m_q;
    int m_y0, m_y1, m_ya, m_yb;
    std::vector<float> m_distance, m_row_sum, m_patch, m_feature, m_scratch;
    std::array<std::vector<float>, 4> m_sums;
    float m_inv_patch = 0, m_k2 = 0, m_albedo_tolerance2 = 0, m_normal_tolerance2 = 0,
          m_inv_depth = 0;
};

}  // namespace

NlMeansDenoiser::NlMeansDenoiser(const NlMeansParameters& parameters) : m_parameters(parameters)
{
    const NlMeansParameters& q = m_parameters;
    if (q.search_radius < 0 || q.search_radius > 32 || q.patch_radius < 0 || q.patch_radius > 8 ||
        q.variance_radius < 0 || q.variance_radius > 8)
        throw Error("denoise: the search radius must be 0 to 32, the patch and variance radii 0 to 8");
    if (!(q.colour_k > 0) || !(q.variance_cancel >= 0) || !(q.albedo_tolerance > 0) ||
        !(q.normal_tolerance > 0) || !(q.depth_tolerance > 0))
        throw Error("denoise: the colour scale and the feature tolerances must be positive");
}

std::uint64_t NlMeansDenoiser::working_bytes(int width, int height) const
{
    const std::uint64_t w = std::uint64_t(std::max(width, 0)), h = std::uint64_t(std::max(height, 0));
    // Prepared: colour, variance, albedo, normal planes, their variances, depth's five,
    // organ (20 values a pixel); each band in flight: two distance rows per row with the patch margin,
    // and 4 sums per pixel.
    const std::uint64_t bands = (h + band_rows - 1) / band_rows;
    const std::uint64_t in_flight = std::min<std::uint64_t>(
        bands, std::max(1u, std::thread::hardware_concurrency()));
    const std::uint64_t band = (2 * (band_rows + 2 * std::uint64_t(m_parameters.patch_radius)) +
                                4 * band_rows) * w * sizeof(float);
    return w * h * 20 * sizeof(float) + in_flight * band;
}

std::vector<float> NlMeansDenoiser::denoise(const DenoiseInput& input) const
{
    check_input(input);
    const NlMeansParameters& q = m_parameters;
    const Prepared p = prepare(input, q.variance_radius);
    std::vector<float> out(input.beauty.size());
    const int bands = (p.h + band_rows - 1) / band_rows;
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& r) {
        for (int b = r.begin(); b != r.end(); ++b) {
            Band band(p, q, b * band_rows, std::min(p.h, (b + 1) * band_rows));
            const int s = q.search_radius;
            for (int dy = -s; dy <= s; ++dy)
                for (int dx = -s; dx <= s; ++dx)
                    band.add_offset(dx, dy);
            band.write(input.beauty, out);
        }
    });
    return out;
}

std::unique_ptr<Denoiser> make_default_denoiser()
{
    return std::make_unique<NlMeansDenoiser>();
}

}  // namespace cambium::render
