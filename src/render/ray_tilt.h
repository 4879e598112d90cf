// SPDX-License-Identifier: Apache-2.0
// The tilt of rays traced in scenes with Embree's round Hermite curves.
#pragma once

#include <cmath>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "render/vecf.h"

namespace cambium::render {

/// Embree's round Hermite curves are many times slower for a ray with a direction
/// component exactly zero (9x per sample on the corpus's GeneralizedCylinder, whose every
/// camera ray, as in cpfg's default parallel view, points down -z). In scenes with such
/// curves, components below a millionth of the largest are raised to that: a tilt under
/// 1e-6 rad, far below a pixel. (Other scenes keep their rays exact: pixel-width lines
/// are drawn to OpenGL's exact pixels.)
/// (Without branches, on SSE: a camera ray has two tiny components, a bounce none, so
/// the scalar code's three branches were mispredicted often.)
inline Vec3f off_axis(const Vec3f& d)
{
#if defined(__SSE2__)
    const __m128 v = _mm_set_ps(0.0f, d.z, d.y, d.x);
    const __m128 sign = _mm_set1_ps(-0.0f);
    const __m128 magnitude = _mm_andnot_ps(sign, v);
    // the largest of the three, in every lane (the fourth is zero, never the largest)
    __m128 largest = _mm_max_ps(magnitude, _mm_shuffle_ps(magnitude, magnitude, 0b10110001));
    largest = _mm_max_ps(largest, _mm_shuffle_ps(largest, largest, 0b01001110));
    const __m128 least = _mm_mul_ps(_mm_set1_ps(1e-6f), largest);
    const __m128 raise = _mm_cmplt_ps(magnitude, least);
    const __m128 raised = _mm_or_ps(_mm_and_ps(v, sign), least);  // copysign(least, c)
    const __m128 out = _mm_or_ps(_mm_and_ps(raise, raised), _mm_andnot_ps(raise, v));
    alignas(16) float c[4];
    _mm_store_ps(c, out);
    return {c[0], c[1], c[2]};
#else
    float least = 1e-6f * std::fmax(std::fabs(d.x), std::fmax(std::fabs(d.y), std::fabs(d.z)));
    auto raise = [least](float c) { return std::fabs(c) < least ? std::copysign(least, c) : c; };
    return {raise(d.x), raise(d.y), raise(d.z)};
#endif
}

}  // namespace cambium::render
