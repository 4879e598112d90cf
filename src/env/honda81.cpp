// SPDX-License-Identifier: Apache-2.0
// vlab's honda81: a query is blocked (?E(0)) when another query of its group with at
// least its vigor lies within the radius, free (?E(1)) otherwise. The program computes
// in single precision; so does this, for the same answers at the boundary.
#include <cmath>

#include "env/builtins.h"
#include "env/spatial_grid.h"
#include "env/spec_values.h"

namespace cambium::env {
namespace {

/// A query as honda81 stores it: in 2-D its second coordinate is the turtle's z.
struct Point {
    std::array<float, 3> position;
    float vigor;
    double group;  ///< group_of the second parameter
    std::uint64_t address;
};

class Honda81 final : public Environment {
public:
    Honda81(float radius, bool three_d) : m_radius(radius), m_three_d(three_d) {}

    std::vector<Reply> pass(const std::vector<Query>& queries, int) override
    {
        std::vector<Point> points;
        std::vector<std::array<float, 3>> cells;
        for (const Query& q : queries) {
            // the program skips a query without a whole position or without parameters
            if (q.position.count < 3 || q.module.params.empty())
                continue;
            const auto& p = q.position.values;
            Point point{{p[0], m_three_d ? p[1] : p[2], m_three_d ? p[2] : 0.0f},
                        q.module.params[0],
                        q.module.params.size() > 1 ? group_of(q.module.params[1]) : 0.0,
                        q.address};
            points.push_back(point);
            cells.push_back(point.position);
        }
        const float r2 = m_radius * m_radius;
        const SpatialGrid grid(cells, std::fabs(m_radius), m_three_d ? 3 : 2);
        std::vector<Reply> replies;
        replies.reserve(points.size());
        for (std::size_t i = 0; i < points.size(); ++i) {
            const Point& a = points[i];
            bool blocked = false;
            grid.for_each_near(a.position, [&](std::uint32_t j) {
                const Point& b = points[j];
                if (blocked || j == i || b.group != a.group || !(a.vigor <= b.vigor))
                    return;
                float d2 = 0;
                for (int k = 0; k < (m_three_d ? 3 : 2); ++k) {
                    const float e = a.position[static_cast<std::size_t>(k)] -
                                    b.position[static_cast<std::size_t>(k)];
                    d2 += e * e;
                }
                blocked = d2 <= r2;
            });
            replies.push_back(Reply{a.address, {blocked ? 0.0f : 1.0f}});
        }
        return replies;
    }

private:
    float m_radius;
    bool m_three_d;
};

}  // namespace

std::unique_ptr<Environment> make_honda81(const std::vector<std::string>& args, const Context& context)
{
    float radius = 0;
    bool three_d = false;
    for (const SpecLine& line : read_spec_file(spec_argument("honda81", args), context)) {
        if (line.keyword == "radius")
            radius = static_cast<float>(number_value(line));
        else if (line.keyword == "3d case")
            three_d = switch_value(line, {"on"});
        else if (line.keyword != "verbose")
            warn_unknown_keyword("honda81", line);
    }
    return std::make_unique<Honda81>(radius, three_d);
}

}  // namespace cambium::env
