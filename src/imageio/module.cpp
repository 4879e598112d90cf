// SPDX-License-Identifier: Apache-2.0
// The one exported symbol of libcambium_imageio.so (render/image_codec.h).
#include "imageio/oiio_codec.h"

extern "C" __attribute__((visibility("default"))) const cambium::render::ImageCodec*
cambium_image_codec(int version)
{
    return version == cambium::render::image_codec_version ? &cambium::render::oiio_codec()
                                                           : nullptr;
}
