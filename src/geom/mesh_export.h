// SPDX-License-Identifier: Apache-2.0
// The plant's geometry as mesh files for other programs: Wavefront OBJ with its MTL
// materials, binary PLY with colours, and cpfg's GLS statements (manual 6.4), which a
// background scene reads back.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "base/limits.h"
#include "base/output_format.h"
#include "geom/scene.h"
#include "geom/tessellate.h"

namespace cambium::geom {

struct MeshExportOptions {
    Tessellation tessellation;
    /// The folder the scene's relative texture names are relative to (the view file's).
    std::filesystem::path texture_folder;
    /// The tessellated mesh may take at most this much memory (--max-memory).
    std::uint64_t max_memory_bytes = default_max_memory_bytes();
    /// A texture file glTF cannot embed (SGI, TIFF, ...) encoded as PNG bytes, empty
    /// when it cannot be read. Unset: such textures are left out, with a warning.
    std::function<std::vector<unsigned char>(const std::filesystem::path&)> png_of{};
};

/// What one exported triangle takes while the tessellated mesh is held: three vertices
/// of position, normal and uv, three indices, two materials, a texture and a module.
/// Every geometry export counts it against --max-memory.
inline constexpr std::uint64_t exported_triangle_bytes = 3 * (12 + 12 + 8) + 12 + 6 + 4;

/// The scene's material `index`, or the default material past the palette's end.
const Material& exported_material(const Scene& scene, std::uint16_t index);

/// Writes the scene's geometry, every primitive tessellated (geom/tessellate.h) and every
/// instance placed, as `file` in `format` (base/output_format.h: by its extension); an OBJ's materials go to the `.mtl` of the same
/// name beside it. Files appear whole or not at all. Throws cambium::Error naming the file,
/// or the memory budget when the mesh would pass it.
void write_mesh(const Scene& scene, const std::filesystem::path& file, MeshFormat format,
                const MeshExportOptions& options = {});

}  // namespace cambium::geom
