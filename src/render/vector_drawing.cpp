// SPDX-License-Identifier: Apache-2.0
#include "render/vector_drawing.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "geom/primitives.h"

namespace cambium::render {
namespace {

geom::Vec3 vec(const geom::Float3& p) { return {p[0], p[1], p[2]}; }

const geom::Material& material_of(const geom::Scene& scene, std::uint16_t index)
{
    static const geom::Material fallback;
    return index < scene.materials.size() ? scene.materials[index] : fallback;
}

/// The colour a material starts from: a colour-index lit one's starting index, as the
/// rayshade output's surfaces name it.
geom::Rgb base_colour(const geom::Scene& scene, const geom::Material& m)
{
    if (m.index_lighting != geom::IndexLighting::none) {
        std::size_t base = std::size_t(m.colour_table) + m.colour_index;
        if (base < scene.materials.size())
            return scene.materials[base].diffuse;
    }
    return m.diffuse;
}

float unit(double v) { return static_cast<float>(std::clamp(v, 0.0, 1.0)); }

/// Depth along the view direction from the eye (perspective) or the focus (parallel),
/// the measure of the camera's clipping planes.
double depth_of(const Camera& camera, const geom::Vec3& p)
{
    return dot(p - camera.origin(), camera.forward());
}

/// Whether a shape with these vertex depths may be drawn: in front of a perspective eye
/// and, by its centre's depth, between the clipping planes.
bool visible(const Camera& camera, std::span<const double> depths, double centre)
{
    if (camera.projection() == Camera::Projection::perspective)
        for (double d : depths)
            if (!(d > 1e-9 * std::max(1.0, std::abs(centre))))
                return false;
    return centre >= camera.clip_near() && centre <= camera.clip_far();
}

/// Whether the shape's points lie wholly to one side outside the window.
bool off_window(std::span<const PixelPoint> points, int width, int height)
{
    double x0 = points[0].x, x1 = x0, y0 = points[0].y, y1 = y0;
    for (const PixelPoint& p : points) {
        x0 = std::min(x0, p.x);
        x1 = std::max(x1, p.x);
        y0 = std::min(y0, p.y);
        y1 = std::max(y1, p.y);
    }
    return x1 < 0 || y1 < 0 || x0 > width || y0 > height || !std::isfinite(x0 + x1 + y0 + y1);
}

/// Twice the triangle's signed area with its corners on a grid of 1/256 pixel, in
/// grid units.
double page_area_in_256ths(const std::array<PixelPoint, 3>& p)
{
    auto grid = [](double v) { return std::nearbyint(v * 256); };
    const double x0 = grid(p[0].x), y0 = grid(p[0].y);
    return (grid(p[1].x) - x0) * (grid(p[2].y) - y0) - (grid(p[2].x) - x0) * (grid(p[1].y) - y0);
}

void add_lines(const geom::Scene& scene, const geom::LinearCurves& lines,
               const geom::Instance* instance, const Camera& camera, VectorDrawing& out)
{
    for (std::size_t i = 0; i < lines.segment_count(); ++i) {
        const geom::Float4& ka = lines.keys[lines.segments[i]];
        const geom::Float4& kb = lines.keys[lines.segments[i] + 1];
        geom::Vec3 a{ka[0], ka[1], ka[2]}, b{kb[0], kb[1], kb[2]};
        std::uint16_t material = i < lines.material.size() ? lines.material[i] : 0;
        if (instance) {
            a = geom::Affine3x4(instance->transform).apply(a);
            b = geom::Affine3x4(instance->transform).apply(b);
            if (material == geom::inherit_material)
                material = instance->material;
        }
        const double depths[2] = {depth_of(camera, a), depth_of(camera, b)};
        const double centre = 0.5 * (depths[0] + depths[1]);
        if (!visible(camera, depths, centre))
            continue;
        VectorShape s;
        s.kind = VectorShape::Kind::line;
        s.points[0] = camera.project(a);
        s.points[1] = camera.project(b);
        if (off_window(std::span(s.points.data(), 2), out.width, out.height))
            continue;
        // pixel lines are unlit in cpfg's window: the flat colour
        s.colour = base_colour(scene, material_of(scene, material));
        s.line_width = std::max(1.0f, 2 * ka[3]);  // the key holds the radius in pixels
        s.depth = centre;
        out.shapes.push_back(s);
    }
}

}  // namespace

geom::Rgb vector_colour(const geom::Scene& scene, std::uint16_t material, const geom::Vec3& normal,
                        const geom::Vec3& centre, const Camera& camera)
{
    const geom::Material& m = material_of(scene, material);
    const geom::Rgb base = base_colour(scene, m);
    if (scene.shading == geom::Shading::filled || scene.shading == geom::Shading::wireframe)
        return base;
    const bool index_lit = m.index_lighting != geom::IndexLighting::none;
    const bool has_ambient = m.ambient.r + m.ambient.g + m.ambient.b > 0 ||
                             m.emission.r + m.emission.g + m.emission.b > 0;
    // a colormap colour that no index lighting moves is drawn as it is (no OpenGL lighting)
    if (!index_lit && !has_ambient)
        return base;
    geom::Vec3 to_light = -camera.forward();
    geom::Rgb la{0.2f, 0.2f, 0.2f}, ld{1, 1, 1};
    if (!scene.lights.empty()) {
        const geom::Light& l = scene.lights.front();
        to_light = l.kind == geom::Light::Kind::directional ? l.direction : l.position - centre;
        la = l.ambient;
        ld = l.diffuse;
    }
    const double len = length(to_light);
    const double cosine = len > 0 ? std::abs(dot(normal, to_light / len)) : 1.0;
    if (index_lit) {
        // cpfg moves the index through its block by ambient + diffuse x |N.L|
        double ka = 0.15, kd = 0.75;
        if (scene.colour_index_light) {
            ka = scene.colour_index_light->surface_ambient;
            kd = scene.colour_index_light->surface_diffuse;
        }
        const double k = std::min(1.0, ka + kd * cosine) / std::min(1.0, ka + kd);
        return {unit(base.r * k), unit(base.g * k), unit(base.b * k)};
    }
    // OpenGL's lighting by one light: emission + ambient La + diffuse Ld |N.L|
    return {unit(m.emission.r + m.ambient.r * la.r + base.r * ld.r * cosine),
            unit(m.emission.g + m.ambient.g * la.g + base.g * ld.g * cosine),
            unit(m.emission.b + m.ambient.b * la.b + base.b * ld.b * cosine)};
}

VectorDrawing project_drawing(const geom::Scene& scene, const geom::TriangleMesh& triangles,
                              const Camera& camera)
{
    VectorDrawing out;
    out.width = camera.width();
    out.height = camera.height();
    out.background = scene.background;
    out.shapes.reserve(triangles.size());
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        const auto& t = triangles.triangles[i];
        const geom::Vec3 p[3] = {vec(triangles.positions[t[0]]), vec(triangles.positions[t[1]]),
                                 vec(triangles.positions[t[2]])};
        const double depths[3] = {depth_of(camera, p[0]), depth_of(camera, p[1]),
                                  depth_of(camera, p[2])};
        const geom::Vec3 centre = (p[0] + p[1] + p[2]) / 3.0;
        const double centre_depth = (depths[0] + depths[1] + depths[2]) / 3.0;
        if (!visible(camera, depths, centre_depth))
            continue;
        VectorShape s;
        for (int k = 0; k < 3; ++k)
            s.points[k] = camera.project(p[k]);
        if (off_window(s.points, out.width, out.height))
            continue;
        // Seen edge on, degenerate, or too small to cover anything once its corners are
        // rounded to 1/256 pixel (what vector writers keep), a triangle draws nothing.
        if (page_area_in_256ths(s.points) == 0)
            continue;
        const geom::Vec3 n = cross(p[1] - p[0], p[2] - p[0]);
        const double area = length(n);
        if (!(area > 0))
            continue;
        // the side the window sees: its vertex normals' side, else its winding's
        geom::Vec3 front = n;
        if (t[0] < triangles.normals.size() && t[1] < triangles.normals.size() &&
            t[2] < triangles.normals.size()) {
            const geom::Vec3 sum = vec(triangles.normals[t[0]]) + vec(triangles.normals[t[1]]) +
                                   vec(triangles.normals[t[2]]);
            if (length(sum) > 0)
                front = sum;
        }
        const geom::Vec3 to_eye = camera.projection() == Camera::Projection::perspective
                                      ? camera.origin() - centre
                                      : -camera.forward();
        const bool back = dot(front, to_eye) < 0 && i < triangles.back_material.size();
        std::uint16_t material = i < triangles.material.size() ? triangles.material[i] : 0;
        if (back)
            material = triangles.back_material[i];
        s.colour = vector_colour(scene, material, n / area, centre, camera);
        s.depth = centre_depth;
        out.shapes.push_back(s);
    }
    if (scene.line_radius_in_pixels) {
        add_lines(scene, scene.geometry.lines, nullptr, camera, out);
        for (const geom::Instance& in : scene.instances)
            if (in.prototype < scene.prototypes.size())
                add_lines(scene, scene.prototypes[in.prototype].geometry.lines, &in, camera, out);
    }
    // painter's algorithm: the farthest first, so nearer shapes cover it
    std::stable_sort(out.shapes.begin(), out.shapes.end(),
                     [](const VectorShape& a, const VectorShape& b) { return a.depth > b.depth; });
    return out;
}

}  // namespace cambium::render
