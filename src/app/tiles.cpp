// SPDX-License-Identifier: Apache-2.0
// Tiles of a still: bands, their exact byte encoding, and pasting (docs/distributed.md).
#include "app/tiles.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "base/diagnostics.h"
#include "geom/text_input.h"

namespace cambium::app {
namespace {

namespace fs = std::filesystem;

/// Tile files start with this line; the number is the format's version.
constexpr std::string_view magic = "cambium tile 1\n";

/// The header's integers after the magic line.
struct Header {
    std::int32_t index, count, width, height, x, y, tile_width, tile_height, transparent, layers;
};

template <typename T>
void append(std::string& out, const std::vector<T>& values)
{
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

/// Copies rows of `channels` floats per pixel from `from` (width `from_width`) at (fx, fy)
/// into `to` (width `to_width`) at (tx, ty).
void copy_rows(const std::vector<float>& from, int from_width, std::vector<float>& to,
               int to_width, int x, int y, int width, int height, int channels)
{
    for (int row = 0; row < height; ++row)
        std::copy_n(from.begin() + std::ptrdiff_t(std::size_t(row) * std::size_t(from_width) *
                                                  std::size_t(channels)),
                    std::size_t(width) * std::size_t(channels),
                    to.begin() + std::ptrdiff_t((std::size_t(y + row) * std::size_t(to_width) +
                                                 std::size_t(x)) *
                                                std::size_t(channels)));
}

}  // namespace

render::PixelRect band(int index, int count, int width, int height)
{
    auto row = [&](int i) { return int(std::int64_t(i) * height / count); };
    return {0, row(index), width, row(index + 1) - row(index)};
}

render::Image blank_image(int width, int height, bool layers, bool transparent)
{
    std::size_t n = std::size_t(width) * std::size_t(height);
    render::Image image{width, height, std::vector<float>(n * 4, 0.0f)};
    image.transparent = transparent;
    if (layers) {
        image.albedo.assign(n * 3, 0.0f);
        image.normal.assign(n * 3, 0.0f);
        image.depth.assign(n, std::numeric_limits<float>::infinity());
    }
    return image;
}

void paste(render::Image& whole, const render::Image& part, int x, int y)
{
    if (x < 0 || y < 0 || x + part.width > whole.width || y + part.height > whole.height ||
        part.albedo.empty() != whole.albedo.empty())
        throw Error(fmt::format("a tile of {}x{} at {},{} does not fit the {}x{} image", part.width,
                                part.height, x, y, whole.width, whole.height));
    copy_rows(part.rgba, part.width, whole.rgba, whole.width, x, y, part.width, part.height, 4);
    if (part.albedo.empty())
        return;
    copy_rows(part.albedo, part.width, whole.albedo, whole.width, x, y, part.width, part.height, 3);
    copy_rows(part.normal, part.width, whole.normal, whole.width, x, y, part.width, part.height, 3);
    copy_rows(part.depth, part.width, whole.depth, whole.width, x, y, part.width, part.height, 1);
}

std::string encode_tile(const Tile& tile)
{
    const render::Image& im = tile.image;
    Header h{tile.index, tile.count, tile.width, tile.height, tile.rect.x, tile.rect.y,
             im.width,  im.height,  im.transparent ? 1 : 0, im.albedo.empty() ? 0 : 1};
    std::string out(magic);
    out.append(reinterpret_cast<const char*>(&h), sizeof h);
    append(out, im.rgba);
    append(out, im.albedo);
    append(out, im.normal);
    append(out, im.depth);
    return out;
}

Tile decode_tile(const std::string& bytes, const std::string& source)
{
    auto fail = [&](const std::string& why) -> Tile { throw Error(FileLoc{source}, why); };
    if (bytes.size() < magic.size() + sizeof(Header) || bytes.compare(0, magic.size(), magic) != 0)
        return fail("is not a Cambium tile (written by cambium --tile)");
    Header h;
    std::memcpy(&h, bytes.data() + magic.size(), sizeof h);
    bool sane = h.count >= 1 && h.index >= 0 && h.index < h.count && h.width > 0 &&
                h.height > 0 && std::int64_t(h.width) * h.height <= render::max_image_pixels &&
                h.x >= 0 && h.y >= 0 && h.tile_width >= 0 && h.tile_height >= 0 &&
                h.x <= h.width - h.tile_width && h.y <= h.height - h.tile_height;
    if (!sane)
        return fail("has a damaged tile header");
    std::size_t n = std::size_t(h.tile_width) * std::size_t(h.tile_height);
    std::size_t floats = n * (h.layers ? 11 : 4);
    if (bytes.size() != magic.size() + sizeof h + floats * sizeof(float))
        return fail("is cut short or too long for its tile header");
    Tile tile{h.index, h.count, h.width, h.height, {h.x, h.y, h.tile_width, h.tile_height}, {}};
    tile.image = blank_image(h.tile_width, h.tile_height, h.layers != 0, h.transparent != 0);
    const char* p = bytes.data() + magic.size() + sizeof h;
    for (std::vector<float>* layer : {&tile.image.rgba, &tile.image.albedo, &tile.image.normal,
                                      &tile.image.depth}) {
        if (!layer->empty())  // an absent layer has no data() to copy into
            std::memcpy(layer->data(), p, layer->size() * sizeof(float));
        p += layer->size() * sizeof(float);
    }
    return tile;
}

fs::path tile_file(const fs::path& output, int index, int count)
{
    fs::path file = output;
    file.replace_filename(fmt::format("{}.tile{}of{}.ctile", output.stem().string(), index, count));
    return file;
}

render::Image assemble_tiles(const fs::path& output, int count, int width, int height)
{
    render::Image whole;
    for (int i = 0; i < count; ++i) {
        fs::path file = tile_file(output, i, count);
        if (!fs::exists(file))
            throw Error(FileLoc{file.string()},
                        fmt::format("cannot be read: tile {} of {} is missing", i, count));
        // Its size is bounded by the band it must hold before anything is read: a regular
        // file no larger than that band with every layer (the header then says exactly).
        render::PixelRect rect = band(i, count, width, height);
        std::uintmax_t most =
            magic.size() + sizeof(Header) +
            std::uintmax_t(rect.width) * std::uintmax_t(rect.height) * 11 * sizeof(float);
        std::string bytes = read_file(file, "the tile", most);
        Tile tile = decode_tile(bytes, file.string());
        if (tile.index != i || tile.count != count || tile.width != width ||
            tile.height != height || tile.rect != band(i, count, width, height))
            throw Error(FileLoc{file.string()},
                        fmt::format("is tile {} of {} of a {}x{} image, not tile {} of {} of "
                                    "{}x{}: render the tiles and assemble with the same options",
                                    tile.index, tile.count, tile.width, tile.height, i, count,
                                    width, height));
        if (i == 0)
            whole = blank_image(width, height, !tile.image.albedo.empty(), tile.image.transparent);
        if (tile.image.transparent != whole.transparent)
            throw Error(FileLoc{file.string()}, "differs from tile 0 in --transparent");
        paste(whole, tile.image, tile.rect.x, tile.rect.y);
    }
    return whole;
}

}  // namespace cambium::app
