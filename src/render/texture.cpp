// SPDX-License-Identifier: Apache-2.0
// The view file's textures: decoded by the image I/O module (render/image_codec.h),
// loaded only when a model has textures, and filtered here (render/mip_map.h).
#include "render/texture.h"

#include <atomic>
#include <optional>

#include "base/diagnostics.h"
#include "render/image_codec.h"
#include "render/mip_map.h"

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace cambium::render {

namespace {

struct Entry {
    std::optional<MipMap> map;  // none: the file was missing or unreadable
    bool decal = false;
};

std::atomic<std::uint64_t> texture_sets_constructed{0};

}  // namespace

struct TextureSet::Impl {
    std::vector<Entry> entries;
};

std::uint64_t TextureSet::constructed_count() { return texture_sets_constructed.load(); }

TextureSet::TextureSet(const std::vector<geom::TextureDef>& defs,
                       const std::filesystem::path& base, std::uint64_t max_memory_bytes)
    : m_impl(std::make_unique<Impl>())
{
    texture_sets_constructed.fetch_add(1);
    for (const geom::TextureDef& def : defs) {
        std::filesystem::path file = def.file;
        if (file.is_relative() && !base.empty())
            file = base / file;
        // As cpfg, a texture that cannot be read is a warning and the surfaces it names
        // are drawn untextured (the corpus names maple.rgb beside a maple.png); the
        // index keeps its place for @Tx.
        Entry& entry = m_impl->entries.emplace_back();
        if (!std::filesystem::is_regular_file(file)) {
            warn(FileLoc{file.string()}, "texture not found; drawing without it");
            continue;
        }
        std::string why;
        std::optional<TexturePixels> pixels =
            image_codec().read_texture(file, max_memory_bytes, why);
        if (!pixels) {
            warn(FileLoc{file.string()}, "texture cannot be read" +
                                             (why.empty() ? std::string() : ": " + why) +
                                             "; drawing without it");
            continue;
        }
        entry.map.emplace(std::move(*pixels), TextureFilter{def.linear_filter, def.mipmap});
        entry.decal = def.decal;
    }
}

TextureSet::~TextureSet() = default;

std::size_t TextureSet::size() const { return m_impl->entries.size(); }

bool TextureSet::valid(int index) const
{
    return index >= 0 && static_cast<std::size_t>(index) < m_impl->entries.size() &&
           m_impl->entries[static_cast<std::size_t>(index)].map.has_value();
}

bool TextureSet::decal(int index) const
{
    return valid(index) && m_impl->entries[static_cast<std::size_t>(index)].decal;
}

bool TextureSet::has_alpha(int index) const
{
    return valid(index) && m_impl->entries[static_cast<std::size_t>(index)].map->has_alpha();
}

bool TextureSet::cuts_out(int index) const
{
    return valid(index) && m_impl->entries[static_cast<std::size_t>(index)].map->can_cut_out();
}

float TextureSet::footprint_texels(int index) const
{
    return valid(index) ? m_impl->entries[static_cast<std::size_t>(index)].map->footprint_texels()
                        : 0.0f;
}

Texel TextureSet::lookup(int index, float s, float t, float width) const
{
    return lookup(index, s, t, TextureFootprint{width, 0, 0, width});
}

Texel TextureSet::lookup(int index, float s, float t, const TextureFootprint& fp) const
{
    return valid(index) ? m_impl->entries[static_cast<std::size_t>(index)].map->lookup(s, t, fp)
                        : Texel{};
}

void TextureSet::apply(int index, const Vec3f& diffuse, float s, float t,
                       const TextureFootprint& footprint, Rgbx& out) const
{
    Vec3f c = diffuse;
    if (valid(index)) {
        const Entry& entry = m_impl->entries[static_cast<std::size_t>(index)];
        const Texel texel = entry.map->lookup(s, t, footprint);
        c = entry.decal ? texel.colour : diffuse * texel.colour;
    }
#if defined(__SSE2__)
    _mm_store_ps(out.v, _mm_setr_ps(c.x, c.y, c.z, 0.0f));
#else
    out = {{c.x, c.y, c.z, 0.0f}};
#endif
}

}  // namespace cambium::render
