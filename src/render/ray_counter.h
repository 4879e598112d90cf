// SPDX-License-Identifier: Apache-2.0
// Counting rays traced by many threads at the cost of one uncontended add per ray.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace cambium::render {

/// Rays traced, summed over threads. Each thread adds to its own cache line (its slot is
/// fixed the first time it counts), so concurrent rays never contend; more threads than
/// slots share lines and stay exact, only slower.
class RayCounter {
public:
    void add(std::uint64_t n = 1) const noexcept
    {
        m_slots[thread_slot()].count.fetch_add(n, std::memory_order_relaxed);
    }

    std::uint64_t total() const noexcept
    {
        std::uint64_t sum = 0;
        for (const Slot& s : m_slots)
            sum += s.count.load(std::memory_order_relaxed);
        return sum;
    }

private:
    static constexpr std::size_t slot_count = 64;

    struct alignas(64) Slot {
        std::atomic<std::uint64_t> count{0};
    };

    static std::size_t thread_slot() noexcept
    {
        static std::atomic<std::size_t> next{0};
        thread_local const std::size_t slot = next.fetch_add(1) % slot_count;
        return slot;
    }

    mutable std::array<Slot, slot_count> m_slots{};
};

}  // namespace cambium::render
