// SPDX-License-Identifier: Apache-2.0
// Sample values as a pure function of (pixel, sample index, dimension, seed): Owen-scrambled
// Sobol points in padded 2D pairs (a low-discrepancy sequence), or white noise.
#pragma once

#include <algorithm>
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

/// The bits of v in reverse order (a byte swap, then the bits within each byte).
constexpr std::uint32_t reverse_bits(std::uint32_t v)
{
    v = __builtin_bswap32(v);
    v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
    v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
    return ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
}

/// The bits of a 64-bit v in reverse order: two 32-bit words reversed at the cost of one
/// (the halves change places).
constexpr std::uint64_t reverse_bits64(std::uint64_t v)
{
    v = __builtin_bswap64(v);
    v = ((v >> 4) & 0x0f0f0f0f0f0f0f0fULL) | ((v & 0x0f0f0f0f0f0f0f0fULL) << 4);
    v = ((v >> 2) & 0x3333333333333333ULL) | ((v & 0x3333333333333333ULL) << 2);
    return ((v >> 1) & 0x5555555555555555ULL) | ((v & 0x5555555555555555ULL) << 1);
}

/// reverse_bits in shifts and masks only, without the byte swap: the same bits, in a form
/// that vectorises.
constexpr std::uint32_t reverse_bits_shifts(std::uint32_t v)
{
    v = (v >> 16) | (v << 16);
    v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
    v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
    v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
    return ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
}

/// A hash-based nested uniform (Owen) scramble of a binary fraction held bit-reversed
/// (its most significant bit in bit 0): each step changes a bit by a function of the bits
/// below it only (carries and multiplication by an even number propagate upward), which
/// in the fraction's own order are the bits above it; the seed-dependent steps make the
/// flips differ per seed. So every aligned binary interval maps onto another of the same
/// size and a net stays a net. Working on reversed fractions saves reversing before and
/// after each scramble (Sampler keeps its values reversed until they become floats).
struct ScrambleKey {
    std::uint32_t add, odd, add2;  // the seed's parts the steps use
    explicit constexpr ScrambleKey(std::uint64_t seed)
        : add(static_cast<std::uint32_t>(seed)), odd(static_cast<std::uint32_t>(seed >> 32) | 1u),
          add2(static_cast<std::uint32_t>(seed >> 17))
    {
    }
};
constexpr std::uint32_t scramble_reversed(std::uint32_t r, const ScrambleKey& key)
{
    r += key.add;
    r ^= r * 0x3d4e9a2cu;
    r *= key.odd;
    r ^= r * 0xa6f1c3d8u;
    r += key.add2;
    r ^= r * 0x5b0e7f64u;
    return r;
}
constexpr std::uint32_t scramble_reversed(std::uint32_t r, std::uint64_t seed)
{
    return scramble_reversed(r, ScrambleKey(seed));
}

