// SPDX-License-Identifier: Apache-2.0
// The rendered image and its output through OpenImageIO (PNG, EXR, TIFF, JPEG).
#include "render/film.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <string>
#include <system_error>

#include <unistd.h>

#include "base/diagnostics.h"
#include "render/color.h"

namespace cambium::render {

namespace {

enum class Format { png, jpeg, tiff, exr };

Format format_of(const std::filesystem::path& file)
{
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png")
        return Format::png;
    if (ext == ".jpg" || ext == ".jpeg")
        return Format::jpeg;
    if (ext == ".tif" || ext == ".tiff")
        return Format::tiff;
    if (ext == ".exr")
        return Format::exr;
    throw Error(file.string() + ": unknown image format '" + ext +
                "' (use .png, .exr, .tif or .jpg)");
}

/// A unique name beside `file`, keeping its extension so OIIO picks the same format.
std::filesystem::path temporary_name(const std::filesystem::path& file)
{
    static std::atomic<unsigned> counter{0};
    std::string name = "." + file.stem().string() + ".tmp" + std::to_string(::getpid()) + "-" +
                       std::to_string(counter++) + file.extension().string();
    return file.parent_path() / name;
}

/// Display-referred pixels: sRGB-encoded, quantised to `Int` with `channels` channels.
template <class Int>
std::vector<Int> encode_srgb(const Image& image, int channels)
{
    constexpr float max = static_cast<float>(std::numeric_limits<Int>::max());
    std::size_t n = std::size_t(image.width) * image.height;
    std::vector<Int> out(n * channels);
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < channels; ++c) {
            float v = image.rgba[i * 4 + c];
            float e = c < 3 ? linear_to_srgb(v) : std::clamp(v, 0.0f, 1.0f);
            out[i * channels + c] = static_cast<Int>(std::lround(e * max));
        }
    return out;
}

void write_with_oiio(const Image& image, const std::filesystem::path& temp, Format format,
                     const std::filesystem::path& file)
{
    auto out = OIIO::ImageOutput::create(temp.string());
    if (!out)
        throw Error(file.string() + ": cannot write this format: " + OIIO::geterror());
    bool ok = false;
    if (format == Format::exr) {
        OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::HALF);
        spec.attribute("oiio:ColorSpace", "Linear");
        spec.attribute("compression", "zip");
        ok = out->open(temp.string(), spec) &&
             out->write_image(OIIO::TypeDesc::FLOAT, image.rgba.data());
    } else if (format == Format::tiff) {
        OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::UINT16);
        spec.attribute("oiio:ColorSpace", "sRGB");
        // Colour is composited over the background; alpha is a coverage matte.
        spec.attribute("oiio:UnassociatedAlpha", 1);
        auto pixels = encode_srgb<std::uint16_t>(image, 4);
        ok = out->open(temp.string(), spec) &&
             out->write_image(OIIO::TypeDesc::UINT16, pixels.data());
    } else {
        OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
        spec.attribute("oiio:ColorSpace", "sRGB");
        if (format == Format::jpeg)
            spec.attribute("Compression", "jpeg:95");
        auto pixels = encode_srgb<std::uint8_t>(image, 3);
        ok = out->open(temp.string(), spec) &&
             out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
    }
    ok = out->close() && ok;
    if (!ok)
        throw Error(file.string() + ": cannot write the image: " + out->geterror());
}

}  // namespace

void check_output_format(const std::filesystem::path& file)
{
    format_of(file);
    std::filesystem::path folder = file.parent_path();
    std::error_code ec;
    if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
        throw Error(file.string() + ": the folder " + folder.string() + " does not exist");
}

void write_image(const Image& image, const std::filesystem::path& file)
{
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != std::size_t(image.width) * image.height * 4)
        throw Error(file.string() + ": cannot write an empty or malformed image");
    Format format = format_of(file);
    std::filesystem::path temp = temporary_name(file);
    try {
        write_with_oiio(image, temp, format, file);
        std::error_code ec;
        std::filesystem::rename(temp, file, ec);
        if (ec)
            throw Error(file.string() + ": cannot write the image: " + ec.message());
    } catch (...) {
        std::error_code ignored;
        std::filesystem::remove(temp, ignored);
        throw;
    }
}

}  // namespace cambium::render
