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
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "base/diagnostics.h"

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

/// The inputs prepared once per frame, shared read-only by the bands.
struct Prepared {
    int w = 0, h = 0;
    std::vector<float> colour;    // RGB, 3 per pixel
    std::vector<float> variance;  // smoothed, 3 per pixel
    std::vector<float> slope;     // the depth's gradient (x, y), 2 per pixel
    std::span<const float> albedo, normal, depth;
    std::span<const std::uint32_t> organ;

    std::size_t at(int x, int y) const { return std::size_t(y) * std::size_t(w) + std::size_t(x); }
    std::uint32_t organ_at(std::size_t i) const { return organ.empty() ? 0 : organ[i]; }
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
}

/// The colour, the variance smoothed over each pixel's own organ within `radius`, and
/// the depth's gradient.
Prepared prepare(const DenoiseInput& in, int radius)
{
    Prepared p;
    p.w = in.width;
    p.h = in.height;
    p.albedo = in.albedo;
    p.normal = in.normal;
    p.depth = in.depth;
    p.organ = in.organ;
    const std::size_t n = std::size_t(p.w) * std::size_t(p.h);
    p.colour.resize(n * 3);
    p.variance.assign(n * 3, 0.0f);
    p.slope.assign(n * 2, 0.0f);
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            p.colour[i * 3 + c] = in.beauty[i * 4 + c];
    tbb::parallel_for(tbb::blocked_range<int>(0, p.h, 8), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < p.w; ++x) {
                const std::size_t i = p.at(x, y);
                // Variance: the mean over the box's pixels of the same organ.
                if (!in.variance.empty()) {
                    double sum[3] = {0, 0, 0};
                    int count = 0;
                    const std::uint32_t organ = p.organ_at(i);
                    for (int yy = std::max(0, y - radius); yy <= std::min(p.h - 1, y + radius); ++yy)
                        for (int xx = std::max(0, x - radius); xx <= std::min(p.w - 1, x + radius); ++xx) {
                            const std::size_t j = p.at(xx, yy);
                            if (p.organ_at(j) != organ)
                                continue;
                            for (int c = 0; c < 3; ++c)
                                sum[c] += in.variance[j * 3 + c];
                            ++count;
                        }
                    for (int c = 0; c < 3; ++c)
                        p.variance[i * 3 + c] = static_cast<float>(sum[c] / count);
                }
                // Depth gradient, one-sided across discontinuities.
                if (!in.depth.empty()) {
                    constexpr float none = std::numeric_limits<float>::infinity();
                    const float z = in.depth[i];
                    p.slope[i * 2 + 0] = depth_slope(x > 0 ? in.depth[i - 1] : none, z,
                                                     x + 1 < p.w ? in.depth[i + 1] : none);
                    p.slope[i * 2 + 1] = depth_slope(y > 0 ? in.depth[i - std::size_t(p.w)] : none, z,
                                                     y + 1 < p.h ? in.depth[i + std::size_t(p.w)] : none);
                }
            }
    });
    return p;
}

/// One band's filter: rows y0 .. y1 - 1 of `out`.
class Band {
public:
    Band(const Prepared& p, const NlMeansParameters& q, int y0, int y1)
        : m_p(p), m_q(q), m_y0(y0), m_y1(y1), m_ya(std::max(0, y0 - q.patch_radius)),
          m_yb(std::min(p.h, y1 + q.patch_radius)),
          m_distance(std::size_t(m_yb - m_ya) * std::size_t(p.w)),
          m_row_sum(m_distance.size()),
          m_sums(std::size_t(y1 - y0) * std::size_t(p.w) * 4, 0.0f)
    {
        const float k2 = q.colour_k * q.colour_k;
        m_inv_patch = 1.0f / float((2 * q.patch_radius + 1) * (2 * q.patch_radius + 1) * 3);
        m_k2 = k2;
        m_inv_albedo = 1.0f / (q.albedo_tolerance * q.albedo_tolerance);
        m_inv_normal = 1.0f / (q.normal_tolerance * q.normal_tolerance);
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
                const float* s = &m_sums[(std::size_t(y - m_y0) * std::size_t(m_p.w) + std::size_t(x)) * 4];
                const float inv = 1.0f / s[3];  // the centre's own weight is 1: never 0
                for (int c = 0; c < 3; ++c)
                    out[i * 4 + c] = s[c] * inv;
                out[i * 4 + 3] = beauty[i * 4 + 3];
            }
    }