/// The same scramble of the 32-bit binary fraction v in its own bit order (Burley 2020's
/// "nested uniform scramble"): bit b is flipped by a pseudo-random function of `seed` and
/// of the bits above it only.
constexpr std::uint32_t owen_scramble(std::uint32_t v, std::uint64_t seed)
{
    return reverse_bits(scramble_reversed(reverse_bits(v), seed));
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

/// The second dimension bit-reversed, as the sampler scrambles it (also linear).
struct SobolSecondReversedTable {
    std::array<std::array<std::uint32_t, 256>, 4> byte{};
    constexpr SobolSecondReversedTable()
    {
        for (std::uint32_t b = 0; b < 4; ++b)
            for (std::uint32_t v = 0; v < 256; ++v)
                byte[b][v] = reverse_bits(sobol_second_bitwise(v << (8 * b)));
    }
};
inline constexpr SobolSecondReversedTable sobol_second_reversed_table;

constexpr std::uint32_t sobol_second_reversed(std::uint32_t index)
{
    const auto& t = sobol_second_reversed_table.byte;
    return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^
           t[3][index >> 24];
}

/// The same without the table, in shifts and masks only (which vectorise; table lookups
/// do not): bit j of the reversed value is the xor of the index bits b whose bit position
/// holds every bit of j's (Pascal's triangle mod 2: C(b, j) is odd iff j & ~b == 0, by
/// Lucas's theorem), a sum over supersets of the 5 bits of a position, made one position
/// bit at a time.
constexpr std::uint32_t sobol_second_reversed_shifts(std::uint32_t index)
{
    index ^= (index >> 1) & 0x55555555u;
    index ^= (index >> 2) & 0x33333333u;
    index ^= (index >> 4) & 0x0f0f0f0fu;
    index ^= (index >> 8) & 0x00ff00ffu;
    return index ^ (index >> 16);
}

constexpr std::uint32_t sobol_second(std::uint32_t index)
{
    const auto& t = sobol_second_table.byte;
    return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^
           t[3][index >> 24];
}

constexpr float to_unit(std::uint32_t v) { return static_cast<float>(v >> 8) * 0x1.0p-24f; }

/// The three scrambles' seeds of one dimension pair, from the pair's hash: the index
/// shuffle takes it as it is, x and y cheap bijective remixes of it (a xorshift and an
/// odd multiply).
struct PairSeeds {
    std::uint64_t shuffle, x, y;
    explicit constexpr PairSeeds(std::uint64_t h)
        : shuffle(h), x((h ^ (h >> 31)) * 0xd1b54a32d192ed03ULL),
          y((h ^ (h >> 29)) * 0xaef17502108ef2d9ULL)
    {
    }
};

/// The pixel's shuffled sample index for a pair: an Owen scramble of the sample index's
/// bits (`sample_reversed`: the index bit-reversed, as the scramble takes it).
constexpr std::uint32_t shuffled_index(std::uint32_t sample_reversed, const PairSeeds& s)
{
    return reverse_bits(scramble_reversed(sample_reversed, s.shuffle));
}

/// The pair's two values at the shuffled index: x the van der Corput point of the index
/// (bit-reversed, the index itself), y the second Sobol dimension, each Owen-scrambled,
/// then reversed together in one 64-bit reversal (x above, y below).
inline std::array<float, 2> pair_values(std::uint32_t index, const PairSeeds& s)
{
    std::uint64_t rx = scramble_reversed(index, s.x);
    std::uint64_t ry = scramble_reversed(sobol_second_reversed(index), s.y);
    std::uint64_t xy = reverse_bits64(ry << 32 | rx);
    return {to_unit(static_cast<std::uint32_t>(xy >> 32)), to_unit(static_cast<std::uint32_t>(xy))};
}

}  // namespace sobol

/// The hash of (pixel, seed) every draw of the pixel starts from.
constexpr std::uint64_t pixel_hash(std::uint32_t x, std::uint32_t y, std::uint64_t seed)
{
    return mix64(mix64(seed ^ 0x9e3779b97f4a7c15ULL) ^ ((std::uint64_t{y} << 32) | x));
}

/// The hash of one dimension pair of a pixel, which seeds the pair's scrambles.
constexpr std::uint64_t pair_hash(std::uint64_t pixel, std::uint32_t pair)
{
    return mix64(pixel + (std::uint64_t{pair} + 1) * 0x9e3779b97f4a7c15ULL);
}

/// What the samples of one pixel (and seed) share: the pixel's hash and its first pairs'
/// hashes, each computed once on first use rather than once per sample. Local to the
/// thread that samples the pixel (it fills itself in as samplers read it).
class PixelSeeds {
public:
    static constexpr std::uint32_t cached_pairs = 32;

    PixelSeeds(std::uint32_t x, std::uint32_t y, std::uint64_t seed)
        : m_pixel(pixel_hash(x, y, seed))
    {
    }

    std::uint64_t pixel() const { return m_pixel; }

    std::uint64_t pair(std::uint32_t pair) const
    {
        if (pair >= cached_pairs)
            return pair_hash(m_pixel, pair);
        if (!(m_known >> pair & 1u)) {
            m_pairs[pair] = pair_hash(m_pixel, pair);
            m_known |= std::uint32_t{1} << pair;
        }
        return m_pairs[pair];
    }

private:
    std::uint64_t m_pixel;
    mutable std::uint32_t m_known = 0;
    mutable std::array<std::uint64_t, cached_pairs> m_pairs;
};

