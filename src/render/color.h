// SPDX-License-Identifier: Apache-2.0
// sRGB transfer functions: cpfg colours are display values, the renderer works in linear RGB.
#pragma once

#include <cmath>

#include "geom/vec.h"
#include "render/vecf.h"

namespace cambium::render {

/// The sRGB decoding curve (IEC 61966-2-1): display value in [0, 1] -> linear.
inline float srgb_to_linear(float v)
{
    v = std::fmin(std::fmax(v, 0.0f), 1.0f);
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

/// The sRGB encoding curve: linear -> display value in [0, 1] (clamped).
inline float linear_to_srgb(float v)
{
    v = std::fmin(std::fmax(v, 0.0f), 1.0f);
    return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

/// Decodes a cpfg display colour (colormap, material, background, light) to linear RGB.
inline Vec3f decode_display(const geom::Rgb& c)
{
    return {srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b)};
}

}  // namespace cambium::render
