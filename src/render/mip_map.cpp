// SPDX-License-Identifier: Apache-2.0
#include "render/mip_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "render/color.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace cambium::render {

namespace {

/// The fractional part of a texture coordinate: GL_REPEAT makes only it matter, and
/// taking it first keeps the texel arithmetic in int range for any coordinate.
float repeat(float c)
{
    if (!std::isfinite(c))
        return 0;
    return c - std::floor(c);
}

/// The finer level's texels [begin, end) that make up coarser texel i of n along an axis
/// of `size` texels: two, or three where the size is odd.
std::pair<int, int> span(int i, int n, int size)
{
    return {static_cast<int>(std::int64_t(i) * size / n),
            static_cast<int>(std::int64_t(i + 1) * size / n)};
}

/// The next coarser level's values: each texel the mean of the finer ones it covers.
template <typename T>
std::vector<T> reduce(const std::vector<T>& fine, int width, int height, int channels,
                      int coarse_width, int coarse_height)
{
    std::vector<T> coarse(std::size_t(coarse_width) * coarse_height * channels);
    for (int j = 0; j < coarse_height; ++j) {
        auto [y0, y1] = span(j, coarse_height, height);
        for (int i = 0; i < coarse_width; ++i) {
            auto [x0, x1] = span(i, coarse_width, width);
            float count = float((x1 - x0) * (y1 - y0));
            for (int c = 0; c < channels; ++c) {
                float sum = 0;
                for (int y = y0; y < y1; ++y)
                    for (int x = x0; x < x1; ++x)
                        sum += float(fine[(std::size_t(y) * width + x) * channels + c]);
                float mean = sum / count;
                T& out = coarse[(std::size_t(j) * coarse_width + i) * channels + c];
                if constexpr (std::is_same_v<T, std::uint8_t>)
                    out = static_cast<std::uint8_t>(std::lround(std::clamp(mean, 0.0f, 255.0f)));
                else
                    out = mean;
            }
        }
    }
    return coarse;
}

/// srgb_to_linear at i / srgb_steps, and the step to the next entry (0 after the last:
/// decode_srgb reads entry srgb_steps too). One 8-byte load a channel; the step is the
/// same float subtraction decode_srgb made at every lookup. Filled before main: no guard
/// on each lookup.
constexpr int srgb_steps = 1024;
struct SrgbEntry {
    float value, step;
};
const std::array<SrgbEntry, srgb_steps + 1> srgb_table = [] {
    std::array<float, srgb_steps + 1> v{};
    for (int i = 0; i <= srgb_steps; ++i)
        v[i] = srgb_to_linear(float(i) / srgb_steps);
    std::array<SrgbEntry, srgb_steps + 1> t{};
    for (int i = 0; i <= srgb_steps; ++i)
        t[i] = {v[i], (i < srgb_steps ? v[i + 1] : v[i]) - v[i]};
    return t;
}();

/// srgb_to_linear on [0, 1] from the table, linearly interpolated: within 5e-7 of the
/// curve (its second derivative is below 4), and without a powf per channel per lookup.
/// (Filtering comes first, so the value is not one of 256 bytes: no byte table does.)
float decode_srgb(float v)
{
    // std::fmin and std::fmax are library calls here; NaN -> 0 as with them.
    const float x = (v > 0 ? (v < 1 ? v : 1.0f) : 0.0f) * srgb_steps;
    const int i = static_cast<int>(x);
    const SrgbEntry& e = srgb_table[i];
    return e.value + (x - float(i)) * e.step;
}

}  // namespace

