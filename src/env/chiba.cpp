// SPDX-License-Identifier: Apache-2.0
// vlab's chiba: light reaching leaf balls. Each ?E is a ball (first parameter: its radius)
// at the turtle's position; from each ball one ray goes towards every light source (or
// every sky sample), through a voxel grid around all balls, and each other ball it meets
// lets through only part of the light. The answer is the light received (the sources'
// intensities sum to 1) and, with four parameters, the direction it mostly comes from.
//
// Answers are compared digit for digit with the program's, so this computes as it does:
// single precision where it keeps floats, double where C promotes them (a float against
// a double constant, sqrt, pow, acos), in the same order. It also keeps the program's
// voxel walk, whose voxel centres leave out the grid's origin: a ray from a grid far from
// the origin visits other voxels than it passes through, and the models' strings depend
// on that.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "env/builtins.h"
#include "env/spec_values.h"

namespace cambium::env {
namespace {

using Vec3f = std::array<float, 3>;

/// A light direction (unit length, pointing towards the light) and its share.
struct Direction {
    Vec3f dir{};
    float intensity = 0;
};

struct Settings {
    std::array<int, 3> grid_size{1, 1, 1};
    float lower_to_upper = 0.7f;
    float transmittance = 0.6f;
    float radius = 25;       ///< of a ball whose ?E gives no positive radius
    float beam_radius = 0;   ///< the ray's own radius, as a share of the receiving ball's
    bool estimate_area = false;
    bool cie_sky = false;
    long samples = 20;
    std::vector<Direction> sources;
};

constexpr long max_samples = 8L << 14;       // the sphere's subdivision level 8
constexpr long max_voxels = 256L * 256 * 256;
constexpr long max_listed = 1L << 30;        // balls listed in voxels, over all voxels
constexpr std::size_t max_sources = 100;    // the program ignores the sources after these

/// The program's normalisation: the length from a float sum of squares, left as it is
/// when zero.
void normalize(Vec3f& v)
{
    const float length = static_cast<float>(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    if (length > 0)
        for (float& c : v)
            c /= length;
}

/// The unit sphere as an octahedron whose faces are cut `level - 1` times into four (the
/// midpoints of the edges pushed onto the sphere), in double precision, in the order the
/// program produces them: the sample order decides the order of the float sums.
std::vector<std::array<Vec3f, 3>> sphere_triangles(int level)
{
    using Point = std::array<double, 3>;
    using Triangle = std::array<Point, 3>;
    const Point xp{1, 0, 0}, xm{-1, 0, 0}, yp{0, 1, 0}, ym{0, -1, 0}, zp{0, 0, 1}, zm{0, 0, -1};
    // the octahedron's faces, first the four around +z, then the four around -z; each
    // face's vertices in the order the subdivision below expects
    std::vector<Triangle> faces = {{yp, zp, xp}, {xm, zp, yp}, {ym, zp, xm}, {xp, zp, ym},
                                   {zm, yp, xp}, {zm, xm, yp}, {zm, ym, xm}, {zm, xp, ym}};
    auto on_sphere = [](const Point& a, const Point& b) {
        Point m{(a[0] + b[0]) * 0.5, (a[1] + b[1]) * 0.5, (a[2] + b[2]) * 0.5};
        double length2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
        if (length2 != 0.0) {
            length2 = 1.0 / std::sqrt(length2);
            for (double& c : m)
                c *= length2;
        }
        return m;
    };
    for (int l = 1; l < level; ++l) {
        std::vector<Triangle> finer;
        finer.reserve(faces.size() * 4);
        for (const Triangle& t : faces) {
            const Point a = on_sphere(t[0], t[2]), b = on_sphere(t[0], t[1]), c = on_sphere(t[1], t[2]);
            finer.push_back({t[0], b, a});
            finer.push_back({b, t[1], c});
            finer.push_back({a, b, c});
            finer.push_back({a, c, t[2]});
        }
        faces = std::move(finer);
    }
    std::vector<std::array<Vec3f, 3>> out;
    out.reserve(faces.size());
    for (const Triangle& t : faces) {
        std::array<Vec3f, 3> f{};
        for (int v = 0; v < 3; ++v)
            for (int c = 0; c < 3; ++c)
                f[v][c] = static_cast<float>(t[v][c]);
        out.push_back(f);
    }
    return out;
}

/// The CIE overcast sky's luminance at `cos_zenith`.
double overcast_sky(double cos_zenith)
{
    return (1 + cos_zenith) / 3.0 * (8.6 * cos_zenith + 0.123) / 0.203;
}

/// The sky: the centres of a subdivided octahedron's faces, at least `requested` of them
/// (8·4^k), the upper (y > 0) and lower halves weighted as the settings say.
std::vector<Direction> sky_samples(const Settings& s)
{
    // the program's level: 8·4^(level-1) faces, level 0 (1 or 2 requested) keeping the
    // octahedron's first two faces
    const int level = static_cast<int>(std::ceil(std::log(static_cast<double>(s.samples) / 8.0) /
                                                 std::log(4.0)) + 1);
    const auto count = static_cast<std::size_t>(std::floor(0.5 + 8.0 * std::pow(4.0, level - 1)));
    const std::vector<std::array<Vec3f, 3>> faces = sphere_triangles(std::max(level, 1));
    std::vector<Direction> samples(std::min(count, faces.size()));
    for (std::size_t i = 0; i < samples.size(); ++i) {
        for (int c = 0; c < 3; ++c)
            samples[i].dir[c] = static_cast<float>((faces[i][0][c] + faces[i][1][c] + faces[i][2][c]) / 3.0);
        normalize(samples[i].dir);
    }
    if (s.cie_sky) {
        float total = 0;
        for (Direction& d : samples) {
            if (d.dir[1] <= 0) {
                d.intensity = 0;
                continue;
            }
            const double horizontal = std::sqrt(static_cast<double>(d.dir[0] * d.dir[0] + d.dir[1] * d.dir[1]));
            d.intensity = static_cast<float>(overcast_sky(d.dir[1] / horizontal));
            total += d.intensity;
        }
        for (Direction& d : samples)
            d.intensity /= total;
        return samples;
    }
    int up = 0;
    for (const Direction& d : samples)
        up += d.dir[1] >= 0 ? 1 : 0;
    const int down = static_cast<int>(samples.size()) - up;
    const float ltou = s.lower_to_upper;
    for (Direction& d : samples)
        d.intensity = d.dir[1] >= 0
                          ? static_cast<float>(1.0 / static_cast<float>(up) / (1.0 + ltou))
                          : static_cast<float>(ltou / static_cast<float>(down) / (1.0 + ltou));
    return samples;
}

/// A leaf ball as received.
struct Ball {
    Vec3f pos{};
    float radius = 0;
    float area = 0;  ///< of its disc, π·radius²
    std::size_t num_params = 0;
    std::uint64_t address = 0;
};

class Chiba final : public Environment {
public:
    Chiba(Settings settings, std::vector<Direction> directions)
        : m_s(std::move(settings)), m_directions(std::move(directions))
    {
    }

    std::vector<Reply> pass(const std::vector<Query>& queries, int) override
    {
        collect(queries);
        if (m_balls.empty())
            return {};
        build_grid();
        m_stamp.assign(m_balls.size(), 0);
        m_ray = 0;
        std::vector<Reply> replies;
        replies.reserve(m_balls.size());
        for (std::size_t i = 0; i < m_balls.size(); ++i) {
            float sum = 0;
            Vec3f brightest{};
            for (const Direction& d : m_directions) {
                const float a = light_from(i, d);
                sum += a;
                for (int c = 0; c < 3; ++c)
                    brightest[c] += a * d.dir[c];
            }
            Reply reply{m_balls[i].address, {sum}};
            if (m_balls[i].num_params >= 4) {
                normalize(brightest);
                for (float c : brightest)
                    reply.params.emplace_back(c);
            }
            replies.push_back(std::move(reply));
        }
        return replies;
    }

private:
    /// The balls of the pass, and the box around them (the program grows it ball by ball
    /// in single precision; its edges decide the voxels).
    void collect(const std::vector<Query>& queries)
    {
        m_balls.clear();
        for (const Query& q : queries) {
            const std::vector<float>& p = q.module.params;
            // the program takes one parameter or at least four, and a whole position
            if ((p.size() != 1 && p.size() < 4) || q.position.count < 3)
                continue;
            Ball b;
            b.pos = q.position.values;
            b.radius = p[0] > 0 ? p[0] : m_s.radius;
            b.area = static_cast<float>(std::numbers::pi * b.radius * b.radius);
            b.num_params = p.size();
            b.address = q.address;
            if (m_balls.empty()) {
                for (int c = 0; c < 3; ++c) {
                    m_origin[c] = b.pos[c] - b.radius;
                    m_extent[c] = 2 * b.radius;
                }
                m_max_radius = b.radius;
            } else {
                for (int c = 0; c < 3; ++c) {
                    float grow = m_origin[c] - (b.pos[c] - b.radius);
                    if (grow > 0) {
                        m_origin[c] -= grow;
                        m_extent[c] += grow;
                    }
                    grow = (b.pos[c] + b.radius) - (m_origin[c] + m_extent[c]);
                    if (grow > 0)
                        m_extent[c] += grow;
                }
                m_max_radius = std::max(m_max_radius, b.radius);
            }
            m_balls.push_back(b);
        }
    }

    /// The voxel of coordinate `v` on axis `c`, as the program floors it (single
    /// precision), kept within one voxel beyond the grid so that a degenerate box cannot
    /// send a walk through billions of voxels.
    std::int64_t voxel(float v, int c) const
    {
        const double n = std::floor((v - m_origin[c]) / m_extent[c] * static_cast<float>(m_s.grid_size[c]));
        if (!(n == n))
            return 0;
        return static_cast<std::int64_t>(std::clamp(n, -1.0, static_cast<double>(m_s.grid_size[c])));
    }

    std::int64_t cell_index(std::int64_t x, std::int64_t y, std::int64_t z) const
    {
        const auto& n = m_s.grid_size;
        x = std::clamp<std::int64_t>(x, 0, n[0] - 1);
        y = std::clamp<std::int64_t>(y, 0, n[1] - 1);
        z = std::clamp<std::int64_t>(z, 0, n[2] - 1);
        return (z * n[1] + y) * n[0] + x;
    }

    /// The voxels (first and last on each axis, clamped to the grid) that may lie within
    /// a ball's reach: one beyond those its box touches, as the program takes them; empty
    /// when the box is not a number.
    struct VoxelBox {
        std::array<std::int64_t, 3> lo{}, hi{};
        double count() const
        {
            double n = 1;
            for (int c = 0; c < 3; ++c)
                n *= static_cast<double>(std::max<std::int64_t>(0, hi[c] - lo[c] + 1));
            return n;
        }
    };
    VoxelBox voxel_box(const Ball& b) const
    {
        const auto& n = m_s.grid_size;
        const float beam = m_max_radius * m_s.beam_radius;
        VoxelBox box;
        for (int c = 0; c < 3; ++c) {
            const float size = static_cast<float>(n[c]);
            const double first = std::floor((b.pos[c] - b.radius - beam - m_origin[c]) / m_extent[c] * size) - 1;
            const double last = 1 + std::floor((b.pos[c] + b.radius + beam - m_origin[c]) / m_extent[c] * size);
            if (!(first == first) || !(last == last))
                return VoxelBox{{0, 0, 0}, {-1, -1, -1}};
            box.lo[c] = static_cast<std::int64_t>(std::clamp(first, 0.0, static_cast<double>(n[c])));
            box.hi[c] = static_cast<std::int64_t>(std::clamp(last, -1.0, static_cast<double>(n[c] - 1)));
        }
        return box;
    }

    /// Calls visit(cell) for each voxel whose centre lies within a ball's reach (its
    /// radius, the widest beam and half a voxel diagonal).
    template <class Visit>
    void for_each_voxel(const Ball& b, float half_diagonal, Visit&& visit) const
    {
        const auto& n = m_s.grid_size;
        const float beam = m_max_radius * m_s.beam_radius;
        const VoxelBox box = voxel_box(b);
        const auto& lo = box.lo;
        const auto& hi = box.hi;
        const float reach = b.radius + beam + half_diagonal;
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
            const float cz = centre(z, 2);
            for (std::int64_t y = lo[1]; y <= hi[1]; ++y) {
                const float cy = centre(y, 1);
                for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
                    const Vec3f d{b.pos[0] - centre(x, 0), b.pos[1] - cy, b.pos[2] - cz};
                    if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= reach * reach)
                        visit((z * n[1] + y) * n[0] + x);
                }
            }
        }
    }

