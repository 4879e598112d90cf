// SPDX-License-Identifier: Apache-2.0
// libcambium_imageio.so: a texture file's pixels, decoded by OpenImageIO (any format it
// reads, SGI .rgb included). Filtering is the render layer's (render/mip_map.h).
#include "imageio/oiio_codec.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <string>

#include "base/diagnostics.h"

namespace cambium::render {

namespace {

/// Refuses, from its header alone, a texture too large to decode: a small file may
/// declare 30000 x 30000 pixels. 8-bit files are kept as bytes, deeper ones as floats.
void check_texture_size(const std::filesystem::path& file, const OIIO::ImageSpec& spec,
                        std::uint64_t max_memory_bytes)
{
    if (spec.width > max_texture_side || spec.height > max_texture_side || spec.depth > 1)
        throw Error(FileLoc{file.string()},
                    "texture is " + std::to_string(spec.width) + " x " +
                        std::to_string(spec.height) +
                        (spec.depth > 1 ? " x " + std::to_string(spec.depth) : std::string()) +
                        " pixels; textures may have at most " + std::to_string(max_texture_side) +
                        " pixels on a side (and one layer)");
    // the decoded pixels and their MIP levels (a third more)
    const std::uint64_t value_bytes = spec.format.size() == 1 ? 1 : sizeof(float);
    std::uint64_t bytes = std::uint64_t(std::max(spec.width, 0)) *
                          std::uint64_t(std::max(spec.height, 0)) *
                          std::uint64_t(std::clamp(spec.nchannels, 0, 4)) * value_bytes * 4 / 3;
    if (bytes > max_memory_bytes)
        throw Error(FileLoc{file.string()},
                    "texture needs " + byte_size_text(bytes) +
                        " decoded, more than the memory budget of " +
                        byte_size_text(max_memory_bytes) + " (--max-memory)");
}

}  // namespace

std::optional<TexturePixels> read_oiio_texture(const std::filesystem::path& file,
                                               std::uint64_t max_memory_bytes, std::string& why)
{
    // Colours as stored: cpfg's OpenGL textures are not premultiplied by alpha, and
    // OpenImageIO would premultiply a PNG's otherwise.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto input = OIIO::ImageInput::open(file.string(), &config);
    if (!input) {
        why = OIIO::geterror();
        return std::nullopt;
    }
    const OIIO::ImageSpec& spec = input->spec();
    check_texture_size(file, spec, max_memory_bytes);
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
        why = "no pixels";
        return std::nullopt;
    }
    TexturePixels pixels;
    pixels.width = spec.width;
    pixels.height = spec.height;
    // Colour channels beyond RGBA (and their alpha) are not textures' business.
    pixels.channels = std::min(spec.nchannels, 4);
    pixels.srgb = !spec.format.is_floating_point();
    const std::size_t values = std::size_t(spec.width) * spec.height * pixels.channels;
    bool ok;
    if (spec.format.size() == 1) {
        pixels.bytes.resize(values);
        ok = input->read_image(0, 0, 0, pixels.channels, OIIO::TypeDesc::UINT8,
                               pixels.bytes.data());
    } else {
        pixels.floats.resize(values);
        ok = input->read_image(0, 0, 0, pixels.channels, OIIO::TypeDesc::FLOAT,
                               pixels.floats.data());
    }
    if (!ok) {
        why = input->geterror();
        return std::nullopt;
    }
    return pixels;
}

}  // namespace cambium::render
