// SPDX-License-Identifier: Apache-2.0
// A texture's pixels and their MIP levels in memory, filtered as OpenGL filters a
// GL_REPEAT texture (nearest or linear within a level, linear between levels).
//
// Why not OpenImageIO's TextureSystem, which the textures used to go through: its tile
// cache and general filters cost 3 to 4 times as much a lookup, a fifth of the render
// time of a textured plant (docs/benchmarks.md), while a view file's textures are small
// images that fit in memory whole. OpenImageIO still decodes the files (render/image_codec.h).
#pragma once

#include <cstdint>
#include <vector>

#include "render/texture.h"

namespace cambium::render {

/// A decoded texture file: rows top to bottom, `channels` values a pixel (1 grey,
/// 2 grey and alpha, 3 RGB, 4 RGBA). 8-bit files keep their bytes (values / 255); deeper
/// ones are stored as floats, 16-bit ones scaled to [0, 1].
struct TexturePixels {
    int width = 0, height = 0, channels = 0;
    std::vector<std::uint8_t> bytes;  // 8-bit files
    std::vector<float> floats;        // 16-bit and floating-point files
    /// Whether the values are display values (integer files), decoded as sRGB after
    /// filtering; floating-point files hold linear values.
    bool srgb = true;
};

/// How a texture is filtered (the texture: line's options, geom::TextureDef).
struct TextureFilter {
    bool linear = true;  // bilinear within a level, else the nearest texel
    bool mipmap = true;  // MIP levels chosen by the footprint, else the finest level only
};

/// A texture's MIP pyramid and its lookups. Read-only after construction, so lookups
/// from many threads need no locks.
class MipMap {
public:
    /// Builds the levels from the pixels (each level half the last, box-filtered, down to
    /// one texel). Throws std::invalid_argument for empty pixels or a channel count out
    /// of 1..4.
    MipMap(TexturePixels pixels, TextureFilter filter);

    int channels() const { return m_channels; }
    bool has_alpha() const { return m_channels == 2 || m_channels == 4; }
    /// Whether a lookup at the finest level can give alpha below 1/2 (the cut-out test):
    /// false when every texel's alpha is at least 128/255 (floats: 0.501), since a blend
    /// of such texels stays above 1/2 by far more than its rounding.
    bool can_cut_out() const { return m_can_cut_out; }
    std::size_t levels() const { return m_levels.size(); }
    /// The finest level's longer side in texels, where lookup() chooses a level by the
    /// footprint; 0 where it has only the one level (any footprint gives the finest).
    float footprint_texels() const { return m_footprint_texels; }
    /// Bytes held by all levels.
    std::uint64_t bytes() const;

    /// The filtered texel at OpenGL's (s, t): t = 0 the bottom row, both wrapping. The
    /// footprint chooses the level (its longer axis, in texels of the finest level).
    Texel lookup(float s, float t, const TextureFootprint& footprint) const;

private:
    struct Level {
        int width, height;
        std::vector<std::uint8_t> bytes;
        std::vector<float> floats;
    };
    /// The level's values at s and `down` (both in [0, 1], down from the top row),
    /// unconverted: 4 values (grey filled out to RGB, missing alpha 1).
    void sample(const Level& level, float s, float down, float out[4]) const;

    std::vector<Level> m_levels;
    int m_channels;
    bool m_srgb;
    bool m_can_cut_out = false;
    float m_footprint_texels = 0;
    TextureFilter m_filter;
};

}  // namespace cambium::render
