// SPDX-License-Identifier: Apache-2.0
// Which pixels' camera rays can meet the scene at all: every primitive's bounds projected
// through the camera, so that a pixel no bounds reach is known to show the background
// without tracing a ray (most of a plant's frame is empty sky).
#pragma once

#include <cstdint>
#include <vector>

#include "geom/scene.h"
#include "render/camera.h"

namespace cambium::render {

/// A conservative mask over the image: may_hit() is false only where no camera sample of
/// the pixel (within `reach` pixels of its centre) can meet any primitive of the scene.
/// Kept in square blocks of pixels (one pixel each up to a million pixels; larger images
/// use larger blocks, so the mask stays within a few megabytes).
class ScreenMask {
public:
    /// Every pixel may be hit: nothing is skipped.
    ScreenMask() = default;

    /// The mask of `scene` seen through `camera` (a pinhole or parallel camera: a lens
    /// spreads each pixel's rays over the aperture, which the mask does not model).
    /// `reach`: how far from a pixel's centre its samples lie, in pixels (the filter's
    /// radius; 0.5 for the box filter). Primitives with coordinates that are not finite,
    /// or a box that reaches behind a perspective camera's eye, make every pixel count.
    /// The projection runs in parallel on the caller's TBB arena.
    ScreenMask(const geom::Scene& scene, const Camera& camera, double reach);

    /// Whether a camera ray of pixel (x, y) may meet a primitive (x, y within the image).
    bool may_hit(int x, int y) const
    {
        if (m_cells.empty())
            return true;
        return m_cells[std::size_t(y >> m_shift) * m_columns + std::size_t(x >> m_shift)] != 0;
    }

    /// The share of the image's pixels known to show only the background (0 for a mask
    /// that skips nothing).
    double empty_share() const { return m_empty_share; }

    /// Pixels added around every primitive's projection beyond the samples' reach: the
    /// float rounding of camera rays and of Embree's intersection tests is far below it.
    static constexpr double safety_px = 1.5;

private:
    std::vector<std::uint8_t> m_cells;  ///< per block: 1 when some projection touches it
    std::size_t m_columns = 0;
    int m_shift = 0;  ///< blocks are 2^shift pixels square
    double m_empty_share = 0;
};

}  // namespace cambium::render
