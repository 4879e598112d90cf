// SPDX-License-Identifier: Apache-2.0
// libcambium_imageio.so's entry point and its environment map reader.
#include "imageio/oiio_codec.h"

#include <OpenImageIO/imageio.h>

#include "base/diagnostics.h"

namespace cambium::render {

MapTexels read_oiio_map(const std::filesystem::path& file, float scale, std::size_t max_texels)
{
    auto in = OIIO::ImageInput::open(file.string());
    if (!in)
        throw Error(file.string() + ": cannot read the environment map: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    int w = spec.width, h = spec.height, channels = spec.nchannels;
    if (w <= 0 || h <= 0 || std::size_t(w) * std::size_t(h) > max_texels || channels <= 0)
        throw Error(file.string() + ": environment map of " + std::to_string(w) + "x" +
                    std::to_string(h) + " texels is empty or larger than 2^25 texels");
    // Only the channels used are decoded (RGB, or the first as grey): a header may
    // declare thousands, which the texel limit alone would multiply.
    const int used = channels >= 3 ? 3 : 1;
    std::vector<float> pixels(std::size_t(w) * std::size_t(h) * std::size_t(used));
    if (!in->read_image(0, 0, 0, used, OIIO::TypeDesc::FLOAT, pixels.data()))
        throw Error(file.string() + ": cannot read the environment map: " + in->geterror());
    MapTexels map{w, h, std::vector<float>(std::size_t(w) * h * 3)};
    for (std::size_t p = 0; p < std::size_t(w) * h; ++p)
        for (int c = 0; c < 3; ++c)
            map.rgb[p * 3 + c] = pixels[p * std::size_t(used) + (used == 3 ? c : 0)] * scale;
    return map;
}

namespace {

class OiioCodec final : public ImageCodec {
public:
    void write(const Image& image, const std::filesystem::path& temporary, ImageFormat format,
               const std::filesystem::path& file, const WriteOptions& options) const override
    {
        write_with_oiio(image, temporary, format, file, options);
    }
    std::optional<TexturePixels> read_texture(const std::filesystem::path& file,
                                              std::uint64_t max_memory_bytes,
                                              std::string& why) const override
    {
        return read_oiio_texture(file, max_memory_bytes, why);
    }
    MapTexels read_map(const std::filesystem::path& file, float scale,
                       std::size_t max_texels) const override
    {
        return read_oiio_map(file, scale, max_texels);
    }
};

}  // namespace

const ImageCodec& oiio_codec()
{
    static const OiioCodec codec;
    return codec;
}

}  // namespace cambium::render
