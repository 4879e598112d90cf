// SPDX-License-Identifier: Apache-2.0
// Organ masks (--organ-masks; docs/masks.md): per pixel, which organs its camera samples
// met and with what share, written to EXR as Cryptomatte layers (Psyop's specification
// 1.2: ids are MurmurHash3 of names, stored as floats, with a manifest) and as organ
// channels (index, age, branch order, plant) of the organ that covers most of the pixel.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "geom/scene.h"
#include "render/image.h"

namespace cambium::render {

/// MurmurHash3_x86_32 of `bytes` (Austin Appleby's public-domain hash), as
/// Cryptomatte hashes names.
std::uint32_t murmur3_32(std::string_view bytes, std::uint32_t seed = 0);

/// Cryptomatte's id of a hash: the float with the hash's bits, one exponent bit flipped
/// where the exponent is all zeros or all ones, so that no id is a denormal, an
/// infinity or a NaN (which compositors mangle).
float cryptomatte_id(std::uint32_t hash);

/// The hash of a name as the manifest writes it: 8 lowercase hex digits.
std::string hash_text(std::uint32_t hash);

/// An organ as the film keys it: its plant placement (Instance::plant; no_plant for a
/// single plant) in the high 32 bits, the module's index in the derived string below.
using OrganKey = std::uint64_t;
inline constexpr OrganKey organ_key(std::uint32_t plant, std::uint32_t module)
{
    return (OrganKey(plant) << 32) | module;
}
/// The ground plane (--ground), and primitives no module drew (a background scene).
inline constexpr OrganKey ground_organ = organ_key(0xfffffffeu, 0);
inline constexpr OrganKey unattributed_organ =
    organ_key(geom::Instance::no_plant, geom::no_module);

/// The organs a pixel's camera samples met and how many samples met each: 8 slots
/// (two more than the default rank depth, so the ranks written are rarely ones that
/// lost samples to a full pixel). A sample of a ninth organ is not counted (its
/// pixel's coverages then sum to less than its alpha). 96 bytes a pixel.
struct OrganSamples {
    static constexpr std::size_t slots = 8;
    std::array<OrganKey, slots> key{};
    std::array<std::uint32_t, slots> count{};

    void add(OrganKey k)
    {
        for (std::size_t s = 0; s < slots; ++s) {
            if (count[s] == 0)
                key[s] = k;
            if (key[s] == k) {
                ++count[s];
                return;
            }
        }
    }
};

/// The default rank depth: (id, coverage) pairs per pixel and layer (3 RGBA groups).
inline constexpr int default_organ_mask_depth = 6;

/// Bytes a pixel's organ masks take, in the film and in the image (Image::organ_masks),
/// for --max-memory.
std::uint64_t organ_mask_bytes_per_pixel(int depth);

/// The Cryptomatte layers and organ channels of one image, pixel by pixel (resolve).
class OrganMaskBuilder {
public:
    /// `depth`: ranks per pixel (at most OrganSamples::slots).
    OrganMaskBuilder(const geom::Scene& scene, std::size_t pixels, int depth);
    /// Pixel i's samples (`samples` of them taken in all).
    void pixel(std::size_t i, const OrganSamples& organs, std::uint32_t samples);
    OrganLayers finish();

    /// An organ's name in the CryptoOrgan layer ("L 12"; a scene file's:
    /// "plant 3 MODEL/L 12"; "ground"; "unattributed"), and its symbol's ("L").
    std::string organ_name(OrganKey key) const;
    std::string symbol_name(OrganKey key) const;

private:
    struct Organ {
        float organ_id = 0, symbol_id = 0;
        float index = -1, age = -1, order = -1, plant = -1;
    };
    const Organ& organ(OrganKey key);
    /// The module table and model name that name `key`'s module.
    const geom::ModuleTable* table_of(OrganKey key, std::string* model) const;

    const geom::Scene& m_scene;
    geom::OrganModules m_organ_modules;
    int m_depth;
    OrganLayers m_out;
    std::unordered_map<OrganKey, Organ> m_organs;
    std::map<std::string, std::uint32_t> m_organ_manifest, m_symbol_manifest;
};

}  // namespace cambium::render
