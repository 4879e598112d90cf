// SPDX-License-Identifier: Apache-2.0
// The window's projection of a Scene as flat vector shapes, sorted far to near: what the
// PostScript, SVG and PDF outputs draw (render/vector_writer.h). No drawing library here.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "geom/scene.h"
#include "geom/vec.h"
#include "render/camera.h"

namespace cambium::render {

/// One projected primitive: a filled triangle, or a stroked pixel-width line segment.
struct VectorShape {
    enum class Kind : std::uint8_t { triangle, line };
    Kind kind = Kind::triangle;
    std::array<PixelPoint, 3> points;  ///< image coordinates; a line uses the first two
    geom::Rgb colour;                  ///< display values in [0, 1]
    float line_width = 1;              ///< pixels (lines)
    double depth = 0;                  ///< along the view direction: larger is farther
};

/// A drawing of the window: its size in pixels, the background, and the shapes in the
/// order they are painted (far to near).
struct VectorDrawing {
    int width = 0, height = 0;
    geom::Rgb background;
    std::vector<VectorShape> shapes;
};

/// Memory one shape of a drawing takes, to check a drawing against --max-memory first.
inline constexpr std::uint64_t vector_shape_bytes = sizeof(VectorShape);

/// Projects `triangles` (the scene's primitives tessellated, instances placed: geometry
/// in world space) and the scene's pixel-width lines (`line style: pixel`) through
/// `camera`, colours each shape by its material (the back material where the window sees
/// a triangle's back; lit by the view's first light, as
/// vector_colour() says) and sorts them far to near by the depth of their centres
/// (painter's algorithm). Shapes wholly behind a perspective eye or outside the clipping
/// planes are left out.
VectorDrawing project_drawing(const geom::Scene& scene, const geom::TriangleMesh& triangles,
                              const Camera& camera);

/// The colour a triangle with unit normal `normal` and centre `centre` is filled with:
/// the material's base colour (a colour-index lit material's starting index), times
/// ambient + diffuse x |N.L| for the view's first light (the view direction without one;
/// cpfg's window lights both sides); unlit (the flat colour) in `render mode: filled`
/// or `wireframe`.
geom::Rgb vector_colour(const geom::Scene& scene, std::uint16_t material, const geom::Vec3& normal,
                        const geom::Vec3& centre, const Camera& camera);

}  // namespace cambium::render
