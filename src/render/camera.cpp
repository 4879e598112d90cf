// SPDX-License-Identifier: Apache-2.0
// The camera that frames a Scene as cpfg's window does: parallel auto-fit or perspective.
//
// cpfg framing, checked against the corpus oracle (cpfg's own window grabs and its
// rayshade export, see tests/render/camera_test.cpp):
// - Both projections look along (reference point - viewpoint), up = +y made
//   perpendicular to that direction, then rotated by `twist` about it.
// - Parallel: the box (`box:` or the geometry's bounds) is projected onto the view
//   plane; its centre goes to the window centre and the scale is
//   scale_factor * min(width / box_width, height / box_height) pixels per unit, so the
//   limiting dimension of the box fills scale_factor of the window.
// - Perspective: no auto-fit. The eye sits at reference + (viewpoint - reference) /
//   scale_factor, looking at the reference point, with `viewing angle` as the vertical
//   field of view (rayshade's export: eyep = lookp + (vp - lookp)/sf, horizontal fov =
//   2 atan(aspect tan(angle/2))).
#include "render/camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "base/diagnostics.h"
#include "geom/scene_limits.h"
#include "render/simd_clones.h"

namespace cambium::render {

using geom::Vec3;

namespace {

constexpr double deg_to_rad = std::numbers::pi / 180.0;

/// Rotates v about the unit axis k by angle (Rodrigues).
Vec3 rotate(const Vec3& v, const Vec3& k, double angle)
{
    double c = std::cos(angle), s = std::sin(angle);
    return v * c + geom::cross(k, v) * s + k * (geom::dot(k, v) * (1 - c));
}

struct Frame {
    Vec3 forward, right, up;
};

/// Shirley and Chiu's concentric map from the unit square to the unit disk: uniform in
/// area, and neighbouring samples stay neighbours.
std::pair<double, double> concentric_disk(double u, double v)
{
    double a = 2 * u - 1, b = 2 * v - 1;
    if (a == 0 && b == 0)
        return {0, 0};
    double r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = std::numbers::pi / 4 * (b / a);
    } else {
        r = b;
        phi = std::numbers::pi / 2 - std::numbers::pi / 4 * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

/// The viewing frame: forward from viewpoint to reference, up = +y (twisted).
Frame view_frame(const geom::View& view)
{
    Vec3 forward = geom::normalize(view.reference_point - view.viewpoint);
    // cpfg: a viewpoint on the reference point becomes viewpoint (0,0,-1), vrp 0.
    if (geom::length(forward) == 0)
        forward = {0, 0, 1};
    Vec3 up_hint{0, 1, 0};
    if (std::abs(geom::dot(forward, up_hint)) > 1 - 1e-12)
        // cpfg (SetView): v = n x Y is zero, so v = (-1,0,0) and up = v x n: looking
        // straight down the far side (-z) is up, looking straight up +z is up.
        up_hint = forward.y < 0 ? Vec3{0, 0, -1} : Vec3{0, 0, 1};
    Vec3 right = geom::normalize(geom::cross(forward, up_hint));
    Vec3 up = geom::cross(right, forward);
    // Positive twist turns the up vector counter-clockwise as the viewer sees it
    // (right-handed about the view normal n = -forward), so the image turns clockwise
    // (cpfg's rot_by_quat, read from the source; no corpus model uses a twist).
    double twist = view.twist_deg * deg_to_rad;
    if (twist != 0) {
        up = rotate(up, -forward, twist);
        right = geom::cross(forward, up);
    }
    return {forward, right, up};
}

/// The eight corners of a box.
std::array<Vec3, 8> corners(const geom::Bounds3& b)
{
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i)
        c[i] = {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
    return c;
}

Camera make_parallel(const geom::View& view, const Frame& f, const geom::Bounds3& fit,
                     const geom::Bounds3& geometry, int width, int height)
{
    // Extent of the box projected onto the view plane.
    double lo_x = 1e300, hi_x = -1e300, lo_y = 1e300, hi_y = -1e300;
    for (const Vec3& p : corners(fit)) {
        lo_x = std::min(lo_x, geom::dot(p, f.right));
        hi_x = std::max(hi_x, geom::dot(p, f.right));
        lo_y = std::min(lo_y, geom::dot(p, f.up));
        hi_y = std::max(hi_y, geom::dot(p, f.up));
    }
    double ex = hi_x - lo_x, ey = hi_y - lo_y;
    // cpfg's CalculateWindow: span = max(ex/2, (ey/2) W/H) / scale, k = W / (2 span) pixels
    // per unit, i.e. k = scale * min(W/ex, H/ey). A point-like box gets span 1 unscaled.
    double sf = view.scale_factor > 0 ? view.scale_factor : 1.0;
    double span = std::max(ex / 2, ey / 2 * width / height) / sf;
    if (span <= 0)
        span = 1;
    double pixel_size = 2 * span / width;

    // Rays start behind everything: the geometry and the fitted box.
    geom::Bounds3 all = fit;
    all.extend(geometry);
    Vec3 centre = fit.center();
    double back_off = geom::length(all.extent()) + geom::length(all.center() - centre) + 1.0;
    return Camera::parallel(centre, f.forward, f.up, pixel_size, back_off, width, height);
}

/// A parallel camera's numbers as generate_ray() and clip() use them, for
/// parallel_block: the same operands, so the same operations give the same bits.
struct ParallelFrame {
    double half_width, half_height, pixel_size;
    Vec3 origin, right, up, forward;
    Vec3 back;  // forward * back_off
    double rate;  // clip(): depth gained per unit of t, dot(forward, forward)
    double near, far;  // clipping depths (infinite without)
    Vec3f dir;
};

constexpr std::size_t parallel_block_size = 16;

/// parallel_block's loop; `unit_rate`: c.rate is 1, and dividing by 1 changes nothing, so
/// the divisions (a block's slowest instructions) are left out: the same bits.
template <bool unit_rate>
[[gnu::always_inline]] inline void parallel_block_of(const ParallelFrame& c, float pixel_x,
                                                     float pixel_y, const float* __restrict x,
                                                     const float* __restrict y,
                                                     double* __restrict tnear,
                                                     float* __restrict org_x,
                                                     float* __restrict org_y,
                                                     float* __restrict org_z,
                                                     float* __restrict tfar)
{
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < parallel_block_size; ++k) {
        double sx = (static_cast<double>(pixel_x + x[k]) - c.half_width) * c.pixel_size;
        double sy = (c.half_height - static_cast<double>(pixel_y + y[k])) * c.pixel_size;
        double ox = c.origin.x + c.right.x * sx + c.up.x * sy - c.back.x;
        double oy = c.origin.y + c.right.y * sx + c.up.y * sy - c.back.y;
        double oz = c.origin.z + c.right.z * sx + c.up.z * sy - c.back.z;
        double depth = (ox - c.origin.x) * c.forward.x + (oy - c.origin.y) * c.forward.y +
                       (oz - c.origin.z) * c.forward.z;
        double tn = std::max(0.0, unit_rate ? c.near - depth : (c.near - depth) / c.rate);
        double tf = std::max(0.0, unit_rate ? c.far - depth : (c.far - depth) / c.rate);
        tnear[k] = tn;
        org_x[k] = static_cast<float>(tn > 0 ? ox + c.forward.x * tn : ox);
        org_y[k] = static_cast<float>(tn > 0 ? oy + c.forward.y * tn : oy);
        org_z[k] = static_cast<float>(tn > 0 ? oz + c.forward.z * tn : oz);
        // tf is never NaN (std::max gives 0 for it): finite is below infinity.
        tfar[k] = tf < inf ? static_cast<float>(tf - tn) : std::numeric_limits<float>::infinity();
    }
}

/// generate_ray() then traced_ray() for the image points (pixel_x + x[k], pixel_y + y[k])
/// (summed in float) of a block: the same
/// double operations in the same order (ISO C++ mode contracts nothing into FMAs), over a
/// fixed count in separate arrays, which vectorises (camera.cpp is compiled without
/// trapping math, so that the choices become selects). An unclipped camera's infinite
/// planes give clip()'s tnear 0 and tfar infinity. A view along an axis (most of cpfg's)
/// has a forward() whose squared length, clip()'s rate, is exactly 1.
CAMBIUM_SIMD_CLONES void parallel_block(const ParallelFrame& c, float pixel_x, float pixel_y,
                                        const float* __restrict x, const float* __restrict y,
                                        double* __restrict tnear, float* __restrict org_x,
                                        float* __restrict org_y, float* __restrict org_z,
                                        float* __restrict tfar)
{
    if (c.rate == 1)
        parallel_block_of<true>(c, pixel_x, pixel_y, x, y, tnear, org_x, org_y, org_z, tfar);
    else
        parallel_block_of<false>(c, pixel_x, pixel_y, x, y, tnear, org_x, org_y, org_z, tfar);
}

}  // namespace

Camera Camera::parallel(const Vec3& focus, const Vec3& forward, const Vec3& up,
                        double pixel_size, double back_off, int width, int height)
{
    Camera c;
    c.m_projection = Projection::parallel;
    c.m_origin = focus;
    c.m_forward = forward;
    c.m_up = up;
    c.m_right = geom::cross(forward, up);
    c.m_pixel_size = pixel_size;
    c.m_back_off = back_off;
    c.m_width = width;
    c.m_height = height;
    return c;
}

Camera Camera::perspective(const Vec3& eye, const Vec3& focus, const Vec3& up, double fov_deg,
                           int width, int height)
{
    Camera c;
    c.m_projection = Projection::perspective;
    c.m_origin = eye;
    c.m_forward = geom::normalize(focus - eye);
    c.m_right = geom::normalize(geom::cross(c.m_forward, up));
    c.m_up = geom::cross(c.m_right, c.m_forward);
    c.m_focus_distance = geom::length(focus - eye);
    c.m_lens_focus = c.m_focus_distance;
    double fov = std::clamp(fov_deg, 1e-3, 179.0) * deg_to_rad;
    c.m_pixel_size = 2 * c.m_focus_distance * std::tan(fov / 2) / height;
    c.m_width = width;
    c.m_height = height;
    c.m_origin_f = Vec3f(c.m_origin);
    c.m_forward_f = Vec3f(c.m_forward * c.m_focus_distance);
    c.m_right_f = Vec3f(c.m_right * c.m_pixel_size);
    c.m_up_f = Vec3f(c.m_up * c.m_pixel_size);
    c.m_half_width_f = static_cast<float>(width * 0.5);
    c.m_half_height_f = static_cast<float>(height * 0.5);
    return c;
}

PixelPoint Camera::project(const Vec3& p) const
{
    Vec3 rel = p - m_origin;
    double x = geom::dot(rel, m_right), y = geom::dot(rel, m_up);
    if (m_projection == Projection::perspective) {
        double scale = m_focus_distance / geom::dot(rel, m_forward);
        x *= scale;
        y *= scale;
    }
    return {m_width * 0.5 + x / m_pixel_size, m_height * 0.5 - y / m_pixel_size};
}

void Camera::generate_rays(std::span<const PixelPoint> points, std::span<CameraRay> rays) const
{
    const std::size_t n = std::min(points.size(), rays.size());
    for (std::size_t i = 0; i < n; ++i)
        rays[i] = unnormalised_ray(points[i].x, points[i].y);
    if (m_projection == Projection::perspective)
        for (std::size_t i = 0; i < n; ++i)
            normalise(rays[i]);
    if (clipped())
        for (std::size_t i = 0; i < n; ++i)
            clip(rays[i]);
}

void Camera::generate_rays_f(std::span<const float> xs, std::span<const float> ys,
                             std::span<CameraRayF> rays) const
{
    // Blocks of 16 in separate arrays per component, so that the arithmetic vectorises
    // (several rays per square root and division, the same correctly rounded results).
    constexpr std::size_t block = 16;
    const std::size_t n = std::min({xs.size(), ys.size(), rays.size()});
    for (std::size_t k0 = 0; k0 < n; k0 += block) {
        const std::size_t m = std::min(block, n - k0);
        std::array<float, block> dx{}, dy{}, dz{}, inv{};
        for (std::size_t k = 0; k < m; ++k) {
            float sx = xs[k0 + k] - m_half_width_f, sy = m_half_height_f - ys[k0 + k];
            dx[k] = m_forward_f.x + m_right_f.x * sx + m_up_f.x * sy;
            dy[k] = m_forward_f.y + m_right_f.y * sx + m_up_f.y * sy;
            dz[k] = m_forward_f.z + m_right_f.z * sx + m_up_f.z * sy;
        }
        for (std::size_t k = 0; k < block; ++k)
            inv[k] = 1.0f / std::sqrt(dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]);
        for (std::size_t k = 0; k < m; ++k) {
            CameraRayF& r = rays[k0 + k];
            r.org = m_origin_f;
            r.dir = {dx[k] * inv[k], dy[k] * inv[k], dz[k] * inv[k]};
            r.tfar = std::numeric_limits<float>::infinity();
        }
    }
}

