// SPDX-License-Identifier: Apache-2.0
// The camera that frames a Scene as cpfg's window does: parallel auto-fit or perspective.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#include "geom/scene.h"
#include "geom/vec.h"
#include "render/vecf.h"

namespace cambium::render {

/// A point on the image plane in continuous pixel coordinates: x to the right from the
/// left edge, y downward from the top edge; pixel (i, j) covers [i, i+1) x [j, j+1).
struct PixelPoint {
    double x = 0, y = 0;
};

/// A world-space ray; dir is unit length. Only t in [tnear, tfar] is seen: the view
/// file's front and back clipping planes (tnear = 0, tfar = infinity without them).
struct CameraRay {
    geom::Vec3 org, dir;
    double tnear = 0;
    double tfar = std::numeric_limits<double>::infinity();
};

/// A camera ray in single precision, as EmbreeScene::intersect_coherent() traces it: from
/// org along dir for t < tfar.
struct CameraRayF {
    Vec3f org, dir;
    float tfar = 0;
};

/// Camera rays along one direction (a parallel camera's), at most `capacity`, in separate
/// arrays per component, as SIMD code makes them and a coherent stream is filled from them
/// (Camera::generate_parallel_rays, EmbreeScene::intersect_coherent): ray k starts at
/// (org_x[k], org_y[k], org_z[k]) and runs along `dir` for t < tfar[k].
struct ParallelRays {
    static constexpr std::size_t capacity = 16;
    std::array<float, capacity> org_x, org_y, org_z, tfar;
    Vec3f dir;

    CameraRayF ray(std::size_t k) const { return {{org_x[k], org_y[k], org_z[k]}, dir, tfar[k]}; }
};

/// Camera ray `ray` as the path tracer traces it: in single precision, from the near
/// clipping plane (front clipping: org + tnear dir), tfar counted from there (far
/// clipping: geometry beyond the back plane must not show); `tnear`: where it starts
/// along the camera's ray.
inline CameraRayF traced_ray(const CameraRay& ray, double& tnear)
{
    CameraRayF out;
    out.org = Vec3f(ray.tnear > 0 ? ray.org + ray.dir * ray.tnear : ray.org);
    out.dir = Vec3f(ray.dir);
    out.tfar = std::isfinite(ray.tfar) ? static_cast<float>(ray.tfar - ray.tnear)
                                       : std::numeric_limits<float>::infinity();
    tnear = ray.tnear;
    return out;
}

/// A pinhole or orthographic camera in world units. Immutable after make_camera().
class Camera {
public:
    enum class Projection { parallel, perspective };

    /// Orthographic camera: looks along `forward` at `focus`, `pixel_size` world units
    /// per pixel; rays start `back_off` units behind the focus plane.
    static Camera parallel(const geom::Vec3& focus, const geom::Vec3& forward,
                           const geom::Vec3& up, double pixel_size, double back_off,
                           int width, int height);
    /// Pinhole camera at `eye` looking at `focus` with the vertical field of view `fov_deg`.
    static Camera perspective(const geom::Vec3& eye, const geom::Vec3& focus,
                              const geom::Vec3& up, double fov_deg, int width, int height);

    /// Where the world point p lands on the image (perspective: p must be in front).
    PixelPoint project(const geom::Vec3& p) const;
    /// The ray through the image point (x, y) (continuous pixel coordinates), from the
    /// centre of the lens.
    CameraRay generate_ray(double x, double y) const
    {
        // Inline: one call per camera sample, and its result is used at once.
        CameraRay ray = unnormalised_ray(x, y);
        if (m_projection == Projection::perspective)
            normalise(ray);
        if (clipped())
            clip(ray);
        return ray;
    }
    /// generate_ray(x, y) for each of `points`, into `rays` (as many): the same rays, made
    /// in passes over the batch so that the square roots and divisions of one ray do not
    /// wait on those of the ray before (a camera sample's own time was mostly that wait).
    void generate_rays(std::span<const PixelPoint> points, std::span<CameraRay> rays) const;
    /// Whether generate_rays_f() makes this camera's rays: a pinhole perspective camera
    /// without clipping planes. A parallel view (pixel-exact lines), a lens or clipping
    /// (cpfg's planes, measured in double) keep generate_ray()'s double precision.
    bool single_precision() const
    {
        return m_projection == Projection::perspective && m_aperture_radius <= 0 && !clipped();
    }
    /// For a single_precision() camera: the ray through the image point (xs[k], ys[k]) for
    /// each k, into `rays` (as many; tfar infinite), made in float arithmetic from the
    /// camera's frame rounded to float once. The direction is generate_ray()'s within a
    /// few float roundings (about 1e-7 rad, a ten-thousandth of a pixel); a float square
    /// root and reciprocal per ray instead of double ones, which held up every camera
    /// sample.
    void generate_rays_f(std::span<const float> xs, std::span<const float> ys,
                         std::span<CameraRayF> rays) const;
    /// For a parallel camera (cpfg's default view, with or without clipping planes; any
    /// other throws std::logic_error): for each k < min(size, ParallelRays::capacity),
    /// traced_ray(generate_ray(x + xs[k], y + ys[k]), tnear[k]) as rays.ray(k) (the image
    /// point summed in float, as the box filter's are), the same bits, made as a block in
    /// separate arrays per component, which vectorise (one ray at a time, a camera
    /// sample's own time was mostly scalar double arithmetic on 64-byte rays), and
    /// written as they are made, without gathering each ray's floats into a CameraRayF.
    void generate_parallel_rays(int x, int y, std::span<const float> xs,
                                std::span<const float> ys, std::span<double> tnear,
                                ParallelRays& rays) const;
    /// The same through the lens point given by two uniforms in [0, 1) (a thin lens:
    /// every ray through (x, y) meets the others on the plane in focus). Equals
    /// generate_ray(x, y) for a pinhole camera.
    CameraRay generate_ray(double x, double y, double lens_u, double lens_v) const;

