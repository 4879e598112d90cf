// SPDX-License-Identifier: Apache-2.0
#include "render/sun_position.h"

#include <cmath>
#include <numbers>

namespace cambium::render {
namespace {

constexpr double deg = std::numbers::pi / 180;

bool leap(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

int days_in_month(int y, int m)
{
    constexpr int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return m == 2 && leap(y) ? 29 : days[m - 1];
}

/// The Julian day at 0h UT of a Gregorian date (Meeus, chapter 7).
double julian_day(int y, int m, int d)
{
    if (m <= 2) {
        y -= 1;
        m += 12;
    }
    const int a = y / 100 - (y < 0 && y % 100 != 0 ? 1 : 0);
    const int b = 2 - a + a / 4;
    return std::floor(365.25 * (y + 4716)) + std::floor(30.6001 * (m + 1)) + d + b - 1524.5;
}

/// The refraction that lifts the sun's image, in degrees, at true elevation e (NOAA's
/// piecewise fit).
double refraction_deg(double e)
{
    if (e > 85)
        return 0;
    const double t = std::tan(e * deg);
    double arcsec;
    if (e > 5)
        arcsec = 58.1 / t - 0.07 / (t * t * t) + 0.000086 / std::pow(t, 5);
    else if (e > -0.575)
        arcsec = 1735 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)));
    else
        arcsec = -20.774 / t;
    return arcsec / 3600;
}

}  // namespace

bool valid_local_time(const LocalTime& t)
{
    return t.year >= -4000 && t.year <= 10000 && t.month >= 1 && t.month <= 12 && t.day >= 1 &&
           t.day <= days_in_month(t.year, t.month) && t.hour >= 0 && t.hour <= 23 &&
           t.minute >= 0 && t.minute <= 59 && t.second >= 0 && t.second < 60 &&
           std::abs(t.utc_offset_hours) <= 14;
}

SunPosition sun_position(double latitude_deg, double longitude_deg, const LocalTime& t)
{
    // Time: Julian centuries since J2000.0, from the clock turned to UT
    const double local_minutes = t.hour * 60 + t.minute + t.second / 60;
    const double ut_minutes = local_minutes - t.utc_offset_hours * 60;
    const double jd = julian_day(t.year, t.month, t.day) + ut_minutes / 1440;
    const double T = (jd - 2451545) / 36525;

    // The sun's orbit: mean longitude, mean anomaly, eccentricity, equation of centre
    const double L0 = std::fmod(280.46646 + T * (36000.76983 + T * 0.0003032), 360);
    const double M = 357.52911 + T * (35999.05029 - 0.0001537 * T);
    const double e = 0.016708634 - T * (0.000042037 + 0.0000001267 * T);
    const double C = std::sin(M * deg) * (1.914602 - T * (0.004817 + 0.000014 * T)) +
                     std::sin(2 * M * deg) * (0.019993 - 0.000101 * T) +
                     std::sin(3 * M * deg) * 0.000289;
    // Apparent longitude (nutation and aberration) and the obliquity of the ecliptic
    const double omega = 125.04 - 1934.136 * T;
    const double lambda = L0 + C - 0.00569 - 0.00478 * std::sin(omega * deg);
    const double eps0 =
        23 + (26 + (21.448 - T * (46.815 + T * (0.00059 - T * 0.001813))) / 60) / 60;
    const double eps = eps0 + 0.00256 * std::cos(omega * deg);
    const double decl = std::asin(std::sin(eps * deg) * std::sin(lambda * deg)) / deg;

    // Equation of time, minutes
    const double y = std::tan(eps / 2 * deg) * std::tan(eps / 2 * deg);
    const double eot =
        4 / deg *
        (y * std::sin(2 * L0 * deg) - 2 * e * std::sin(M * deg) +
         4 * e * y * std::sin(M * deg) * std::cos(2 * L0 * deg) -
         0.5 * y * y * std::sin(4 * L0 * deg) - 1.25 * e * e * std::sin(2 * M * deg));

    // Hour angle from true solar time, then the horizon coordinates
    double solar_minutes = std::fmod(ut_minutes + eot + 4 * longitude_deg, 1440);
    if (solar_minutes < 0)
        solar_minutes += 1440;
    const double H = solar_minutes / 4 - 180;
    const double phi = latitude_deg * deg, d = decl * deg, h = H * deg;
    const double sin_elevation =
        std::sin(phi) * std::sin(d) + std::cos(phi) * std::cos(d) * std::cos(h);
    const double elevation = std::asin(std::fmax(-1.0, std::fmin(1.0, sin_elevation))) / deg;
    // clockwise from north: atan2 gives it from south, westward
    double azimuth =
        std::atan2(std::sin(h), std::cos(h) * std::sin(phi) - std::tan(d) * std::cos(phi)) / deg +
        180;
    if (azimuth >= 360)
        azimuth -= 360;

    SunPosition s;
    s.elevation_deg = elevation + refraction_deg(elevation);
    s.azimuth_deg = azimuth;
    s.declination_deg = decl;
    s.equation_of_time_min = eot;
    return s;
}

Vec3f sun_direction(const SunPosition& sun)
{
    const double e = sun.elevation_deg * deg, a = sun.azimuth_deg * deg;
    return {float(std::cos(e) * std::sin(a)), float(std::sin(e)),
            float(-std::cos(e) * std::cos(a))};
}

}  // namespace cambium::render