void Camera::generate_parallel_rays(int x, int y, std::span<const float> xs,
                                    std::span<const float> ys, std::span<double> tnear,
                                    ParallelRays& rays) const
{
    static_assert(ParallelRays::capacity == parallel_block_size);
    const std::size_t n = std::min({xs.size(), ys.size(), tnear.size(), ParallelRays::capacity});
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double rate = geom::dot(m_forward, m_forward);
    const auto fx = static_cast<float>(x), fy = static_cast<float>(y);
    if (m_projection != Projection::parallel)
        throw std::logic_error("Camera::generate_parallel_rays: the camera is not parallel");
    if (!(rate > 0)) {  // clip() empties every ray; each runs along forward()
        rays.dir = Vec3f(m_forward);
        for (std::size_t k = 0; k < n; ++k) {
            CameraRayF r = traced_ray(generate_ray(fx + xs[k], fy + ys[k]), tnear[k]);
            rays.org_x[k] = r.org.x;
            rays.org_y[k] = r.org.y;
            rays.org_z[k] = r.org.z;
            rays.tfar[k] = r.tfar;
            rays.dir = r.dir;
        }
        return;
    }
    const ParallelFrame frame{m_width * 0.5,  m_height * 0.5, m_pixel_size, m_origin,
                              m_right,        m_up,           m_forward,    m_forward * m_back_off,
                              rate,           clipped() ? m_clip_near : -inf,
                              clipped() ? m_clip_far : inf,   Vec3f(m_forward)};
    rays.dir = frame.dir;
    if (n == parallel_block_size) {  // a whole block (a batch's usual 16 samples): in place
        parallel_block(frame, fx, fy, xs.data(), ys.data(), tnear.data(), rays.org_x.data(),
                       rays.org_y.data(), rays.org_z.data(), rays.tfar.data());
        return;
    }
    std::array<float, parallel_block_size> px{}, py{};
    std::array<double, parallel_block_size> tn;
    std::copy_n(xs.data(), n, px.data());
    std::copy_n(ys.data(), n, py.data());
    parallel_block(frame, fx, fy, px.data(), py.data(), tn.data(), rays.org_x.data(),
                   rays.org_y.data(), rays.org_z.data(), rays.tfar.data());
    std::copy_n(tn.data(), n, tnear.data());
}

