// SPDX-License-Identifier: Apache-2.0
// Cameras for sequences and for the command line's camera options.
//
// A turntable orbits the camera about the vertical axis (+y, cpfg's view-up vector)
// through the centre of the plant's bounds. Everything the bounds can reach during the
// orbit lies in the cylinder they sweep about that axis, and the cylinder is the same
// seen from every angle; framing the cylinder once therefore keeps the plant inside
// every frame at one constant scale.
#include "render/framing.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cambium::render {
namespace {

using geom::Vec3;
constexpr double deg = std::numbers::pi / 180.0;
const Vec3 vertical{0, 1, 0};

/// Rotates v about the unit axis k by `angle` radians (Rodrigues).
Vec3 rotated(const Vec3& v, const Vec3& k, double angle)
{
    double c = std::cos(angle), s = std::sin(angle);
    return v * c + geom::cross(k, v) * s + k * (geom::dot(k, v) * (1 - c));
}

geom::Bounds3 non_empty(geom::Bounds3 b)
{
    if (b.empty())
        b.extend(Vec3{0, 0, 0});
    return b;
}

/// The cylinder about the vertical axis through the box's centre that holds the box
/// in every rotation about that axis.
struct SweptCylinder {
    Vec3 centre;
    double radius = 0;
    double below = 0, above = 0;  ///< heights of its ends relative to the centre
};

SweptCylinder swept_cylinder(const geom::Bounds3& b)
{
    SweptCylinder s;
    s.centre = b.center();
    double dx = b.extent().x / 2, dz = b.extent().z / 2;
    s.radius = std::sqrt(dx * dx + dz * dz);
    s.below = b.lo.y - s.centre.y;
    s.above = b.hi.y - s.centre.y;
    return s;
}

/// The direction and up vector of the orbit at angle theta.
struct OrbitPose {
    Vec3 forward, up;
};

OrbitPose orbit_pose(const Vec3& horizontal, double elevation, double theta)
{
    Vec3 h = rotated(horizontal, vertical, theta);
    Vec3 forward = h * std::cos(elevation) - vertical * std::sin(elevation);
    Vec3 up = geom::normalize(vertical - forward * geom::dot(vertical, forward));
    return {forward, up};
}

/// Whether every point of the cylinder's rims projects inside the image's inner part.
bool rims_inside(const Camera& camera, const SweptCylinder& s, double margin)
{
    constexpr int samples = 90;
    for (double height : {s.below, s.above})
        for (int i = 0; i < samples; ++i) {
            double a = 2 * std::numbers::pi * i / samples;
            Vec3 p = s.centre + Vec3{s.radius * std::cos(a), height, s.radius * std::sin(a)};
            if (geom::dot(p - camera.origin(), camera.forward()) <= 0)
                return false;
            PixelPoint q = camera.project(p);
            if (q.x < margin * camera.width() || q.x > (1 - margin) * camera.width() ||
                q.y < margin * camera.height() || q.y > (1 - margin) * camera.height())
                return false;
        }
    return true;
}

}  // namespace

geom::View apply_overrides(geom::View view, const ViewOverrides& o, const geom::Bounds3& bounds)
{
    if (o.perspective)
        view.perspective = *o.perspective;
    if (o.fov_deg)
        view.viewing_angle_deg = *o.fov_deg;
    if (o.fit) {
        view.box.reset();
        view.scale_factor = 1;
        if (view.perspective) {
            // The bounding sphere fills the narrower field of view.
            geom::Bounds3 b = non_empty(bounds);
            double radius = std::max(geom::length(b.extent()) / 2, 1e-6);
            double fov = std::clamp(view.viewing_angle_deg, 1.0, 170.0) * deg;
            Vec3 away = geom::normalize(view.viewpoint - view.reference_point);
            if (geom::length(away) == 0)
                away = {0, 0, 1};
            view.reference_point = b.center();
            view.viewpoint = b.center() + away * (radius / std::sin(fov / 2));
        }
    }
    if (o.orbit_azimuth_deg || o.orbit_elevation_deg) {
        Vec3 d = view.viewpoint - view.reference_point;
        d = rotated(d, vertical, o.orbit_azimuth_deg.value_or(0) * deg);
        Vec3 raise = geom::normalize(geom::cross(d, vertical));
        if (geom::length(raise) > 0)
            d = rotated(d, raise, o.orbit_elevation_deg.value_or(0) * deg);
        view.viewpoint = view.reference_point + d;
    }
    view.scale_factor *= o.zoom;
    return view;
}