private:
    /// The per-pixel colour distance of (s, s + offset) for the band's rows and the
    /// patch's margin, neighbours clamped to the image (Rousselle et al. 2012: the
    /// squared difference less the noise's expected share, over the noise's variance).
    void colour_distances(int dx, int dy)
    {
        const int w = m_p.w;
        for (int y = m_ya; y < m_yb; ++y) {
            const int qy = std::clamp(y + dy, 0, m_p.h - 1);
            float* row = &m_distance[std::size_t(y - m_ya) * std::size_t(w)];
            for (int x = 0; x < w; ++x) {
                const int qx = std::clamp(x + dx, 0, w - 1);
                const float* up = &m_p.colour[m_p.at(x, y) * 3];
                const float* uq = &m_p.colour[m_p.at(qx, qy) * 3];
                const float* vp = &m_p.variance[m_p.at(x, y) * 3];
                const float* vq = &m_p.variance[m_p.at(qx, qy) * 3];
                float d = 0;
                for (int c = 0; c < 3; ++c) {
                    const float diff = up[c] - uq[c];
                    const float noise = m_q.variance_cancel * (vp[c] + std::min(vp[c], vq[c]));
                    d += (diff * diff - noise) / (epsilon + m_k2 * (vp[c] + vq[c]));
                }
                row[x] = d;
            }
        }
    }

    /// Each row's distances summed over the patch's width (clamped at the image's edge).
    void box_rows()
    {
        const int w = m_p.w, r = m_q.patch_radius;
        for (int y = m_ya; y < m_yb; ++y) {
            const float* d = &m_distance[std::size_t(y - m_ya) * std::size_t(w)];
            float* s = &m_row_sum[std::size_t(y - m_ya) * std::size_t(w)];
            for (int x = 0; x < w; ++x) {
                float sum = 0;
                if (x >= r && x + r < w) {
                    for (int k = -r; k <= r; ++k)
                        sum += d[x + k];
                } else {
                    for (int k = -r; k <= r; ++k)
                        sum += d[std::clamp(x + k, 0, w - 1)];
                }
                s[x] = sum;
            }
        }
    }

    /// The features' distance of the centre p and its neighbour q = p + (dx, dy).
    float feature_distance(std::size_t p, std::size_t q, int dx, int dy) const
    {
        float d = 0;
        if (!m_p.albedo.empty()) {
            float s = 0;
            for (int c = 0; c < 3; ++c) {
                const float e = m_p.albedo[p * 3 + c] - m_p.albedo[q * 3 + c];
                s += e * e;
            }
            d += s * m_inv_albedo;
        }
        if (!m_p.normal.empty()) {
            float s = 0;
            for (int c = 0; c < 3; ++c) {
                const float e = m_p.normal[p * 3 + c] - m_p.normal[q * 3 + c];
                s += e * e;
            }
            d += s * m_inv_normal;
        }
        if (!m_p.depth.empty()) {
            const float zp = m_p.depth[p], zq = m_p.depth[q];
            if (std::isfinite(zp) && std::isfinite(zq) && zp > 0) {
                // Against the centre's plane: a slanted surface keeps its neighbours.
                const float predicted = zp + m_p.slope[p * 2] * float(dx) + m_p.slope[p * 2 + 1] * float(dy);
                const float e = (zq - predicted) / zp;
                d += e * e * m_inv_depth;
            }
        }
        return d;
    }

    /// The neighbours at (dx, dy) weighted into the band's sums.
    void accumulate(int dx, int dy)
    {
        const int w = m_p.w, r = m_q.patch_radius;
        for (int y = m_y0; y < m_y1; ++y) {
            const int qy = y + dy;
            if (qy < 0 || qy >= m_p.h)
                continue;
            const int x0 = std::max(0, -dx), x1 = std::min(w, w - dx);
            float* sums = &m_sums[std::size_t(y - m_y0) * std::size_t(w) * 4];
            for (int x = x0; x < x1; ++x) {
                const std::size_t p = m_p.at(x, y), q = m_p.at(x + dx, qy);
                if (m_p.organ_at(p) != m_p.organ_at(q))
                    continue;
                float patch = 0;
                for (int k = -r; k <= r; ++k) {
                    const int yy = std::clamp(y + k, 0, m_p.h - 1);
                    patch += m_row_sum[std::size_t(yy - m_ya) * std::size_t(w) + std::size_t(x)];
                }
                const float colour = std::max(0.0f, patch * m_inv_patch);
                const float weight = std::exp(-(colour + feature_distance(p, q, dx, dy)));
                const float* uq = &m_p.colour[q * 3];
                float* s = &sums[std::size_t(x) * 4];
                s[0] += weight * uq[0];
                s[1] += weight * uq[1];
                s[2] += weight * uq[2];
                s[3] += weight;
            }
        }
    }

    const Prepared& m_p;
    const NlMeansParameters& m_q;
    int m_y0, m_y1, m_ya, m_yb;
    std::vector<float> m_distance, m_row_sum, m_sums;
    float m_inv_patch = 0, m_k2 = 0, m_inv_albedo = 0, m_inv_normal = 0, m_inv_depth = 0;
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
    // Prepared: colour, variance, slope (8 floats a pixel); each band in flight: two
    // distance rows per row with the patch margin, and 4 sums per pixel.
    const std::uint64_t bands = (h + band_rows - 1) / band_rows;
    const std::uint64_t in_flight = std::min<std::uint64_t>(
        bands, std::max(1u, std::thread::hardware_concurrency()));
    const std::uint64_t band = (2 * (band_rows + 2 * std::uint64_t(m_parameters.patch_radius)) +
                                4 * band_rows) * w * sizeof(float);
    return w * h * 8 * sizeof(float) + in_flight * band;
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
