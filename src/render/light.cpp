// SPDX-License-Identifier: Apache-2.0
// The view file's lights (point, directional, spot) as delta lights for next-event estimation.
#include "render/light.h"

#include <cmath>
#include <numbers>

#include "render/color.h"

namespace cambium::render {

namespace {

float attenuation(const RenderLight& l, float d)
{
    float a = l.att_constant + l.att_linear * d + l.att_quadratic * d * d;
    return a > 0 ? 1.0f / a : 0.0f;
}

/// OpenGL's spot factor: (cos angle)^exponent inside the cone, 0 outside.
float spot_factor(const RenderLight& l, const Vec3f& from_light)
{
    float c = dot(from_light, l.spot_axis);
    if (c < l.spot_cos_cutoff)
        return 0;
    return l.spot_exponent > 0 ? std::pow(std::fmax(c, 0.0f), l.spot_exponent) : 1.0f;
}

}  // namespace

LightSample sample_light(const RenderLight& light, const Vec3f& p)
{
    constexpr float pi = std::numbers::pi_v<float>;
    if (light.kind == RenderLight::Kind::directional)
        return {light.toward_light, std::numeric_limits<float>::infinity(), light.colour * pi};
    Vec3f to = light.position - p;
    float d = length(to);
    if (d <= 0)
        return {Vec3f(0, 0, 1), 0, Vec3f()};
    Vec3f wi = to / d;
    float scale = pi * attenuation(light, d);
    if (light.kind == RenderLight::Kind::spot)
        scale *= spot_factor(light, -wi);
    return {wi, d, light.colour * scale};
}

std::vector<RenderLight> make_lights(const std::vector<geom::Light>& lights)
{
    constexpr double deg_to_rad = std::numbers::pi / 180.0;
    std::vector<RenderLight> out;
    out.reserve(lights.size());
    for (const geom::Light& l : lights) {
        RenderLight r;
        switch (l.kind) {
        case geom::Light::Kind::point: r.kind = RenderLight::Kind::point; break;
        case geom::Light::Kind::directional: r.kind = RenderLight::Kind::directional; break;
        case geom::Light::Kind::spot: r.kind = RenderLight::Kind::spot; break;
        }
        r.position = Vec3f(l.position);
        r.toward_light = normalize(Vec3f(l.direction));
        r.spot_axis = normalize(Vec3f(l.spot_direction));
        r.spot_exponent = l.spot_exponent;
        r.spot_cos_cutoff = l.spot_cutoff_deg >= 180
                                ? -1.0f
                                : static_cast<float>(std::cos(l.spot_cutoff_deg * deg_to_rad));
        r.att_constant = l.attenuation_constant;
        r.att_linear = l.attenuation_linear;
        r.att_quadratic = l.attenuation_quadratic;
        r.colour = decode_display(l.diffuse);
        if (r.kind == RenderLight::Kind::directional && is_black(r.toward_light))
            continue;  // a zero V: vector has no direction; cpfg draws nothing lit by it
        out.push_back(r);
    }
    return out;
}

}  // namespace cambium::render