    /// A voxel's centre on axis `c` (with the grid's origin: the bug is only in the walk).
    float centre(std::int64_t v, int c) const
    {
        return static_cast<float>(m_origin[c] + (static_cast<float>(v) + 0.5) /
                                                    static_cast<float>(m_s.grid_size[c]) * m_extent[c]);
    }

    /// The balls each voxel may hold, as one list per voxel (highest ball first, the
    /// order in which the program's lists hold them and so multiplies the reductions).
    void build_grid()
    {
        const auto& n = m_s.grid_size;
        const std::size_t cells = static_cast<std::size_t>(n[0]) * n[1] * n[2];
        float half = 0;
        for (int c = 0; c < 3; ++c) {
            const float side = m_extent[c] / static_cast<float>(n[c]);
            half += side * side;
        }
        half = static_cast<float>(0.5 * std::sqrt(static_cast<double>(half)));
        // the lists hold at most the voxels of the balls' boxes: refuse what would not fit
        double listed = 0;
        for (const Ball& b : m_balls)
            listed += voxel_box(b).count();
        if (listed > static_cast<double>(max_listed))
            throw Error("chiba: " + std::to_string(m_balls.size()) +
                        " leaf balls would reach more than 2^30 voxels of the " + std::to_string(n[0]) + "x" +
                        std::to_string(n[1]) + "x" + std::to_string(n[2]) +
                        " grid; a coarser grid size in the specification file lowers this");
        m_first.assign(cells + 1, 0);
        for (const Ball& b : m_balls)
            for_each_voxel(b, half, [&](std::int64_t cell) { ++m_first[static_cast<std::size_t>(cell) + 1]; });
        for (std::size_t i = 0; i < cells; ++i)
            m_first[i + 1] += m_first[i];
        m_members.assign(m_first[cells], 0);
        std::vector<std::size_t> fill(m_first.begin(), m_first.end() - 1);
        // filled from the last ball down, so each list runs from the highest index
        for (std::size_t i = m_balls.size(); i-- > 0;)
            for_each_voxel(m_balls[i], half, [&](std::int64_t cell) {
                m_members[fill[static_cast<std::size_t>(cell)]++] = static_cast<std::uint32_t>(i);
            });
    }

