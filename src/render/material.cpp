// SPDX-License-Identifier: Apache-2.0
// Surface materials: cpfg materials mapped to a small physically-based model.
#include "render/material.h"

#include <algorithm>
#include <cmath>

#include "render/color.h"

namespace cambium::render {

SurfaceMaterial mix(const SurfaceMaterial& a, const SurfaceMaterial& b, float w)
{
    auto lerp = [w](auto x, auto y) { return x * (1 - w) + y * w; };
    SurfaceMaterial m;
    m.diffuse = lerp(a.diffuse, b.diffuse);
    m.translucency = lerp(a.translucency, b.translucency);
    m.specular = lerp(a.specular, b.specular);
    m.exponent = lerp(a.exponent, b.exponent);
    m.emission = lerp(a.emission, b.emission);
    m.opacity = lerp(a.opacity, b.opacity);
    m.ambient_glow = lerp(a.ambient_glow, b.ambient_glow);
    return m;
}

geom::Rgb opengl_ambient_light(const std::vector<geom::Light>& lights)
{
    constexpr float light_model_ambient = 0.2f;  // OpenGL's GL_LIGHT_MODEL_AMBIENT default
    geom::Rgb sum{light_model_ambient, light_model_ambient, light_model_ambient};
    if (lights.empty())
        return {sum.r + 1, sum.g + 1, sum.b + 1};  // cpfg's default light has A: 1 1 1
    for (const geom::Light& l : lights)
        sum = {sum.r + l.ambient.r, sum.g + l.ambient.g, sum.b + l.ambient.b};
    return sum;
}

std::vector<SurfaceMaterial> make_materials(const std::vector<geom::Material>& materials,
                                            const geom::Rgb& ambient_light)
{
    std::vector<SurfaceMaterial> out;
    out.reserve(materials.size());
    for (const geom::Material& m : materials) {
        SurfaceMaterial s;
        s.diffuse = decode_display(m.diffuse);
        s.translucency = std::clamp(m.translucency, 0.0f, 1.0f);
        // OpenGL's shininess is a Blinn-Phong (half-vector) exponent; a Phong lobe about
        // the mirror direction is about as wide with a quarter of it.
        s.exponent = std::clamp(m.shininess, 0.0f, 128.0f) / 4;
        // OpenGL adds an unnormalized highlight that peaks at specular x light colour.
        // The normalized lobe peaks at albedo (n + 2) / 2 x light colour (a light of
        // colour c gives irradiance pi c), so albedo 2 / (n + 2) x specular keeps cpfg's
        // highlight and its small energy: a shiny stem stays its diffuse colour.
        s.specular = decode_display(m.specular) * (2 / (s.exponent + 2));
        s.emission = decode_display(m.emission);
        s.opacity = 1 - std::clamp(m.transparency, 0.0f, 1.0f);
        // OpenGL adds ambient x light ambient to the displayed colour (clamped at 1).
        geom::Rgb glow{std::min(m.ambient.r * ambient_light.r, 1.0f),
                       std::min(m.ambient.g * ambient_light.g, 1.0f),
                       std::min(m.ambient.b * ambient_light.b, 1.0f)};
        s.ambient_glow = decode_display(glow);
        out.push_back(s);
    }
    return out;
}

namespace {

constexpr int index_block = 64;  // cpfg's surface rule works within blocks of 64 entries

/// The albedo of display colour `entry` at the brightness of display colour `own`,
/// scaled down where a channel would pass 1. Scaled in display values, where colormap
/// ramps are made: a ramp of one colour in several brightnesses gives `own` exactly.
Vec3f hue_at_luminance(const geom::Rgb& entry, const geom::Rgb& own)
{
    Vec3f e(entry.r, entry.g, entry.b), o(own.r, own.g, own.b);
    float y = luminance(e);
    if (y <= 0)
        return decode_display(own);  // black has no hue to keep
    Vec3f c = e * (luminance(o) / y);
    float top = std::max({c.x, c.y, c.z});
    if (top > 1)
        c = c * (1 / top);
    return decode_display({c.x, c.y, c.z});
}

}  // namespace

std::vector<IndexRamp> make_index_ramps(const std::vector<geom::Material>& materials,
                                        const geom::ColourIndexLight& light)
{
    std::vector<IndexRamp> ramps(materials.size());
    for (std::size_t m = 0; m < materials.size(); ++m) {
        const geom::Material& material = materials[m];
        // The entries the index moves over: 256 from the material's colour table on.
        const std::size_t table = material.colour_table;
        const int last =
            table < materials.size()
                ? static_cast<int>(std::min(materials.size() - table, geom::colour_indices)) - 1
                : -1;
        auto entry = [&](int index) {
            return materials[table + static_cast<std::size_t>(std::clamp(index, 0, last))].diffuse;
        };
        IndexRamp& ramp = ramps[m];
        ramp.rule = last < 0 ? geom::IndexLighting::none : material.index_lighting;
        const int own = material.colour_index;
        const geom::Rgb& own_colour = material.diffuse;
        if (ramp.rule == geom::IndexLighting::cosine) {
            ramp.reach = std::abs(light.diffuse_reflection);
            for (int offset = -ramp.reach; offset <= ramp.reach; ++offset)
                ramp.albedo.push_back(hue_at_luminance(entry(own + offset), own_colour));
        } else if (ramp.rule == geom::IndexLighting::surface) {
            ramp.place = own % index_block;
            const int block = own - ramp.place;
            for (int k = 0; k < index_block; ++k)
                ramp.albedo.push_back(hue_at_luminance(entry(block + k), own_colour));
        }
    }
    return ramps;
}

Vec3f index_lit_albedo(const IndexRamp& ramp, const geom::ColourIndexLight& light, float cos_light)
{
    if (ramp.rule == geom::IndexLighting::cosine) {
        // C's float-to-int conversion truncates toward zero, as cpfg's index arithmetic.
        int offset = static_cast<int>(static_cast<float>(light.diffuse_reflection) * cos_light);
        return ramp.albedo[static_cast<std::size_t>(std::clamp(offset, -ramp.reach, ramp.reach) + ramp.reach)];
    }
    float level = light.surface_ambient + light.surface_diffuse * std::fabs(cos_light);
    float place = static_cast<float>(ramp.place) * level;
    // Clamped as a float first: a huge or NaN level must not reach the int conversion.
    place = place >= 0 ? std::min(place, static_cast<float>(index_block - 1)) : 0.0f;
    return ramp.albedo[static_cast<std::size_t>(place)];
}

}  // namespace cambium::render
