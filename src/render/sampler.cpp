// SPDX-License-Identifier: Apache-2.0
// The film pairs of a batch of camera samples, in SIMD code where the processor allows.
#include "render/sampler.h"

#include <algorithm>
#include <array>

#include "render/simd_clones.h"

namespace cambium::render {

namespace {

/// The pair values of samples first .. first + 15 (sobol_pairs). Plain integer arithmetic
/// over a fixed count, which vectorises: GCC builds one version for AVX-512 (the block's
/// 16 lanes in one register), one for AVX2 (vpmulld does a lane's multiply in one
/// instruction) and one for the baseline processor, and picks at load time (an ifunc).
/// All give the same bits.
CAMBIUM_SIMD_CLONES void pair_block(const sobol::ScrambleKey& shuffle, const sobol::ScrambleKey& kx,
                                    const sobol::ScrambleKey& ky, std::uint32_t first,
                                    float* __restrict x, float* __restrict y)
{
    using namespace sobol;
    for (std::uint32_t k = 0; k < 16; ++k) {
        std::uint32_t index =
            reverse_bits_shifts(scramble_reversed(reverse_bits_shifts(first + k), shuffle));
        x[k] = to_unit(reverse_bits_shifts(scramble_reversed(index, kx)));
        y[k] = to_unit(
            reverse_bits_shifts(scramble_reversed(sobol_second_reversed_shifts(index), ky)));
    }
}

}  // namespace

void sobol_pairs(const PixelSeeds& seeds, std::uint32_t dimension, std::uint32_t first,
                 std::uint32_t n, float* xs, float* ys)
{
    const sobol::PairSeeds pair(seeds.pair(dimension >> 1));
    const sobol::ScrambleKey shuffle(pair.shuffle), kx(pair.x), ky(pair.y);
    constexpr std::uint32_t block = 16;
    for (std::uint32_t k0 = 0; k0 < n; k0 += block) {
        // The whole block (a fixed count vectorises); values past n are not stored.
        const std::uint32_t m = std::min(block, n - k0);
        if (m == block) {
            pair_block(shuffle, kx, ky, first + k0, xs + k0, ys + k0);
            continue;
        }
        alignas(32) std::array<float, block> x, y;
        pair_block(shuffle, kx, ky, first + k0, x.data(), y.data());
        std::copy_n(x.data(), m, xs + k0);
        std::copy_n(y.data(), m, ys + k0);
    }
}

}  // namespace cambium::render
