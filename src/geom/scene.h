// SPDX-License-Identifier: Apache-2.0
// The Scene: renderer-independent plain data produced by the turtle, consumed by render.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "geom/vec.h"

namespace cambium::geom {

/// Round linear curve segments (cylinders drawn by F and G), in the layout Embree
/// takes directly: a key buffer (x, y, z, radius) and one first-key index per segment;
/// segment i spans keys[segments[i]] .. keys[segments[i] + 1].
struct LinearCurves {
    /// Embree's RTC_CURVE_FLAG_NEIGHBOR_LEFT / _RIGHT values: the segment continues a
    /// previous segment at its start / is continued by the next one at its end, so the
    /// joint is closed without a cap or a bulge.
    static constexpr std::uint8_t neighbour_left = 1;
    static constexpr std::uint8_t neighbour_right = 2;

    std::vector<std::array<float, 4>> keys;
    std::vector<std::uint32_t> segments;
    std::vector<std::uint8_t> flags;       ///< per segment, neighbour_* bits
    std::vector<std::uint16_t> material;   ///< per segment, index into Scene::materials

    std::size_t segment_count() const { return segments.size(); }
};

/// A cpfg material (manual 5.4.2) or colormap entry (5.4.1, as diffuse), with the
/// file's display values in [0, 1]. render decodes them (docs/materials.md).
struct Material {
    Rgb ambient{0.2f, 0.2f, 0.2f};
    Rgb diffuse{0.8f, 0.8f, 0.8f};
    Rgb emission{0, 0, 0};
    Rgb specular{0, 0, 0};
    float shininess = 0;     ///< 0..128
    float transparency = 0;  ///< 0 opaque .. 1 fully transparent
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

/// Everything render needs to draw one frame of a plant.
struct Scene {
    LinearCurves lines;
    /// true when line radii are in pixels (`line style: pixel`): render converts
    /// them with its camera's pixel footprint.
    bool line_radius_in_pixels = false;

    std::vector<Material> materials = std::vector<Material>(256);  ///< by colour index
    Rgb background{0, 0, 0};  ///< display values: colormap entry 0 or material 0's emission
    std::vector<Light> lights;
    View view;
    /// Bounds of the interpreted geometry as cpfg computes them for the auto-fit.
    Bounds3 bounds;
};

}  // namespace cambium::geom
