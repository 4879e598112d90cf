// SPDX-License-Identifier: Apache-2.0
// Derives, interprets and renders a small L-system through the installed libraries.
#include <cstdio>

#include "geom/interpreter.h"
#include "geom/view_file.h"
#include "lsys/lsystem.h"
#include "render/render.h"

int main()
{
    using namespace cambium;
    const auto system = lsys::LSystem::from_source(
        "Lsystem: 1\nderivation length: 2\nAxiom: F\nF --> F[+F]F\nendlsystem\n");
    const lsys::ModuleString derived = system.derive();
    const geom::Scene scene =
        geom::interpret(derived, system.symbols(), geom::parse_view_file("", "consumer.v"));
    render::RenderSettings settings;
    settings.width = settings.height = 8;
    settings.samples_per_pixel = 1;
    const render::Image image = render::render(scene, settings);
    std::printf("consumer: %zu modules, %zu segments, %dx%d image\n", derived.size(),
                scene.geometry.lines.segment_count(), image.width, image.height);
}
