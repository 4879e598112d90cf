// SPDX-License-Identifier: Apache-2.0
// cpfg's colormap-mode lighting (manual 5.2.5): instead of shading by lights, a surface's
// colour index moves along its colormap ramp with the cosine to the light.
#pragma once

#include "geom/palette.h"
#include "geom/scene.h"
#include "geom/view_file.h"

namespace cambium::geom {

/// Whether cpfg lights this model by moving colour indices: colormap mode (a -m file or
/// none) in render mode flat or shaded, but not cpfg's interpolated fill, which it draws
/// without any lighting.
bool lit_by_colour_index(const ViewFile& view, const Palette& palette);

/// Sets the scene's ColourIndexLight from the view file and lays its materials out for
/// it: 0..255 the selected colormap `colour_block` (cosine rule), 256..511 the same
/// (surface rule, for predefined surfaces and patches), 512..767 the next colormap
/// (surface rule) for patch colours past 255.
void light_by_colour_index(Scene& scene, const ViewFile& view, const Palette& palette, int colour_block);

}  // namespace cambium::geom
