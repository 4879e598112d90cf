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
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/output_format.h"
#include "geom/scene.h"
#include "render/image_io.h"
#include "render/mip_map.h"

namespace cambium::render {

/// An environment map's texels: linear RGB, rows top to bottom, scaled.
struct MapTexels {
    int width = 0, height = 0;
    std::vector<float> rgb;
};


class ImageCodec {
public:
    virtual ~ImageCodec() = default;
    /// Writes the valid `image` to `temporary` in `format`; errors name `file`.
    virtual void write(const Image& image, const std::filesystem::path& temporary,
                       ImageFormat format, const std::filesystem::path& file,
                       const WriteOptions& options) const = 0;
    /// A texture file's pixels. Throws cambium::Error naming the file when its header
    /// declares more than max_texture_side pixels on a side, or pixels (with MIP levels)
    /// past `max_memory_bytes`, found before any pixel is read; nullopt with `why` set
    /// when the file cannot be read (cpfg draws without such a texture).
    virtual std::optional<TexturePixels> read_texture(const std::filesystem::path& file,
                                                      std::uint64_t max_memory_bytes,
                                                      std::string& why) const = 0;
    /// Throws cambium::Error naming the file when it cannot be read or is too large.
    virtual MapTexels read_map(const std::filesystem::path& file, float scale,
                               std::size_t max_texels) const = 0;
};

/// The module's codec, loaded on first use; throws cambium::Error when it cannot be.
const ImageCodec& image_codec();

/// The interface's version: the loader refuses a module of another version.
inline constexpr int image_codec_version = 3;

}  // namespace cambium::render

extern "C" {
/// cambium_image_codec(version): the module's codec, or null for another version.
using cambium_image_codec_fn = const cambium::render::ImageCodec*(int version);
}
