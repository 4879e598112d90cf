// SPDX-License-Identifier: Apache-2.0
// The rendered image's output through OpenImageIO (base/output_format.h).
#pragma once

#include <filesystem>

#include "render/image.h"
#include "render/tonemap.h"

namespace cambium::render {

/// How write_image turns linear radiance into a file.
struct WriteOptions {
    /// Display formats (PNG, JPEG, TIFF) scale RGB by 2^exposure before encoding; EXR
    /// keeps the scene-referred values.
    float exposure = 0;
    /// ... and then apply this tone curve (render/tonemap.h); EXR is never tone mapped.
    ToneMap tonemap = ToneMap::none;
};

/// Writes by extension (base/output_format.h): .png, .rgb/.sgi (SGI) and .tga (Targa)
/// as 8-bit sRGB (RGB, or RGBA with straight alpha when the image is transparent),
/// .jpg/.jpeg (8-bit sRGB RGB; a transparent image comes out over black), .tif/.tiff
/// (16-bit sRGB RGBA, associated alpha), .exr (half-float linear RGBA with A = coverage,
/// plus layers albedo.{R,G,B}, normal.{X,Y,Z} and a float Z for the depth when the image
/// has them, and for a denoised image noisy.{R,G,B,A} (the raw frame), variance.{R,G,B},
/// variance.{albedo,normal} and a 32-bit unsigned organ.id; with organ masks the
/// 32-bit float Cryptomatte layers, their header attributes and the organ.index, .age,
/// .order, .plant channels: docs/masks.md). The image is written to a temporary name in the same
/// folder and renamed, so a failure never leaves a partial file. Throws cambium::Error
/// naming the file on failure.
void write_image(const Image& image, const std::filesystem::path& file,
                 const WriteOptions& options = {});

/// Throws cambium::Error when `file` could not be written by write_image: an unknown
/// extension or a missing folder. Lets the command fail before rendering, not after.
void check_output_format(const std::filesystem::path& file);

}  // namespace cambium::render
