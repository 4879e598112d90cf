// SPDX-License-Identifier: Apache-2.0
// Organ masks: Cryptomatte layers and organ channels (docs/masks.md).
#include "render/organ_masks.h"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>

#include "base/diagnostics.h"

namespace cambium::render {

namespace {

constexpr std::uint32_t rotl32(std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); }

/// MurmurHash3's finalisation: every input bit reaches every output bit.
constexpr std::uint32_t fmix32(std::uint32_t h)
{
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

/// A JSON string literal of `s` (names are symbols and model names: any byte may occur).
std::string json_string(std::string_view s)
{
    std::string out = "\"";
    for (unsigned char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += char(c);
        } else if (c < 0x20) {
            char buffer[8];
            std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
            out += buffer;
        } else {
            out += char(c);
        }
    }
    return out + "\"";
}

std::string manifest_json(const std::map<std::string, std::uint32_t>& names)
{
    std::string out = "{";
    for (const auto& [name, hash] : names) {
        if (out.size() > 1)
            out += ',';
        out += json_string(name) + ":" + json_string(hash_text(hash));
    }
    return out + "}";
}

constexpr std::uint16_t no_order = 0xffff;

}  // namespace

std::uint32_t murmur3_32(std::string_view bytes, std::uint32_t seed)
{
    constexpr std::uint32_t c1 = 0xcc9e2d51u, c2 = 0x1b873593u;
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const std::size_t n = bytes.size(), blocks = n / 4;
    std::uint32_t h = seed;
    for (std::size_t b = 0; b < blocks; ++b) {
        // little-endian blocks, whatever the machine
        std::uint32_t k = std::uint32_t(data[4 * b]) | std::uint32_t(data[4 * b + 1]) << 8 |
                          std::uint32_t(data[4 * b + 2]) << 16 | std::uint32_t(data[4 * b + 3]) << 24;
        k = rotl32(k * c1, 15) * c2;
        h = rotl32(h ^ k, 13) * 5 + 0xe6546b64u;
    }
    const unsigned char* tail = data + 4 * blocks;
    std::uint32_t k = 0;
    for (std::size_t j = n & 3; j > 0; --j)
        k |= std::uint32_t(tail[j - 1]) << (8 * (j - 1));
    if (n & 3)
        h ^= rotl32(k * c1, 15) * c2;
    return fmix32(h ^ static_cast<std::uint32_t>(n));
}

float cryptomatte_id(std::uint32_t hash)
{
    const std::uint32_t exponent = (hash >> 23) & 0xffu;
    if (exponent == 0 || exponent == 0xffu)
        hash ^= 1u << 23;
    return std::bit_cast<float>(hash);
}

std::string hash_text(std::uint32_t hash)
{
    char buffer[16];
    std::snprintf(buffer, sizeof buffer, "%08x", hash);
    return buffer;
}

std::uint64_t organ_mask_bytes_per_pixel(int depth)
{
    // the film's slots, two layers of depth floats pairs, four organ channels
    return sizeof(OrganSamples) + std::uint64_t(2 * 2 * depth + 4) * sizeof(float);
}

OrganMaskBuilder::OrganMaskBuilder(const geom::Scene& scene, std::size_t pixels, int depth)
    : m_scene(scene), m_organ_modules(scene), m_depth(depth)
{
    if (depth <= 0 || depth % 2 != 0 || std::size_t(depth) > OrganSamples::slots)
        throw Error("organ masks: the rank depth must be even, from 2 to " +
                    std::to_string(OrganSamples::slots) + ", not " + std::to_string(depth));
    m_out.depth = depth;
    for (const char* name : {"CryptoOrgan", "CryptoSymbol"})
        m_out.cryptomatte.push_back({name, std::vector<float>(pixels * std::size_t(2 * depth), 0.0f)});
    for (auto* channel : {&m_out.index, &m_out.age, &m_out.order, &m_out.plant})
        channel->assign(pixels, -1.0f);
}

const geom::ModuleTable* OrganMaskBuilder::table_of(OrganKey key, std::string* model) const
{
    const auto plant = static_cast<std::uint32_t>(key >> 32);
    const geom::Prototype* p = m_organ_modules.plant_prototype(plant);
    if (model && p)
        *model = p->name;
    return &m_organ_modules.of(plant, static_cast<std::uint32_t>(key));
}

std::string OrganMaskBuilder::organ_name(OrganKey key) const
{
    if (key == ground_organ)
        return "ground";
    const auto plant = static_cast<std::uint32_t>(key >> 32);
    const auto module = static_cast<std::uint32_t>(key);
    if (module == geom::no_module)
        return "unattributed";
    std::string model;
    const geom::ModuleTable* table = table_of(key, &model);
    const geom::ModuleRecord* r = table->find(module);
    std::string name = (r ? std::string(table->name(*r)) : std::string("module")) + " " +
                       std::to_string(module);
    if (r) {
        // an animation's organ: where it appeared, the same in every frame it lives in
        const auto at = static_cast<std::size_t>(r - table->records.data());
        if (at < table->births.size() && r->age != geom::unknown_age)
            name = std::string(table->name(*r)) + " " + std::to_string(table->births[at]) + "@" +
                   std::to_string(r->age);
    }
    if (plant == geom::Instance::no_plant)
        return name;
    return "plant " + std::to_string(plant) + " " + model + "/" + name;
}

