// SPDX-License-Identifier: Apache-2.0
// `@L` labels drawn as cpfg's window draws them: screen-space text at the projected turtle
// position, in the label's colour, hidden where the plant is in front of it.
#pragma once

#include <optional>

#include "geom/scene.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/image_io.h"

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
/// `canvas`: none when the image is the whole picture.
void draw_labels(Image& image, const geom::Scene& scene, const Camera& camera, const EmbreeScene& accel,
                 std::optional<LabelCanvas> canvas = std::nullopt);

}  // namespace cambium::render
