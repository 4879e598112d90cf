// SPDX-License-Identifier: Apache-2.0
// The rendered image's output: checked here, encoded by the image I/O module
// (render/image_codec.h, OpenImageIO).
#include "render/image_io.h"

#include <algorithm>
#include <string>

#include "base/atomic_file.h"
#include "base/diagnostics.h"
#include "render/image_codec.h"
#include "base/output_format.h"

namespace cambium::render {

namespace {

/// The image format of `file`; Error naming the extensions that are.
ImageFormat format_of(const std::filesystem::path& file)
{
    const OutputFormat* format = find_output_format(file);
    if (!format || !format->is_image())
        throw Error(file.string() + ": unknown image format '" + file.extension().string() +
                    "' (use " + image_extensions_text() + ")");
    return format->image;
}

}  // namespace

void check_output_format(const std::filesystem::path& file)
{
    format_of(file);
    std::filesystem::path folder = file.parent_path();
    std::error_code ec;
    if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
        throw Error(file.string() + ": the folder " + folder.string() + " does not exist");
}

void write_image(const Image& image, const std::filesystem::path& file,
                 const WriteOptions& options)
{
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != std::size_t(image.width) * image.height * 4)
        throw Error(file.string() + ": cannot write an empty or malformed image");
    ImageFormat format = format_of(file);
    const ImageCodec& codec = image_codec();
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        codec.write(image, temporary, format, file, options);
    });
}

}  // namespace cambium::render
