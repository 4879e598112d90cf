// SPDX-License-Identifier: Apache-2.0
// The Scene: renderer-independent plain data produced by the turtle, consumed by render.
//
// Every primitive array is in the layout Embree takes directly (keys as float4, indices
// as uint32), but nothing here depends on Embree. Per-primitive attributes are parallel
// vectors: material[i] belongs to primitive i. The optional attributes `v` and `texture`
// may be left empty, meaning v = 0 and no_texture everywhere.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "geom/vec.h"

namespace cambium::geom {

using Float4 = std::array<float, 4>;
using Float3 = std::array<float, 3>;
using Float2 = std::array<float, 2>;

/// Provenance (docs/architecture.md): no module of the string drew the primitive (the
/// background scene, wireframe edges), or it is unknown.
inline constexpr std::uint32_t no_module = 0xffffffffu;
/// Provenance: the module's age is unknown (the derivation recorded no lineage).
inline constexpr std::uint16_t unknown_age = 0xffff;

/// Provenance: one module that drew primitives (an organ), in a ModuleTable.
struct ModuleRecord {
    std::uint32_t index = 0;     ///< in the derived string
    std::uint16_t name = 0;      ///< in ModuleTable::names
    std::uint16_t age = unknown_age;  ///< the derivation step at which the module appeared
};

/// Provenance: the modules that drew a Geometry's primitives or placed instances, in
/// string order, with their symbols and ages: 8 bytes a module (each primitive holds
/// only its module's index, 4 bytes).
struct ModuleTable {
    std::vector<ModuleRecord> records;  ///< sorted by index, each index once
    std::vector<std::string> names;     ///< symbol names, each once
    /// Each record's branch order (the `[` open where the turtle begins the module's
    /// successor; no_branch_order where unknown), parallel to `records` where asked for
    /// (InterpretOptions::branch_orders: organ masks), else empty.
    std::vector<std::uint16_t> orders;
    static constexpr std::uint16_t no_branch_order = 0xffff;
    /// In an animation with organ masks (InterpretOptions::births): each record's index in
    /// the string of the frame where its module appeared (with the record's age, its
    /// identity across frames), parallel to `records`; else empty.
    std::vector<std::uint32_t> births;

    /// The record of module `index`, or null.
    const ModuleRecord* find(std::uint32_t index) const
    {
        auto it = std::lower_bound(records.begin(), records.end(), index,
                                   [](const ModuleRecord& r, std::uint32_t i) { return r.index < i; });
        return it != records.end() && it->index == index ? &*it : nullptr;
    }
    std::string_view name(const ModuleRecord& r) const { return names[r.name]; }
};

/// Material index meaning "the instance's material" inside a prototype.
inline constexpr std::uint16_t inherit_material = 0xffff;
/// Texture index meaning "no texture".
inline constexpr std::int16_t no_texture = -1;

/// Embree's RTC_CURVE_FLAG_NEIGHBOR_LEFT / _RIGHT values: the segment continues a
/// previous segment at its start / is continued by the next one at its end, so the
/// joint is closed without a cap or a bulge.
struct CurveFlags {
    static constexpr std::uint8_t neighbour_left = 1;
    static constexpr std::uint8_t neighbour_right = 2;
};

/// Linear curve segments (cylinders drawn by F and G; render draws them as Embree cone
/// curves, exact frustums with discs and joint spheres): keys (x, y, z, radius) and
/// one first-key index per segment; segment i spans keys[segments[i]] .. keys[segments[i]+1].
struct LinearCurves {
    static constexpr std::uint8_t neighbour_left = CurveFlags::neighbour_left;
    static constexpr std::uint8_t neighbour_right = CurveFlags::neighbour_right;

    std::vector<Float4> keys;
    std::vector<float> v;                  ///< per key: texture v along the axis (report 4.2)
    std::vector<std::uint32_t> segments;
    std::vector<std::uint8_t> flags;       ///< per segment, neighbour_* bits
    std::vector<std::uint16_t> material;   ///< per segment, index into Scene::materials
    std::vector<std::int16_t> texture;     ///< per segment, index into Scene::textures or no_texture
    /// Per segment, optional (empty: unknown): the module of the derived string that drew it
    /// (its index there, through the homomorphism), or no_module. Geometry::modules names it.
    std::vector<std::uint32_t> module;