std::string OrganMaskBuilder::symbol_name(OrganKey key) const
{
    if (key == ground_organ)
        return "ground";
    const auto module = static_cast<std::uint32_t>(key);
    if (module == geom::no_module)
        return "unattributed";
    const geom::ModuleTable* table = table_of(key, nullptr);
    const geom::ModuleRecord* r = table->find(module);
    return r ? std::string(table->name(*r)) : std::string("module");
}

const OrganMaskBuilder::Organ& OrganMaskBuilder::organ(OrganKey key)
{
    auto [it, fresh] = m_organs.try_emplace(key);
    if (!fresh)
        return it->second;
    Organ& o = it->second;
    const std::string name = organ_name(key), symbol = symbol_name(key);
    const std::uint32_t organ_hash = murmur3_32(name), symbol_hash = murmur3_32(symbol);
    o.organ_id = cryptomatte_id(organ_hash);
    o.symbol_id = cryptomatte_id(symbol_hash);
    m_organ_manifest.emplace(name, organ_hash);
    m_symbol_manifest.emplace(symbol, symbol_hash);
    const auto plant = static_cast<std::uint32_t>(key >> 32);
    const auto module = static_cast<std::uint32_t>(key);
    if (key == ground_organ || module == geom::no_module)
        return o;
    o.index = static_cast<float>(module);
    o.plant = plant == geom::Instance::no_plant ? 0.0f : static_cast<float>(plant);
    const geom::ModuleTable* table = table_of(key, nullptr);
    if (const geom::ModuleRecord* r = table->find(module)) {
        if (r->age != geom::unknown_age)
            o.age = static_cast<float>(r->age);
        const auto at = static_cast<std::size_t>(r - table->records.data());
        if (at < table->orders.size() && table->orders[at] != no_order)
            o.order = static_cast<float>(table->orders[at]);
    }
    return o;
}

void OrganMaskBuilder::pixel(std::size_t i, const OrganSamples& organs, std::uint32_t samples)
{
    if (samples == 0)
        return;
    std::array<std::size_t, OrganSamples::slots> rank{};
    std::size_t n = 0;
    for (std::size_t s = 0; s < OrganSamples::slots && organs.count[s] > 0; ++s)
        rank[n++] = s;
    // the largest coverage first; ties by key, so that the order is the same every run
    std::sort(rank.begin(), rank.begin() + n, [&](std::size_t a, std::size_t b) {
        return organs.count[a] != organs.count[b] ? organs.count[a] > organs.count[b]
                                                  : organs.key[a] < organs.key[b];
    });
    const float inv = 1.0f / static_cast<float>(samples);
    float* organ_ranks = &m_out.cryptomatte[0].ranks[i * std::size_t(2 * m_depth)];
    float* symbol_ranks = &m_out.cryptomatte[1].ranks[i * std::size_t(2 * m_depth)];
    // CryptoSymbol: every counted organ's coverage summed per symbol, ranked again
    std::array<std::pair<float, float>, OrganSamples::slots> symbols{};  // (id, coverage)
    std::size_t symbol_count = 0;
    for (std::size_t r = 0; r < n; ++r) {
        const std::size_t s = rank[r];
        const Organ& o = organ(organs.key[s]);
        const float coverage = static_cast<float>(organs.count[s]) * inv;
        if (r < std::size_t(m_depth)) {
            organ_ranks[2 * r] = o.organ_id;
            organ_ranks[2 * r + 1] = coverage;
        }
        if (r == 0) {
            m_out.index[i] = o.index;
            m_out.age[i] = o.age;
            m_out.order[i] = o.order;
            m_out.plant[i] = o.plant;
        }
        auto same = std::find_if(symbols.begin(), symbols.begin() + symbol_count, [&](const auto& p) {
            return std::bit_cast<std::uint32_t>(p.first) == std::bit_cast<std::uint32_t>(o.symbol_id);
        });
        if (same != symbols.begin() + symbol_count)
            same->second += coverage;
        else
            symbols[symbol_count++] = {o.symbol_id, coverage};
    }
    std::stable_sort(symbols.begin(), symbols.begin() + symbol_count,
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    for (std::size_t r = 0; r < std::min(symbol_count, std::size_t(m_depth)); ++r) {
        symbol_ranks[2 * r] = symbols[r].first;
        symbol_ranks[2 * r + 1] = symbols[r].second;
    }
}

OrganLayers OrganMaskBuilder::finish()
{
    for (std::size_t l = 0; l < m_out.cryptomatte.size(); ++l) {
        const std::string& name = m_out.cryptomatte[l].name;
        const std::string key = "cryptomatte/" + hash_text(murmur3_32(name)).substr(0, 7);
        m_out.attributes.emplace_back(key + "/name", name);
        m_out.attributes.emplace_back(key + "/hash", "MurmurHash3_32");
        m_out.attributes.emplace_back(key + "/conversion", "uint32_to_float32");
        m_out.attributes.emplace_back(key + "/manifest",
                                      manifest_json(l == 0 ? m_organ_manifest : m_symbol_manifest));
    }
    return std::move(m_out);
}

}  // namespace cambium::render
