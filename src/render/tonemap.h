// SPDX-License-Identifier: Apache-2.0
// Tone curves that map scene-referred radiance to display values before sRGB encoding.
#pragma once

namespace cambium::render {

/// --tonemap: `none` clips at 1 (cpfg's look); `filmic` rolls highlights off smoothly.
enum class ToneMap { none, filmic };

/// The ACES filmic curve as fitted by K. Narkowicz ("ACES Filmic Tone Mapping Curve",
/// 2015): f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14) on 0.6 x (his exposure
/// match to the reference ACES transform), clamped to [0, 1]. Monotonic, f(0) = 0,
/// approaching 1 for bright values instead of clipping.
float filmic(float linear);

/// The curve's value for one channel.
inline float tone_map(ToneMap curve, float linear)
{
    return curve == ToneMap::filmic ? filmic(linear) : linear;
}

}  // namespace cambium::render