    std::size_t segment_count() const { return segments.size(); }
};

/// Round cubic Hermite segments: generalized cylinders with the circular contour.
/// Segment i spans points[segments[i]] .. points[segments[i]+1] with the tangents at
/// the same indices; the fourth component is the radius (points) and its derivative
/// (tangents), so `@Gr` radius profiles survive (Embree's ROUND_HERMITE_CURVE layout).
struct HermiteCurves {
    std::vector<Float4> points;
    std::vector<Float4> tangents;
    std::vector<float> v;                  ///< per point: texture v along the axis
    std::vector<std::uint32_t> segments;
    std::vector<std::uint8_t> flags;       ///< per segment, CurveFlags bits
    std::vector<std::uint16_t> material;   ///< per segment: the material at its start
    std::vector<std::int16_t> texture;
    /// Per segment, optional: the material at its end, blended linearly in u from
    /// `material` (cpfg's `render mode: interpolated` colours along a generalized
    /// cylinder). Empty, shorter than `segments` or equal to `material`: one material.
    std::vector<std::uint16_t> end_material;
    /// Per segment, optional (empty: unknown): the module of the derived string that drew it
    /// (its index there, through the homomorphism), or no_module. Geometry::modules names it.
    std::vector<std::uint32_t> module;

    std::size_t segment_count() const { return segments.size(); }
};

/// Spheres (`@O`): centre and radius.
struct Spheres {
    std::vector<Float4> centres;           ///< x, y, z, radius
    std::vector<std::uint16_t> material;
    std::vector<std::int16_t> texture;
    /// Per sphere, optional (empty: unknown): the module of the derived string that drew it
    /// (its index there, through the homomorphism), or no_module. Geometry::modules names it.
    std::vector<std::uint32_t> module;

    std::size_t size() const { return centres.size(); }
};

/// Oriented discs (`@o`, `@c`): centre, radius and the unit normal of the front face.
struct Discs {
    std::vector<Float4> centres;           ///< x, y, z, radius
    std::vector<Float3> normals;           ///< unit, the front side
    std::vector<std::uint16_t> material;       ///< front
    std::vector<std::uint16_t> back_material;  ///< back
    /// Per disc, optional (empty: unknown): the module of the derived string that drew it
    /// (its index there, through the homomorphism), or no_module. Geometry::modules names it.
    std::vector<std::uint32_t> module;

    std::size_t size() const { return centres.size(); }
};

/// Triangles: polygons, patches, surfaces, non-circular contours, tsurfaces, background.
/// normals and uvs are per vertex and as long as positions (flat faces carry their face
/// normal; untextured ones carry zeros as uv), except that uvs may be left empty, read as
/// zeros, where no hit reads them (geom::fit_mesh_buffers). The front of a triangle is the
/// side its vertex normals point to (or, for a flat face, the side its winding a,b,c makes
/// counter-clockwise).
struct TriangleMesh {
    std::vector<Float3> positions;
    std::vector<Float3> normals;
    std::vector<Float2> uvs;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::uint16_t> material;       ///< per triangle, front
    std::vector<std::uint16_t> back_material;  ///< per triangle, back
    std::vector<std::int16_t> texture;         ///< per triangle
    /// Per triangle, optional (missing entries are 0): bit k set when the edge from
    /// vertex k to vertex k + 1 lies inside its turtle polygon, which
    /// `render mode: wireframe` draws as its outline only (OpenGL's edge flags). Filled
    /// only for wireframe views.
    std::vector<std::uint8_t> hidden_edges;
    /// Per triangle, optional (empty: unknown): the module of the derived string that drew it
    /// (its index there, through the homomorphism), or no_module. Geometry::modules names it.
    std::vector<std::uint32_t> module;

    std::size_t size() const { return triangles.size(); }
};

/// A set of primitives of every kind: the scene's own, or a prototype's.
struct Geometry {
    LinearCurves lines;
    HermiteCurves curves;
    Spheres spheres;
    Discs discs;
    TriangleMesh mesh;
    /// Provenance: the modules its primitives' `module` entries name (and, in the
    /// Scene's own geometry, its instances'); empty for an organ's prototype.
    ModuleTable modules;

