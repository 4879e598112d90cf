// SPDX-License-Identifier: Apache-2.0
// The plant as binary glTF 2.0 (docs/export.md): what a mesh output named `.glb` writes.
#pragma once

#include <cstddef>
#include <filesystem>

#include "geom/mesh_export.h"

namespace cambium::geom {

/// Writes `scene` as a `.glb` file: each organ (the derived string's module that drew it,
/// provenance) a node named by its symbol and index with its triangles; each prototype a
/// mesh shared by the nodes of its instances (one per material and texture it is placed
/// with); cpfg's materials as metallic-roughness ones (docs/export.md); PNG and JPEG
/// textures embedded; pixel-wide lines (`line style: pixel`) as line primitives of unlit
/// materials. The file appears whole or not at all.
void write_glb(const Scene& scene, const std::filesystem::path& file, const MeshExportOptions& options);

/// The triangles (and pixel-wide line segments) write_glb() holds: the scene's own and
/// one copy per shared mesh; an upper bound (degenerate segments give no triangles).
std::size_t gltf_primitives(const Scene& scene, const Tessellation& how);

}  // namespace cambium::geom