std::vector<Camera> turntable_cameras(const geom::View& view, const geom::Bounds3& bounds,
                                      int frames, std::optional<double> elevation_deg,
                                      int width, int height, double margin)
{
    SweptCylinder s = swept_cylinder(non_empty(bounds));
    Vec3 forward = geom::normalize(view.reference_point - view.viewpoint);
    if (geom::length(forward) == 0)
        forward = {0, 0, -1};
    Vec3 horizontal = geom::normalize(forward - vertical * geom::dot(forward, vertical));
    if (geom::length(horizontal) == 0)
        horizontal = {0, 0, -1};  // looking straight down or up: orbit from the front
    double elevation = elevation_deg ? *elevation_deg * deg
                                     : -std::asin(std::clamp(forward.y, -1.0, 1.0));
    elevation = std::clamp(elevation, -89.9 * deg, 89.9 * deg);

    // The cylinder seen at this elevation: its half-width is its radius; its ends are
    // ellipses whose vertical half-axes are radius * |sin(elevation)|.
    double tilt = std::abs(std::sin(elevation)), upright = std::cos(elevation);
    double low = s.below * upright - s.radius * tilt, high = s.above * upright + s.radius * tilt;
    double middle = (low + high) / 2;
    double usable = 1 - 2 * margin;
    // --zoom (the view's scale factor) magnifies the fitted orbit, as make_camera does:
    // smaller pixels in parallel, the eye nearer in perspective.
    double zoom = view.scale_factor > 0 ? view.scale_factor : 1.0;

    std::vector<Camera> cameras;
    cameras.reserve(static_cast<std::size_t>(frames));
    if (!view.perspective) {
        double pixel_size = std::max({2 * s.radius / (width * usable),
                                      (high - low) / (height * usable), 1e-9}) / zoom;
        double back_off = s.radius + std::max(std::abs(s.below), std::abs(s.above)) +
                          std::abs(middle) + 1.0;
        for (int k = 0; k < frames; ++k) {
            OrbitPose pose = orbit_pose(horizontal, elevation, 2 * std::numbers::pi * k / frames);
            cameras.push_back(Camera::parallel(s.centre + pose.up * middle, pose.forward, pose.up,
                                               pixel_size, back_off, width, height));
        }
        return cameras;
    }

    // Perspective: the view's field of view; the nearest distance where the rims fit
    // (by bisection: farther away, the cylinder only shrinks in the image).
    auto camera_at = [&](double distance, double theta) {
        OrbitPose pose = orbit_pose(horizontal, elevation, theta);
        Vec3 focus = s.centre + pose.up * middle;
        return Camera::perspective(focus - pose.forward * distance, focus, pose.up,
                                   view.viewing_angle_deg, width, height);
    };
    double size = s.radius + std::max(std::abs(s.below), std::abs(s.above)) + 1e-6;
    double near = 0, far = size;
    while (!rims_inside(camera_at(far, 0), s, margin) && far < size * 1e6)
        far *= 2;
    for (int i = 0; i < 60; ++i) {
        double mid = (near + far) / 2;
        (rims_inside(camera_at(mid, 0), s, margin) ? far : near) = mid;
    }
    for (int k = 0; k < frames; ++k)
        cameras.push_back(camera_at(far / zoom, 2 * std::numbers::pi * k / frames));
    return cameras;
}

Camera transform_object_view(const Camera& camera, const Vec3& rotation_deg, const Vec3& scale,
                             const geom::Bounds3& bounds)
{
    // Seeing the object rotated by R = Rz Ry Rx is seeing it unrotated from R^-1.
    auto inverse = [&](Vec3 v) {
        v = rotated(v, {0, 0, 1}, -rotation_deg.z * deg);
        v = rotated(v, {0, 1, 0}, -rotation_deg.y * deg);
        return rotated(v, {1, 0, 0}, -rotation_deg.x * deg);
    };
    double s = std::cbrt(std::abs(scale.x * scale.y * scale.z));
    if (!(s > 0) || !std::isfinite(s))
        s = 1;
    Vec3 forward = inverse(camera.forward()), up = inverse(camera.up());
    Vec3 origin = inverse(camera.origin()) / s;
    if (camera.projection() == Camera::Projection::parallel) {
        geom::Bounds3 b = non_empty(bounds);
        double back_off =
            geom::length(b.extent()) + geom::length(b.center() - origin) + 1.0;
        return Camera::parallel(origin, forward, up, camera.pixel_size() / s, back_off,
                                camera.width(), camera.height());
    }
    double distance = camera.focus_distance() / s;
    double fov = 2 * std::atan(camera.pixel_size() * camera.height() / 2 /
                               camera.focus_distance()) / deg;
    return Camera::perspective(origin, origin + forward * distance, up, fov, camera.width(),
                               camera.height());
}

}  // namespace cambium::render
