// SPDX-License-Identifier: Apache-2.0
// libcambium_imageio.so: the view file's textures, looked up through one OpenImageIO
// TextureSystem per render (render/texture.h says what a TextureSet does).
#include "imageio/oiio_codec.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <string>

#include "base/diagnostics.h"
#include "render/color.h"

namespace cambium::render {

namespace {

/// Destroys an unshared TextureSystem (and its own ImageCache).
struct SystemDeleter {
    void operator()(OIIO::TextureSystem* ts) const { OIIO::TextureSystem::destroy(ts, true); }
};

struct Entry {
    OIIO::TextureSystem::TextureHandle* handle = nullptr;
    OIIO::TextureOpt options;
    int channels = 3;
    bool srgb = true;
    bool decal = false;
};

}  // namespace

struct OiioTextures {
    std::unique_ptr<OIIO::TextureSystem, SystemDeleter> system;
    std::vector<Entry> entries;
    /// Each render thread's OIIO lookup state, owned here rather than left in OIIO's
    /// thread-specific storage: a TBB worker that outlives this set would otherwise
    /// free that state at its exit, after the system and its tiles are gone (a crash
    /// at process exit, found by the corpus sweep).
    tbb::enumerable_thread_specific<OIIO::TextureSystem::Perthread*> per_thread{nullptr};

    OIIO::TextureSystem::Perthread* thread_info()
    {
        OIIO::TextureSystem::Perthread*& info = per_thread.local();
        if (!info)
            info = system->create_thread_info();
        return info;
    }

