// SPDX-License-Identifier: Apache-2.0
// cpfg's -iv output (manual 6.5): the plant as an Open Inventor 2.1 ASCII scene.
#pragma once

#include <filesystem>

#include "geom/mesh_export.h"
#include "geom/scene.h"

namespace cambium::geom {

/// Writes `scene` as an Inventor 2.1 ASCII file (`#Inventor V2.1 ascii`): one Separator
/// with the view file's lights, a ShapeHints that lights both sides, the materials the
/// primitives use (one Material node of lists, bound per face by index), and every
/// primitive tessellated (geom/tessellate.h, instances placed) as one IndexedFaceSet with
/// smooth vertex normals; pixel-width lines as an IndexedLineSet. No camera, as cpfg's.
/// The file appears whole or not at all; throws cambium::Error naming it, or the memory
/// budget (options.max_memory_bytes) when the mesh would pass it.
void write_inventor(const Scene& scene, const std::filesystem::path& file,
                    const MeshExportOptions& options = {});

}  // namespace cambium::geom
