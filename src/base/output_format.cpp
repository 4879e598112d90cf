// SPDX-License-Identifier: Apache-2.0
#include "base/output_format.h"

#include <algorithm>
#include <cctype>

namespace cambium {

const OutputFormat* find_output_format(const std::filesystem::path& file)
{
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext.empty())
        return nullptr;
    for (const OutputFormat& f : output_formats)
        if (std::find(f.extensions.begin(), f.extensions.end(), ext) != f.extensions.end())
            return &f;
    return nullptr;
}

std::string image_extensions_text()
{
    std::string text;
    std::size_t left = 0;
    for (const OutputFormat& f : output_formats)
        left += f.is_image();
    for (const OutputFormat& f : output_formats) {
        if (!f.is_image())
            continue;
        text += f.extensions.front();
        --left;
        text += left == 0 ? "" : left == 1 ? " or " : ", ";
    }
    return text;
}

}  // namespace cambium
