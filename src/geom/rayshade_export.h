// SPDX-License-Identifier: Apache-2.0
// cpfg's -ray output (manual 6.1): the plant as a rayshade 4.0 scene, with cpfg's
// surfaces, view, lights, primitives and instanced objects (docs/export.md).
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "geom/scene.h"

namespace cambium::geom {

struct RayshadeOptions {
    /// The main object's name: cpfg uses the output file's name without its folder.
    std::string object_name = "plant.ray";
    /// Colormap mode (-m or no colour file): surfaces are the colours primitives use,
    /// ambient = diffuse. Material mode (-M): the materials' components.
    bool colormap = true;
    /// The window the view is framed for: `screen` and the horizontal field of view.
    int width = 320, height = 240;
    /// The view file's `rayshade scale:`, applied to the main object's instance.
    double scale = 1;
    /// By colour index, the material file's transparencies, which the scene's materials
    /// drop (the window draws the L-system opaque) and rayshade's surfaces keep; an index
    /// past its end keeps the scene's.
    std::vector<float> transparency;
    /// Line segments shorter than this are left out, as cpfg leaves them out (none of
    /// the corpus's files holds one shorter than 0.0033; segments up to 0.0028 long are
    /// missing from them).
    double shortest_segment = 0.003;
};

/// The scene as rayshade 4.0 text: cpfg's layout, #ifndef NOSURFACES / NOHEADERS and
/// #ifdef BBOX blocks included. Line segments become cylinders (cones where the radius
/// changes), spheres and discs stay themselves, triangles stay triangles, generalized
/// cylinders become triangles, prototypes become named objects placed by `object`.
std::string rayshade_text(const Scene& scene, const RayshadeOptions& options);

/// Writes rayshade_text() to `out` as it is made.
void write_rayshade(std::ostream& out, const Scene& scene, const RayshadeOptions& options);

/// Writes rayshade_text() as `file`, whole or not at all; throws cambium::Error naming it.
void write_rayshade(const Scene& scene, const std::filesystem::path& file,
                    const RayshadeOptions& options);

}  // namespace cambium::geom
