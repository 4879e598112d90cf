// SPDX-License-Identifier: Apache-2.0
#include "base/confinement.h"

#include <algorithm>

namespace cambium {

bool is_within(const std::filesystem::path& folder, const std::filesystem::path& path)
{
    auto [f, p] = std::mismatch(folder.begin(), folder.end(), path.begin(), path.end());
    return f == folder.end();
}

bool lies_within(const std::filesystem::path& file, const std::filesystem::path& folder)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path canonical_folder = fs::weakly_canonical(fs::absolute(folder, ec), ec);
    if (ec)
        return false;
    const fs::path canonical_file = fs::weakly_canonical(fs::absolute(file, ec), ec);
    return !ec && is_within(canonical_folder, canonical_file);
}

}  // namespace cambium
