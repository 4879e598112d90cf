// SPDX-License-Identifier: Apache-2.0
// The pixel reconstruction filter, importance sampled: where in the pixel's footprint a
// camera sample lies.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace cambium::render {

/// The pixel reconstruction filter. Filters are importance sampled: each sample's
/// position within the pixel's footprint is drawn from the filter (tabulated, 64 bins
/// per radius) and weighted 1, so every pixel stays a pure function of its own samples.
enum class PixelFilter {
    box,              ///< uniform over the pixel (radius fixed at 0.5): cpfg-like crisp edges
    gaussian,         ///< exp(-x^2 / (2 s^2)) - its edge value, s = radius / 3
    blackman_harris,  ///< the 4-term Blackman-Harris window over [-radius, radius]
};

/// Draws a pixel-space offset from a separable filter profile: a 1D table over
/// [-radius, radius], piecewise constant, inverted by binary search.
class FilterTable {
public:
    /// `radius` 0: the filter's default (1.5 pixels for gaussian, 1 for blackman_harris).
    FilterTable(PixelFilter filter, float radius);

    bool box() const { return m_cdf.empty(); }
    /// How far from the pixel centre a sample may lie, in pixels.
    double radius() const { return m_radius; }

    /// The offset from the pixel centre for the uniform u (inline: once per sample and axis).
    double offset(float u) const
    {
        auto it = std::upper_bound(m_cdf.begin(), m_cdf.end(), double(u));
        std::size_t bin = std::min<std::size_t>(
            std::size_t(std::max<std::ptrdiff_t>(it - m_cdf.begin() - 1, 0)), m_cdf.size() - 2);
        double width = m_cdf[bin + 1] - m_cdf[bin];
        double t = width > 0 ? std::clamp((u - m_cdf[bin]) / width, 0.0, 1.0) : 0.5;
        double bins = double(m_cdf.size() - 1);
        return -m_radius + (double(bin) + t) * 2 * m_radius / bins;
    }

private:
    double m_radius = 0.5;
    std::vector<double> m_cdf;
};

}  // namespace cambium::render
