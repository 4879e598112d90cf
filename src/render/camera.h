// SPDX-License-Identifier: Apache-2.0
// The camera that frames a Scene as cpfg's window does: parallel auto-fit or perspective.
#pragma once

#include "geom/scene.h"
#include "geom/vec.h"

namespace cambium::render {

/// A point on the image plane in continuous pixel coordinates: x to the right from the
/// left edge, y downward from the top edge; pixel (i, j) covers [i, i+1) x [j, j+1).
struct PixelPoint {
    double x = 0, y = 0;
};

/// A world-space ray; dir is unit length.
struct CameraRay {
    geom::Vec3 org, dir;
};

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
    /// The ray through the image point (x, y) (continuous pixel coordinates).
    CameraRay generate_ray(double x, double y) const;
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

private:
    Camera() = default;

    Projection m_projection = Projection::parallel;
    geom::Vec3 m_origin;                // eye, or the point imaged at the window centre
    geom::Vec3 m_forward, m_right, m_up;  // orthonormal, right = forward x up
    double m_pixel_size = 1;            // world units per pixel at the focus
    double m_focus_distance = 1;        // perspective: eye to focus plane
    double m_back_off = 0;              // parallel: ray origins this far behind the focus
    int m_width = 1, m_height = 1;
};

/// The camera that frames the scene as cpfg does (docs: render/camera.cpp, "cpfg framing").
/// `bounds` are the geometry's bounds (the view's `box:` overrides them for the fit).
Camera make_camera(const geom::View& view, const geom::Bounds3& bounds, int width, int height);

}  // namespace cambium::render
