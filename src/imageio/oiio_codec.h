// SPDX-License-Identifier: Apache-2.0
// libcambium_imageio.so's parts (render/image_codec.h is its interface): OpenImageIO
// behind the codec. Tests link them directly through the cambium_imageio_impl library.
#pragma once

#include "render/image_codec.h"

namespace cambium::render {

void write_with_oiio(const Image& image, const std::filesystem::path& temporary,
                     ImageFormat format, const std::filesystem::path& file,
                     const WriteOptions& options);

std::optional<TexturePixels> read_oiio_texture(const std::filesystem::path& file,
                                               std::uint64_t max_memory_bytes, std::string& why);

MapTexels read_oiio_map(const std::filesystem::path& file, float scale, std::size_t max_texels);

/// The codec of the functions above.
const ImageCodec& oiio_codec();

}  // namespace cambium::render
