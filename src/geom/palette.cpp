// SPDX-License-Identifier: Apache-2.0
// Colormaps (.map, manual 5.4.1) and material files (.mat, 5.4.2) and the table they fill.
#include "geom/palette.h"

#include "base/diagnostics.h"
#include "geom/text_input.h"

namespace cambium::geom {
namespace {

constexpr std::size_t colormap_bytes = 768;
constexpr float unloaded_grey = 200 / 255.0f;  // cpfg's colour for a block with no file

/// cpfg's material for ids a material file does not define.
Material undefined_material()
{
    Material m;
    m.ambient = {0, 0, 0};
    m.diffuse = {1, 1, 1};
    return m;
}

std::vector<Material> grey_table()
{
    Material grey;  // a colour-index colour: no OpenGL ambient term (cpfg does not light them)
    grey.ambient = {0, 0, 0};
    grey.diffuse = {unloaded_grey, unloaded_grey, unloaded_grey};
    return std::vector<Material>(256, grey);
}
constexpr std::size_t material_record_bytes = 15;

Rgb rgb_from_bytes(const unsigned char* p) { return {p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f}; }

}  // namespace

std::vector<Material> read_colormap(const std::filesystem::path& file)
{
    std::vector<unsigned char> bytes = read_binary_file(file, "colormap file", 1u << 20);
    if (bytes.size() != colormap_bytes)
        throw Error(FileLoc{file.string()},
                    "a colormap file must be exactly 768 bytes (256 RGB triples); this one has " +
                        std::to_string(bytes.size()));
    std::vector<Material> table(256);
    for (std::size_t i = 0; i < 256; ++i) {
        // colormap mode draws without OpenGL lighting: no ambient term
        table[i].diffuse = rgb_from_bytes(&bytes[3 * i]);
        table[i].ambient = {0, 0, 0};
    }
    return table;
}

std::vector<Material> read_material_file(const std::filesystem::path& file)
{
    std::vector<unsigned char> bytes = read_binary_file(file, "material file", 1u << 20);
    if (bytes.empty() || bytes.size() % material_record_bytes != 0)
        throw Error(FileLoc{file.string()},
                    "a material file holds 15-byte records; this one has " +
                        std::to_string(bytes.size()) + " bytes");
    std::vector<Material> table(256, undefined_material());
    for (std::size_t at = 0; at < bytes.size(); at += material_record_bytes) {
        const unsigned char* r = &bytes[at];
        Material& m = table[r[0]];
        m.transparency = r[1] / 255.0f;
        m.ambient = rgb_from_bytes(r + 2);
        m.diffuse = rgb_from_bytes(r + 5);
        m.emission = rgb_from_bytes(r + 8);
        m.specular = rgb_from_bytes(r + 11);
        m.shininess = static_cast<float>(r[14]);
        if (m.shininess > 128) {
            warn(FileLoc{file.string()}, "material " + std::to_string(r[0]) +
                                             ": shininess above 128 clamped");
            m.shininess = 128;
        }
    }
    return table;
}

void Palette::check_block(int block) const
{
    if (block < 0 || block >= static_cast<int>(m_blocks.size()))
        throw Error("colour map number " + std::to_string(block) + " is out of range 0..15");
}

void Palette::load_colormap(int block, const std::filesystem::path& file)
{
    check_block(block);
    if (m_mode == Mode::materials)
        throw Error("cannot mix colormaps (-m) and material files (-M)");
    m_blocks[static_cast<std::size_t>(block)] = read_colormap(file);
    m_mode = Mode::colormap;
}

void Palette::load_materials(int block, const std::filesystem::path& file)
{
    check_block(block);
    if (m_mode == Mode::colormap)
        throw Error("cannot mix colormaps (-m) and material files (-M)");
    m_blocks[static_cast<std::size_t>(block)] = read_material_file(file);
    m_mode = Mode::materials;
}

std::vector<Material> Palette::entries(int block) const
{
    check_block(block);
    const auto& entries = m_blocks[static_cast<std::size_t>(block)];
    if (entries)
        return *entries;
    if (m_mode == Mode::materials)
        return std::vector<Material>(256, undefined_material());
    return grey_table();
}

Rgb Palette::background(int block) const
{
    const auto& entries = m_blocks[static_cast<std::size_t>(block)];
    if (!entries)
        return {0, 0, 0};
    const Material& first = (*entries)[0];
    return m_mode == Mode::colormap ? first.diffuse : first.emission;
}

}  // namespace cambium::geom
