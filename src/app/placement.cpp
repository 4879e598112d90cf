// SPDX-License-Identifier: Apache-2.0
// Placements of a scene's plants: explicit transforms, scatters over a rectangle or a
// mesh, and the OBJ meshes scatters and grounds use.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <unordered_map>

#include "app/obj_lines.h"
#include "app/scene_file.h"
#include "base/diagnostics.h"
#include "geom/text_input.h"

namespace cambium::app {
namespace {

/// Uniform doubles in [0, 1) from a generator whose sequence the C++ standard fixes
/// (std::uniform_real_distribution is not the same on every library).
class Uniform {
public:
    explicit Uniform(std::uint64_t seed) : m_engine(seed) {}
    double operator()() { return double(m_engine() >> 11) * 0x1.0p-53; }

private:
    std::mt19937_64 m_engine;
};

/// Accepted points in a hash grid of cells min_spacing wide, for the spacing test.
/// Cells are never narrower than 2^-40 of the largest coordinate `extent`: a tiny
/// spacing over a large area would otherwise give cell indices past long long's range
/// (undefined, then every point in one cell). Wider cells still hold every neighbour
/// closer than the spacing within one cell of a point's.
class SpacingGrid {
public:
    SpacingGrid(double spacing, double extent)
        : m_spacing(spacing), m_cell(std::max(spacing, extent * 0x1p-40))
    {
    }

    bool far_enough(const geom::Vec3& p) const
    {
        if (m_spacing <= 0)
            return true;
        auto c = cell(p);
        for (long long dx = -1; dx <= 1; ++dx)
            for (long long dy = -1; dy <= 1; ++dy)
                for (long long dz = -1; dz <= 1; ++dz) {
                    auto it = m_cells.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
                    if (it == m_cells.end())
                        continue;
                    for (const geom::Vec3& q : it->second)
                        if (geom::length(p - q) < m_spacing)
                            return false;
                }
        return true;
    }
    void add(const geom::Vec3& p)
    {
        if (m_spacing > 0) {
            auto c = cell(p);
            m_cells[key(c[0], c[1], c[2])].push_back(p);
        }
    }

private:
    std::array<long long, 3> cell(const geom::Vec3& p) const
    {
        return {static_cast<long long>(std::floor(p.x / m_cell)),
                static_cast<long long>(std::floor(p.y / m_cell)),
                static_cast<long long>(std::floor(p.z / m_cell))};
    }
    static std::uint64_t key(long long x, long long y, long long z)
    {
        auto h = [](long long v) { return static_cast<std::uint64_t>(v) * 0x9E3779B97F4A7C15ull; };
        return h(x) ^ (h(y) >> 21) ^ (h(z) << 21) ^ (h(z) >> 43);
    }

    double m_spacing;
    double m_cell;  ///< at least m_spacing
    std::unordered_map<std::uint64_t, std::vector<geom::Vec3>> m_cells;
};

/// Where candidate points come from: a rectangle on y = 0 or a mesh's area.
class PointSource {
public:
    PointSource(const ScatterSpec& spec, const GroundMesh* mesh) : m_spec(spec), m_mesh(mesh)
    {
        if (!mesh)
            return;
        double total = 0;
        for (const auto& t : mesh->triangles) {
            total += area(t);
            m_cumulative.push_back(total);
        }
        if (!(total > 0))
            throw Error("the scatter's mesh has no area");
    }

    /// The largest absolute coordinate a point can have.
    double extent() const
    {
        double most = 0;
        auto widen = [&](double v) { most = std::max(most, std::abs(v)); };
        if (!m_mesh)
            std::for_each(m_spec.rectangle.begin(), m_spec.rectangle.end(), widen);
        else
            for (const geom::Float3& v : m_mesh->positions)
                std::for_each(v.begin(), v.end(), widen);
        return most;
    }

    geom::Vec3 operator()(Uniform& u) const
    {
        if (!m_mesh) {
            const auto& r = m_spec.rectangle;
            double x = r[0] + (r[2] - r[0]) * u();
            double z = r[1] + (r[3] - r[1]) * u();
            return {x, 0, z};
        }
        double pick = u() * m_cumulative.back();
        std::size_t i = static_cast<std::size_t>(
            std::upper_bound(m_cumulative.begin(), m_cumulative.end(), pick) - m_cumulative.begin());
        i = std::min(i, m_cumulative.size() - 1);
        // uniform in the triangle: reflect the unit square's upper half
        double a = u(), b = u();
        if (a + b > 1) {
            a = 1 - a;
            b = 1 - b;
        }
        auto [p, q, r] = corners(m_mesh->triangles[i]);
        return p + (q - p) * a + (r - p) * b;
    }

private:
    std::array<geom::Vec3, 3> corners(const std::array<std::uint32_t, 3>& t) const
    {
        auto v = [&](std::uint32_t k) {
            const geom::Float3& f = m_mesh->positions[k];
            return geom::Vec3{f[0], f[1], f[2]};
        };
        return {v(t[0]), v(t[1]), v(t[2])};
    }
    double area(const std::array<std::uint32_t, 3>& t) const
    {
        auto [p, q, r] = corners(t);
        return 0.5 * geom::length(geom::cross(q - p, r - p));
    }