CameraRay Camera::generate_ray(double x, double y, double lens_u, double lens_v) const
{
    if (m_aperture_radius <= 0 || m_projection == Projection::parallel)
        return generate_ray(x, y);
    // The pinhole ray meets the plane in focus here; every lens point aims at it.
    Vec3 through = unnormalised_ray(x, y).dir;
    Vec3 target = m_origin + through * (m_lens_focus / m_focus_distance);
    auto [lx, ly] = concentric_disk(lens_u, lens_v);
    Vec3 lens = m_origin + m_right * (lx * m_aperture_radius) + m_up * (ly * m_aperture_radius);
    CameraRay ray{lens, geom::normalize(target - lens)};
    clip(ray);
    return ray;
}

void Camera::clip(CameraRay& ray) const
{
    if (std::isinf(m_clip_near) && std::isinf(m_clip_far))
        return;
    // Depth along forward of the ray origin, and depth gained per unit of t.
    double origin_depth = geom::dot(ray.org - m_origin, m_forward);
    double rate = geom::dot(ray.dir, m_forward);
    if (rate <= 0) {
        ray.tnear = 0;
        ray.tfar = 0;
        return;
    }
    ray.tnear = std::max(0.0, (m_clip_near - origin_depth) / rate);
    ray.tfar = std::max(0.0, (m_clip_far - origin_depth) / rate);
}

