// SPDX-License-Identifier: Apache-2.0
#include "render/pixel_filter.h"

#include <cmath>
#include <numbers>

namespace cambium::render {

FilterTable::FilterTable(PixelFilter filter, float radius)
{
    if (filter == PixelFilter::box)
        return;
    m_radius = radius > 0 ? radius : (filter == PixelFilter::gaussian ? 1.5f : 1.0f);
    constexpr int bins = 128;
    m_cdf.resize(bins + 1);
    double sigma = m_radius / 3.0;
    double edge = std::exp(-m_radius * m_radius / (2 * sigma * sigma));
    for (int i = 0; i < bins; ++i) {
        double x = -m_radius + (i + 0.5) * 2 * m_radius / bins;
        double f;
        if (filter == PixelFilter::gaussian) {
            f = std::max(0.0, std::exp(-x * x / (2 * sigma * sigma)) - edge);
        } else {
            double t = 2 * std::numbers::pi * (x + m_radius) / (2 * m_radius);
            f = 0.35875 - 0.48829 * std::cos(t) + 0.14128 * std::cos(2 * t) -
                0.01168 * std::cos(3 * t);
        }
        m_cdf[i + 1] = m_cdf[i] + std::max(f, 0.0);
    }
    for (double& c : m_cdf)
        c /= m_cdf.back();
}

}  // namespace cambium::render
