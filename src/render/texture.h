// SPDX-License-Identifier: Apache-2.0
// The view file's textures: decoded by OpenImageIO, MIP-mapped and filtered in memory.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "base/limits.h"
#include "geom/scene.h"
#include "render/vecf.h"

namespace cambium::render {

/// One filtered texture sample: linear RGB and coverage alpha.
struct Texel {
    Vec3f colour{1.0f};
    float alpha = 1;
};

/// A lookup's filter footprint: the change of (s, t) across one pixel's footprint along
/// two directions on the surface (OIIO's dsdx, dtdx, dsdy, dtdy). Zero: the finest level.
struct TextureFootprint {
    float dsdx = 0, dtdx = 0, dsdy = 0, dtdy = 0;
};

/// The Scene's TextureDefs, opened once (MIP-mapped when opened, any format OIIO reads,
/// SGI .rgb included). Thread-safe lookups after construction.
///
/// Coordinates are OpenGL's: (s, t) in [0, 1]^2 with t = 0 the image's bottom row; both
/// wrap (GL_REPEAT). 8-bit and 16-bit images hold display values and are decoded as sRGB
/// after filtering; floating-point images are taken as linear (docs/materials.md).
/// The largest texture side accepted: OpenGL's usual GL_MAX_TEXTURE_SIZE, beyond which
/// cpfg could not have drawn the texture either.
inline constexpr int max_texture_side = 16384;

class TextureSet {
public:
    /// Opens every texture; relative paths are taken relative to `base` (the view file's
    /// folder). A file that is missing or unreadable is a warning naming it, and its
    /// index is not valid(): what it textures is drawn untextured, as cpfg does. A file
    /// whose header declares more than max_texture_side pixels on a side, or whose
    /// decoded pixels (with MIP levels) would take more than `max_memory_bytes`, is an
    /// error naming it, found before any pixel is read.
    explicit TextureSet(const std::vector<geom::TextureDef>& defs,
                        const std::filesystem::path& base = {},
                        std::uint64_t max_memory_bytes = default_max_memory_bytes());
    ~TextureSet();
    TextureSet(const TextureSet&) = delete;
    TextureSet& operator=(const TextureSet&) = delete;

    std::size_t size() const;
    /// How many TextureSets this process has constructed (a sequence should open one).
    static std::uint64_t constructed_count();
    /// Whether `index` is a texture (not no_texture and in range).
    bool valid(int index) const;
    /// E: decal (replaces the diffuse colour) rather than modulate.
    bool decal(int index) const;
    /// Whether the image has an alpha channel.
    bool has_alpha(int index) const;
    /// Whether some of the image is cut out: alpha below 1/2 at the finest level
    /// (MipMap::can_cut_out). Hits on an opaque image's surfaces need no alpha test.
    bool cuts_out(int index) const;

    /// The longer side of the texture's finest level in texels, where its lookups choose
    /// a MIP level by their footprint; 0 where no footprint matters (one level, or not a
    /// valid index): what footprint_within_texel() (integrator.h) compares with.
    float footprint_texels(int index) const;

    /// The filtered texel at (s, t); `width` is the lookup's footprint in texture units
    /// (0: the finest level). Invalid indices give white, alpha 1.
    Texel lookup(int index, float s, float t, float width = 0) const;
    /// The same filtered over an anisotropic footprint (mipmapped textures only).
    Texel lookup(int index, float s, float t, const TextureFootprint& footprint) const;

    /// A colour written whole: R, G, B and a fourth value of no meaning.
    struct alignas(16) Rgbx {
        float v[4];
        Vec3f rgb() const { return {v[0], v[1], v[2]}; }
    };
    /// The diffuse albedo after texture `index` at (s, t) (`diffuse` itself for an
    /// invalid index): modulated or replaced. Written into `out` with one 16-byte store: a
    /// Vec3f returned by value comes back in two registers, which the path tracer stored
    /// apart and read back as one 8-byte load across both (a stalled store forward at
    /// every textured vertex).
    void apply(int index, const Vec3f& diffuse, float s, float t,
               const TextureFootprint& footprint, Rgbx& out) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace cambium::render