    bool empty() const
    {
        return lines.segment_count() == 0 && curves.segment_count() == 0 && spheres.size() == 0 &&
               discs.size() == 0 && mesh.size() == 0;
    }
};

/// Geometry drawn many times (a predefined surface `~x`, an `-o>` object): built once in
/// its own frame, placed by instances. Its material indices may be inherit_material.
struct Prototype {
    std::string name;
    Geometry geometry;
};

/// One placement of a prototype: x' = transform * (x, 1), a 3x4 matrix stored column-major
/// (columns: images of the x, y, z axes, then the translation), as Embree's
/// RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR. The materials replace inherit_material.
struct Instance {
    std::uint32_t prototype = 0;
    std::array<float, 12> transform{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    std::uint16_t material = 0;
    std::uint16_t back_material = 0;
    std::int16_t texture = no_texture;
    /// Provenance: the module that placed it (an `-o>` object, a predefined surface),
    /// which every primitive of the placed prototype takes, or no_module (then the
    /// prototype's own `module` entries, if any, stand).
    std::uint32_t module = no_module;
    /// In a scene file (docs/scenes.md): the plant placement this instance belongs to
    /// (its place among all the file's placements, plant by plant in file order), or
    /// no_plant.
    std::uint32_t plant = no_plant;
    static constexpr std::uint32_t no_plant = 0xffffffffu;
};


/// How cpfg's colormap mode lights a colour index (manual 5.2.5): it does not light it
/// (pixel lines, filled modes, material files), it moves the index by `diffuse
/// reflection:` x N.L (lines, cylinders, polygons, spheres), or it picks the index in
/// the index's block of 64 by `surface ambient:` + `surface diffuse:` x |N.L|
/// (predefined surfaces and patches). render keeps the moved entry's hue (docs/materials.md).
enum class IndexLighting : std::uint8_t { none, cosine, surface };

/// Entries of a colormap or material file: a turtle colour index is 0..255.
inline constexpr std::size_t colour_indices = 256;

/// A cpfg material (manual 5.4.2) or colormap entry (5.4.1, as diffuse), with the
/// file's display values in [0, 1]. render decodes them (docs/materials.md).
struct Material {
    Rgb ambient{0.2f, 0.2f, 0.2f};
    Rgb diffuse{0.8f, 0.8f, 0.8f};
    Rgb emission{0, 0, 0};
    Rgb specular{0, 0, 0};
    float shininess = 0;     ///< 0..128
    float transparency = 0;  ///< 0 opaque .. 1 fully transparent
    /// Cambium extension (view file `translucency:`, docs/materials.md): the fraction of
    /// the diffuse albedo transmitted through the surface instead of reflected.
    float translucency = 0;
    /// Colormap-mode lighting: the rule and the colour index (0..255) it starts from,
    /// in the 256 materials from `colour_table` on (the colormap whose entries the
    /// index moves over: the selected one, or the next for patch colours past 255).
    IndexLighting index_lighting = IndexLighting::none;
    std::uint8_t colour_index = 0;
    std::uint16_t colour_table = 0;
};

/// The settings of cpfg's colormap-mode lighting (manual 5.2.5): the direction toward
/// its light (the first light's, normalised) and the view file's coefficients.
struct ColourIndexLight {
    Vec3 to_light{1, 0, 0};
    int diffuse_reflection = 10;   ///< `diffuse reflection:`
    float surface_ambient = 0.15f;  ///< `surface ambient:`
    float surface_diffuse = 0.75f;  ///< `surface diffuse:`
};

/// A `texture:` of the view file (manual 5.2.7), in order: `@Tx(i)` and surfaces name
/// them by index.
struct TextureDef {
    std::filesystem::path file;  ///< absolute or relative to the view file's folder
    bool decal = false;          ///< E: decal; otherwise modulate
    bool linear_filter = true;   ///< H: / L: filters (mag / min): false = nearest
    bool mipmap = true;
};

/// A view-file light (manual 5.2.6).
struct Light {
    enum class Kind { point, directional, spot };
    Kind kind = Kind::point;
    Vec3 position{0, 0, 1};         ///< point and spot lights (O:)
    Vec3 direction{0, 0, 1};        ///< directional lights (V:): the vector as given
    Rgb ambient{1, 1, 1};
    Rgb diffuse{1, 1, 1};
    Rgb specular{1, 1, 1};
    Vec3 spot_direction{0, 0, -1};  ///< P: x y z
    float spot_exponent = 0;
    float spot_cutoff_deg = 180;
    float attenuation_constant = 1, attenuation_linear = 0, attenuation_quadratic = 0;
};

/// The view-file camera settings (manual 5.2.2), uninterpreted: render frames them.
struct View {
    Vec3 viewpoint{0, 0, 1};
    Vec3 reference_point{0, 0, 0};
    double twist_deg = 0;
    bool perspective = false;
    double viewing_angle_deg = 45;
    double scale_factor = 1;
    std::optional<Bounds3> box;     ///< `box:` overrides the auto-fit bounds
    std::optional<double> front_distance, back_distance;
};

/// `@L` text at the turtle position, in the colour of `material` (render/labels.h).
struct Label {
    std::string text;
    Vec3 position;
    std::uint16_t material = 0;
};

/// The font labels are drawn in, from the view file's `font:` (an X font name) or
/// `winfont:` (name, size in pixels, flags): a fontconfig family name, a size in pixels
/// and the style. The default is cpfg's, `-*-courier-bold-r-*-12-*`.
struct LabelFont {
    std::string family = "courier";
    int pixel_size = 12;
    bool bold = true;
    bool italic = false;
};

/// `render mode:` (manual 5.2) read by a path tracer: shaded (lit with smooth normals),
/// flat (lit with each facet's own normal), filled (unlit: every surface in its flat
/// colour, as OpenGL without lighting), wireframe (unlit: only the edges of polygons and
/// of the tessellated surfaces, as pixel-width lines; geom/wireframe.h).
enum class Shading { shaded, flat, filled, wireframe };

/// Everything render needs to draw one frame of a plant.
struct Scene {
    Geometry geometry;
    std::vector<Prototype> prototypes;
    std::vector<Instance> instances;
    std::vector<Label> labels;
    LabelFont label_font;

