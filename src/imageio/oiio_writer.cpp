// SPDX-License-Identifier: Apache-2.0
// libcambium_imageio.so: the rendered image written through OpenImageIO (PNG, EXR, TIFF,
// JPEG).
#include "imageio/oiio_codec.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#include "base/diagnostics.h"
#include "render/color.h"
#include "base/output_format.h"

namespace cambium::render {

namespace {

/// How a file with an alpha channel stores colour: straight (PNG's rule) or
/// associated, i.e. premultiplied by alpha after encoding (TIFF's usual reading).
enum class AlphaStorage { straight, associated };

/// Display-referred pixels: exposure, sRGB-encoded, quantised to `Int` with `channels`
/// channels (3: RGB, 4: RGBA with colour stored as `storage` says).
template <class Int>
std::vector<Int> encode_srgb(const Image& image, int channels, const WriteOptions& options,
                             AlphaStorage storage = AlphaStorage::straight)
{
    constexpr float max = static_cast<float>(std::numeric_limits<Int>::max());
    float gain = std::exp2(options.exposure);
    // A transparent image's colour is premultiplied; it is encoded straight.
    bool unpremultiply = image.transparent && channels == 4;
    bool associate = channels == 4 && storage == AlphaStorage::associated;
    std::size_t n = std::size_t(image.width) * image.height;
    std::vector<Int> out(n * channels);
    for (std::size_t i = 0; i < n; ++i) {
        float alpha = std::clamp(image.rgba[i * 4 + 3], 0.0f, 1.0f);
        float scale = unpremultiply && alpha > 0 ? gain / image.rgba[i * 4 + 3] : gain;
        for (int c = 0; c < channels; ++c) {
            float v = image.rgba[i * 4 + c];
            float e = c < 3 ? linear_to_srgb(tone_map(options.tonemap, v * scale)) *
                                  (associate ? alpha : 1.0f)
                            : alpha;
            out[i * channels + c] = static_cast<Int>(std::lround(e * max));
        }
    }
    return out;
}

/// OpenImageIO stamps EXR (capDate) and TIFF files with the time of writing unless
/// DateTime is set; an empty one writes none, so identical runs give identical files.
void without_time_stamp(OIIO::ImageSpec& spec) { spec.attribute("DateTime", ""); }

bool has_layer(const Image& image, const std::vector<float>& layer, int per_pixel)
{
    return layer.size() == std::size_t(image.width) * image.height * per_pixel;
}

/// The EXR's channels interleaved: RGBA, then each AOV layer the image holds.
void write_exr(OIIO::ImageOutput& out, const Image& image, const std::filesystem::path& temp,
               bool& ok)
{
    std::vector<std::string> names{"R", "G", "B", "A"};
    std::vector<std::pair<const std::vector<float>*, int>> layers;
    if (has_layer(image, image.albedo, 3)) {
        names.insert(names.end(), {"albedo.R", "albedo.G", "albedo.B"});
        layers.emplace_back(&image.albedo, 3);
    }
    if (has_layer(image, image.normal, 3)) {
        names.insert(names.end(), {"normal.X", "normal.Y", "normal.Z"});
        layers.emplace_back(&image.normal, 3);
    }
    // A denoised image: the raw frame and the variance the denoiser was given.
    if (has_layer(image, image.noisy, 4)) {
        names.insert(names.end(), {"noisy.R", "noisy.G", "noisy.B", "noisy.A"});
        layers.emplace_back(&image.noisy, 4);
    }
    if (has_layer(image, image.variance, 3)) {
        names.insert(names.end(), {"variance.R", "variance.G", "variance.B"});
        layers.emplace_back(&image.variance, 3);
    }
    if (has_layer(image, image.feature_variance, 2)) {
        names.insert(names.end(), {"variance.albedo", "variance.normal"});
        layers.emplace_back(&image.feature_variance, 2);
    }
    const int halves = static_cast<int>(names.size());
    bool depth = has_layer(image, image.depth, 1);
    if (depth) {
        names.emplace_back("Z");
        layers.emplace_back(&image.depth, 1);
    }
    // Organ masks (docs/masks.md): Cryptomatte ids are float bit patterns and organ
    // indices whole numbers past half's range, so all in 32-bit float.
    const OrganLayers& masks = image.organ_masks;
    const bool with_masks = !masks.empty();
    if (with_masks) {
        for (const CryptomatteLayer& layer : masks.cryptomatte) {
            for (int group = 0; group < masks.depth / 2; ++group) {
                char prefix[16];
                std::snprintf(prefix, sizeof prefix, "%02d.", group);
                for (const char* c : {"R", "G", "B", "A"})
                    names.push_back(layer.name + prefix + c);
            }
            layers.emplace_back(&layer.ranks, 2 * masks.depth);
        }
        names.insert(names.end(), {"organ.index", "organ.age", "organ.order", "organ.plant"});
        for (const auto* channel : {&masks.index, &masks.age, &masks.order, &masks.plant})
            layers.emplace_back(channel, 1);
    }
    // The organ id, as a 32-bit unsigned channel (exact, unlike a float's 24 bits).
    const bool organ = image.organ.size() == std::size_t(image.width) * image.height;
    if (organ)
        names.emplace_back("organ.id");
    int channels = static_cast<int>(names.size());
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::HALF);
    spec.channelnames = names;
    spec.alpha_channel = 3;
    if (depth || organ || with_masks) {
        // Distances need more than half's 11 bits.
        spec.channelformats.assign(std::size_t(channels), OIIO::TypeDesc::HALF);
        if (depth) {
            spec.channelformats[std::size_t(halves)] = OIIO::TypeDesc::FLOAT;
            spec.z_channel = halves;
        }
        for (int c = halves + (depth ? 1 : 0); c < channels; ++c)
            spec.channelformats[std::size_t(c)] = OIIO::TypeDesc::FLOAT;
        if (organ)
            spec.channelformats.back() = OIIO::TypeDesc::UINT;
    }
    spec.attribute("oiio:ColorSpace", "Linear");
    spec.attribute("compression", "zip");
    for (const auto& [name, value] : masks.attributes)
        spec.attribute(name, value);
    without_time_stamp(spec);
    std::size_t n = std::size_t(image.width) * image.height;
    if (!organ && !with_masks) {
        std::vector<float> pixels(n * std::size_t(channels));
        for (std::size_t i = 0; i < n; ++i) {
            float* p = &pixels[i * channels];
            for (int c = 0; c < 4; ++c)
                *p++ = image.rgba[i * 4 + c];
            for (const auto& [layer, count] : layers)
                for (int c = 0; c < count; ++c)
                    *p++ = (*layer)[i * count + c];
        }
        ok = out.open(temp.string(), spec) && out.write_image(OIIO::TypeDesc::FLOAT, pixels.data());
        return;
    }
    // With the organ id or masks the channels differ in type: written in the file's own types
    // (TypeDesc::UNKNOWN), each pixel's bytes packed as the channel formats say.
    std::vector<std::size_t> offset(std::size_t(channels) + 1, 0);
    for (int c = 0; c < channels; ++c)
        offset[std::size_t(c) + 1] = offset[std::size_t(c)] + spec.channelformat(c).size();
    const std::size_t stride = offset.back();
    std::vector<unsigned char> pixels(n * stride);
    for (std::size_t i = 0; i < n; ++i) {
        unsigned char* p = &pixels[i * stride];
        int c = 0;
        auto put = [&](float v) {
            if (spec.channelformat(c) == OIIO::TypeDesc::FLOAT) {
                std::memcpy(p + offset[std::size_t(c)], &v, sizeof v);
            } else {
                OIIO::convert_pixel_values(OIIO::TypeDesc::FLOAT, &v, OIIO::TypeDesc::HALF,
                                           p + offset[std::size_t(c)]);
            }
            ++c;
        };
        for (int k = 0; k < 4; ++k)
            put(image.rgba[i * 4 + k]);
        for (const auto& [layer, count] : layers)
            for (int k = 0; k < count; ++k)
                put((*layer)[i * count + k]);
        if (organ)
            std::memcpy(p + offset[std::size_t(c)], &image.organ[i], sizeof(std::uint32_t));
    }
    ok = out.open(temp.string(), spec) &&
         out.write_image(OIIO::TypeDesc::UNKNOWN, pixels.data());
}

}  // namespace

