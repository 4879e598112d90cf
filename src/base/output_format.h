// SPDX-License-Identifier: Apache-2.0
// Every output file a render can become, by its extension: one table that the checks
// before a run, the writers and the choice of what to compute all read.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <string_view>


namespace cambium {

/// The image file formats the image writers know.
enum class ImageFormat { png, jpeg, tiff, exr, sgi, targa };

/// The mesh file formats geom::write_mesh knows.
enum class MeshFormat { none, obj, ply, gls, glb };

/// The vector drawing formats of the window's projection (render/vector_writer.h).
enum class VectorFormat { none, ps, svg, pdf };

/// What one kind of output file holds.
struct OutputFormat {
    std::string_view name;                      ///< for messages: "PNG", "SGI RGB"
    std::array<std::string_view, 4> extensions; ///< lower case, with the dot; "" past the last
    bool video = false;   ///< frames encoded by ffmpeg (app/video.h), not an image file
    ImageFormat image = ImageFormat::png;       ///< the codec's format (images only)
    MeshFormat mesh = MeshFormat::none;         ///< the plant's geometry, not a picture
    bool keeps_layers = false;  ///< albedo, normal and depth layers beside RGBA (EXR)
    bool keeps_alpha = false;   ///< a transparent render keeps its alpha channel
    VectorFormat vector = VectorFormat::none;   ///< the window's projection as vector paths

    bool is_image() const { return !video && mesh == MeshFormat::none && vector == VectorFormat::none; }
};

// clang-format off
/// The table. The image I/O module reads it too (it links nothing of render), so it lives
/// here, whole.
inline constexpr std::array<OutputFormat, 14> output_formats{{
    {"PNG",      {".png"},                          false, ImageFormat::png,   MeshFormat::none, false, true},
    {"OpenEXR",  {".exr"},                          false, ImageFormat::exr,   MeshFormat::none, true,  true},
    {"TIFF",     {".tif", ".tiff"},                 false, ImageFormat::tiff,  MeshFormat::none, false, true},
    {"JPEG",     {".jpg", ".jpeg"},                 false, ImageFormat::jpeg,  MeshFormat::none, false, false},
    {"SGI RGB",  {".rgb", ".sgi"},                  false, ImageFormat::sgi,   MeshFormat::none, false, true},
    {"Targa",    {".tga"},                          false, ImageFormat::targa, MeshFormat::none, false, true},
    {"video",    {".mp4", ".mov", ".mkv", ".webm"}, true,  ImageFormat::png,   MeshFormat::none, false, false},
    {"Wavefront OBJ", {".obj"},                     false, ImageFormat::png,   MeshFormat::obj,  false, false},
    {"PLY",      {".ply"},                          false, ImageFormat::png,   MeshFormat::ply,  false, false},
    {"GLS",      {".gls"},                          false, ImageFormat::png,   MeshFormat::gls,  false, false},
    {"glTF binary", {".glb"},                       false, ImageFormat::png,   MeshFormat::glb,  false, false},
    {"PostScript", {".ps"},                         false, ImageFormat::png,   MeshFormat::none, false, false, VectorFormat::ps},
    {"SVG",      {".svg"},                          false, ImageFormat::png,   MeshFormat::none, false, false, VectorFormat::svg},
    {"PDF",      {".pdf"},                          false, ImageFormat::png,   MeshFormat::none, false, false, VectorFormat::pdf},
}};
// clang-format on

/// The table's entry for an image format.
constexpr const OutputFormat& output_format(ImageFormat image)
{
    for (const OutputFormat& f : output_formats)
        if (f.is_image() && f.image == image)
            return f;
    return output_formats.front();
}

/// The format of `file` by its extension, in any case; nullptr when none is.
const OutputFormat* find_output_format(const std::filesystem::path& file);

/// The image formats' extensions, for messages: ".png, .jpg, ... or .tga".
std::string image_extensions_text();

}  // namespace cambium
