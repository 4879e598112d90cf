// SPDX-License-Identifier: Apache-2.0
// Cross-sections of generalized cylinders: cpfg's contour files (.con, manual 5.4.4),
// contour galleries (5.4.5), and their resampling by arc length (report 3.2.3).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "geom/vec.h"

namespace cambium::geom {

/// A contour as read: the B-spline control points (multiplicities expanded, 2D files
/// with z = 0) and whether the curve closes on itself.
struct Contour {
    std::string name;
    std::vector<Vec3> points;  ///< uniform cubic B-spline control points
    bool closed = true;
    /// `cver 1 2`/`1 3` type `oe`/`ce`. cpfg reads it and draws the regular spline;
    /// Cambium clamps open contours so they start and end at their end points.
    bool endpoint_interpolation = false;
    int samples = 0;  ///< `cver 1 3` samples (cpfg reads and ignores it); 0 = none given
    int version = 0;  ///< 0 (plain header), 101, 102 or 103

    /// Number of cubic segments of the spline (n for closed, n-3 for open contours).
    int segment_count() const;
    /// The spline point at parameter t in [0, segment_count()].
    Vec3 evaluate(double t) const;
    /// Its derivative with respect to t.
    Vec3 derivative(double t) const;
};

/// A contour resampled to `sides` vertices at (nearly) equal arc length, as cpfg's
/// MakeContour builds it: closed contours are rotated about z so that the first vertex
/// lies on +x and hold `sides` distinct vertices; open ones keep their orientation and
/// hold `sides + 1` vertices (both ends). Arc length is measured in x and y only.
struct ContourSamples {
    std::vector<Vec3> vertices;
    std::vector<Vec3> normals;  ///< in-plane unit normals (z = 0), to the right of the direction of travel
    bool closed = true;
    /// The contour's perimeter (closed: including the closing edge), in x and y.
    double length = 0;
};

/// The default circular contour (id 0): `sides` points on the unit circle, the first at +x.
ContourSamples circle_samples(int sides);

/// Resamples a contour to `sides` vertices (sides >= 3), cpfg's 10 points per segment
/// of the length table followed by linear inversion.
ContourSamples resample(const Contour& contour, int sides);

/// Reads a contour from text of any version (plain `n dim type`, `cver 1 1`..`1 3`).
/// Malformed text throws Error with the file and line.
Contour parse_contour(std::string_view text, const std::string& file_name);
Contour read_contour(const std::filesystem::path& file);

/// A contour gallery (`contourgalleryver 1 1`): its items, numbered from 1 in the file,
/// at index item - 1 here.
std::vector<Contour> parse_contour_gallery(std::string_view text, const std::string& file_name);

/// What `contour: id file` reads: one contour from a contour file, or every item of a
/// gallery (a file starting with `contourgalleryver`), in order. cpfg itself reads only
/// contour files there; Cambium gives gallery item k the id `id + k - 1`, so
/// `contour: 1 shapes.cset` numbers the items from 1 as the manual (5.4.5) numbers them.
std::vector<Contour> parse_contours(std::string_view text, const std::string& file_name);
std::vector<Contour> read_contours(const std::filesystem::path& file);

/// The contours a view file defines (`contour: id file`), by id; id 0 is the circle
/// and is never stored here.
using ContourTable = std::map<int, Contour>;

}  // namespace cambium::geom
