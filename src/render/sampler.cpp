// SPDX-License-Identifier: Apache-2.0
// The film pairs of a batch of camera samples, in SIMD code where the processor allows.
#include "render/sampler.h"

#include <algorithm>
#include <array>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define CAMBIUM_GFNI_PAIRS 1
#endif

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

#ifdef CAMBIUM_GFNI_PAIRS
#define CAMBIUM_GFNI_TARGET [[gnu::target("avx512f,avx512bw,gfni")]]

/// Every lane c.
CAMBIUM_GFNI_TARGET inline __m512i broadcast(std::uint32_t c)
{
    return _mm512_set1_epi32(static_cast<int>(c));
}

/// Each lane shifted right by `shift` (in the compiler's vector arithmetic: GCC 12's
/// _mm512_srli_epi32 warns of an uninitialised operand inside its own header).
CAMBIUM_GFNI_TARGET inline __m512i shift_right(__m512i v, unsigned shift)
{
    return reinterpret_cast<__m512i>(reinterpret_cast<__v16su>(v) >> shift);
}

/// reverse_bits_shifts of each 32-bit lane: its bytes reversed (a byte shuffle), then the
/// bits within each byte (a GF(2) affine map whose matrix is the bit reversal): 2
/// instructions instead of the 13 that the shifts and masks take in AVX-512.
CAMBIUM_GFNI_TARGET inline __m512i reverse_lanes(__m512i v)
{
    const __m512i bytes = _mm512_set_epi8(
        60, 61, 62, 63, 56, 57, 58, 59, 52, 53, 54, 55, 48, 49, 50, 51, 44, 45, 46, 47, 40,
        41, 42, 43, 36, 37, 38, 39, 32, 33, 34, 35, 28, 29, 30, 31, 24, 25, 26, 27, 20, 21,
        22, 23, 16, 17, 18, 19, 12, 13, 14, 15, 8, 9, 10, 11, 4, 5, 6, 7, 0, 1, 2, 3);
    // (vpshufb picks within each 128-bit quarter: indices taken modulo 16 there)
    const __m512i reversal = _mm512_set1_epi64(static_cast<long long>(0x8040201008040201ULL));
    return _mm512_gf2p8affine_epi64_epi8(_mm512_shuffle_epi8(v, bytes), reversal, 0);
}

/// sobol::scramble_reversed of each lane.
CAMBIUM_GFNI_TARGET inline __m512i scramble_lanes(__m512i r, const sobol::ScrambleKey& key)
{
    r = _mm512_add_epi32(r, broadcast(key.add));
    r = _mm512_xor_si512(r, _mm512_mullo_epi32(r, broadcast(0x3d4e9a2cu)));
    r = _mm512_mullo_epi32(r, broadcast(key.odd));
    r = _mm512_xor_si512(r, _mm512_mullo_epi32(r, broadcast(0xa6f1c3d8u)));
    r = _mm512_add_epi32(r, broadcast(key.add2));
    return _mm512_xor_si512(r, _mm512_mullo_epi32(r, broadcast(0x5b0e7f64u)));
}

/// One step of sobol::sobol_second_reversed_shifts in each lane: v ^ ((v >> shift) & mask).
CAMBIUM_GFNI_TARGET inline __m512i fold_lanes(__m512i v, unsigned shift, std::uint32_t mask)
{
    return _mm512_xor_si512(v, _mm512_and_si512(shift_right(v, shift), broadcast(mask)));
}

/// sobol::to_unit of each lane: the top 24 bits (below 2^24, so the signed conversion is
/// exact), scaled by 2^-24.
CAMBIUM_GFNI_TARGET inline __m512 unit_lanes(__m512i v)
{
    // (a vector conversion: _mm512_cvtepi32_ps warns as _mm512_srli_epi32 does)
    const auto top24 = reinterpret_cast<__v16si>(shift_right(v, 8));
    const __v16sf top = __builtin_convertvector(top24, __v16sf);
    return reinterpret_cast<__m512>(top * 0x1.0p-24f);
}

/// pair_block with the bit reversals in GFNI instructions (where the processor has them
/// with AVX-512BW): the same integer operations otherwise, so the same bits.
CAMBIUM_GFNI_TARGET void pair_block_gfni(const sobol::ScrambleKey& shuffle,
                                         const sobol::ScrambleKey& kx,
                                         const sobol::ScrambleKey& ky, std::uint32_t first,
                                         float* x, float* y)
{
    const __m512i k = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i index = reverse_lanes(
        scramble_lanes(reverse_lanes(_mm512_add_epi32(broadcast(first), k)), shuffle));
    // sobol::sobol_second_reversed_shifts
    __m512i second = fold_lanes(index, 1, 0x55555555u);
    second = fold_lanes(second, 2, 0x33333333u);
    second = fold_lanes(second, 4, 0x0f0f0f0fu);
    second = fold_lanes(second, 8, 0x00ff00ffu);
    second = fold_lanes(second, 16, 0xffffffffu);
    _mm512_storeu_ps(x, unit_lanes(reverse_lanes(scramble_lanes(index, kx))));
    _mm512_storeu_ps(y, unit_lanes(reverse_lanes(scramble_lanes(second, ky))));
}

/// Whether pair_block_gfni runs here.
bool gfni_pairs()
{
    static const bool supported = __builtin_cpu_supports("avx512f") &&
                                  __builtin_cpu_supports("avx512bw") &&
                                  __builtin_cpu_supports("gfni");
    return supported;
}

/// pair_block, in GFNI instructions where the processor has them.
inline void pair_block_best(const sobol::ScrambleKey& shuffle, const sobol::ScrambleKey& kx,
                            const sobol::ScrambleKey& ky, std::uint32_t first, float* x, float* y)
{
    if (gfni_pairs())
        pair_block_gfni(shuffle, kx, ky, first, x, y);
    else
        pair_block(shuffle, kx, ky, first, x, y);
}
#else
inline void pair_block_best(const sobol::ScrambleKey& shuffle, const sobol::ScrambleKey& kx,
                            const sobol::ScrambleKey& ky, std::uint32_t first, float* x, float* y)
{
    pair_block(shuffle, kx, ky, first, x, y);
}
#endif

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
            pair_block_best(shuffle, kx, ky, first + k0, xs + k0, ys + k0);
            continue;
        }
        alignas(32) std::array<float, block> x, y;
        pair_block_best(shuffle, kx, ky, first + k0, x.data(), y.data());
        std::copy_n(x.data(), m, xs + k0);
        std::copy_n(y.data(), m, ys + k0);
    }
}

}  // namespace cambium::render
