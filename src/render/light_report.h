// SPDX-License-Identifier: Apache-2.0
// The light each organ absorbs: rays traced from the scene's lights through the plant,
// scattered by the materials' reflectance and transmittance, tallied per organ (the
// module that drew the primitive: geom's provenance). docs/light.md.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geom/scene.h"
#include "render/environment.h"
#include "render/light.h"

namespace cambium::render {

/// A surface side's optics for the whole scene: the shares reflected and transmitted
/// (diffusely); the rest is absorbed.
struct SurfaceOptics {
    double reflectance = 0;
    double transmittance = 0;
};

struct LightReportSettings {
    /// Rays from the lights in all, shared among them by their power.
    std::uint64_t rays = 1'000'000;
    std::uint64_t seed = 0;
    /// Worker threads (0: TBB's default). The numbers do not depend on it.
    int threads = 0;
    /// A path ends once its power falls below this fraction of its start (the rest is
    /// reported as `truncated`) or after max_bounces surfaces.
    double cutoff = 1e-12;
    int max_bounces = 4096;
    /// The view file's lights (directional, point, spot); false as --no-view-lights.
    bool view_lights = true;
    /// Lights traced besides the view file's, their colours linear: a directional light
    /// of colour (w, w, w) delivers irradiance w (the light environment's sources).
    std::vector<RenderLight> lights;
    /// Every surface's optics, front side then back, instead of its material's (the
    /// light environment's leaf materials); surfaces are then opaque.
    std::optional<std::array<SurfaceOptics, 2>> optics;
    /// The --sky or --env around the scene, traced too (none: not traced).
    std::shared_ptr<const Environment> environment;
    /// Repeat the scene sideways: a ray leaving the x-z bounds of every primitive through
    /// a side comes back through the opposite side (a stand of infinite extent).
    bool infinite_canopy = false;
    /// The canopy's tile, x0 z0 x1 z1, when not those bounds: it must hold them (a stand
    /// of plants spaced wider than they are).
    std::optional<std::array<double, 4>> canopy_tile;
    /// The --ground: an infinite Lambertian plane, as the renderer's (its display colour
    /// decoded to albedo), at `height` or the scene's lowest point (lowest_point). It hides
    /// what lies below its horizon (the environment's lower half, lights under it).
    struct Ground {
        geom::Rgb colour{0.5f, 0.5f, 0.5f};
        std::optional<double> height;
    };
    std::optional<Ground> ground;
};

/// One organ: a module that drew primitives, in one plant placement.
struct OrganLight {
    std::uint32_t module = geom::no_module;  ///< index in the derived string
    std::string symbol;
    std::uint16_t age = geom::unknown_age;
    std::uint32_t plant = geom::Instance::no_plant;
    double area = 0;       ///< one-sided: a flat primitive's one side, a closed one's surface
    double absorbed = 0;   ///< flux absorbed
    double absorbed_ci95 = 0;  ///< half width of its 95% confidence interval
    double incident_front = 0, incident_back = 0;  ///< flux arriving on each side
};

struct LightReport {
    std::vector<OrganLight> organs;  ///< in order of plant, then string index
    double emitted = 0;    ///< flux leaving the lights
    double absorbed = 0;   ///< by every surface, organs or not
    double unattributed = 0;  ///< of it, by primitives no module drew (background)
    double escaped = 0;    ///< left the scene
    double escaped_down = 0;  ///< of it, going down (-y): what reaches the ground
    double truncated = 0;  ///< in paths cut short (settings.cutoff, max_bounces)
    /// With a ground: its albedo (the channels' mean) and height; the flux of the traced
    /// rays that reach it (the lights' unshadowed rays, light the plant sends down; signed),
    /// the part of that it absorbs, and what it sends up into the scene (its unshadowed
    /// reflection over the whole plane, less the plant's shadow, and its reflection of the
    /// light the plant sends down). emitted + ground_emitted = absorbed + ground_reached +
    /// escaped + truncated.
    bool ground = false;
    double ground_albedo = 0, ground_height = 0;
    double ground_reached = 0, ground_absorbed = 0, ground_emitted = 0;
    std::uint64_t rays = 0;
    std::vector<std::string> lights;          ///< traced, described
    std::vector<std::string> skipped_lights;  ///< not traced (and why)
};

/// Traces the scene's lights onto its organs: the view file's directional, point and spot
/// lights and settings.environment. Irradiance unit: a directional light of diffuse
/// colour (1, 1, 1) delivers 1 to a surface facing it (the mean of its decoded colour's
/// channels in general); the renderer's irradiance is pi times it, so an environment of
/// radiance L all round gives L to a surface; area unit: the model's; flux: their
/// product. Reflection and transmission are diffuse (the glossy lobe's albedo reflects
/// with the diffuse one); transparency passes rays straight on; textures are not read.
/// The same numbers at any thread count. Throws cambium::Error (Embree).
LightReport trace_light(const geom::Scene& scene, const LightReportSettings& settings = {});

/// Writes the report as JSON (`.json`) or CSV (`.csv`), atomically. Throws cambium::Error
/// on another extension or a failed write.
void write_light_report(const LightReport& report, const std::filesystem::path& file);

}  // namespace cambium::render
