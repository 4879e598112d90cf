// SPDX-License-Identifier: Apache-2.0
// `@L` labels drawn as cpfg's window draws them: screen-space text at the projected turtle
// position, in the label's colour, hidden where the plant is in front of it.
#pragma once

#include <cstdint>
#include <optional>

#include "base/limits.h"

#include "geom/scene.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/image.h"

namespace cambium::render {

/// Draws the scene's labels onto `image` (linear, RGB premultiplied by A): each text
/// rasterised by FreeType in the font fontconfig matches to Scene::label_font (its size
/// in pixels, whatever the image size, as cpfg's bitmap fonts), its baseline starting at
/// the projected label position (OpenGL's raster position: a label whose anchor is off
/// the image or outside the clipping planes is not drawn). Every text pixel keeps the
/// anchor's depth and is hidden where the scene has a surface in front of that depth
/// along the pixel's ray (cpfg's depth-tested glBitmap). Colour: the label material's
/// diffuse colour as a display value. Throws cambium::Error when labels have text and no
/// font file can be found (install fonts-dejavu-core) or read.
/// Where `image` lies in the whole picture: a crop (RenderSettings::crop) at (x, y) of a
/// picture width x height, so a label is drawn on the pixels of the crop it covers.
struct LabelCanvas {
    int x = 0, y = 0, width = 0, height = 0;
};
/// What drawing labels may cost (docs/security.md): the glyphs of the font and one depth
/// per image pixel (the first surface along its ray, traced once for all labels) within
/// the memory budget, and at most `max_glyph_pixels` coverage pixels composited in all
/// (about a second of work; a million ten-character labels at 12 pixels take ~6e8).
struct LabelLimits {
    std::uint64_t max_memory_bytes = default_max_memory_bytes();
    std::uint64_t max_glyph_pixels = std::uint64_t{1} << 30;
};
/// `canvas`: none when the image is the whole picture. Throws cambium::Error naming the
/// limit when `limits` are exceeded, before anything is drawn.
void draw_labels(Image& image, const geom::Scene& scene, const Camera& camera, const EmbreeScene& accel,
                 std::optional<LabelCanvas> canvas = std::nullopt, const LabelLimits& limits = {});

}  // namespace cambium::render