    /// The light ball `self` receives from one direction: its share, reduced by every
    /// ball met in the voxels the walk visits (each ball once, never the ball itself).
    float light_from(std::size_t self, const Direction& d)
    {
        if (d.intensity == 0)
            return 0.0f;
        const Ball& leaf = m_balls[self];
        const auto& n = m_s.grid_size;
        std::array<std::int64_t, 3> step{1, n[0], static_cast<std::int64_t>(n[0]) * n[1]};
        Vec3f half{};
        for (int c = 0; c < 3; ++c) {
            half[c] = static_cast<float>(0.5 * m_extent[c] / static_cast<float>(n[c]));
            if (d.dir[c] < 0) {
                half[c] = -half[c];
                step[c] = -step[c];
            }
        }
        std::array<std::int64_t, 3> node{};
        Vec3f middle{};
        for (int c = 0; c < 3; ++c) {
            node[c] = voxel(leaf.pos[c], c);
            // the program's voxel centre, without the grid's origin (kept: see the top)
            middle[c] = static_cast<float>((static_cast<float>(node[c]) + 0.5) / static_cast<float>(n[c]) *
                                           m_extent[c]);
        }
        // the program steps a cell pointer from the clamped first voxel alongside `node`;
        // they part only when the ball lies outside the grid, where a cell off the grid
        // holds nothing here
        std::int64_t cell = cell_index(node[0], node[1], node[2]);
        const auto cells = static_cast<std::int64_t>(m_first.size()) - 1;

        if (++m_ray == 0) {
            m_ray = 1;
            std::fill(m_stamp.begin(), m_stamp.end(), 0);
        }
        m_stamp[self] = m_ray;
        float reduction = 1;
        const float t = m_s.transmittance;
        for (;;) {
            if (cell >= 0 && cell < cells)
                for (std::size_t k = m_first[static_cast<std::size_t>(cell)];
                     k < m_first[static_cast<std::size_t>(cell) + 1]; ++k) {
                    const std::uint32_t other = m_members[k];
                    if (m_stamp[other] == m_ray)
                        continue;
                    const Ball& hit = m_balls[other];
                    if (m_s.estimate_area) {
                        const float covered = covered_area(leaf.pos, d.dir, hit, leaf.radius);
                        if (covered > 0) {
                            m_stamp[other] = m_ray;
                            reduction *= 1 - (1 - t) * covered / leaf.area;
                        }
                    } else {
                        const float length = chord(leaf.pos, d.dir, hit, leaf.radius);
                        if (length > 0) {
                            m_stamp[other] = m_ray;
                            reduction = static_cast<float>(
                                reduction *
                                std::pow(static_cast<double>(t),
                                         length / (2.0 * (hit.radius + m_s.beam_radius * leaf.radius))));
                        }
                    }
                }
            // the next voxel: across the face the ray reaches first, as judged from the
            // (shifted) centres
            float smallest = std::fabs(middle[0] + half[0] - leaf.pos[0]);
            int axis = 0;
            for (int c = 1; c < 3; ++c) {
                const float gap = middle[c] + half[c] - leaf.pos[c];
                if (std::fabs(gap * d.dir[axis]) < std::fabs(smallest * d.dir[c])) {
                    smallest = gap;
                    axis = c;
                }
            }
            middle[axis] += 2 * half[axis];
            cell += step[axis];
            node[axis] += d.dir[axis] > 0 ? 1 : -1;
            if (node[axis] < 0 || node[axis] >= n[axis])
                return d.intensity * reduction;
        }
    }

