// SPDX-License-Identifier: Apache-2.0
// Random numbers as a pure function of (pixel, sample index, dimension, seed).
#pragma once

#include <cstdint>

namespace cambium::render {

/// A 64-bit finaliser with good avalanche (splitmix64 / Stafford variant 13).
constexpr std::uint64_t mix64(std::uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/// The sample stream of one (pixel, sample index): next() returns the value for the next
/// dimension. Nothing depends on which thread or tile asks, so images are bit-identical
/// for any thread count (unlike a per-tile or per-thread generator).
class Sampler {
public:
    Sampler(std::uint32_t x, std::uint32_t y, std::uint32_t sample, std::uint64_t seed)
        : m_key(mix64(mix64(seed ^ 0x9e3779b97f4a7c15ULL) ^
                      ((std::uint64_t{y} << 32) | x)) ^
                (std::uint64_t{sample} * 0xd1b54a32d192ed03ULL))
    {
    }

    /// Uniform in [0, 1).
    float next()
    {
        std::uint64_t h = mix64(m_key + (std::uint64_t{m_dimension++} * 0x9e3779b97f4a7c15ULL));
        return static_cast<float>(h >> 40) * 0x1.0p-24f;
    }

    std::uint32_t dimension() const { return m_dimension; }

private:
    std::uint64_t m_key;
    std::uint32_t m_dimension = 0;
};

}  // namespace cambium::render
