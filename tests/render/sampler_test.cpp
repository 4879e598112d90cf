// SPDX-License-Identifier: Apache-2.0
// Sampler: a pure function of (pixel, sample, dimension, seed), uniform on [0, 1).
#include <gtest/gtest.h>

#include "render/color.h"
#include "render/sampler.h"

namespace cambium::render {
namespace {

TEST(Sampler, SameKeySameStream)
{
    Sampler a(3, 7, 11, 42), b(3, 7, 11, 42);
    for (int i = 0; i < 16; ++i)
        EXPECT_EQ(a.next(), b.next());
    Sampler c(3, 7, 12, 42), d(3, 7, 11, 43), e(7, 3, 11, 42);
    Sampler f(3, 7, 11, 42);
    float v = f.next();
    EXPECT_NE(c.next(), v);
    EXPECT_NE(d.next(), v);
    EXPECT_NE(e.next(), v);
}

TEST(Sampler, UniformMeanAndRange)
{
    double sum = 0, sum2 = 0;
    int n = 0;
    for (std::uint32_t p = 0; p < 200; ++p)
        for (std::uint32_t s = 0; s < 50; ++s) {
            Sampler sm(p, p / 7, s, 5);
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
