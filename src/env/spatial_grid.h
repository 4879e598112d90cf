// SPDX-License-Identifier: Apache-2.0
// A uniform grid over points, for the built-ins' "which others lie within r" questions:
// each point is compared with the points of its own and the neighbouring cells only.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace cambium::env {

class SpatialGrid {
public:
    /// Points as (x, y, z); `cell` the cell side (a neighbour search reaches one cell
    /// around); `dimensions` 2 (x and y only, z ignored) or 3.
    SpatialGrid(const std::vector<std::array<float, 3>>& points, double cell, int dimensions)
        : m_cell(cell > 0 && std::isfinite(cell) ? cell : 1.0), m_dimensions(dimensions)
    {
        m_cells.reserve(points.size());
        for (std::size_t i = 0; i < points.size(); ++i)
            m_cells[key(coordinates(points[i]))].push_back(static_cast<std::uint32_t>(i));
    }

    /// Calls visit(j) for every point in the cells around `p` (itself included).
    template <class Visit>
    void for_each_near(const std::array<float, 3>& p, Visit&& visit) const
    {
        const std::array<std::int64_t, 3> c = coordinates(p);
        const int dz = m_dimensions == 3 ? 1 : 0;
        for (int x = -1; x <= 1; ++x)
            for (int y = -1; y <= 1; ++y)
                for (int z = -dz; z <= dz; ++z) {
                    auto it = m_cells.find(key({c[0] + x, c[1] + y, c[2] + z}));
                    if (it != m_cells.end())
                        for (std::uint32_t j : it->second)
                            visit(j);
                }
    }

private:
    /// Cell coordinates, clamped so that far points share border cells instead of
    /// overflowing (a shared cell costs comparisons, never a wrong answer).
    std::array<std::int64_t, 3> coordinates(const std::array<float, 3>& p) const
    {
        std::array<std::int64_t, 3> c{};
        for (int a = 0; a < 3; ++a) {
            if (a == 2 && m_dimensions == 2)
                continue;
            double v = std::floor(static_cast<double>(p[static_cast<std::size_t>(a)]) / m_cell);
            if (!(v == v))
                v = 0;
            c[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(std::clamp(v, -limit, limit));
        }
        return c;
    }

    static std::uint64_t key(const std::array<std::int64_t, 3>& c)
    {
        // 21 bits an axis after clamping: distinct cells of the clamped range never collide
        auto bits = [](std::int64_t v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffff; };
        return bits(c[0]) | bits(c[1]) << 21 | bits(c[2]) << 42;
    }

    static constexpr double limit = (1 << 20) - 2;
    double m_cell;
    int m_dimensions;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> m_cells;
};

}  // namespace cambium::env
