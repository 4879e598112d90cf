// SPDX-License-Identifier: Apache-2.0
// libcambium_imageio.so's entry point and its environment map reader.
#include "imageio/oiio_codec.h"

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <fstream>
#include <string>

#include "base/diagnostics.h"
#include "base/input_file.h"

namespace cambium::render {

namespace {

/// A map's file: an 8192 x 4096 RGBA map of 32-bit floats, uncompressed, is 512 MiB.
constexpr std::uintmax_t max_map_file_bytes = std::uintmax_t{1} << 30;

/// The channels a map of the largest size may have: all of its values are decoded.
constexpr std::size_t max_map_channels = 4;

/// Checks an OpenEXR file's headers before OpenImageIO opens it: OpenEXR allocates each
/// attribute's declared size before reading its value, so a few hundred bytes could ask
/// for gigabytes. Every attribute must fit in what the file has left; the walk seeks past
/// the values and reads only names (at most 256 bytes each). Other files are left alone.
void check_exr_headers(const std::filesystem::path& file)
{
    std::ifstream in(file, std::ios::binary);
    char magic[8];
    if (!in.read(magic, sizeof magic) || std::memcmp(magic, "\x76\x2f\x31\x01", 4) != 0)
        return;
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(file, ec);
    if (ec)
        return;  // OpenImageIO reports it
    const bool multipart = (static_cast<unsigned char>(magic[5]) & 0x10) != 0;
    auto fail = [&](const std::string& why) {
        throw Error(FileLoc{file.string()}, "is not a valid OpenEXR file: " + why);
    };
    auto text = [&](const char* what) {
        std::string s;
        for (char c; in.get(c) && c != '\0';) {
            s += c;
            if (s.size() > 255)
                fail(std::string("a header's ") + what + " is longer than 255 bytes");
        }
        if (!in)
            fail("a header is cut short");
        return s;
    };
    for (;;) {  // headers: one, or a multi-part file's list ended by an empty one
        std::size_t attributes = 0;
        for (;; ++attributes) {
            std::string name = text("attribute name");
            if (name.empty())
                break;
            text("attribute type");
            unsigned char b[4];
            if (!in.read(reinterpret_cast<char*>(b), 4))
                fail("a header is cut short");
            const std::uint32_t declared = std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 |
                                           std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
            const auto at = static_cast<std::uintmax_t>(in.tellg());
            if (declared > 0x7fffffffu || declared > size - at)
                fail("the header's attribute '" + name + "' declares " + std::to_string(declared) +
                     " bytes, more than the " + std::to_string(size - at) + " the file has left");
            in.seekg(std::streamoff(declared), std::ios::cur);
        }
        if (!multipart || attributes == 0)
            return;
    }
}

}  // namespace

MapTexels read_oiio_map(const std::filesystem::path& file, float scale, std::size_t max_texels)
{
    regular_file_size(file, "the environment map", max_map_file_bytes);
    check_exr_headers(file);
    auto in = OIIO::ImageInput::open(file.string());
    if (!in)
        throw Error(file.string() + ": cannot read the environment map: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    int w = spec.width, h = spec.height, channels = spec.nchannels;
    if (w <= 0 || h <= 0 || std::size_t(w) * std::size_t(h) > max_texels || channels <= 0)
        throw Error(file.string() + ": environment map of " + std::to_string(w) + "x" +
                    std::to_string(h) + " texels is empty or larger than 2^25 texels");
    // OpenImageIO decodes whole chunks with every channel a file has before it keeps the
    // ones asked for, so the file's values, not only its texels, are bounded.
    const std::size_t values = std::size_t(w) * std::size_t(h) * std::size_t(channels);
    if (values > max_texels * max_map_channels)
        throw Error(FileLoc{file.string()},
                    "environment map of " + std::to_string(w) + "x" + std::to_string(h) +
                        " texels with " + std::to_string(channels) + " channels holds " +
                        std::to_string(values) + " values, more than the " +
                        std::to_string(max_texels * max_map_channels) +
                        " (the texel limit with 4 channels) a map may hold: all are decoded");
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
