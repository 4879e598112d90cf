// SPDX-License-Identifier: Apache-2.0
// The string's storage (detail::PodArray): growth from malloc'd to mapped blocks and
// through mremap keeps every value, sizes past what a block can hold are refused before
// any size computation overflows, and copies and moves own their blocks.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <new>

#include "lsys/module_string.h"

namespace cambium::lsys {
namespace {

using detail::PodArray;

/// Value i of a test array of T: distinct bytes, so that a lost or moved page shows.
template <class T>
T value_at(std::size_t i)
{
    T v{};
    auto* bytes = reinterpret_cast<unsigned char*>(&v);
    for (std::size_t b = 0; b < sizeof(T); ++b)
        bytes[b] = static_cast<unsigned char>((i * 131 + b * 7 + i / 251) & 0xff);
    return v;
}

template <class T>
bool same(const T& a, const T& b)
{
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

/// Appends values one by one up to `n` (through every growth: malloc, realloc, the move
/// to a mapped block, mremap) and checks them all.
template <class T>
void grow_and_check(std::size_t n)
{
    PodArray<T> a;
    for (std::size_t i = 0; i < n; ++i)
        a.push_back(value_at<T>(i));
    ASSERT_EQ(a.size(), n);
    EXPECT_GE(a.capacity(), n);
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < n; ++i)
        wrong += same(a[i], value_at<T>(i)) ? 0 : 1;
    EXPECT_EQ(wrong, 0u) << sizeof(T) << "-byte values";
}

TEST(PodArray, GrowingThroughMappedBlocksKeepsEveryValue)
{
    // 6 MB of each: past the size from which blocks are mapped and remapped
    grow_and_check<std::uint8_t>(6u << 20);
    grow_and_check<float>(6u << 18);
    grow_and_check<std::array<char, 3>>(2u << 20);    // sizes that do not divide a page
    grow_and_check<std::array<float, 3>>(1u << 19);
    grow_and_check<std::array<char, 5000>>(1200);     // values larger than a page
}

TEST(PodArray, AppendFromItselfSurvivesGrowth)
{
    PodArray<std::uint32_t> a;
    for (std::uint32_t i = 0; i < 1000; ++i)
        a.push_back(i);
    for (int round = 0; round < 10; ++round)  // 1000 << 10 values: mapped, remapped
        a.append(a.begin(), a.end());
    ASSERT_EQ(a.size(), std::size_t{1000} << 10);
    for (std::size_t i = 0; i < a.size(); i += 997)
        EXPECT_EQ(a[i], i % 1000) << i;
}

TEST(PodArray, CopiesAndMovesOwnTheirBlocks)
{
    PodArray<float> big;
    for (int i = 0; i < (1 << 20); ++i)
        big.push_back(static_cast<float>(i));
    PodArray<float> copy(big);
    big[5] = -1;
    EXPECT_EQ(copy[5], 5.0f);
    PodArray<float> moved(std::move(copy));
    EXPECT_EQ(copy.size(), 0u);
    EXPECT_EQ(copy.data(), nullptr);
    EXPECT_EQ(moved[(1 << 20) - 1], static_cast<float>((1 << 20) - 1));
    PodArray<float> small;
    small.push_back(1);
    small = moved;  // a small block grows to a mapped one
    EXPECT_EQ(small.size(), moved.size());
    moved = std::move(small);
    EXPECT_EQ(moved[12345], 12345.0f);
    moved.clear();
    EXPECT_GE(moved.capacity(), std::size_t{1} << 20);  // clear() keeps the block
}

TEST(PodArray, SizesPastABlockAreRefusedBeforeTheyOverflow)
{
    // (2^62 + 1) floats are 2^64 + 4 bytes: computed in a size_t, 4 bytes
    PodArray<float> a;
    a.push_back(7);
    EXPECT_THROW(a.reserve(std::numeric_limits<std::size_t>::max() / 4 + 2), std::bad_alloc);
    EXPECT_THROW(a.reserve(PodArray<float>::max_size() + 1), std::bad_alloc);
    // size + extra wraps around to 0 in a size_t
    EXPECT_THROW(a.make_room(std::numeric_limits<std::size_t>::max()), std::bad_alloc);
    EXPECT_THROW(a.make_room(PodArray<float>::max_size()), std::bad_alloc);
    ASSERT_EQ(a.size(), 1u);  // as it was
    EXPECT_EQ(a[0], 7.0f);
    EXPECT_THROW(detail::PodArray<std::uint8_t>().reserve(detail::max_block_bytes + 1),
                 std::bad_alloc);
}

TEST(ModuleString, LargeStringsKeepSymbolsCountsAndParameters)
{
    // 300 000 modules: every array past the mapped size, appended module by module
    // and by ranges, the symbols widened to 16 bits halfway
    ModuleString s;
    std::size_t params = 0;
    for (std::uint32_t i = 0; i < 300000; ++i) {
        auto symbol = static_cast<SymbolId>(i < 150000 ? i % 200 : i % 600);
        std::size_t count = i % 4;
        float* to = s.append_module(symbol, count);
        for (std::size_t k = 0; k < count; ++k)
            to[k] = static_cast<float>(i) + 0.25f * static_cast<float>(k);
        params += count;
    }
    ModuleString t;
    t.append_range(s, 0, 1000, 0);
    t.append(s);
    ASSERT_EQ(s.size(), 300000u);
    ASSERT_EQ(s.param_total(), params);
    ASSERT_EQ(t.size(), 301000u);
    std::size_t offset = 0, wrong = 0;
    for (std::uint32_t i = 0; i < 300000; ++i) {
        auto symbol = static_cast<SymbolId>(i < 150000 ? i % 200 : i % 600);
        wrong += s.symbol(i) != symbol || t.symbol(i + 1000) != symbol ||
                 s.param_count(i) != i % 4;
        for (std::size_t k = 0; k < i % 4; ++k)
            wrong += s.param_data()[offset + k] !=
                     static_cast<float>(i) + 0.25f * static_cast<float>(k);
        offset += i % 4;
    }
    EXPECT_EQ(wrong, 0u);
}

}  // namespace
}  // namespace cambium::lsys
