// SPDX-License-Identifier: Apache-2.0
// Sample values as a pure function of (pixel, sample index, dimension, seed): Owen-scrambled
// Sobol points in padded 2D pairs (a low-discrepancy sequence), or white noise.
#pragma once

#include <array>
#include <cstdint>

namespace cambium::render {

/// A 64-bit finaliser with good avalanche (splitmix64 / Stafford variant 13).
constexpr std::uint64_t mix64(std::uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/// How sample values are drawn.
enum class SampleSequence {
    /// Owen-scrambled Sobol points: error falls faster than white noise's spp^-1/2 on
    /// anything smooth or with edges (see Sampler).
    sobol,
    /// An independent hash per dimension (the sampler before Sobol; for comparisons).
    white,
};

/// The fixed dimension layout of one camera sample: a dimension always means the same
/// draw, whatever the path meets (an opacity draw is spent even on an opaque surface), so
/// the sequence's stratification is never shifted onto another purpose. Pairs start at
/// even dimensions and are stratified jointly.
namespace sample_dimension {
inline constexpr std::uint32_t film = 0;  ///< pair: position in the pixel (filter)
inline constexpr std::uint32_t lens = 2;  ///< pair: position on the thin lens
/// Each path vertex's block starts at vertex(depth); within it:
inline constexpr std::uint32_t light_choice = 0;       ///< which light (by power) ...
inline constexpr std::uint32_t area_light_choice = 1;  ///< ... and which emissive primitive
inline constexpr std::uint32_t light_point = 2;        ///< pair: point on it / direction
inline constexpr std::uint32_t bsdf = 4;  ///< pair: lobe (rescaled) and direction
inline constexpr std::uint32_t opacity = 6;   ///< stop at this surface or pass through
inline constexpr std::uint32_t roulette = 7;  ///< Russian roulette
inline constexpr std::uint32_t per_vertex = 8;
/// The first dimension of the block of the path vertex `depth` (0: the camera ray's hit).
constexpr std::uint32_t vertex(int depth)
{
    return 4 + per_vertex * static_cast<std::uint32_t>(depth);
}
}  // namespace sample_dimension

namespace sobol {

constexpr std::uint32_t reverse_bits(std::uint32_t v)
{
    v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
    v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
    v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
    v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
    return (v >> 16) | (v << 16);
}

/// A hash-based Owen scramble (Burley 2020) of the 32-bit binary fraction v: bit b is
/// flipped by a pseudo-random function of `seed` and of the bits above it only, so every
/// aligned binary interval maps onto another of the same size and a net stays a net.
/// Bit-reversed, "the bits above" become the bits below, and each step below changes a
/// bit by a function of lower bits only (carries and multiplication by an even number
/// propagate upward); the two seed-dependent steps make the flips differ per seed.
constexpr std::uint32_t owen_scramble(std::uint32_t v, std::uint64_t seed)
{
    std::uint32_t r = reverse_bits(v);
    r += static_cast<std::uint32_t>(seed);
    r ^= r * 0x3d4e9a2cu;
    r *= static_cast<std::uint32_t>(seed >> 32) | 1u;
    r ^= r * 0xa6f1c3d8u;
    r += static_cast<std::uint32_t>(seed >> 17);
    r ^= r * 0x5b0e7f64u;
    return reverse_bits(r);
}

/// The second dimension of the Sobol sequence, bit by bit: the (0,2)-sequence partner of
/// the first (the van der Corput sequence, reverse_bits(index)), whose generator matrix is
/// Pascal's triangle mod 2 (each column is the previous one xor itself shifted down by one).
constexpr std::uint32_t sobol_second_bitwise(std::uint32_t index)
{
    std::uint32_t y = 0;
    for (std::uint32_t column = 0x80000000u; index != 0; index >>= 1, column ^= column >> 1)
        if (index & 1u)
            y ^= column;
    return y;
}

/// The same, a byte of the index at a time: y is linear (xor) in the index's bits, so it
/// is the xor of the four bytes' contributions, tabulated at compile time.
struct SobolSecondTable {
    std::array<std::array<std::uint32_t, 256>, 4> byte{};
    constexpr SobolSecondTable()
    {
        for (std::uint32_t b = 0; b < 4; ++b)
            for (std::uint32_t v = 0; v < 256; ++v)
                byte[b][v] = sobol_second_bitwise(v << (8 * b));
    }
};
inline constexpr SobolSecondTable sobol_second_table;

constexpr std::uint32_t sobol_second(std::uint32_t index)
{
    const auto& t = sobol_second_table.byte;
    return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^
           t[3][index >> 24];
}

constexpr float to_unit(std::uint32_t v) { return static_cast<float>(v >> 8) * 0x1.0p-24f; }

}  // namespace sobol

/// The sample values of one (pixel, sample index). With SampleSequence::sobol each pair
/// of dimensions (2k, 2k+1) is its own 2D Sobol sequence ("padded"), Owen-scrambled with a
/// hash of (seed, pixel, pair), and read at a per-pixel, per-pair shuffle of the sample
/// index: an Owen scramble of the index's bits, which maps every aligned block of 2^k
/// indices onto another, so each pixel's first 2^k samples are a (0,k,2)-net in every
/// pair, while different pairs (and pixels) are decorrelated. Nothing depends on which
/// thread, tile or pass asks, or on the frame of a turntable: images are bit-identical for
/// any thread or pass count and the pattern stays put between frames.
class Sampler {
public:
    Sampler(std::uint32_t x, std::uint32_t y, std::uint32_t sample, std::uint64_t seed,
            SampleSequence sequence = SampleSequence::sobol)
        : m_pixel(mix64(mix64(seed ^ 0x9e3779b97f4a7c15ULL) ^
                        ((std::uint64_t{y} << 32) | x))),
          m_sample(sample), m_sequence(sequence)
    {
    }

    /// The value of `dimension`, uniform in [0, 1).
    float get1d(std::uint32_t dimension) const
    {
        if (m_sequence == SampleSequence::white)
            return white(dimension, 0);
        std::uint32_t pair = dimension >> 1;
        std::uint32_t index = shuffled_index(pair);
        std::uint32_t v = (dimension & 1u) ? sobol::sobol_second(index)
                                           : sobol::reverse_bits(index);
        return sobol::to_unit(sobol::owen_scramble(v, pair_seed(pair, 1 + (dimension & 1u))));
    }

    /// The values of the pair (dimension, dimension + 1); `dimension` is even.
    std::array<float, 2> get2d(std::uint32_t dimension) const
    {
        if (m_sequence == SampleSequence::white)
            return {white(dimension, 0), white(dimension + 1, 0)};
        std::uint32_t pair = dimension >> 1;
        std::uint32_t index = shuffled_index(pair);
        return {sobol::to_unit(sobol::owen_scramble(sobol::reverse_bits(index),
                                                    pair_seed(pair, 1))),
                sobol::to_unit(sobol::owen_scramble(sobol::sobol_second(index),
                                                    pair_seed(pair, 2)))};
    }

    /// An independent value for the `k`-th extra draw of `dimension` (k > 0): white noise,
    /// for draws a path may need any number of times (passing through many surfaces).
    float extra(std::uint32_t dimension, std::uint32_t k) const { return white(dimension, k); }

    /// The next dimension in order (for code that needs a stream of uniforms: tests).
    float next() { return get1d(m_dimension++); }

private:
    float white(std::uint32_t dimension, std::uint32_t k) const
    {
        // For k = 0, the same stream as the sampler before Sobol.
        std::uint64_t key = m_pixel ^ (std::uint64_t{m_sample} * 0xd1b54a32d192ed03ULL) ^
                            (std::uint64_t{k} * 0xaef17502108ef2d9ULL);
        std::uint64_t h = mix64(key + std::uint64_t{dimension} * 0x9e3779b97f4a7c15ULL);
        return static_cast<float>(h >> 40) * 0x1.0p-24f;
    }

    /// Seeds of one pair: role 0 shuffles the index, 1 and 2 scramble x and y.
    std::uint64_t pair_seed(std::uint32_t pair, std::uint32_t role) const
    {
        return mix64(m_pixel + (std::uint64_t{pair} * 3 + role + 1) * 0x9e3779b97f4a7c15ULL);
    }

    std::uint32_t shuffled_index(std::uint32_t pair) const
    {
        return sobol::owen_scramble(m_sample, pair_seed(pair, 0));
    }

    std::uint64_t m_pixel;
    std::uint32_t m_sample;
    SampleSequence m_sequence;
    std::uint32_t m_dimension = 0;
};

}  // namespace cambium::render
