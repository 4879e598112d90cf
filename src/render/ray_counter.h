// SPDX-License-Identifier: Apache-2.0
// Counting rays traced by many threads at the cost of one unlocked add per ray.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>

namespace cambium::render {

/// Rays traced, summed over threads. Each of the first threads to count owns a cache
/// line (its slot is fixed the first time it counts) and adds to it without a locked
/// instruction (a relaxed load and store: no other thread writes there), so concurrent
/// rays neither contend nor pay for an atomic read-modify-write. Threads beyond the
/// owned slots share one line with atomic adds and stay exact, only slower.
class RayCounter {
public:
    void add(std::uint64_t n = 1) const noexcept
    {
        std::size_t slot = thread_slot();
        std::atomic<std::uint64_t>& count = m_slots[slot].count;
        if (slot < owned_slots)
            count.store(count.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
        else
            count.fetch_add(n, std::memory_order_relaxed);
    }

    std::uint64_t total() const noexcept
    {
        std::uint64_t sum = 0;
        for (const Slot& s : m_slots)
            sum += s.count.load(std::memory_order_relaxed);
        return sum;
    }

private:
    static constexpr std::size_t owned_slots = 64;

    struct alignas(64) Slot {
        std::atomic<std::uint64_t> count{0};
    };

    /// The calling thread's slot: its own for the first owned_slots threads of the
    /// process, the shared last one for all later threads.
    static std::size_t thread_slot() noexcept
    {
        static std::atomic<std::size_t> next{0};
        thread_local const std::size_t slot = std::min(next.fetch_add(1), owned_slots);
        return slot;
    }

    mutable std::array<Slot, owned_slots + 1> m_slots{};
};

}  // namespace cambium::render
