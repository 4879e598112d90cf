// SPDX-License-Identifier: Apache-2.0
#include "render/mip_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "render/color.h"

namespace cambium::render {

namespace {

/// i modulo n, in [0, n) for negative i too.
int wrap(int i, int n)
{
    int r = i % n;
    return r < 0 ? r + n : r;
}

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

/// srgb_to_linear on [0, 1] from a table, linearly interpolated: within 5e-7 of the
/// curve (its second derivative is below 4), and without a powf per channel per lookup.
float decode_srgb(float v)
{
    constexpr int steps = 1024;
    static const std::array<float, steps + 2> table = [] {
        std::array<float, steps + 2> t{};
        for (int i = 0; i <= steps; ++i)
            t[i] = srgb_to_linear(float(i) / steps);
        t[steps + 1] = t[steps];
        return t;
    }();
    const float x = std::fmin(std::fmax(v, 0.0f), 1.0f) * steps;  // NaN -> 0
    const int i = static_cast<int>(x);
    return table[i] + (x - float(i)) * (table[i + 1] - table[i]);
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
}

std::uint64_t MipMap::bytes() const
{
    std::uint64_t total = 0;
    for (const Level& level : m_levels)
        total += level.bytes.size() + level.floats.size() * sizeof(float);
    return total;
}

void MipMap::fetch(const Level& level, int x, int y, float out[4]) const
{
    const std::size_t at = (std::size_t(y) * level.width + x) * m_channels;
    float v[4];
    if (!level.bytes.empty())
        for (int c = 0; c < m_channels; ++c)
            v[c] = level.bytes[at + c] * (1.0f / 255.0f);
    else
        for (int c = 0; c < m_channels; ++c)
            v[c] = level.floats[at + c];
    switch (m_channels) {
    case 1: out[0] = out[1] = out[2] = v[0], out[3] = 1; break;
    case 2: out[0] = out[1] = out[2] = v[0], out[3] = v[1]; break;
    case 3: out[0] = v[0], out[1] = v[1], out[2] = v[2], out[3] = 1; break;
    default: out[0] = v[0], out[1] = v[1], out[2] = v[2], out[3] = v[3]; break;
    }
}

void MipMap::sample(const Level& level, float s, float t, float out[4]) const
{
    // Rows run top to bottom, OpenGL's t bottom to top.
    const float x = repeat(s) * float(level.width), y = repeat(1 - t) * float(level.height);
    if (!m_filter.linear) {
        fetch(level, std::min(int(x), level.width - 1), std::min(int(y), level.height - 1), out);
        return;
    }
    // Texel centres sit at half-integer coordinates.
    const float fx = x - 0.5f, fy = y - 0.5f;
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float ax = fx - x0f, ay = fy - y0f;
    const int x0 = wrap(int(x0f), level.width), x1 = wrap(int(x0f) + 1, level.width);
    const int y0 = wrap(int(y0f), level.height), y1 = wrap(int(y0f) + 1, level.height);
    float a[4], b[4], c[4], d[4];
    fetch(level, x0, y0, a);
    fetch(level, x1, y0, b);
    fetch(level, x0, y1, c);
    fetch(level, x1, y1, d);
    for (int k = 0; k < 4; ++k)
        out[k] = (1 - ay) * ((1 - ax) * a[k] + ax * b[k]) + ay * ((1 - ax) * c[k] + ax * d[k]);
}

Texel MipMap::lookup(float s, float t, const TextureFootprint& fp) const
{
    float v[4];
    const Level& finest = m_levels.front();
    // The footprint's longer axis, in texels of the finest level: its log2 is the level.
    const float w = float(finest.width), h = float(finest.height);
    const float ax = fp.dsdx * w, ay = fp.dtdx * h, bx = fp.dsdy * w, by = fp.dtdy * h;
    const float extent2 = std::fmax(ax * ax + ay * ay, bx * bx + by * by);
    if (m_levels.size() == 1 || !(extent2 > 1)) {
        sample(finest, s, t, v);
    } else {
        const float lod = std::fmin(0.5f * std::log2(extent2), float(m_levels.size() - 1));
        const std::size_t fine = static_cast<std::size_t>(lod);
        const float blend = lod - float(fine);
        sample(m_levels[fine], s, t, v);
        if (blend > 0 && fine + 1 < m_levels.size()) {
            float coarse[4];
            sample(m_levels[fine + 1], s, t, coarse);
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