Camera Camera::with_lens(double aperture_radius, double focus_distance) const
{
    Camera c = *this;
    c.m_aperture_radius = std::max(0.0, aperture_radius);
    c.m_lens_focus = focus_distance > 0 ? focus_distance : m_focus_distance;
    return c;
}

Camera Camera::with_clipping(double near, double far) const
{
    Camera c = *this;
    c.m_clip_near = near;
    c.m_clip_far = far;
    return c;
}

double Camera::pixel_size_at(const Vec3& p) const
{
    if (m_projection == Projection::parallel)
        return m_pixel_size;
    double depth = geom::dot(p - m_origin, m_forward);
    return m_pixel_size * std::max(depth, 0.0) / m_focus_distance;
}

double Camera::farthest_ray_origin() const
{
    auto max_abs = [](const Vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
    double half_image = (m_width / 2.0 + 2) + (m_height / 2.0 + 2);
    if (m_projection == Projection::parallel)
        return max_abs(m_origin) + m_back_off + half_image * m_pixel_size;
    return max_abs(m_origin) + std::sqrt(3.0) * m_aperture_radius;
}

bool Camera::parallel_rays_in_reach() const
{
    if (m_projection != Projection::parallel)
        return false;
    // A ray starts at most farthest_ray_origin() from the origin; clipping moves it along
    // forward() to the front plane's depth from origin(), whose own distance from the
    // origin is within farthest_ray_origin() too.
    double front = std::isinf(m_clip_near) ? 0.0 : std::abs(m_clip_near);
    double reach = 2 * farthest_ray_origin() + front;
    return reach <= geom::max_ray_start / 2;  // false for NaN
}

void Camera::check_range(const std::string& what) const
{
    auto unit = [](const Vec3& v) { return std::abs(geom::length(v) - 1) < 1e-6; };
    bool frame_ok = unit(m_forward) && unit(m_right) && unit(m_up);
    bool scale_ok = m_pixel_size > 0 && std::isfinite(m_pixel_size) &&
                    (m_projection == Projection::parallel || m_focus_distance > 1e-9);
    double reach = farthest_ray_origin();
    const char* advice = "; check the viewpoint, view reference point, scale factor and box";
    if (!frame_ok || !scale_ok)
        throw Error(what + ": the camera has no finite view direction or pixel size" + advice);
    if (!(reach <= geom::max_ray_origin)) {
        char text[96];
        std::snprintf(text, sizeof text, "the camera's rays would start %g from the origin, beyond %g",
                      reach, geom::max_ray_origin);
        throw Error(what + ": " + text + advice);
    }
}

namespace {

/// cpfg's clipping planes: from the eye in perspective; in parallel projection positions
/// relative to the viewpoint along the view direction, in either order (glOrtho accepts
/// near > far, and corpus views use both orders), converted to depths from origin().
Camera apply_clipping(const Camera& camera, const geom::View& view)
{
    if (!view.front_distance && !view.back_distance)
        return camera;
    constexpr double inf = std::numeric_limits<double>::infinity();
    double front = view.front_distance.value_or(-inf);
    double back = view.back_distance.value_or(inf);
    if (camera.projection() == Camera::Projection::perspective)
        return camera.with_clipping(front, back);
    double viewpoint_depth = geom::dot(view.viewpoint - camera.origin(), camera.forward());
    if (view.front_distance && view.back_distance && front > back)
        std::swap(front, back);
    return camera.with_clipping(viewpoint_depth + front, viewpoint_depth + back);
}

}  // namespace

Camera make_camera(const geom::View& view, const geom::Bounds3& bounds, int width, int height)
{
    Frame f = view_frame(view);
    if (view.perspective) {
        double sf = view.scale_factor > 0 ? view.scale_factor : 1.0;
        Vec3 eye = view.reference_point + (view.viewpoint - view.reference_point) / sf;
        if (geom::length(eye - view.reference_point) == 0)
            eye = view.reference_point - f.forward;
        return apply_clipping(Camera::perspective(eye, view.reference_point, f.up,
                                                  view.viewing_angle_deg, width, height),
                              view);
    }
    geom::Bounds3 fit = view.box ? *view.box : bounds;
    if (fit.empty())
        fit.extend(Vec3{0, 0, 0});
    return apply_clipping(make_parallel(view, f, fit, bounds, width, height), view);
}

}  // namespace cambium::render
