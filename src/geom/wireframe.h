// SPDX-License-Identifier: Apache-2.0
// `render mode: wireframe` (manual 5.2: "the wireframe of all objects is visualized"),
// as cpfg's window draws it: OpenGL in GL_LINE polygon mode, unlit. Every primitive
// becomes the edges of the polygons cpfg would send (its tessellation), drawn as
// pixel-width lines in the primitive's colour; the faces are not drawn.
#pragma once

#include "geom/scene.h"

namespace cambium::geom {

struct WireframeStyle {
    /// The edges' width in pixels (wireframe_edge_width).
    double edge_width_px = 1;
    /// Polygons around a cylinder, disc or sphere (cpfg's cylinder sides: `contour sides:`).
    int sides = 8;
    /// Spheres as gluSphere's silhouette, meridians and parallels (cpfg with a material
    /// file); otherwise the subdivided octahedron cpfg draws in colormap mode.
    bool quadric_spheres = true;
};

/// cpfg's line width in wireframe mode: the view volume's x extent over the window's
/// width in pixels over 10, which OpenGL raises to its smallest width, 1 pixel.
double wireframe_edge_width(const Bounds3& view_volume, int image_width);

/// Replaces every primitive of `scene` (its own and its prototypes') by its edges as
/// pixel-width lines (`line_radius_in_pixels` becomes true; pixel lines keep their own
/// widths, as cpfg's GL lines do):
/// - triangles: their three edges, each once; a turtle polygon's inner edges
///   (TriangleMesh::hidden_edges) are not drawn, so a polygon shows its outline;
/// - cylinders: cpfg's triangle strip of `sides` quads, each split by its diagonal, and
///   the rings at both ends (the frame carried along joined segments);
/// - generalized cylinders left as round Hermite curves: the same, over 4 pieces each;
/// - discs: their rim; spheres: as WireframeStyle::quadric_spheres says.
/// The poles of spheres lie on the z axis (cpfg orients them by the turtle, which the
/// Scene does not keep).
void draw_as_wireframe(Scene& scene, const WireframeStyle& style);

}  // namespace cambium::geom
