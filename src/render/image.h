// SPDX-License-Identifier: Apache-2.0
// The rendered image: RGBA and the layers beside it, and rectangles of its pixels.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace cambium::render {

/// A rectangle of pixels: columns x .. x + width - 1 and rows y .. y + height - 1, rows
/// counted from the top.
struct PixelRect {
    int x = 0, y = 0, width = 0, height = 0;
    bool empty() const { return width <= 0 || height <= 0; }
    bool operator==(const PixelRect&) const = default;
};

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

}  // namespace cambium::render