    /// The area of `hit`'s disc (seen along `dir`) that covers the disc of radius
    /// `own_radius` around `from`: 0 when `hit` lies behind, else the two circles' overlap.
    static float covered_area(const Vec3f& from, const Vec3f& dir, const Ball& hit, float own_radius)
    {
        const Vec3f v{from[0] - hit.pos[0], from[1] - hit.pos[1], from[2] - hit.pos[2]};
        const float along = dir[0] * v[0] + dir[1] * v[1] + dir[2] * v[2];
        if (along > 0)
            return 0;
        float d = v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - along * along;  // squared offset
        const float reach = hit.radius + own_radius;
        if (!(d < reach * reach))
            return 0;
        const float r1 = std::max(hit.radius, own_radius), r2 = hit.radius < own_radius ? hit.radius : own_radius;
        const float r2s = r2 * r2, r1s = r1 * r1;
        d = static_cast<float>(std::sqrt(d));
        if (d + r2 <= r1)
            return static_cast<float>(std::numbers::pi * r2s);  // the smaller disc lies inside
        // the lens: two circular segments, cut at the chord between the intersections
        const float x1 = (r1s + d * d - r2s) / (2 * d);
        const float x2 = (r2s + d * d - r1s) / (2 * d);
        const float y = static_cast<float>(std::sqrt(r2s - x2 * x2));
        return static_cast<float>(r1s * std::acos(static_cast<double>(x1 / r1)) +
                                  r2s * std::acos(static_cast<double>(x2 / r2)) - y * d);
    }

