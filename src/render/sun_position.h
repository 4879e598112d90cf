// SPDX-License-Identifier: Apache-2.0
// Where the sun stands for a place and a time: NOAA's solar calculator equations (after
// Meeus, Astronomical Algorithms), for the --sky's sun (docs/light.md, "The sun from a
// place and a time").
#pragma once

#include "render/vecf.h"

namespace cambium::render {

/// A civil date and local clock time, with the clock's offset from UTC in hours (east
/// positive: +2 for central European summer time).
struct LocalTime {
    int year = 2000, month = 1, day = 1;
    int hour = 12, minute = 0;
    double second = 0;
    double utc_offset_hours = 0;
};

/// Whether the date exists in the proleptic Gregorian calendar and the clock reads a time
/// of day (0:00:00 .. 23:59:59.999) with an offset within -14 .. +14 hours.
bool valid_local_time(const LocalTime& t);

/// The sun as seen from the ground, in degrees: elevation above the horizon (atmospheric
/// refraction included, as NOAA's calculator gives it), and azimuth clockwise from north
/// (90: east).
struct SunPosition {
    double elevation_deg = 0;
    double azimuth_deg = 0;
    double declination_deg = 0;       ///< the sun's declination
    double equation_of_time_min = 0;  ///< apparent minus mean solar time, in minutes
};

/// The sun at latitude (degrees, north positive) and longitude (degrees, east positive) at
/// local time `t`: NOAA's solar calculator equations (Meeus), good to about 0.01 degree
/// between 1800 and 2100. The caller checks the ranges and valid_local_time().
SunPosition sun_position(double latitude_deg, double longitude_deg, const LocalTime& t);

/// The unit vector toward a sun at that elevation and azimuth in Cambium's world: +y up,
/// north along -z, east along +x (so -z is what cpfg's default view looks along).
Vec3f sun_direction(const SunPosition& sun);

}  // namespace cambium::render
