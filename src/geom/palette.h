// SPDX-License-Identifier: Apache-2.0
// Colormaps (.map, manual 5.4.1) and material files (.mat, 5.4.2) and the table they fill.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <vector>

#include "geom/scene.h"

namespace cambium::geom {

/// 256 colours of a colormap file, each as a material whose diffuse colour it is.
std::vector<Material> read_colormap(const std::filesystem::path& file);

/// The materials of a material file, indexed by their record id (0..255); ids the
/// file does not define get cpfg's default (white diffuse, everything else 0).
std::vector<Material> read_material_file(const std::filesystem::path& file);

/// cpfg's colour table: 16 blocks of 256 entries (-m[n] / -M[n] load block n, -c n
/// selects the block the turtle's colour indices address; the default block is 1).
class Palette {
public:
    enum class Mode { none, colormap, materials };
    static constexpr int blocks = 16;

    void load_colormap(int block, const std::filesystem::path& file);
    void load_materials(int block, const std::filesystem::path& file);

    Mode mode() const { return m_mode; }
    /// The 256 entries of `block`. A block no file was loaded into is cpfg's grey
    /// (200, 200, 200) in colormap mode (and with no file at all), or default
    /// materials in material mode.
    std::vector<Material> entries(int block) const;
    /// Colormap entry 0, or material 0's emission, of `block` (manual 3.2); black
    /// for a block no file was loaded into.
    Rgb background(int block) const;

private:
    void check_block(int block) const;

    Mode m_mode = Mode::none;
    std::array<std::optional<std::vector<Material>>, blocks> m_blocks;
};

}  // namespace cambium::geom
