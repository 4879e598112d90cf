// SPDX-License-Identifier: Apache-2.0
// The unidirectional path tracer: next-event estimation toward one light per vertex, chosen
// by what each can deliver there from the view file's lights, the environment and
// emissive primitives (MIS against BSDF sampling), transmission, opacity, Russian
// roulette, ray cones for texture filtering.
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "render/accel.h"
#include "render/area_light.h"
#include "render/environment.h"
#include "render/ground.h"
#include "render/light.h"
#include "render/material.h"
#include "render/sampler.h"
#include "render/texture.h"
#include "render/vecf.h"

namespace cambium::render {

/// A ray's footprint as a cone: `width` at its origin, growing by `spread` per unit of
/// distance (a pixel's angle). Camera rays carry one so textures are filtered over what a
/// pixel sees (mipmapping); paths keep growing it after they scatter.
struct RayCone {
    float width = 0;
    float spread = 0;
};

/// Everything a path needs, read-only and shared by all threads.
struct PathContext {
    const EmbreeScene* accel = nullptr;
    std::vector<SurfaceMaterial> materials;
    std::vector<RenderLight> lights;
    /// Emissive primitives sampled for next-event estimation (MIS against BSDF hits on
    /// them); not owned. Null: emission is found by BSDF sampling only.
    const AreaLights* area_lights = nullptr;
    const TextureSet* textures = nullptr;  ///< textures of hits (none: untextured)
    Vec3f background;  ///< linear; seen by camera rays that miss
    /// Seen by secondary rays that escape and sampled for next-event estimation (MIS
    /// against BSDF sampling); not owned. Null: the uniform radiance `ambient`.
    const Environment* environment = nullptr;
    Vec3f ambient;     ///< linear; used only when environment is null
    /// Camera rays that miss see `environment` (a sky or an HDR map the user chose)
    /// instead of cpfg's background colour.
    bool environment_visible = false;
    int max_depth = 6;
    int roulette_depth = 1;  ///< as RenderSettings::roulette_depth
    /// `render mode: filled` / `wireframe`: every surface shows its flat colour, unlit.
    bool unlit = false;
    /// `render mode: flat`: shading uses each facet's own normal.
    bool facet_normals = false;
    /// cpfg's colormap-mode lighting, per material (empty: none): a lit hit's diffuse
    /// albedo follows the entry its colour index moves to (geom::IndexLighting).
    std::vector<IndexRamp> index_ramps;
    geom::ColourIndexLight index_light;
    /// The camera rays' cone (zero: textures are looked up at their finest level).
    RayCone camera_cone;
    /// The ground plane (--ground), beside the Embree scene; none: no ground.
    std::optional<GroundPlane> ground;
    /// Half the scene's diagonal: how far area lights' power is taken to reach when lights
    /// are chosen (variance only; 0 counts as 1).
    float scene_radius = 0;