MipMap::MipMap(TexturePixels pixels, TextureFilter filter)
    : m_channels(pixels.channels), m_srgb(pixels.srgb), m_filter(filter)
{
    const std::size_t values = std::size_t(std::max(pixels.width, 0)) *
                               std::size_t(std::max(pixels.height, 0)) *
                               std::size_t(std::max(pixels.channels, 0));
    if (pixels.width <= 0 || pixels.height <= 0 || pixels.channels < 1 || pixels.channels > 4 ||
        (pixels.bytes.size() != values && pixels.floats.size() != values))
        throw std::invalid_argument("MipMap: empty pixels or a channel count out of 1..4");
    const bool bytes = pixels.bytes.size() == values;
    if (has_alpha())
        for (std::size_t i = std::size_t(m_channels) - 1; i < values; i += m_channels)
            if (bytes ? pixels.bytes[i] < 128 : !(pixels.floats[i] >= 0.501f)) {
                m_can_cut_out = true;
                break;
            }
    m_levels.push_back({pixels.width, pixels.height,
                        bytes ? std::move(pixels.bytes) : std::vector<std::uint8_t>{},
                        bytes ? std::vector<float>{} : std::move(pixels.floats)});
    while (filter.mipmap && (m_levels.back().width > 1 || m_levels.back().height > 1)) {
        const Level& fine = m_levels.back();
        Level coarse{std::max(1, fine.width / 2), std::max(1, fine.height / 2), {}, {}};
        if (bytes)
            coarse.bytes = reduce(fine.bytes, fine.width, fine.height, m_channels, coarse.width,
                                  coarse.height);
        else
            coarse.floats = reduce(fine.floats, fine.width, fine.height, m_channels,
                                   coarse.width, coarse.height);
        m_levels.push_back(std::move(coarse));
    }
    if (m_levels.size() > 1)
        m_footprint_texels = float(std::max(m_levels.front().width, m_levels.front().height));
}

std::uint64_t MipMap::bytes() const
{
    std::uint64_t total = 0;
    for (const Level& level : m_levels)
        total += level.bytes.size() + level.floats.size() * sizeof(float);
    return total;
}

namespace {

/// A stored value as a float: bytes are display values over 255.
inline float value(std::uint8_t v) { return v * (1.0f / 255.0f); }
inline float value(float v) { return v; }

/// A texel's RGBA from its C stored channels: grey fills out R, G and B, and a texture
/// without alpha is opaque.
template <int C, class T>
inline void texel_rgba(const T* texel, float out[4])
{
    const float first = value(texel[0]);
    if constexpr (C <= 2) {
        out[0] = out[1] = out[2] = first;
        out[3] = C == 2 ? value(texel[1]) : 1.0f;
    } else {
        out[0] = first, out[1] = value(texel[1]), out[2] = value(texel[2]);
        out[3] = C == 4 ? value(texel[3]) : 1.0f;
    }
}

/// The index along an axis of n texels of i in [-n, 2n): GL_REPEAT without a division
/// (a bilinear pair's first texel is at least -1, its second at most n).
inline int wrap_near(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }

/// Where a sample falls in a level: the texels around it and the weights between them
/// (nearest: x0, y0 only).
struct Footing {
    std::size_t row0, row1;  // first values of rows y0 and y1
    int x0, x1;
    float ax, ay;
};

/// The bilinear blend of the four texels of `at`, channel by channel (grey's three
/// colour channels are one value, blended once).
template <int C, class T>
void blend4(const T* data, const Footing& at, float out[4])
{
    float a[4], b[4], c[4], d[4];
    texel_rgba<C>(data + at.row0 + std::size_t(at.x0) * C, a);
    texel_rgba<C>(data + at.row0 + std::size_t(at.x1) * C, b);
    texel_rgba<C>(data + at.row1 + std::size_t(at.x0) * C, c);
    texel_rgba<C>(data + at.row1 + std::size_t(at.x1) * C, d);
    const float ax = at.ax, ay = at.ay;
    auto lerp2 = [&](int k) {
        return (1 - ay) * ((1 - ax) * a[k] + ax * b[k]) + ay * ((1 - ax) * c[k] + ax * d[k]);
    };
    if constexpr (C <= 2) {
        out[0] = out[1] = out[2] = lerp2(0);
        out[3] = C == 2 ? lerp2(3) : 1.0f;
    } else {
        for (int k = 0; k < 3; ++k)
            out[k] = lerp2(k);
        out[3] = C == 4 ? lerp2(3) : 1.0f;
    }
}

#if defined(__SSE2__)
/// 8-bit RGBA, the usual texture, four channels to a register: the same operations
/// lane by lane as the generic blend4, so the same values bit for bit.
template <>
void blend4<4, std::uint8_t>(const std::uint8_t* data, const Footing& at, float out[4])
{
    const __m128i zero = _mm_setzero_si128();
    const __m128 scale = _mm_set1_ps(1.0f / 255.0f);
    auto texel = [&](std::size_t first) {
        std::int32_t bits;
        std::memcpy(&bits, data + first, sizeof bits);
        const __m128i bytes = _mm_cvtsi32_si128(bits);
        const __m128i ints = _mm_unpacklo_epi16(_mm_unpacklo_epi8(bytes, zero), zero);
        return _mm_mul_ps(_mm_cvtepi32_ps(ints), scale);
    };
    const __m128 a = texel(at.row0 + std::size_t(at.x0) * 4);
    const __m128 b = texel(at.row0 + std::size_t(at.x1) * 4);
    const __m128 c = texel(at.row1 + std::size_t(at.x0) * 4);
    const __m128 d = texel(at.row1 + std::size_t(at.x1) * 4);
    const __m128 one = _mm_set1_ps(1.0f), ax = _mm_set1_ps(at.ax), ay = _mm_set1_ps(at.ay);
    const __m128 bx = _mm_sub_ps(one, ax), by = _mm_sub_ps(one, ay);
    const __m128 top = _mm_add_ps(_mm_mul_ps(bx, a), _mm_mul_ps(ax, b));
    const __m128 bottom = _mm_add_ps(_mm_mul_ps(bx, c), _mm_mul_ps(ax, d));
    _mm_storeu_ps(out, _mm_add_ps(_mm_mul_ps(by, top), _mm_mul_ps(ay, bottom)));
}
#endif

template <class T>
void blend4(int channels, const T* data, const Footing& at, float out[4])
{
    switch (channels) {
    case 1: blend4<1>(data, at, out); break;
    case 2: blend4<2>(data, at, out); break;
    case 3: blend4<3>(data, at, out); break;
    default: blend4<4>(data, at, out); break;
    }
}

template <class T>
void nearest(int channels, const T* texel, float out[4])
{
    switch (channels) {
    case 1: texel_rgba<1>(texel, out); break;
    case 2: texel_rgba<2>(texel, out); break;
    case 3: texel_rgba<3>(texel, out); break;
    default: texel_rgba<4>(texel, out); break;
    }
}

}  // namespace