    ~OiioTextures()
    {
        for (OIIO::TextureSystem::Perthread* info : per_thread)
            if (info)
                system->destroy_thread_info(info);
    }
};

namespace {

/// Refuses, from its header alone, a texture too large to decode: a small file may
/// declare 30000 x 30000 pixels, which OIIO would otherwise allocate when it builds the
/// MIP levels. A header that cannot be read is left to the TextureSystem's warning.
void check_texture_size(const std::filesystem::path& file, std::uint64_t max_memory_bytes)
{
    auto input = OIIO::ImageInput::open(file.string());
    if (!input) {
        (void)OIIO::geterror();  // the TextureSystem says why below
        return;
    }
    const OIIO::ImageSpec& spec = input->spec();
    if (spec.width > max_texture_side || spec.height > max_texture_side || spec.depth > 1)
        throw Error(FileLoc{file.string()},
                    "texture is " + std::to_string(spec.width) + " x " +
                        std::to_string(spec.height) +
                        (spec.depth > 1 ? " x " + std::to_string(spec.depth) : std::string()) +
                        " pixels; textures may have at most " + std::to_string(max_texture_side) +
                        " pixels on a side (and one layer)");
    // the decoded pixels and their MIP levels (a third more)
    std::uint64_t bytes = std::uint64_t(std::max(spec.width, 0)) *
                          std::uint64_t(std::max(spec.height, 0)) *
                          std::uint64_t(std::max(spec.nchannels, 0)) * spec.format.size() * 4 / 3;
    if (bytes > max_memory_bytes)
        throw Error(FileLoc{file.string()},
                    "texture needs " + byte_size_text(bytes) +
                        " decoded, more than the memory budget of " +
                        byte_size_text(max_memory_bytes) + " (--max-memory)");
}

/// The TextureSource of one TextureSet.
class OiioTextureSource final : public TextureSource {
public:
    OiioTextureSource(const std::vector<geom::TextureDef>& defs,
                      const std::filesystem::path& base, std::uint64_t max_memory_bytes,
                      const WarnFn& warn);
    std::size_t size() const override { return m_impl->entries.size(); }
    bool valid(int index) const override;
    bool decal(int index) const override { return valid(index) && m_impl->entries[index].decal; }
    bool has_alpha(int index) const override;
    Texel lookup(int index, float s, float t, const TextureFootprint& fp) const override;

private:
    std::unique_ptr<OiioTextures> m_impl;
};

OiioTextureSource::OiioTextureSource(const std::vector<geom::TextureDef>& defs,
                                     const std::filesystem::path& base,
                                     std::uint64_t max_memory_bytes, const WarnFn& warn)
    : m_impl(std::make_unique<OiioTextures>())
{
    if (defs.empty())
        return;
    // One private system per render: no state shared with other renders in the process.
    m_impl->system.reset(OIIO::TextureSystem::create(false));
    OIIO::TextureSystem& ts = *m_impl->system;
    ts.attribute("automip", 1);          // plain images get MIP levels built in memory
    ts.attribute("max_memory_MB", 512.0f);
    // Keep colours as stored (cpfg's OpenGL textures are not premultiplied by alpha).
    ts.attribute("unassociatedalpha", 1);
    for (const geom::TextureDef& def : defs) {
        std::filesystem::path file = def.file;
        if (file.is_relative() && !base.empty())
            file = base / file;
        // As cpfg, a texture that cannot be read is a warning and the surfaces it
        // names are drawn untextured (the corpus names maple.rgb beside a maple.png).
        Entry e;
        if (!std::filesystem::is_regular_file(file)) {
            warn(file.string(), "texture not found; drawing without it");
            m_impl->entries.push_back(e);
            continue;
        }
        check_texture_size(file, max_memory_bytes);
        e.handle = ts.get_texture_handle(OIIO::ustring(file.string()), m_impl->thread_info());
        const OIIO::ImageSpec* spec = e.handle ? ts.imagespec(e.handle, m_impl->thread_info()) : nullptr;
        if (!spec) {
            std::string why = ts.geterror();
            warn(file.string(), "texture cannot be read" +
                                             (why.empty() ? std::string() : ": " + why) +
                                             "; drawing without it");
            e.handle = nullptr;
            m_impl->entries.push_back(e);
            continue;
        }
        e.channels = spec->nchannels;
        e.srgb = !spec->format.is_floating_point();
        e.decal = def.decal;
        e.options.swrap = e.options.twrap = OIIO::TextureOpt::WrapPeriodic;
        e.options.interpmode = def.linear_filter ? OIIO::TextureOpt::InterpBilinear
                                                 : OIIO::TextureOpt::InterpClosest;
        e.options.mipmode = def.mipmap ? OIIO::TextureOpt::MipModeTrilinear
                                       : OIIO::TextureOpt::MipModeNoMIP;
        e.options.fill = 1;
        m_impl->entries.push_back(e);
    }
}

bool OiioTextureSource::valid(int index) const
{
    return index >= 0 && static_cast<std::size_t>(index) < m_impl->entries.size() &&
           m_impl->entries[static_cast<std::size_t>(index)].handle != nullptr;
}

bool OiioTextureSource::has_alpha(int index) const
{
    return valid(index) && (m_impl->entries[index].channels == 2 ||
                            m_impl->entries[index].channels >= 4);
}

Texel OiioTextureSource::lookup(int index, float s, float t, const TextureFootprint& fp) const
{
    if (!valid(index))
        return {};
    const Entry& e = m_impl->entries[index];
    OIIO::TextureOpt options = e.options;  // the lookup may write to it
    float v[4] = {1, 1, 1, 1};
    int n = e.channels >= 4 ? 4 : (e.channels == 2 ? 2 : (e.channels == 1 ? 1 : 3));
    // OIIO's t runs down the image, OpenGL's up: t derivatives change sign.
    bool ok = m_impl->system->texture(e.handle, m_impl->thread_info(), options, s, 1 - t,
                                      fp.dsdx, -fp.dtdx, fp.dsdy, -fp.dtdy, n, v);
    if (!ok)
        return {};
    Texel texel;
    if (n <= 2) {
        texel.colour = Vec3f(v[0]);
        texel.alpha = n == 2 ? v[1] : 1;
    } else {
        texel.colour = {v[0], v[1], v[2]};
        texel.alpha = n == 4 ? v[3] : 1;
    }
    if (e.srgb)
        texel.colour = {srgb_to_linear(texel.colour.x), srgb_to_linear(texel.colour.y),
                        srgb_to_linear(texel.colour.z)};
    return texel;
}

}  // namespace

std::unique_ptr<TextureSource> open_oiio_textures(const std::vector<geom::TextureDef>& defs,
                                                  const std::filesystem::path& base,
                                                  std::uint64_t max_memory_bytes,
                                                  const WarnFn& warn)
{
    return std::make_unique<OiioTextureSource>(defs, base, max_memory_bytes, warn);
}

}  // namespace cambium::render
