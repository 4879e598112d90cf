// SPDX-License-Identifier: Apache-2.0
// vlab's ecosystem: honda81 with circles (spheres in 3-D) whose radius is the ?E's first
// parameter. A circle is dominated (?E(0)) by an intersecting circle of its group that
// is at least as large; otherwise it is free (?E(1)). With `vigor: on` the second
// parameter is a vigor that ranks before size, groups are not used, and a circle
// dominated earlier in string order no longer dominates. Single precision, as the program.
#include <algorithm>
#include <cmath>

#include "env/builtins.h"
#include "env/spatial_grid.h"
#include "env/spec_values.h"

namespace cambium::env {
namespace {

struct Circle {
    std::array<float, 3> position;
    float radius;
    float vigor;
    double group;  ///< group_of the second parameter
    std::uint64_t address;
};

class Ecosystem final : public Environment {
public:
    Ecosystem(bool three_d, bool vigor) : m_three_d(three_d), m_vigor(vigor) {}

    std::vector<Reply> pass(const std::vector<Query>& queries, int) override
    {
        std::vector<Circle> circles;
        std::vector<std::array<float, 3>> cells;
        float largest = 0;
        for (const Query& q : queries) {
            const std::vector<float>& p = q.module.params;
            if (q.position.count < 3 || p.size() < (m_vigor ? 2u : 1u))
                continue;
            const auto& t = q.position.values;
            Circle c{{t[0], m_three_d ? t[1] : t[2], m_three_d ? t[2] : 0.0f},
                     p[0],
                     m_vigor ? p[1] : 1.0f,
                     !m_vigor && p.size() > 1 ? group_of(p[1]) : 0.0,
                     q.address};
            largest = std::max(largest, std::fabs(c.radius));
            circles.push_back(c);
            cells.push_back(c.position);
        }
        const SpatialGrid grid(cells, 2.0 * largest, m_three_d ? 3 : 2);
        std::vector<char> removed(circles.size(), 0);
        std::vector<Reply> replies;
        replies.reserve(circles.size());
        for (std::size_t i = 0; i < circles.size(); ++i) {
            const Circle& a = circles[i];
            bool dominated = false;
            grid.for_each_near(a.position, [&](std::uint32_t j) {
                const Circle& b = circles[j];
                if (j == i || b.group != a.group || (m_vigor && removed[j]))
                    return;
                const bool ranks = m_vigor ? a.vigor < b.vigor ||
                                                 (a.vigor == b.vigor && a.radius < b.radius)
                                           : a.radius <= b.radius;
                if (ranks && intersect(a, b))
                    dominated = true;
            });
            removed[i] = m_vigor && dominated;
            replies.push_back(Reply{a.address, {dominated ? 0.0f : 1.0f}});
        }
        return replies;
    }

private:
    bool intersect(const Circle& a, const Circle& b) const
    {
        float d2 = 0;
        for (int k = 0; k < (m_three_d ? 3 : 2); ++k) {
            const float e = a.position[static_cast<std::size_t>(k)] - b.position[static_cast<std::size_t>(k)];
            d2 += e * e;
        }
        const float reach = a.radius + b.radius;
        return d2 <= reach * reach;
    }

    bool m_three_d;
    bool m_vigor;
};

}  // namespace

std::unique_ptr<Environment> make_ecosystem(const std::vector<std::string>& args, const Context& context)
{
    bool three_d = false, vigor = false;
    for (const SpecLine& line : read_spec_file(spec_argument("ecosystem", args), context)) {
        if (line.keyword == "3d case")
            three_d = switch_value(line, {"on", "yes"});
        else if (line.keyword == "vigor")
            vigor = switch_value(line, {"on"});
        else if (line.keyword != "verbose" && line.keyword != "grid size")
            warn_unknown_keyword("ecosystem", line);
    }
    return std::make_unique<Ecosystem>(three_d, vigor);
}

}  // namespace cambium::env
