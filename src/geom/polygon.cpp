// SPDX-License-Identifier: Apache-2.0
// Triangulation of turtle polygons (`{ . }`): concave outlines by ear clipping.
//
// Plain ear clipping tests every vertex against every candidate ear and is cubic in the
// worst case: a 300 000-vertex outline ran for minutes. Here, as in Mapbox's earcut, the
// outline is a linked ring (an ear is cut in O(1)), only the vertices that can spoil an
// ear are tested (reflex and collinear ones, and those repeating another's position),
// found through a k-d tree of them, and after each ear the walk moves two vertices on
// so that the ears stay small instead of fanning out from one vertex. A work budget
// bounds the rare outline that would still be quadratic.
#include "geom/polygon.h"

#include <algorithm>
#include <cmath>

namespace cambium::geom {
namespace {

struct Point2 {
    double x, y;
};

double cross2(const Point2& a, const Point2& b, const Point2& c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// p inside or on the triangle abc (counter-clockwise), with tolerance eps.
bool inside_triangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c, double eps)
{
    return cross2(a, b, p) >= -eps && cross2(b, c, p) >= -eps && cross2(c, a, p) >= -eps;
}

bool same_point(const Point2& a, const Point2& b) { return a.x == b.x && a.y == b.y; }

/// The outline as a ring that ears are cut from. Vertices are numbered 0..n-1 in outline
/// order (consecutive repeats already dropped); `index` maps them back to the outline.
class EarClipper {
public:
    EarClipper(std::vector<Point2> points, std::vector<std::uint32_t> index, double eps,
               std::size_t max_tests)
        : m_p(std::move(points)), m_index(std::move(index)), m_eps(eps), m_prev(m_p.size()),
          m_next(m_p.size()), m_removed(m_p.size(), 0), m_repeated(m_p.size(), 0),
          m_remaining(m_p.size())
    {
        const std::size_t n = m_p.size();
        for (std::size_t i = 0; i < n; ++i) {
            m_prev[i] = static_cast<std::uint32_t>((i + n - 1) % n);
            m_next[i] = static_cast<std::uint32_t>((i + 1) % n);
        }
        mark_repeated_positions();
        index_spoilers();
        // Work beyond near-linear is allowed up to this many tests (seconds at most).
        m_budget = std::min<std::size_t>(1000 * n + 50'000'000, max_tests);
    }

    /// Cuts ears until fewer than three vertices remain.
    void run(std::vector<std::array<std::uint32_t, 3>>& triangles)
    {
        std::uint32_t k = 0;
        std::size_t misses = 0;
        while (m_remaining >= 3) {
            // every step of the walk counts: rounds of quick misses are the quadratic part
            ++m_tests;
            std::uint32_t a = m_prev[k], c = m_next[k];
            double turn = cross2(m_p[a], m_p[k], m_p[c]);
            bool collinear = std::abs(turn) <= m_eps;
            // Past a full round without an ear the outline crosses itself, and past the
            // budget the rest is cut in order: either way clip anyway (never a hang).
            bool forced = misses > m_remaining || m_tests > m_budget;
            if (collinear || forced || is_ear(k)) {
                if (!collinear && (turn > 0 || forced))
                    triangles.push_back({m_index[a], m_index[k], m_index[c]});
                remove(k);
                misses = 0;
                k = m_remaining >= 3 ? m_next[c] : c;
                continue;
            }
            k = c;
            ++misses;
        }
    }

    bool over_budget() const { return m_tests > m_budget; }

private:
    void mark_repeated_positions()
    {
        std::vector<std::uint32_t> order(m_p.size());
        for (std::uint32_t i = 0; i < order.size(); ++i)
            order[i] = i;
        std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
            return m_p[i].x != m_p[j].x ? m_p[i].x < m_p[j].x : m_p[i].y < m_p[j].y;
        });
        for (std::size_t i = 1; i < order.size(); ++i)
            if (same_point(m_p[order[i]], m_p[order[i - 1]]))
                m_repeated[order[i]] = m_repeated[order[i - 1]] = 1;
    }

    /// Only a vertex that is not convex, or that repeats another's position (an outline
    /// touching itself), can lie in a triangle cut from a simple outline; cutting ears
    /// never makes a convex vertex reflex, so these "spoilers" are indexed once and only
    /// leave. The index is a k-d tree of them whose nodes count the spoilers left, so a
    /// search skips emptied regions and boxes that the ear misses.
    void index_spoilers()
    {
        for (std::uint32_t i = 0; i < m_p.size(); ++i)
            if (may_spoil(i))
                m_items.push_back(i);
        if (!m_items.empty())
            build(0, static_cast<std::uint32_t>(m_items.size()), Node::none, 0);
    }

