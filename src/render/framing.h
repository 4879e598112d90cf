// SPDX-License-Identifier: Apache-2.0
// Cameras for sequences and for the command line's camera options: turntable orbits
// framed once for the whole orbit, view changes (--orbit, --zoom, --fov, --fit), and
// the object rotation and scaling of cpfg's animation frame intervals.
#pragma once

#include <optional>
#include <vector>

#include "geom/scene.h"
#include "render/camera.h"

namespace cambium::render {

/// Camera changes asked for on the command line; each overrides the view file.
struct ViewOverrides {
    std::optional<double> orbit_azimuth_deg;    ///< --orbit AZ EL: turn the viewpoint about
    std::optional<double> orbit_elevation_deg;  ///< the reference point (about +y, then up)
    double zoom = 1;                            ///< --zoom K: multiplies `scale factor`
    bool fit = false;                           ///< --fit: frame the plant's bounds
    std::optional<double> fov_deg;              ///< --fov DEG (vertical)
    std::optional<bool> perspective;            ///< --perspective / --parallel
};

/// `view` with the overrides applied. --fit drops a `box:` and a `scale factor:` (the
/// parallel auto-fit then frames `bounds` exactly); in perspective it aims at the centre
/// of `bounds` from a distance where their bounding sphere fills the field of view.
geom::View apply_overrides(geom::View view, const ViewOverrides& overrides,
                           const geom::Bounds3& bounds);

/// A turntable: `frames` cameras orbiting the view's up vector through the centre of
/// `bounds`, all with the same scale. The framing holds the cylinder the bounds sweep
/// about that axis (with `margin` of the image kept free), so the plant stays inside
/// every frame. `elevation_deg` sets the angle of the view above the plane
/// perpendicular to up (default: the view's own). The view's `scale factor` (--zoom)
/// magnifies the fitted framing as make_camera does (pixels smaller by the factor in
/// parallel, the eye nearer by it in perspective), so a factor above 1 may crop the plant.
/// The view's clipping planes are not applied (an orbit would cut through them).
std::vector<Camera> turntable_cameras(const geom::View& view, const geom::Bounds3& bounds,
                                      int frames, std::optional<double> elevation_deg,
                                      int width, int height, double margin = 0.05);

/// `camera` as it sees the object rotated by `rotation_deg` (about x, then y, then z)
/// and scaled by `scale` about the world origin: cpfg's `rotate` / `scale` of frame
/// intervals. Unequal scale factors are applied as their geometric mean. `bounds` (the
/// geometry's) place a parallel camera's ray origins behind everything.
Camera transform_object_view(const Camera& camera, const geom::Vec3& rotation_deg,
                             const geom::Vec3& scale, const geom::Bounds3& bounds);

}  // namespace cambium::render
