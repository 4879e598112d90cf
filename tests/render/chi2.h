// SPDX-License-Identifier: Apache-2.0
// Pearson's chi-squared test of a sampling routine against its own density, as pbrt's
// bsdfs_test.cpp and Mitsuba's chi2 tests do: directions drawn by the routine are counted
// in bins of equal solid angle over the sphere (z, phi), the expected counts are the pdf
// integrated over each bin, directions the routine refuses (pdf 0) are one more bin, and
// bins expecting fewer than 5 are pooled (also those on the edge of the density's support,
// where the quadrature may see nothing: a sample drawn where the density is 0 everywhere
// shows as a large count in a pool expecting little).
#pragma once

#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "render/sampler.h"
#include "render/vecf.h"

namespace cambium::render::testing {

/// The regularized upper incomplete gamma function Q(a, x) (series below a + 1, a
/// continued fraction above: the textbook pair).
inline double gamma_q(double a, double x)
{
    if (x <= 0)
        return 1;
    double gln = std::lgamma(a);
    if (x < a + 1) {
        double sum = 1 / a, term = sum;
        for (int n = 1; n < 10000 && std::fabs(term) > std::fabs(sum) * 1e-15; ++n) {
            term *= x / (a + n);
            sum += term;
        }
        return 1 - sum * std::exp(-x + a * std::log(x) - gln);
    }
    double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        d = std::fabs(d) < 1e-300 ? 1e-300 : d;
        c = b + an / c;
        c = std::fabs(c) < 1e-300 ? 1e-300 : c;
        d = 1 / d;
        double delta = d * c;
        h *= delta;
        if (std::fabs(delta - 1) < 1e-15)
            break;
    }
    return std::exp(-x + a * std::log(x) - gln) * h;
}

struct Chi2Result {
    double statistic = 0;
    int dof = 0;
    double p_value = 1;
    double pdf_integral = 0;  ///< the density integrated over the sphere
};

/// Draws `samples` directions with `sample` (nullopt: refused) from a sampler seeded by
/// `seed`, and tests them against `pdf` on a z_bins x phi_bins grid, each bin's integral
/// taken on a sub x sub grid of midpoints.
inline Chi2Result chi2_sphere(const std::function<std::optional<Vec3f>(Sampler&)>& sample,
                              const std::function<double(const Vec3f&)>& pdf, int samples,
                              std::uint32_t seed, int z_bins = 20, int phi_bins = 40,
                              int sub = 24)
{
    constexpr double pi = std::numbers::pi;
    const int bins = z_bins * phi_bins;
    std::vector<double> observed(bins + 1, 0.0), expected(bins + 1, 0.0);
    for (int i = 0; i < samples; ++i) {
        Sampler s(static_cast<std::uint32_t>(i), 7, 0, seed);
        std::optional<Vec3f> d = sample(s);
        if (!d) {
            observed[bins] += 1;
            continue;
        }
        double z = std::clamp(double(d->z), -1.0, 1.0);
        double phi = std::atan2(double(d->y), double(d->x));
        phi = phi < 0 ? phi + 2 * pi : phi;
        int zi = std::min(z_bins - 1, int((z + 1) / 2 * z_bins));
        int pi_ = std::min(phi_bins - 1, int(phi / (2 * pi) * phi_bins));
        observed[zi * phi_bins + pi_] += 1;
    }
    Chi2Result r;
    const double cell = 4 * pi / (double(bins) * sub * sub);  // solid angle of a sub-cell
    for (int zi = 0; zi < z_bins; ++zi)
        for (int p = 0; p < phi_bins; ++p) {
            double sum = 0;
            for (int a = 0; a < sub; ++a)
                for (int b = 0; b < sub; ++b) {
                    double z = -1 + 2 * (zi + (a + 0.5) / sub) / z_bins;
                    double phi = 2 * pi * (p + (b + 0.5) / sub) / phi_bins;
                    double rad = std::sqrt(std::max(0.0, 1 - z * z));
                    sum += pdf(Vec3f(float(rad * std::cos(phi)), float(rad * std::sin(phi)),
                                     float(z)));
                }
            expected[zi * phi_bins + p] = sum * cell * samples;
            r.pdf_integral += sum * cell;
        }
    expected[bins] = std::max(0.0, 1 - r.pdf_integral) * samples;
    // Pool bins expecting fewer than 5 (ascending) until the pool expects 5.
    std::vector<int> order(bins + 1);
    for (int i = 0; i <= bins; ++i)
        order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return expected[a] < expected[b]; });
    double pool_e = 0, pool_o = 0;
    int used = 0;
    for (int i : order) {
        if (expected[i] < 5 || pool_e > 0) {
            pool_e += expected[i];
            pool_o += observed[i];
            if (pool_e >= 5) {
                r.statistic += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
                ++used;
                pool_e = pool_o = 0;
            }
            continue;
        }
        r.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
        ++used;
    }
    if (pool_e > 0) {
        r.statistic += (pool_o - pool_e) * (pool_o - pool_e) / std::max(pool_e, 1e-9);
        ++used;
    }
    r.dof = std::max(1, used - 1);
    r.p_value = gamma_q(r.dof / 2.0, r.statistic / 2);
    return r;
}

/// The significance each of `tests` tests must pass for 1% overall (Sidak).
inline double sidak(int tests) { return 1 - std::pow(1 - 0.01, 1.0 / tests); }

}  // namespace cambium::render::testing