    /// The length of the ray from `from` along `dir` inside `hit` grown by the beam's
    /// radius, counting only the part ahead of `from`; 0 when it misses.
    float chord(const Vec3f& from, const Vec3f& dir, const Ball& hit, float own_radius) const
    {
        const Vec3f v{from[0] - hit.pos[0], from[1] - hit.pos[1], from[2] - hit.pos[2]};
        const float along = dir[0] * v[0] + dir[1] * v[1] + dir[2] * v[2];
        const float reach = hit.radius + own_radius * m_s.beam_radius;
        float d = along * along - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + reach * reach;
        if (d >= 0) {
            d = static_cast<float>(std::sqrt(d));
            if (-along + d > 0)
                return -along - d >= 0 ? 2 * d : -along + d;
        }
        return 0;
    }

    Settings m_s;
    std::vector<Direction> m_directions;
    std::vector<Ball> m_balls;
    Vec3f m_origin{}, m_extent{};
    float m_max_radius = 0;
    std::vector<std::size_t> m_first;     ///< per voxel, where its balls start in m_members
    std::vector<std::uint32_t> m_members;
    std::vector<std::uint32_t> m_stamp;   ///< per ball, the last ray that counted it
    std::uint32_t m_ray = 0;
};

}  // namespace

std::unique_ptr<Environment> make_chiba(const std::vector<std::string>& args, const Context& context)
{
    Settings s;
    for (const SpecLine& line : read_spec_file(spec_argument("chiba", args), context)) {
        const std::string& k = line.keyword;
        if (k == "grid size") {
            const std::vector<double> sizes = leading_numbers(line, 3);
            for (std::size_t c = 0; c < sizes.size(); ++c) {
                if (!(sizes[c] >= 1 && sizes[c] <= static_cast<double>(max_voxels)))
                    throw Error(line.loc, "chiba: grid size: each side must be at least 1 voxel, found '" +
                                              line.value + "'");
                s.grid_size[c] = static_cast<int>(sizes[c]);
            }
            if (static_cast<double>(s.grid_size[0]) * s.grid_size[1] * s.grid_size[2] > max_voxels)
                throw Error(line.loc, "chiba: grid size: at most 256x256x256 voxels, found '" + line.value + "'");
        } else if (k == "lower to upper ratio") {
            s.lower_to_upper = static_cast<float>(number_value(line));
        } else if (k == "transmittance") {
            s.transmittance = static_cast<float>(number_value(line));
        } else if (k == "number of samples") {
            const double n = number_value(line);
            if (!(n >= 1 && n <= static_cast<double>(max_samples)))
                throw Error(line.loc, "chiba: number of samples: from 1 to " + std::to_string(max_samples) +
                                          ", found '" + line.value + "'");
            s.samples = static_cast<long>(n);
        } else if (k == "radius") {
            s.radius = static_cast<float>(number_value(line));
            if (!(s.radius > 0))
                throw Error(line.loc, "chiba: radius: must be positive, found '" + line.value + "'");
        } else if (k == "beam radius") {
            s.beam_radius = static_cast<float>(number_value(line));
        } else if (k == "source direction") {
            const std::vector<double> v = numbers_value(line, 4);  // x y z intensity
            if (s.sources.size() >= max_sources) {
                warn(line.loc, "chiba: more than 100 light sources; this one is ignored, as the program does");
                continue;
            }
            s.sources.push_back(Direction{{static_cast<float>(v[0]), static_cast<float>(v[1]),
                                           static_cast<float>(v[2])},
                                          static_cast<float>(v[3])});
        } else if (k == "estimate intersection area") {
            s.estimate_area = switch_value(line, {"on"});
        } else if (k == "use CIE formula") {
            s.cie_sky = switch_value(line, {"yes"});
        } else if (k != "verbose") {
            warn_unknown_keyword("chiba", line);
        }
    }
    std::vector<Direction> directions;
    if (!s.sources.empty()) {
        float total = 0;
        for (const Direction& d : s.sources)
            total += d.intensity;
        for (Direction& d : s.sources) {
            d.intensity /= total;
            normalize(d.dir);
        }
        directions = s.sources;
    } else {
        directions = sky_samples(s);
    }
    // area estimation measures the whole receiving disc
    if (s.estimate_area)
        s.beam_radius = 1;
    return std::make_unique<Chiba>(std::move(s), std::move(directions));
}

}  // namespace cambium::env
