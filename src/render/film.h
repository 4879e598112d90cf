// SPDX-License-Identifier: Apache-2.0
// The rendered image and its output through OpenImageIO (PNG, EXR, TIFF, JPEG).
#pragma once

#include <filesystem>
#include <vector>

namespace cambium::render {

/// A rendered frame: rows top to bottom, 4 floats per pixel. RGB is linear and already
/// composited over the background (what cpfg's window shows); A is the coverage, the
/// fraction of the pixel's samples whose camera ray hit geometry.
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgba;

    float& at(int x, int y, int c) { return rgba[(std::size_t(y) * width + x) * 4 + c]; }
    float at(int x, int y, int c) const { return rgba[(std::size_t(y) * width + x) * 4 + c]; }
};

/// Writes by extension: .png (8-bit sRGB RGB), .jpg/.jpeg (8-bit sRGB RGB), .tif/.tiff
/// (16-bit sRGB RGBA), .exr (linear half-float RGBA, A = coverage). The image is written to
/// a temporary name in the same folder and renamed, so a failure never leaves a partial
/// file. Throws cambium::Error naming the file on failure.
void write_image(const Image& image, const std::filesystem::path& file);

/// Throws cambium::Error when `file` could not be written by write_image: an unknown
/// extension or a missing folder. Lets the command fail before rendering, not after.
void check_output_format(const std::filesystem::path& file);

}  // namespace cambium::render
