// SPDX-License-Identifier: Apache-2.0
// Tone curves that map scene-referred radiance to display values before sRGB encoding.
#include "render/tonemap.h"

#include <algorithm>

namespace cambium::render {

float filmic(float linear)
{
    float x = std::max(linear, 0.0f) * 0.6f;
    float y = x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f);
    return std::clamp(y, 0.0f, 1.0f);
}

}  // namespace cambium::render