    struct Node {
        static constexpr std::uint32_t none = 0xffffffffu;
        std::uint32_t begin, end;  ///< its items: m_items[begin .. begin + alive) are left
        std::uint32_t alive;
        std::uint32_t parent, left = none, right = none;
        Point2 lo, hi;
    };

    std::uint32_t build(std::uint32_t begin, std::uint32_t end, std::uint32_t parent, int depth)
    {
        auto index = static_cast<std::uint32_t>(m_nodes.size());
        Node node{begin, end, end - begin, parent, Node::none, Node::none, {1e300, 1e300}, {-1e300, -1e300}};
        for (std::uint32_t i = begin; i < end; ++i) {
            const Point2& q = m_p[m_items[i]];
            node.lo = {std::min(node.lo.x, q.x), std::min(node.lo.y, q.y)};
            node.hi = {std::max(node.hi.x, q.x), std::max(node.hi.y, q.y)};
        }
        m_nodes.push_back(node);
        if (end - begin <= 8)
            return index;
        // Split the wider side at the median.
        bool by_x = node.hi.x - node.lo.x >= node.hi.y - node.lo.y || depth > 64;
        std::uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(m_items.begin() + begin, m_items.begin() + mid, m_items.begin() + end,
                         [&](std::uint32_t i, std::uint32_t j) {
                             return by_x ? m_p[i].x < m_p[j].x : m_p[i].y < m_p[j].y;
                         });
        std::uint32_t left = build(begin, mid, index, depth + 1);
        std::uint32_t right = build(mid, end, index, depth + 1);
        m_nodes[index].left = left;
        m_nodes[index].right = right;
        return index;
    }

    bool may_spoil(std::uint32_t i) const
    {
        return m_repeated[i] || cross2(m_p[m_prev[i]], m_p[i], m_p[m_next[i]]) <= m_eps;
    }

    void remove(std::uint32_t k)
    {
        m_next[m_prev[k]] = m_next[k];
        m_prev[m_next[k]] = m_prev[k];
        m_removed[k] = 1;
        --m_remaining;
    }

    /// Whether (prev, k, next) is an ear: convex, and no other vertex in it.
    bool is_ear(std::uint32_t k)
    {
        const std::uint32_t a = m_prev[k], c = m_next[k];
        const Point2 &pa = m_p[a], &pk = m_p[k], &pc = m_p[c];
        if (cross2(pa, pk, pc) <= m_eps)
            return false;
        Ear ear{{&pa, &pk, &pc}, {a, k, c}, {}, {}};
        ear.lo = {std::min({pa.x, pk.x, pc.x}), std::min({pa.y, pk.y, pc.y})};
        ear.hi = {std::max({pa.x, pk.x, pc.x}), std::max({pa.y, pk.y, pc.y})};
        return m_nodes.empty() || !node_spoils(ear, 0);
    }

    struct Ear {
        const Point2* corner[3];
        std::uint32_t vertex[3];
        Point2 lo, hi;  ///< the box around it
    };

    bool node_spoils(const Ear& ear, std::uint32_t n)
    {
        ++m_tests;
        const Node& node = m_nodes[n];
        if (node.alive == 0 || node.hi.x < ear.lo.x || node.lo.x > ear.hi.x ||
            node.hi.y < ear.lo.y || node.lo.y > ear.hi.y || outside_an_edge(ear, node))
            return false;
        if (node.left == Node::none)
            return leaf_spoils(ear, n);
        return node_spoils(ear, node.left) || node_spoils(ear, node.right);
    }

    /// Whether the node's box lies wholly beyond one of the ear's edges.
    bool outside_an_edge(const Ear& ear, const Node& node) const
    {
        const Point2 box[4] = {node.lo, {node.hi.x, node.lo.y}, node.hi, {node.lo.x, node.hi.y}};
        for (int e = 0; e < 3; ++e) {
            const Point2 &p = *ear.corner[e], &q = *ear.corner[(e + 1) % 3];
            bool all_out = true;
            for (const Point2& b : box)
                all_out = all_out && cross2(p, q, b) < -m_eps;
            if (all_out)
                return true;
        }
        return false;
    }

