// SPDX-License-Identifier: Apache-2.0
// The interface to libcambium_imageio.so, the one part of Cambium linked with
// OpenImageIO: image files written, textures and environment maps read. OpenImageIO's
// dependency tree is some 260 shared libraries (0.4 s and 130 MB at start-up), so the
// command loads the module with dlopen on first use and a run that reads or writes no
// image (-str, --help) never pays for it. The module is built with the same compiler and
// flags as the rest (C++ types cross the boundary) and is never unloaded.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "geom/scene.h"
#include "render/image_io.h"
#include "render/texture.h"

namespace cambium::render {

/// One TextureSet's opened textures (see TextureSet for the meaning of each call).
class TextureSource {
public:
    virtual ~TextureSource() = default;
    virtual std::size_t size() const = 0;
    virtual bool valid(int index) const = 0;
    virtual bool decal(int index) const = 0;
    virtual bool has_alpha(int index) const = 0;
    virtual Texel lookup(int index, float s, float t, const TextureFootprint& footprint) const = 0;
};

/// An environment map's texels: linear RGB, rows top to bottom, scaled.
struct MapTexels {
    int width = 0, height = 0;
    std::vector<float> rgb;
};

/// Warnings go back through this (the module's copy of base has its own sinks).
using WarnFn = std::function<void(const std::string& file, const std::string& message)>;

/// The image file formats write_image knows, from the file's extension.
enum class ImageFormat { png, jpeg, tiff, exr };

class ImageCodec {
public:
    virtual ~ImageCodec() = default;
    /// Writes the valid `image` to `temporary` in `format`; errors name `file`.
    virtual void write(const Image& image, const std::filesystem::path& temporary,
                       ImageFormat format, const std::filesystem::path& file,
                       const WriteOptions& options) const = 0;
    virtual std::unique_ptr<TextureSource> open_textures(
        const std::vector<geom::TextureDef>& defs, const std::filesystem::path& base,
        std::uint64_t max_memory_bytes, const WarnFn& warn) const = 0;
    /// Throws cambium::Error naming the file when it cannot be read or is too large.
    virtual MapTexels read_map(const std::filesystem::path& file, float scale,
                               std::size_t max_texels) const = 0;
};

/// The module's codec, loaded on first use; throws cambium::Error when it cannot be.
const ImageCodec& image_codec();

/// The interface's version: the loader refuses a module of another version.
inline constexpr int image_codec_version = 1;

}  // namespace cambium::render

extern "C" {
/// cambium_image_codec(version): the module's codec, or null for another version.
using cambium_image_codec_fn = const cambium::render::ImageCodec*(int version);
}
