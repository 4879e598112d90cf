// SPDX-License-Identifier: Apache-2.0
// `-o>` object instancing (manual 8.1): which prototype an object module is, how its
// instance is placed, and how the geometry an expansion draws for the turtle's sake is
// cut away again. The Interpreter decides when; this file decides what.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>

#include "geom/scene.h"
#include "geom/turtle.h"
#include "geom/view_file.h"
#include "lsys/module_string.h"

namespace cambium::geom {

/// The placement of an object built in the turtle's starting frame (H = +y, L = -x,
/// U = -z at the origin): its x axis goes to -L, y to H, z to -U, the origin to the
/// turtle. No scale: the object was built with the first occurrence's turtle scale
/// (cpfg's rayshade output prints the same transformation).
std::array<float, 12> object_transform(const Turtle& t);

/// Appends a prototype's triangles placed by an instance (transform, materials in place
/// of inherit_material, texture for untextured triangles): a `~x` surface inside an
/// `-o>` object becomes part of the object's own geometry, since the renderer's
/// instances are one level deep. Surfaces are triangle meshes only.
void append_placed_mesh(TriangleMesh& into, const TriangleMesh& from, const Instance& instance);

/// The sizes of every array of a Geometry and the neighbour flags of its last line and
/// curve segment, to cut it back to them after an object's expansion has moved the
/// turtle through geometry that its instance draws.
class GeometryCheckpoint {
public:
    explicit GeometryCheckpoint(const Geometry& g);

    /// Cuts `g` back to the checkpoint and un-continues the last segments; true when
    /// lines were drawn since (the chain's last key is then the object's).
    bool restore(Geometry& g) const;

private:
    std::size_t m_line_keys, m_line_v, m_line_segments, m_curve_points, m_curve_v, m_curve_segments,
        m_spheres, m_sphere_textures, m_discs, m_positions, m_uvs, m_triangles, m_mesh_textures;
    int m_line_flag = -1, m_curve_flag = -1;  ///< the last segments' flags; -1: none
};

/// The `-o>` objects of one interpretation: each object module's expansion (kept per
/// exact module up to a bounded number of modules) and each object key's prototype in
/// the Scene (built once, by the caller's builder).
class ObjectInstancer {
public:
    using Expand = std::function<lsys::ModuleString(lsys::ModuleRef)>;
    ObjectInstancer(const ViewFile& view, Expand expand);

    /// The homomorphism successor of an object module (`expand` must depend on the
    /// module only).
    std::shared_ptr<const lsys::ModuleString> expansion(lsys::ModuleRef m);

    /// The key cpfg's hash table compares: the module's name and its parameters printed
    /// with the `rayshade objects:` format, and with `turtle considered` the turtle's
    /// line width, scale, colours and texture.
    std::string key(std::string_view name, lsys::ModuleRef m, const Turtle& turtle) const;

    /// The prototype index in `scene` of `key`, built the first time by `build` (cpfg's
    /// stage 2); -1 when it draws nothing.
    int prototype(std::string key, Scene& scene, const std::function<Geometry()>& build);

private:
    static constexpr std::size_t max_cached_expansion_modules = 4'000'000;

    ObjectKeying m_keying;
    Expand m_expand;
    std::unordered_map<std::string, int> m_prototypes;  ///< key -> prototype, -1: empty
    std::unordered_map<std::string, std::shared_ptr<const lsys::ModuleString>> m_expansions;
    std::size_t m_cached_modules = 0;
};

}  // namespace cambium::geom