    /// Whether a spoiler of the leaf lies in the ear; those gone leave the index.
    bool leaf_spoils(const Ear& ear, std::uint32_t n)
    {
        Node& leaf = m_nodes[n];
        for (std::uint32_t i = leaf.begin; i < leaf.begin + leaf.alive;) {
            ++m_tests;
            std::uint32_t j = m_items[i];
            if (m_removed[j] || !may_spoil(j)) {
                std::swap(m_items[i], m_items[leaf.begin + leaf.alive - 1]);
                for (std::uint32_t up = n; up != Node::none; up = m_nodes[up].parent)
                    --m_nodes[up].alive;
                continue;
            }
            ++i;
            if (spoils(ear, j))
                return true;
        }
        return false;
    }

    /// Whether vertex j (a spoiler) lies in the ear, or touches it from inside.
    bool spoils(const Ear& ear, std::uint32_t j) const
    {
        const Point2& q = m_p[j];
        if (j == ear.vertex[0] || j == ear.vertex[1] || j == ear.vertex[2] || q.x < ear.lo.x ||
            q.x > ear.hi.x || q.y < ear.lo.y || q.y > ear.hi.y)
            return false;
        int shared = -1;
        for (int s = 0; s < 3; ++s)
            if (same_point(q, *ear.corner[s]))
                shared = s;
        if (shared < 0)
            return inside_triangle(q, *ear.corner[0], *ear.corner[1], *ear.corner[2], m_eps);
        // q repeats a corner of the ear (an outline touching itself): the ear is no ear
        // when an edge leaving q runs into the triangle's corner.
        const Point2& x = *ear.corner[shared];
        const Point2& next = *ear.corner[(shared + 1) % 3];
        const Point2& prev = *ear.corner[(shared + 2) % 3];
        for (std::uint32_t n : {m_prev[j], m_next[j]})
            if (cross2(x, next, m_p[n]) > m_eps && cross2(x, m_p[n], prev) > m_eps)
                return true;
        return false;
    }

    std::vector<Point2> m_p;
    std::vector<std::uint32_t> m_index;
    double m_eps;
    std::vector<std::uint32_t> m_prev, m_next;
    std::vector<char> m_removed, m_repeated;
    std::size_t m_remaining;
    std::vector<std::uint32_t> m_items;  ///< the spoilers, in k-d tree order
    std::vector<Node> m_nodes;           ///< the k-d tree, root first
    std::size_t m_tests = 0, m_budget = 0;
};

}  // namespace

Vec3 polygon_normal(std::span<const Vec3> outline)
{
    Vec3 n{0, 0, 0};
    for (std::size_t i = 0; i < outline.size(); ++i) {
        const Vec3& a = outline[i];
        const Vec3& b = outline[(i + 1) % outline.size()];
        n += Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
    }
    double len = length(n);
    return len > 0 ? n / len : Vec3{0, 0, 0};
}

std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const Vec3> outline,
                                                              bool* cut_short,
                                                              std::size_t max_tests)
{
    std::vector<std::array<std::uint32_t, 3>> triangles;
    if (cut_short)
        *cut_short = false;
    Vec3 n = polygon_normal(outline);
    if (outline.size() < 3 || !(dot(n, n) > 0))
        return triangles;

    // A basis (u, v) of the plane with u x v = n, so the outline is counter-clockwise.
    Vec3 helper = std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    Vec3 u = normalize(cross(helper, n));
    Vec3 v = cross(n, u);
    std::vector<Point2> p(outline.size());
    double extent = 0;
    for (std::size_t i = 0; i < outline.size(); ++i) {
        p[i] = {dot(outline[i], u), dot(outline[i], v)};
        extent = std::max({extent, std::abs(p[i].x - p[0].x), std::abs(p[i].y - p[0].y)});
    }
    if (!std::isfinite(extent))
        return triangles;
    const double eps = 1e-12 * extent * extent;  // area tolerance, relative to the size

    std::vector<Point2> ring;  // remaining vertices, repeats dropped
    std::vector<std::uint32_t> index;
    for (std::uint32_t i = 0; i < outline.size(); ++i)
        if (ring.empty() || !same_point(ring.back(), p[i])) {
            ring.push_back(p[i]);
            index.push_back(i);
        }
    while (ring.size() > 1 && same_point(ring.front(), ring.back())) {
        ring.pop_back();
        index.pop_back();
    }
    if (ring.size() < 3)
        return triangles;
    triangles.reserve(ring.size() - 2);
    EarClipper clipper(std::move(ring), std::move(index), eps, max_tests);
    clipper.run(triangles);
    if (cut_short)
        *cut_short = clipper.over_budget();
    return triangles;
}

}  // namespace cambium::geom
