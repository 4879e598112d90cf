// SPDX-License-Identifier: Apache-2.0
// Every output file a render can become, by its extension: one table that the checks
// before a run, the writers and the choice of what to compute all read.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <string_view>

#include "render/image_codec.h"

namespace cambium::render {

/// What one kind of output file holds.
struct OutputFormat {
    std::string_view name;                      ///< for messages: "PNG", "SGI RGB"
    std::array<std::string_view, 4> extensions; ///< lower case, with the dot; "" past the last
    bool video = false;   ///< frames encoded by ffmpeg (app/video.h), not an image file
    ImageFormat image = ImageFormat::png;       ///< the codec's format (images only)
    bool keeps_layers = false;  ///< albedo, normal and depth layers beside RGBA (EXR)
    bool keeps_alpha = false;   ///< a transparent render keeps its alpha channel
};

// clang-format off
/// The table. The image I/O module reads it too (it links nothing of render), so it lives
/// here, whole.
inline constexpr std::array<OutputFormat, 7> output_formats{{
    {"PNG",      {".png"},                          false, ImageFormat::png,   false, true},
    {"OpenEXR",  {".exr"},                          false, ImageFormat::exr,   true,  true},
    {"TIFF",     {".tif", ".tiff"},                 false, ImageFormat::tiff,  false, true},
    {"JPEG",     {".jpg", ".jpeg"},                 false, ImageFormat::jpeg,  false, false},
    {"SGI RGB",  {".rgb", ".sgi"},                  false, ImageFormat::sgi,   false, true},
    {"Targa",    {".tga"},                          false, ImageFormat::targa, false, true},
    {"video",    {".mp4", ".mov", ".mkv", ".webm"}, true,  ImageFormat::png,   false, false},
}};
// clang-format on

/// The table's entry for an image format.
constexpr const OutputFormat& output_format(ImageFormat image)
{
    for (const OutputFormat& f : output_formats)
        if (!f.video && f.image == image)
            return f;
    return output_formats.front();
}

/// The format of `file` by its extension, in any case; nullptr when none is.
const OutputFormat* find_output_format(const std::filesystem::path& file);

/// The image formats' extensions, for messages: ".png, .jpg, ... or .tga".
std::string image_extensions_text();

}  // namespace cambium::render
