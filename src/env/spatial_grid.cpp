// SPDX-License-Identifier: Apache-2.0
#include "env/spatial_grid.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace cambium::env {
namespace {

constexpr double max_cell = (1 << 28);

std::uint64_t mix(std::uint64_t k)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return k;
}

}  // namespace

SpatialGrid::SpatialGrid(const std::vector<std::array<float, 3>>& points, double cell, int dimensions)
    : m_cell(cell > 0 && std::isfinite(cell) ? cell : 1.0), m_dimensions(dimensions)
{
    struct Entry {
        std::uint64_t column;
        std::int32_t z;
        std::uint32_t index;
    };
    std::vector<Entry> entries(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        const std::array<std::int32_t, 3> c = cell_of(points[i]);
        entries[i] = {column(c[0], c[1]), c[2], static_cast<std::uint32_t>(i)};
    }
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
        return a.column != b.column ? a.column < b.column : a.z < b.z;
    });
    m_z.resize(entries.size());
    m_index.resize(entries.size());
    std::size_t columns = 0;
    for (std::size_t k = 0; k < entries.size(); ++k) {
        m_z[k] = entries[k].z;
        m_index[k] = entries[k].index;
        columns += k == 0 || entries[k].column != entries[k - 1].column;
    }
    m_table.resize(std::bit_ceil(std::max<std::size_t>(2 * columns, 16)));
    const std::size_t mask = m_table.size() - 1;
    for (std::size_t k = 0; k < entries.size();) {
        std::size_t end = k;
        while (end < entries.size() && entries[end].column == entries[k].column)
            ++end;
        std::size_t slot = mix(entries[k].column) & mask;
        while (m_table[slot].column != empty)
            slot = (slot + 1) & mask;
        m_table[slot] = {entries[k].column, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(end)};
        k = end;
    }
}

std::array<std::int32_t, 3> SpatialGrid::cell_of(const std::array<float, 3>& p) const
{
    std::array<std::int32_t, 3> c{};
    for (std::size_t a = 0; a < 3; ++a) {
        if (a == 2 && m_dimensions == 2)
            continue;
        double v = std::floor(static_cast<double>(p[a]) / m_cell);
        if (!(v == v))
            v = 0;
        c[a] = static_cast<std::int32_t>(std::clamp(v, -max_cell, max_cell));
    }
    return c;
}

const SpatialGrid::Run* SpatialGrid::find(std::uint64_t column) const
{
    const std::size_t mask = m_table.size() - 1;
    for (std::size_t slot = mix(column) & mask;; slot = (slot + 1) & mask) {
        const Run& r = m_table[slot];
        if (r.column == column)
            return &r;
        if (r.column == empty)
            return nullptr;
    }
}

}  // namespace cambium::env
