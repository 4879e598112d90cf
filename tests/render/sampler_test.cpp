// SPDX-License-Identifier: Apache-2.0
// Sampler: a pure function of (pixel, sample, dimension, seed), uniform on [0, 1);
// Sobol pairs stratified at every power of two, with far less variance than white noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "render/color.h"
#include "render/sampler.h"

namespace cambium::render {
namespace {

TEST(Sampler, SameKeySameStream)
{
    for (SampleSequence seq : {SampleSequence::sobol, SampleSequence::white}) {
        Sampler a(3, 7, 11, 42, seq), b(3, 7, 11, 42, seq);
        for (int i = 0; i < 16; ++i)
            EXPECT_EQ(a.next(), b.next());
        Sampler c(3, 7, 12, 42, seq), d(3, 7, 11, 43, seq), e(7, 3, 11, 42, seq);
        Sampler f(3, 7, 11, 42, seq);
        float v = f.next();
        EXPECT_NE(c.next(), v);
        EXPECT_NE(d.next(), v);  // the seed changes the pattern
        EXPECT_NE(e.next(), v);
    }
}

TEST(Sampler, PixelSeedsGiveTheSameValuesAsPerSampleHashes)
{
    // The per-pixel cache is only a cache: every dimension (cached pairs and beyond), every
    // sample, both sequences.
    for (SampleSequence seq : {SampleSequence::sobol, SampleSequence::white}) {
        const PixelSeeds seeds(17, 5, 42);
        for (std::uint32_t i = 0; i < 20; ++i) {
            Sampler cached(seeds, i, seq), plain(17, 5, i, 42, seq);
            for (std::uint32_t d = 0; d < 2 * PixelSeeds::cached_pairs + 10; d += 2) {
                ASSERT_EQ(cached.get2d(d), plain.get2d(d)) << i << " " << d;
                ASSERT_EQ(cached.get1d(d + 1), plain.get1d(d + 1)) << i << " " << d;
            }
        }
    }
}

TEST(Sampler, BatchedPairsGiveEachSamplersValues)
{
    // sobol_pairs (SIMD where the processor has it) against one Sampler per sample: every
    // start, count (within a block, whole blocks, a block and a bit), cached and uncached
    // pairs, and indices whose high bits are set.
    const PixelSeeds seeds(211, 37, 9);
    for (std::uint32_t first : {0u, 5u, 16u, 1000u, 0x7ffffff0u, 0xfffffff0u})
        for (std::uint32_t n : {1u, 7u, 16u, 17u, 40u})
            for (std::uint32_t d : {0u, 2u, 10u, 2 * PixelSeeds::cached_pairs + 4}) {
                std::vector<float> xs(n), ys(n);
                sobol_pairs(seeds, d, first, n, xs.data(), ys.data());
                for (std::uint32_t k = 0; k < n; ++k) {
                    auto [x, y] = Sampler(seeds, first + k).get2d(d);
                    ASSERT_EQ(xs[k], x) << first << " " << n << " " << d << " " << k;
                    ASSERT_EQ(ys[k], y) << first << " " << n << " " << d << " " << k;
                }
            }
}

TEST(Sampler, PairsAgreeWithSingleDimensions)
{
    Sampler s(5, 9, 77, 3);
    for (std::uint32_t d = 0; d < 40; d += 2) {
        auto [u, v] = s.get2d(d);
        EXPECT_EQ(u, s.get1d(d));
        EXPECT_EQ(v, s.get1d(d + 1));
    }
}

TEST(Sampler, UniformMeanAndRange)
{
    for (SampleSequence seq : {SampleSequence::sobol, SampleSequence::white}) {
        double sum = 0, sum2 = 0;
        int n = 0;
        for (std::uint32_t p = 0; p < 200; ++p)
            for (std::uint32_t s = 0; s < 50; ++s) {
                Sampler sm(p, p / 7, s, 5, seq);
                for (int d = 0; d < 4; ++d) {
                    float u = sm.next();
                    ASSERT_GE(u, 0.0f);
                    ASSERT_LT(u, 1.0f);
                    sum += u;
                    sum2 += u * u;
                    ++n;
                }
            }
        EXPECT_NEAR(sum / n, 0.5, 0.01);
        EXPECT_NEAR(sum2 / n, 1.0 / 3, 0.01);
    }
}

TEST(Sobol, SecondDimensionTableMatchesItsDefinition)
{
    for (std::uint32_t i : {0u, 1u, 2u, 3u, 255u, 256u, 65535u, 0x12345678u, 0xffffffffu})
        EXPECT_EQ(sobol::sobol_second(i), sobol::sobol_second_bitwise(i)) << i;
    // The first points, known from the definition: 0, 1/2, 3/4, 1/4, 5/8.
    const float expect[] = {0, 0.5f, 0.75f, 0.25f, 0.625f};
    for (std::uint32_t i = 0; i < 5; ++i)
        EXPECT_EQ(sobol::to_unit(sobol::sobol_second(i)), expect[i]);
}

TEST(Sobol, BitReversalsAndTheReversedTableAgreeWithTheirDefinitions)
{
    auto reverse_slowly = [](std::uint64_t v, int bits) {
        std::uint64_t r = 0;
        for (int b = 0; b < bits; ++b)
            r |= ((v >> b) & 1u) << (bits - 1 - b);
        return r;
    };
    for (std::uint32_t i : {0u, 1u, 2u, 3u, 255u, 256u, 65535u, 0x12345678u, 0xffffffffu}) {
        EXPECT_EQ(sobol::reverse_bits(i), reverse_slowly(i, 32)) << i;
        EXPECT_EQ(sobol::reverse_bits_shifts(i), reverse_slowly(i, 32)) << i;
        std::uint64_t wide = std::uint64_t{i} * 0x9e3779b97f4a7c15ULL;
        EXPECT_EQ(sobol::reverse_bits64(wide), reverse_slowly(wide, 64)) << i;
        EXPECT_EQ(sobol::sobol_second_reversed(i), sobol::reverse_bits(sobol::sobol_second(i)))
            << i;
    }
    // The table-free form, from the bit-by-bit definition (not the table), on every index
    // below 2^16 and a spread of larger ones.
    for (std::uint64_t i = 0; i < (1u << 16); ++i)
        ASSERT_EQ(sobol::sobol_second_reversed_shifts(std::uint32_t(i)),
                  reverse_slowly(sobol::sobol_second_bitwise(std::uint32_t(i)), 32))
            << i;
    for (std::uint64_t i = 1; i < (std::uint64_t{1} << 32); i = i * 3 + 1)
        ASSERT_EQ(sobol::sobol_second_reversed_shifts(std::uint32_t(i)),
                  reverse_slowly(sobol::sobol_second_bitwise(std::uint32_t(i)), 32))
            << i;
}

TEST(Sobol, OwenScrambleKeepsAlignedIntervals)
{
    // Values sharing their top k bits (one binary interval) still share them scrambled,
    // and different seeds scramble differently.
    int differing_seeds = 0;
    for (std::uint64_t seed = 1; seed < 50; ++seed) {
        for (std::uint32_t k = 1; k < 31; k += 3)
            for (std::uint32_t v = 0; v < 64; ++v) {
                std::uint32_t a = (v * 0x9e3779b9u), b = a ^ (0xffffffffu >> k);
                std::uint32_t mask = ~(0xffffffffu >> k);
                ASSERT_EQ(sobol::owen_scramble(a, seed) & mask,
                          sobol::owen_scramble(b, seed) & mask);
            }
        differing_seeds += sobol::owen_scramble(0x40000000u, seed) !=
                           sobol::owen_scramble(0x40000000u, seed + 1000);
    }
    EXPECT_GT(differing_seeds, 40);
}

/// Whether the points are a (0, m, 2)-net in base 2: every elementary interval of area
/// 1/n (n = 2^m points) holds exactly one point.
bool is_net(const std::vector<std::array<float, 2>>& points)
{
    int m = 0;
    while ((1u << m) < points.size())
        ++m;
    for (int a = 0; a <= m; ++a) {
        std::vector<int> count(points.size(), 0);
        for (const auto& p : points) {
            int cell = (int(p[0] * float(1 << a)) << (m - a)) | int(p[1] * float(1 << (m - a)));
            if (++count[std::size_t(cell)] > 1)
                return false;
        }
    }
    return true;
}

TEST(Sampler, EveryPairIsStratifiedAtEveryPowerOfTwo)
{
    using namespace sample_dimension;
    const std::uint32_t pairs[] = {film, lens, vertex(0) + light_choice, vertex(0) + light_point,
                                   vertex(1) + bsdf, vertex(5) + opacity};
    for (std::uint32_t pixel = 0; pixel < 40; ++pixel)
        for (std::uint64_t seed : {0ull, 7ull})
            for (std::uint32_t d : pairs) {
                std::vector<std::array<float, 2>> points;
                for (std::uint32_t i = 0; i < 64; ++i) {
                    points.push_back(Sampler(pixel, 3 * pixel, i, seed).get2d(d));
                    std::size_t n = points.size();
                    if ((n & (n - 1)) == 0) {  // 1, 2, 4, ... 64: each prefix is a net
                        ASSERT_TRUE(is_net(points)) << "pixel " << pixel << " dim " << d
                                                    << " first " << n;
                    }
                }
                // Hence each of the 64 samples alone in its 1/64 stratum of each dimension.
                std::vector<int> x(64), y(64);
                for (const auto& p : points) {
                    ++x[std::size_t(p[0] * 64)];
                    ++y[std::size_t(p[1] * 64)];
                }
                EXPECT_EQ(std::count(x.begin(), x.end(), 1), 64);
                EXPECT_EQ(std::count(y.begin(), y.end(), 1), 64);
            }
}

/// The variance over many pixels of the 64-sample estimate of the integral of f over the
/// unit square, drawn from dimension pair d, and the mean error.
struct Estimates {
    double variance = 0, mean_error = 0;
};

template <class F>
Estimates estimate_64(SampleSequence seq, std::uint32_t d, double truth, F f)
{
    constexpr int pixels = 4000, spp = 64;
    double sum_sq = 0, sum = 0;
    for (int p = 0; p < pixels; ++p) {
        double estimate = 0;
        for (int i = 0; i < spp; ++i) {
            auto [u, v] = Sampler(std::uint32_t(p % 100), std::uint32_t(p / 100),
                                  std::uint32_t(i), std::uint64_t(p % 3), seq)
                              .get2d(d);
            estimate += f(double(u), double(v));
        }
        double error = estimate / spp - truth;
        sum += error;
        sum_sq += error * error;
    }
    return {sum_sq / pixels, sum / pixels};
}

TEST(Sampler, SobolVarianceFarBelowWhiteNoiseOnStratifiableIntegrals)
{
    // A smooth integrand (x y: mean 1/4, variance 1/9 - 1/16 = 7/144) and a pixel cut by a
    // slanted edge (coverage 1/2, variance 1/4): white noise's 64-sample variance is the
    // integrand's variance / 64.
    struct Case {
        const char* name;
        double truth, white_variance;
        double (*f)(double, double);
    };
    const Case cases[] = {
        {"smooth", 0.25, 7.0 / 144 / 64, [](double x, double y) { return x * y; }},
        {"edge", 0.5, 0.25 / 64, [](double x, double y) { return y < 0.3 + 0.4 * x ? 1.0 : 0.0; }},
    };
    for (const Case& c : cases)
        for (std::uint32_t d : {sample_dimension::film, sample_dimension::vertex(2) +
                                                            sample_dimension::bsdf}) {
            Estimates white = estimate_64(SampleSequence::white, d, c.truth, c.f);
            Estimates sobol = estimate_64(SampleSequence::sobol, d, c.truth, c.f);
            // The harness measures white noise's analytic variance (4000 estimates: the
            // variance's own relative error is about 2%).
            EXPECT_NEAR(white.variance / c.white_variance, 1.0, 0.1) << c.name;
            EXPECT_LT(sobol.variance, 0.25 * c.white_variance) << c.name;
            // Unbiased: the mean error is within 4 standard errors of 0.
            EXPECT_LT(std::fabs(sobol.mean_error), 4 * std::sqrt(sobol.variance / 4000) + 1e-7)
                << c.name;
            std::printf("[sampler] %s, dims %u: variance / white noise's = %.4f\n", c.name, d,
                        sobol.variance / c.white_variance);
        }
}

TEST(Color, SrgbCurveRoundTripsAndMatchesKnownValues)
{
    EXPECT_NEAR(srgb_to_linear(0.5f), 0.214041f, 1e-5f);
    EXPECT_NEAR(linear_to_srgb(0.214041f), 0.5f, 1e-5f);
    EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
    EXPECT_NEAR(srgb_to_linear(1.0f), 1.0f, 1e-6f);
    for (int b = 0; b < 256; ++b)
        EXPECT_EQ(std::lround(linear_to_srgb(srgb_to_linear(b / 255.0f)) * 255), b);
}

}  // namespace
}  // namespace cambium::render
