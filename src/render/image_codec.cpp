// SPDX-License-Identifier: Apache-2.0
// Loads libcambium_imageio.so on first use (render/image_codec.h).
#include "render/image_codec.h"

#include <dlfcn.h>

#include <mutex>

#include "base/diagnostics.h"
#include "base/shared_module.h"

namespace cambium::render {

namespace {

constexpr const char* module_name = "libcambium_imageio.so";

const ImageCodec* load_codec()
{
    std::string reasons;
    // Local: nothing loaded later needs OpenImageIO's symbols.
    SharedModule module = load_module(module_name, RTLD_NOW | RTLD_LOCAL, reasons);
    if (!module.handle) {
        std::string places;
        for (const std::filesystem::path& candidate : module_candidates(module_name))
            places += "\n  " + candidate.lexically_normal().string();
        throw Error(reasons.empty()
                        ? std::string("cannot read or write images: ") + module_name +
                              " is in none of:" + places
                        : "cannot read or write images: the image module cannot be loaded "
                          "(is OpenImageIO installed?):" + reasons);
    }
    auto* entry = reinterpret_cast<cambium_image_codec_fn*>(
        module.symbol("cambium_image_codec", "Cambium's image I/O module"));
    const ImageCodec* codec = entry(image_codec_version);
    if (!codec)
        throw Error(FileLoc{module.file.string()},
                    "is the image I/O module of another Cambium version");
    return codec;
}

}  // namespace

const ImageCodec& image_codec()
{
    // Loaded once; a failure is reported again at each use.
    static std::mutex mutex;
    static const ImageCodec* codec = nullptr;
    std::lock_guard lock(mutex);
    if (!codec)
        codec = load_codec();
    return *codec;
}

}  // namespace cambium::render
