// SPDX-License-Identifier: Apache-2.0
// The rendered image and its output through OpenImageIO (render/output_format.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "render/tonemap.h"

namespace cambium::render {

/// One Cryptomatte layer (render/organ_masks.h): per pixel `depth` (id, coverage) pairs,
/// the largest coverage first (ids 0 and coverage 0 past the organs the pixel shows).
struct CryptomatteLayer {
    std::string name;  ///< the channels' prefix: name00.R, .G, .B, .A, name01.R, ...
    std::vector<float> ranks;
};

/// Organ masks (--organ-masks; docs/masks.md), empty when not asked for.
struct OrganLayers {
    int depth = 0;  ///< (id, coverage) pairs per pixel and layer; even
    std::vector<CryptomatteLayer> cryptomatte;
    /// The header's cryptomatte/<key>/name, hash, conversion and manifest attributes.
    std::vector<std::pair<std::string, std::string>> attributes;
    /// The organ covering most of each pixel: its module's index in the derived string,
    /// its age, its branch order and its plant placement; -1 where unknown or no organ.
    std::vector<float> index, age, order, plant;
    bool empty() const { return cryptomatte.empty(); }
};

/// A rendered frame: rows top to bottom, 4 floats per pixel. RGB is linear; A is the
/// coverage, the fraction of the pixel's samples whose camera ray hit geometry.
/// Normally RGB is already composited over the background (what cpfg's window shows);
/// when `transparent`, camera rays that missed contributed nothing, so RGB is
/// premultiplied by A (associated alpha, as EXR expects).
struct Image {
    int width = 0, height = 0;
    std::vector<float> rgba;
    bool transparent = false;
    /// Auxiliary layers from the camera rays, empty when not computed: the first hit's
    /// diffuse colour (3 floats per pixel) and shading normal (3, facing the camera),
    /// both averaged over the pixel's samples with misses counting as zero, and the
    /// nearest hit distance along the camera ray (1; infinity where every sample missed;
    /// perspective: from the eye, parallel: from the plane the rays start on).
    std::vector<float> albedo{}, normal{}, depth{};
    /// Where the frame was denoised (RenderSettings::denoiser), empty otherwise: the raw
    /// frame (RGBA, 4 floats per pixel; `rgba` holds the denoised one), the variance of
    /// each RGB channel's pixel mean that the denoiser was given (3), and the organ of
    /// each pixel's nearest camera-ray hit (1: the module that drew it, or
    /// render/denoise.h's organ_background, organ_ground, organ_unknown).
    /// The same variance of the albedo's and the normal's pixel means, each summed over
    /// its 3 channels (2 per pixel).
    std::vector<float> noisy{}, variance{}, feature_variance{};
    std::vector<std::uint32_t> organ{};
    /// RenderSettings::organ_mask_depth > 0: the Cryptomatte layers and organ channels.
    OrganLayers organ_masks{};

    float& at(int x, int y, int c) { return rgba[(std::size_t(y) * width + x) * 4 + c]; }
    float at(int x, int y, int c) const { return rgba[(std::size_t(y) * width + x) * 4 + c]; }
};

/// How write_image turns linear radiance into a file.
struct WriteOptions {
    /// Display formats (PNG, JPEG, TIFF) scale RGB by 2^exposure before encoding; EXR
    /// keeps the scene-referred values.
    float exposure = 0;
    /// ... and then apply this tone curve (render/tonemap.h); EXR is never tone mapped.
    ToneMap tonemap = ToneMap::none;
};

/// Writes by extension (render/output_format.h): .png, .rgb/.sgi (SGI) and .tga (Targa)
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