void MipMap::sample(const Level& level, float s, float down, float out[4]) const
{
    const float x = s * float(level.width), y = down * float(level.height);
    const std::size_t row = std::size_t(level.width) * m_channels;
    if (!m_filter.linear) {
        const std::size_t at = std::size_t(std::min(int(y), level.height - 1)) * row +
                               std::size_t(std::min(int(x), level.width - 1)) * m_channels;
        if (!level.bytes.empty())
            nearest(m_channels, level.bytes.data() + at, out);
        else
            nearest(m_channels, level.floats.data() + at, out);
        return;
    }
    // Texel centres sit at half-integer coordinates.
    const float fx = x - 0.5f, fy = y - 0.5f;
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const int y0 = wrap_near(int(y0f), level.height), y1 = wrap_near(int(y0f) + 1, level.height);
    const Footing at{std::size_t(y0) * row, std::size_t(y1) * row,
                     wrap_near(int(x0f), level.width), wrap_near(int(x0f) + 1, level.width),
                     fx - x0f, fy - y0f};
    if (!level.bytes.empty())
        blend4(m_channels, level.bytes.data(), at, out);
    else
        blend4(m_channels, level.floats.data(), at, out);
}

Texel MipMap::lookup(float s_gl, float t_gl, const TextureFootprint& fp) const
{
    // Rows run top to bottom, OpenGL's t bottom to top.
    const float s = repeat(s_gl), down = repeat(1 - t_gl);
    float v[4];
    const Level& finest = m_levels.front();
    // The footprint's longer axis, in texels of the finest level: its log2 is the level.
    const float w = float(finest.width), h = float(finest.height);
    const float ax = fp.dsdx * w, ay = fp.dtdx * h, bx = fp.dsdy * w, by = fp.dtdy * h;
    const float a2 = ax * ax + ay * ay, b2 = bx * bx + by * by;
    const float extent2 = a2 > b2 || std::isnan(b2) ? a2 : b2;  // std::fmax, inline
    if (m_levels.size() == 1 || !(extent2 > 1)) {
        sample(finest, s, down, v);
    } else {
        const float lod = std::min(0.5f * std::log2(extent2), float(m_levels.size() - 1));
        const std::size_t fine = static_cast<std::size_t>(lod);
        const float blend = lod - float(fine);
        sample(m_levels[fine], s, down, v);
        if (blend > 0 && fine + 1 < m_levels.size()) {
            float coarse[4];
            sample(m_levels[fine + 1], s, down, coarse);
            for (int k = 0; k < 4; ++k)
                v[k] += blend * (coarse[k] - v[k]);
        }
    }
    Texel texel{{v[0], v[1], v[2]}, v[3]};
    if (m_srgb)
        texel.colour = {decode_srgb(texel.colour.x), decode_srgb(texel.colour.y),
                        decode_srgb(texel.colour.z)};
    return texel;
}

}  // namespace cambium::render