    /// true when line radii are in pixels (`line style: pixel`): render converts
    /// them with its camera's pixel footprint.
    bool line_radius_in_pixels = false;
    Shading shading = Shading::shaded;  ///< the view file's `render mode:`

    std::vector<Material> materials = std::vector<Material>(256);  ///< by colour index
    /// Set in colormap mode with lighting: materials whose index_lighting is not none
    /// show the colormap entries cpfg's index lighting picks (their colour_index's
    /// neighbours in materials[0..255]).
    std::optional<ColourIndexLight> colour_index_light;
    std::vector<TextureDef> textures;
    Rgb background{0, 0, 0};  ///< display values: colormap entry 0 or material 0's emission
    std::vector<Light> lights;
    View view;
    /// Bounds of the interpreted geometry as cpfg computes them for the auto-fit.
    Bounds3 bounds;
};

/// Where an organ's module is recorded: the scene's own table, or, in a field of plants,
/// its plant's geometry (the prototype that the placement's own instance places), where
/// the plant's interpretation put it. Organs placed whole (an instance with a module) and
/// a plant's own primitives alike are named through it.
class OrganModules {
public:
    explicit OrganModules(const Scene& scene) : m_scene(scene)
    {
        for (const Instance& in : scene.instances)
            if (in.plant != Instance::no_plant && in.module == no_module && in.prototype < scene.prototypes.size()) {
                if (m_plant_prototype.size() <= in.plant)
                    m_plant_prototype.resize(std::size_t(in.plant) + 1, no_prototype);
                if (m_plant_prototype[in.plant] == no_prototype)
                    m_plant_prototype[in.plant] = in.prototype;
            }
    }
    /// The table recording `module` of placement `plant` (Instance::no_plant: a still's).
    const ModuleTable& of(std::uint32_t plant, std::uint32_t module) const
    {
        const Prototype* p = plant_prototype(plant);
        return p && !m_scene.geometry.modules.find(module) ? p->geometry.modules : m_scene.geometry.modules;
    }
    const ModuleTable& of(const Instance& organ) const { return of(organ.plant, organ.module); }
    /// The prototype that placement `plant` places (its variant), or null.
    const Prototype* plant_prototype(std::uint32_t plant) const
    {
        return plant < m_plant_prototype.size() && m_plant_prototype[plant] != no_prototype
                   ? &m_scene.prototypes[m_plant_prototype[plant]]
                   : nullptr;
    }

private:
    static constexpr std::uint32_t no_prototype = 0xffffffffu;
    const Scene& m_scene;
    std::vector<std::uint32_t> m_plant_prototype;  ///< per placement
};

}  // namespace cambium::geom