    /// Scene-wide facts and the light set trace_path needs, made once by
    /// prepare_path_context() after everything above is set.
    struct SceneFlags {
        bool transparent = false;      ///< some material lets light through
        std::vector<float> opacity;    ///< of each material, for transmittance rays
        bool environment_black = true; ///< escaping rays see nothing
        bool environment_nee = false;  ///< the environment is sampled for NEE
        LightSet lights;               ///< what next-event estimation samples
        /// The environment as the light set samples it, where that differs from
        /// `environment` (under an opaque ground: Environment::hidden_below_horizon).
        std::shared_ptr<const Environment> sampled_environment;
    };
    std::optional<SceneFlags> prepared;
};

/// The material at `hit`: ctx.materials[hit.material], or, where a generalized
/// cylinder's colour blends (hit.material_blend > 0), the mix written into `scratch`;
/// under colour-index lighting (index_ramps) with the albedo cpfg's index gives there.
/// Out-of-range indices give a default material.
const SurfaceMaterial& hit_material(const PathContext& ctx, const SurfaceHit& hit,
                                    SurfaceMaterial& scratch);

/// Fills ctx.prepared; call after setting the materials, lights and environment (again
/// after changing them). trace_path throws std::logic_error without it.
void prepare_path_context(PathContext& ctx);

/// The texture footprint of `hit` seen along `dir` through a cone `width` wide there: an
/// ellipse `width` across, stretched by 1 / cos along the incidence plane, taken into (s, t)
/// through the hit's dpds and dpdt (least squares).
TextureFootprint texture_footprint(const SurfaceHit& hit, const Vec3f& dir, float width);

/// Whether texture_footprint(hit, dir, width) is surely under one texel of a texture whose
/// finest level's longer side is `texels` (TextureSet::footprint_texels; 0: no MIP levels,
/// always true), so that the lookup takes the finest level whatever the footprint: then
/// a zero footprint gives the same texel, and the footprint need not be made. A bound on
/// its longest axis from the tangents' Gram matrix alone, with a factor 2 to spare for
/// rounding; false where that cannot show it (a sliver of a tangent frame, NaN).
bool footprint_within_texel(const SurfaceHit& hit, const Vec3f& dir, float width, float texels);

/// The radiance of one path and whether its camera ray hit geometry.
struct PathResult {
    Vec3f radiance;
    bool hit = false;
    /// The camera ray met a shadow catcher (radiance 0, hit false): the luminance a white
    /// Lambertian surface there reflects from direct light and the uniform environment,
    /// with the plant in the way (`lit_with`) and without (`lit_without`), estimated
    /// from the same light and direction samples.
    bool catcher = false;
    float lit_with = 0, lit_without = 0;
};

/// What the camera ray meets first (transparent or not), for the image's albedo, normal
/// and depth layers (pbrt's VisibleSurface).
struct VisibleSurface {
    bool hit = false;
    Vec3f albedo;  ///< the (textured) diffuse albedo, or an unlit line's flat colour
    Vec3f normal;  ///< unit shading normal, facing the camera
    float t = 0;   ///< distance along the camera ray
    /// What was hit, to find its organ (SurfaceHit's fields of the same names).
    std::uint32_t geom_id = 0, primitive = 0, instance = 0;
    Shape shape = Shape::line;
};

/// Throws std::logic_error: `caller` was given a context prepare_path_context() did not fill.
[[noreturn]] void unprepared_path_context(const char* caller);

/// What a ray that escapes along d sees: the environment, or the uniform ambient.
inline Vec3f escaped_radiance(const PathContext& ctx, const Vec3f& d)
{
    return ctx.environment ? ctx.environment->radiance(d) : ctx.ambient;
}

/// What a camera ray that meets nothing along d sees: the environment where the camera
/// sees it, else the view's background.
inline Vec3f seen_by_camera(const PathContext& ctx, const Vec3f& d)
{
    return ctx.environment_visible ? escaped_radiance(ctx, d) : ctx.background;
}

/// What trace_path returns for a camera ray already traced that met nothing (an empty
/// `camera_hit`): the background or the environment it sees, without setting up a path.
/// Most camera rays of a plant miss, so their cost per sample counts (inline: a call per
/// miss was a visible share of the trace).
inline PathResult camera_miss(const PathContext& ctx, const Vec3f& dir)
{
    if (!ctx.prepared)
        unprepared_path_context("camera_miss");
    // As trace_path's first vertex without a hit (bit-identical: its throughput is 1).
    PathResult result;
    if (ctx.max_depth > 0)
        result.radiance += seen_by_camera(ctx, dir);
    return result;
}

/// The probability with which next-event estimation at `hit` (its BSDF seen as `bsdf`)
/// samples each light of the prepared light set, in the set's order. Where it samples
/// every light (LightSet::every_light): 1 for the environment, the sun and each delta
/// light that gives the point something, 0 for a delta light that gives it nothing (its
/// back, or the opaque ground between). Otherwise what the path tracer draws its one
/// light from (LightSet::per_point, delta_only or by power).
std::vector<float> light_choice_probabilities(const PathContext& ctx, const SurfaceHit& hit,
                                              const BsdfAt& bsdf);

/// Traces the camera ray (org, dir), which ends at tfar (far clipping), with the sampler's
/// dimensions; fills `first` when given. `camera_hit`, when given: the camera ray's first
/// hit in ctx.accel, already traced (EmbreeScene::intersect_coherent; only without a
/// ground plane). Allocates nothing.
PathResult trace_path(const PathContext& ctx, const Vec3f& org, const Vec3f& dir,
                      const Sampler& sampler,
                      float tfar = std::numeric_limits<float>::infinity(),
                      VisibleSurface* first = nullptr,
                      const std::optional<SurfaceHit>* camera_hit = nullptr);

}  // namespace cambium::render