void write_with_oiio(const Image& image, const std::filesystem::path& temp, ImageFormat format,
                     const std::filesystem::path& file, const WriteOptions& options)
{
    auto out = OIIO::ImageOutput::create(file.string());  // the format from the real name
    if (!out)
        throw Error(file.string() + ": cannot write this format: " + OIIO::geterror());
    bool ok = false;
    if (format == ImageFormat::exr) {
        write_exr(*out, image, temp, ok);
    } else if (format == ImageFormat::tiff) {
        // Opaque renders have no alpha; transparent ones store associated alpha, which
        // every TIFF reader shows right (unassociated alpha is premultiplied by some
        // readers and left alone by others).
        int channels = image.transparent ? 4 : 3;
        OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT16);
        spec.attribute("oiio:ColorSpace", "sRGB");
        without_time_stamp(spec);
        auto pixels = encode_srgb<std::uint16_t>(image, channels, options,
                                                 AlphaStorage::associated);
        ok = out->open(temp.string(), spec) &&
             out->write_image(OIIO::TypeDesc::UINT16, pixels.data());
    } else {
        int channels = output_format(format).keeps_alpha && image.transparent ? 4 : 3;
        OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
        spec.attribute("oiio:ColorSpace", "sRGB");
        without_time_stamp(spec);
        if (channels == 4)
            spec.attribute("oiio:UnassociatedAlpha", 1);
        if (format == ImageFormat::jpeg)
            spec.attribute("Compression", "jpeg:95");
        auto pixels = encode_srgb<std::uint8_t>(image, channels, options);
        ok = out->open(temp.string(), spec) &&
             out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
    }
    ok = out->close() && ok;
    if (!ok)
        throw Error(file.string() + ": cannot write the image: " + out->geterror());
}

}  // namespace cambium::render
