// SPDX-License-Identifier: Apache-2.0
// The POSIX 48-bit linear congruential generator (drand48/erand48), as cpfg uses it.
#pragma once

#include <cstdint>

namespace cambium::lsys {

/// A 48-bit LCG state with the drand48 family's constants; one instance per stream.
class Rand48 {
public:
    static Rand48 from_state(std::uint64_t s)
    {
        Rand48 r;
        r.set_state(s);
        return r;
    }
    /// srand48(seed): high 32 bits from the seed, low 16 bits 0x330E.
    void seed(long seed)
    {
        m_state = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(seed)) << 16) | 0x330Eu;
    }
    /// The next value in [0, 1), as drand48/erand48.
    double next_double()
    {
        step();
        return static_cast<double>(m_state) / static_cast<double>(std::uint64_t{1} << 48);
    }
    std::uint64_t state() const { return m_state; }
    void set_state(std::uint64_t s) { m_state = s & mask; }

private:
    static constexpr std::uint64_t mask = (std::uint64_t{1} << 48) - 1;
    void step() { m_state = (m_state * 0x5DEECE66Dull + 0xBull) & mask; }
    std::uint64_t m_state = 0x1234ABCD330Eull;
};

/// The seed a stream uses when a scene overrides the model's seeds (docs/scenes.md):
/// the model's own seed and the override, mixed (SplitMix64's finaliser), so that
/// each override gives another plant while the model's separate streams stay apart.
inline long mixed_seed(long model_seed, long override_seed)
{
    std::uint64_t z = static_cast<std::uint64_t>(model_seed) * 0x9E3779B97F4A7C15ull +
                      static_cast<std::uint64_t>(override_seed);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<long>(z ^ (z >> 31));
}

}  // namespace cambium::lsys
