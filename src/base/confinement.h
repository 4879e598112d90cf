// SPDX-License-Identifier: Apache-2.0
// Whether a file a model names lies inside its model's folder (docs/security.md).
#pragma once

#include <filesystem>

namespace cambium {

/// Whether the canonical path `path` is `folder` or lies below it (both already
/// canonical: compared element by element, so "/a/bc" is not below "/a/b").
bool is_within(const std::filesystem::path& folder, const std::filesystem::path& path);

/// Whether `file` lies in `folder` or below once `..` and symbolic links are resolved
/// (std::filesystem::weakly_canonical: a tail that does not exist yet is judged as
/// written). Relative paths are the current folder's.
bool lies_within(const std::filesystem::path& file, const std::filesystem::path& folder);

}  // namespace cambium
