// SPDX-License-Identifier: Apache-2.0
// cpfg's colormap-mode lighting: the scene's ColourIndexLight and its material layout.
#include "geom/colour_index_lighting.h"

#include <algorithm>

#include "geom/interpreter.h"

namespace cambium::geom {

bool lit_by_colour_index(const ViewFile& view, const Palette& palette)
{
    Shading mode = view.render_mode.shading;
    return palette.mode() != Palette::Mode::materials &&
           (mode == Shading::shaded || mode == Shading::flat) && !view.render_mode.interpolated;
}

void light_by_colour_index(Scene& scene, const ViewFile& view, const Palette& palette, int colour_block)
{
    ColourIndexLight light;
    // cpfg's light direction is the first light's position or direction, normalised.
    Light first = effective_lights(view).front();
    Vec3 to_light = first.kind == Light::Kind::directional ? first.direction : first.position;
    if (dot(to_light, to_light) > 0)
        light.to_light = normalize(to_light);
    light.diffuse_reflection = view.colour_index_shading.diffuse_reflection;
    light.surface_ambient = view.colour_index_shading.surface_ambient;
    light.surface_diffuse = view.colour_index_shading.surface_diffuse;
    scene.colour_index_light = light;
    // The colour table runs on from the selected colormap into the next one (an unloaded
    // one is grey, a last one repeats).
    const int next_block = std::min(colour_block + 1, Palette::blocks - 1);
    std::vector<Material> next = next_block > colour_block ? palette.entries(next_block) : scene.materials;
    scene.materials.resize(3 * colour_indices);
    for (std::size_t i = 0; i < colour_indices; ++i) {
        Material& m = scene.materials[i];
        m.index_lighting = IndexLighting::cosine;
        m.colour_index = static_cast<std::uint8_t>(i);
        scene.materials[i + colour_indices] = m;
        scene.materials[i + colour_indices].index_lighting = IndexLighting::surface;
        Material& n = scene.materials[i + 2 * colour_indices];
        n = next.at(i);
        n.transparency = 0;
        n.index_lighting = IndexLighting::surface;
        n.colour_index = static_cast<std::uint8_t>(i);
        n.colour_table = 2 * colour_indices;
    }
}

}  // namespace cambium::geom
