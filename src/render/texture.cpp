// SPDX-License-Identifier: Apache-2.0
// The view file's textures: opened and looked up by the image I/O module
// (render/image_codec.h), loaded only when a model has textures.
#include "render/texture.h"

#include <atomic>

#include "base/diagnostics.h"
#include "render/image_codec.h"

namespace cambium::render {

struct TextureSet::Impl {
    std::unique_ptr<TextureSource> source;  // null: no textures
};

namespace {
std::atomic<std::uint64_t> texture_sets_constructed{0};
}  // namespace

std::uint64_t TextureSet::constructed_count() { return texture_sets_constructed.load(); }

TextureSet::TextureSet(const std::vector<geom::TextureDef>& defs,
                       const std::filesystem::path& base, std::uint64_t max_memory_bytes)
    : m_impl(std::make_unique<Impl>())
{
    texture_sets_constructed.fetch_add(1);
    if (defs.empty())
        return;
    m_impl->source = image_codec().open_textures(
        defs, base, max_memory_bytes,
        [](const std::string& file, const std::string& message) { warn(FileLoc{file}, message); });
}

TextureSet::~TextureSet() = default;

std::size_t TextureSet::size() const { return m_impl->source ? m_impl->source->size() : 0; }

bool TextureSet::valid(int index) const { return m_impl->source && m_impl->source->valid(index); }

bool TextureSet::decal(int index) const { return valid(index) && m_impl->source->decal(index); }

bool TextureSet::has_alpha(int index) const
{
    return valid(index) && m_impl->source->has_alpha(index);
}

Texel TextureSet::lookup(int index, float s, float t, float width) const
{
    return lookup(index, s, t, TextureFootprint{width, 0, 0, width});
}

Texel TextureSet::lookup(int index, float s, float t, const TextureFootprint& fp) const
{
    return valid(index) ? m_impl->source->lookup(index, s, t, fp) : Texel{};
}

Vec3f TextureSet::apply(int index, const Vec3f& diffuse, float s, float t,
                        const TextureFootprint& footprint) const
{
    if (!valid(index))
        return diffuse;
    Texel texel = lookup(index, s, t, footprint);
    return decal(index) ? texel.colour : diffuse * texel.colour;
}

}  // namespace cambium::render
