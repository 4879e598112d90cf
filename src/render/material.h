// SPDX-License-Identifier: Apache-2.0
// Surface materials: cpfg materials mapped to a small physically-based model.
#pragma once

#include <algorithm>
#include <vector>

#include "geom/scene.h"
#include "render/bsdf.h"
#include "render/vecf.h"

namespace cambium::render {

/// A surface's parameters in linear RGB, before any texture: `diffuse` is the albedo the
/// texture modulates or replaces, split into reflection and transmission by translucency.
struct SurfaceMaterial {
    Vec3f diffuse{0.5f};
    float translucency = 0;  ///< fraction of the diffuse albedo transmitted
    Vec3f specular;          ///< glossy lobe albedo at normal incidence
    float exponent = 0;      ///< Phong exponent (cpfg shininess / 4)
    Vec3f emission;          ///< emitted radiance
    float opacity = 1;       ///< 1 - transparency: probability a ray stops here
    /// OpenGL's ambient term in cpfg's window (material ambient x the scene's ambient
    /// light), added where a camera ray meets the surface; it lights nothing else.
    Vec3f ambient_glow;
};

/// The material a fraction `w` of the way from `a` to `b`: every parameter linear in w
/// (a generalized cylinder's colour blends so between its control points).
SurfaceMaterial mix(const SurfaceMaterial& a, const SurfaceMaterial& b, float w);

/// The BSDF of `m` with the (possibly textured) diffuse albedo `diffuse`. The glossy
/// lobe takes its share first: the diffuse lobes keep (1 - max specular) of theirs.
/// (Inline: made at every path vertex.)
inline Bsdf make_bsdf(const SurfaceMaterial& m, const Vec3f& diffuse)
{
    float keep = 1 - std::clamp(max_component(m.specular), 0.0f, 1.0f);
    Vec3f d = diffuse * keep;
    return {d * (1 - m.translucency), d * m.translucency, m.specular, m.exponent};
}
inline Bsdf make_bsdf(const SurfaceMaterial& m) { return make_bsdf(m, m.diffuse); }

/// The colour a surface shows unlit (cpfg's flat colour): its diffuse albedo plus emission.
inline Vec3f flat_colour(const SurfaceMaterial& m) { return m.diffuse + m.emission; }

/// The cpfg materials decoded to linear RGB (display values decoded as sRGB). Each
/// material's ambient (display value) times `ambient_light` is its ambient_glow.
std::vector<SurfaceMaterial> make_materials(const std::vector<geom::Material>& materials,
                                            const geom::Rgb& ambient_light = {0, 0, 0});

/// The albedos one material takes under cpfg's colormap-mode lighting (geom::IndexLighting):
/// each entry the index can move to, with that entry's chromaticity and the luminance of
/// the material's own entry (docs/materials.md: the path tracer supplies the shading, the
/// colormap the change of hue with light).
struct IndexRamp {
    geom::IndexLighting rule = geom::IndexLighting::none;
    int reach = 0;              ///< cosine: |diffuse reflection|; albedo[offset + reach]
    int place = 0;              ///< surface: the index's place in its block (index mod 64)
    std::vector<Vec3f> albedo;  ///< cosine: offsets -reach..reach; surface: 0..63 of the block
};

/// The ramps of `materials` (none where index_lighting is none); entries are read from
/// materials[0..255], indices past the block clamped to it.
std::vector<IndexRamp> make_index_ramps(const std::vector<geom::Material>& materials,
                                        const geom::ColourIndexLight& light);

/// The albedo cpfg's colour index lighting gives a point whose front-side normal has
/// cosine `cos_light` with the direction toward the light: the index moves by
/// trunc(diffuse reflection x cos) (cosine rule), or is the hue block's entry
/// trunc((index mod 64) x (ambient + diffuse |cos|)) (surface rule; manual 5.2.5).
Vec3f index_lit_albedo(const IndexRamp& ramp, const geom::ColourIndexLight& light, float cos_light);

/// The ambient light of cpfg's OpenGL window: the light model's 0.2 plus each light's
/// `A:` (default 1); with no `light:` cpfg makes one default light.
geom::Rgb opengl_ambient_light(const std::vector<geom::Light>& lights);

}  // namespace cambium::render
