// SPDX-License-Identifier: Apache-2.0
// A still rendered in pieces (--tile I/N, --assemble N, --mpi): bands of rows, the
// tile files that carry their exact pixels, and pasting them into the whole image.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "render/render.h"

namespace cambium::app {

/// Band `index` of `count` bands of whole rows: rows index * height / count up to (not
/// including) (index + 1) * height / count. Requires 0 <= index < count <= height.
render::PixelRect band(int index, int count, int width, int height);

/// An image of the whole size with nothing in it yet: black, alpha 0, depth infinite;
/// with the albedo, normal and depth layers when `layers`.
render::Image blank_image(int width, int height, bool layers, bool transparent);

/// Copies `part` (every layer) into `whole` with its top-left pixel at (x, y).
void paste(render::Image& whole, const render::Image& part, int x, int y);

/// One tile of a still: where it lies in the whole image and its pixels.
struct Tile {
    int index = 0, count = 1;     ///< band index of count
    int width = 0, height = 0;    ///< the whole image's size
    render::PixelRect rect;       ///< the tile's pixels in the whole image
    render::Image image;          ///< rect.width x rect.height
};

/// The bytes of a tile: a header, then the float layers exactly as rendered (the
/// machine's byte order). What --tile writes and what MPI ranks send to rank 0.
std::string encode_tile(const Tile& tile);

/// The tile in `bytes`; throws cambium::Error naming `source` when they are not one.
Tile decode_tile(const std::string& bytes, const std::string& source);

/// The tile file of --tile I/N for the first output `output`: out.png -> out.tile3of8.ctile
/// beside it.
std::filesystem::path tile_file(const std::filesystem::path& output, int index, int count);

/// Reads the tile files 0 .. count-1 of `output` and pastes them into the whole image of
/// width x height; throws cambium::Error naming the file that is missing, unreadable, or
/// from another image size or tile count.
render::Image assemble_tiles(const std::filesystem::path& output, int count, int width,
                             int height);

}  // namespace cambium::app