    /// This camera with a thin lens of radius `aperture_radius` (world units; 0 = pinhole)
    /// focused on the plane `focus_distance` in front of the eye (<= 0: the plane through
    /// the view's reference point, where the pinhole camera looks). Parallel cameras
    /// ignore the lens: an orthographic view has no eye to focus.
    Camera with_lens(double aperture_radius, double focus_distance = 0) const;
    /// This camera seeing only depths in [near, far] along forward(), measured from the
    /// eye (perspective) or from origin() (parallel): cpfg's front and back clipping
    /// planes (glFrustum / glOrtho near and far).
    Camera with_clipping(double near, double far) const;
    double aperture_radius() const { return m_aperture_radius; }
    /// Distance from the eye to the plane in focus (perspective).
    double focus_distance() const { return m_lens_focus; }
    double clip_near() const { return m_clip_near; }
    double clip_far() const { return m_clip_far; }
    /// World size of one pixel on the plane through the focus, perpendicular to the view.
    double pixel_size() const { return m_pixel_size; }
    /// World size of one pixel at the depth of p (parallel: pixel_size()).
    double pixel_size_at(const geom::Vec3& p) const;

    Projection projection() const { return m_projection; }
    int width() const { return m_width; }
    int height() const { return m_height; }
    const geom::Vec3& forward() const { return m_forward; }
    const geom::Vec3& right() const { return m_right; }
    const geom::Vec3& up() const { return m_up; }
    /// Eye (perspective) or the focus point (parallel).
    const geom::Vec3& origin() const { return m_origin; }

    /// An upper bound on how far from the world origin (max norm) a ray through the
    /// image, up to two pixels outside it, starts (before clipping); NaN when some
    /// number of the camera is not finite.
    double farthest_ray_origin() const;
    /// Whether every ray generate_parallel_rays() makes for points up to two pixels
    /// outside the image starts within geom::max_ray_start (half of it, for rounding)
    /// when check_range() passed: a front clipping plane moves a ray's start forward, and
    /// one far beyond the scene may take it out of Embree's reach (render skips such
    /// rays). Then EmbreeScene::intersect_coherent need not check each ray.
    bool parallel_rays_in_reach() const;
    /// Throws Error unless every ray the camera makes is one Embree can take: finite,
    /// a unit frame, a positive pixel size, and ray origins within geom::max_ray_origin.
    /// `what` names where the camera came from in the message.
    void check_range(const std::string& what) const;

private:
    /// The ray through the image point (x, y), its direction not yet of unit length
    /// (perspective views) and not clipped.
    CameraRay unnormalised_ray(double x, double y) const
    {
        double sx = (x - m_width * 0.5) * m_pixel_size;
        double sy = (m_height * 0.5 - y) * m_pixel_size;
        if (m_projection == Projection::parallel)
            return {m_origin + m_right * sx + m_up * sy - m_forward * m_back_off, m_forward};
        return {m_origin, m_forward * m_focus_distance + m_right * sx + m_up * sy};
    }
    /// The direction times the reciprocal of its length: one division, not three (a third
    /// of a camera sample's own time was waiting on them), within one rounding of the
    /// double quotient, far below the float the ray is traced in.
    static void normalise(CameraRay& ray) { ray.dir = ray.dir * (1.0 / geom::length(ray.dir)); }
    bool clipped() const { return !std::isinf(m_clip_near) || !std::isinf(m_clip_far); }
    Camera() = default;
    /// Sets the ray's [tnear, tfar] from the clipping planes.
    void clip(CameraRay& ray) const;

    Projection m_projection = Projection::parallel;
    geom::Vec3 m_origin;                // eye, or the point imaged at the window centre
    geom::Vec3 m_forward, m_right, m_up;  // orthonormal, right = forward x up
    double m_pixel_size = 1;            // world units per pixel at the focus
    double m_focus_distance = 1;        // perspective: eye to focus plane
    double m_back_off = 0;              // parallel: ray origins this far behind the focus
    int m_width = 1, m_height = 1;
    double m_aperture_radius = 0;       // thin lens radius; 0 = pinhole
    double m_lens_focus = 1;            // eye to the plane in focus
    double m_clip_near = -std::numeric_limits<double>::infinity();  // depth along forward
    double m_clip_far = std::numeric_limits<double>::infinity();
    // Perspective, for generate_rays_f(): the eye, forward to the focus plane, right and
    // up one pixel long there, half the image size in pixels.
    Vec3f m_origin_f, m_forward_f, m_right_f, m_up_f;
    float m_half_width_f = 0, m_half_height_f = 0;
};

/// The camera that frames the scene as cpfg does (docs: render/camera.cpp, "cpfg framing").
/// `bounds` are the geometry's bounds (the view's `box:` overrides them for the fit).
/// The view's `front distance:` / `back distance:` become clipping planes: from the eye
/// in perspective, from the view file's viewpoint along the view direction in parallel
/// projection (manual 5.2.2).
Camera make_camera(const geom::View& view, const geom::Bounds3& bounds, int width, int height);

}  // namespace cambium::render