/// Sampler(seeds, first + k).get2d(dimension) for k < n (Owen-scrambled Sobol), into
/// xs[k] and ys[k]: the pair values of consecutive samples of one pixel. The samples
/// share the pair's seeds (hashed and remixed once, not once per sample), and blocks of
/// them are made in integer arithmetic without byte swaps or table lookups, which the
/// compiler turns into SIMD code where the processor has AVX2, 8 samples per instruction
/// (the film pair of every camera sample was the path tracer's largest fixed cost per
/// sample). sampler.cpp.
void sobol_pairs(const PixelSeeds& seeds, std::uint32_t dimension, std::uint32_t first,
                 std::uint32_t n, float* xs, float* ys);

/// The sample values of one (pixel, sample index). With SampleSequence::sobol each pair
/// of dimensions (2k, 2k+1) is its own 2D Sobol sequence ("padded"), Owen-scrambled with a
/// hash of (seed, pixel, pair) (one hash per pair seeds all three of its scrambles), and
/// read at a per-pixel, per-pair shuffle of the sample index: an Owen scramble of the index's bits, which maps every aligned block of 2^k
/// indices onto another, so each pixel's first 2^k samples are a (0,k,2)-net in every
/// pair, while different pairs (and pixels) are decorrelated. Nothing depends on which
/// thread, tile or pass asks, or on the frame of a turntable: images are bit-identical for
/// any thread or pass count and the pattern stays put between frames.
class Sampler {
public:
    Sampler(std::uint32_t x, std::uint32_t y, std::uint32_t sample, std::uint64_t seed,
            SampleSequence sequence = SampleSequence::sobol)
        : m_pixel(pixel_hash(x, y, seed)), m_sample(sample),
          m_sample_reversed(sobol::reverse_bits(sample)), m_sequence(sequence)
    {
    }

    /// The same values, with the pixel's hashes from `seeds` (made with the same x, y and
    /// seed), which must outlive the sampler.
    Sampler(const PixelSeeds& seeds, std::uint32_t sample,
            SampleSequence sequence = SampleSequence::sobol)
        : m_pixel(seeds.pixel()), m_seeds(&seeds), m_sample(sample),
          m_sample_reversed(sobol::reverse_bits(sample)), m_sequence(sequence)
    {
    }

    /// The value of `dimension`, uniform in [0, 1).
    float get1d(std::uint32_t dimension) const
    {
        if (m_sequence == SampleSequence::white)
            return white(dimension, 0);
        const sobol::PairSeeds seeds(pair_hash(dimension >> 1));
        const std::uint32_t index = sobol::shuffled_index(m_sample_reversed, seeds);
        std::uint32_t r = (dimension & 1u)
                              ? sobol::scramble_reversed(sobol::sobol_second_reversed(index),
                                                         seeds.y)
                              : sobol::scramble_reversed(index, seeds.x);
        return sobol::to_unit(sobol::reverse_bits(r));
    }

    /// The values of the pair (dimension, dimension + 1); `dimension` is even.
    std::array<float, 2> get2d(std::uint32_t dimension) const
    {
        if (m_sequence == SampleSequence::white)
            return {white(dimension, 0), white(dimension + 1, 0)};
        const sobol::PairSeeds seeds(pair_hash(dimension >> 1));
        return sobol::pair_values(sobol::shuffled_index(m_sample_reversed, seeds), seeds);
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

    /// The hash of (pixel, pair), which seeds the pair's three scrambles (PairSeeds).
    std::uint64_t pair_hash(std::uint32_t pair) const
    {
        return m_seeds ? m_seeds->pair(pair) : render::pair_hash(m_pixel, pair);
    }

    std::uint64_t m_pixel;
    const PixelSeeds* m_seeds = nullptr;
    std::uint32_t m_sample;
    std::uint32_t m_sample_reversed;
    SampleSequence m_sequence;
    std::uint32_t m_dimension = 0;
};

}  // namespace cambium::render