    const ScatterSpec& m_spec;
    const GroundMesh* m_mesh;
    std::vector<double> m_cumulative;  ///< triangle areas, summed
};

}  // namespace

Transform placement_transform(const geom::Vec3& translate, double rotate_y_deg, double scale)
{
    double a = rotate_y_deg * std::numbers::pi / 180;
    auto c = static_cast<float>(std::cos(a) * scale), s = static_cast<float>(std::sin(a) * scale);
    auto k = static_cast<float>(scale);
    // Rotation about +y (right-handed): x axis -> (cos, 0, -sin), z axis -> (sin, 0, cos).
    return {c, 0, -s, 0, k, 0, s, 0, c,
            static_cast<float>(translate.x), static_cast<float>(translate.y),
            static_cast<float>(translate.z)};
}

Transform compose(const Transform& a, const Transform& b)
{
    Transform out{};
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 3; ++row) {
            float v = 0;
            for (int k = 0; k < 3; ++k)
                v += a[std::size_t(k * 3 + row)] * b[std::size_t(col * 3 + k)];
            if (col == 3)
                v += a[std::size_t(9 + row)];
            out[std::size_t(col * 3 + row)] = v;
        }
    return out;
}

std::vector<Transform> scatter(const ScatterSpec& spec, const GroundMesh* mesh)
{
    Uniform u(spec.seed);
    PointSource source(spec, mesh);
    SpacingGrid grid(spec.min_spacing, source.extent());
    std::vector<Transform> out;
    out.reserve(spec.count);
    // Rejection: a bounded number of candidates per wanted point, so a full area ends
    // the scatter instead of looping.
    constexpr std::size_t tries_per_point = 30;
    std::size_t misses = 0;
    while (out.size() < spec.count && misses < tries_per_point * spec.count) {
        geom::Vec3 p = source(u);
        if (!grid.far_enough(p)) {
            ++misses;
            continue;
        }
        grid.add(p);
        double angle = spec.rotate_y ? 360 * u() : 0;
        double scale = spec.scale[0] + (spec.scale[1] - spec.scale[0]) * u();
        out.push_back(placement_transform(p, angle, scale));
    }
    if (out.size() < spec.count)
        warn("scatter: placed " + std::to_string(out.size()) + " of " + std::to_string(spec.count) +
             " plants; no room for more at min_spacing " + std::to_string(spec.min_spacing));
    return out;
}

GroundMesh read_obj_mesh(const std::filesystem::path& file, const SceneLimits& limits)
{
    const std::size_t max_triangles = limits.max_mesh_triangles;
    GroundMesh mesh;
    for_each_obj_line(file, "the mesh", limits, [&](const std::string& kind, std::istringstream& words,
                                                   const std::string&, const FileLoc& loc) {
        if (kind == "v") {
            double x, y, z;
            if (!(words >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) ||
                !std::isfinite(z) || std::max({std::abs(x), std::abs(y), std::abs(z)}) > 1e9)
                throw Error(loc, "expected a vertex 'v x y z' with finite coordinates");
            mesh.positions.push_back({float(x), float(y), float(z)});
        } else if (kind == "f") {
            // f v, f v/vt, f v/vt/vn, f v//vn; negative indices count back from the end
            std::vector<std::uint32_t> face;
            for (std::string w; words >> w;) {
                long long index = 0;
                try {
                    index = std::stoll(w.substr(0, w.find('/')));
                } catch (const std::exception&) {
                    throw Error(loc, "expected vertex indices in the face, not '" + w + "'");
                }
                long long n = static_cast<long long>(mesh.positions.size());
                long long k = index < 0 ? n + index : index - 1;
                if (index == 0 || k < 0 || k >= n)
                    throw Error(loc, "vertex index " + std::to_string(index) +
                                         " is not a vertex defined before the face");
                face.push_back(static_cast<std::uint32_t>(k));
            }
            if (face.size() < 3)
                throw Error(loc, "a face needs 3 vertices at least");
            for (std::size_t i = 1; i + 1 < face.size(); ++i)
                mesh.triangles.push_back({face[0], face[i], face[i + 1]});
            if (mesh.triangles.size() > max_triangles)
                throw Error(loc, "the mesh has more than " + std::to_string(max_triangles) +
                                     " triangles");
        }
        // other statements (vt, vn, g, o, s, usemtl, mtllib) carry nothing needed
        if (mesh.positions.size() > 3 * max_triangles + 3)
            throw Error(loc, "the mesh has too many vertices");
    });
    if (mesh.triangles.empty())
        throw Error(FileLoc{file.string()}, "the mesh has no faces");
    return mesh;
}

}  // namespace cambium::app
