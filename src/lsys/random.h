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

}  // namespace cambium::lsys
