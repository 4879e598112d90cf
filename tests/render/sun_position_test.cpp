// SPDX-License-Identifier: Apache-2.0
// The sun's place for a place and time (NOAA's equations) against independent values: the
// equinox noon sun over the equator, the solstice noon elevation, the equation of time's
// known extremes, and Spencer's (1971) Fourier series; and the world axes it maps to.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "render/sun_position.h"

using namespace cambium::render;

namespace {

constexpr double deg = std::numbers::pi / 180;

LocalTime at(int y, int mo, int d, int h, int mi, double offset = 0)
{
    LocalTime t;
    t.year = y;
    t.month = mo;
    t.day = d;
    t.hour = h;
    t.minute = mi;
    t.utc_offset_hours = offset;
    return t;
}

/// Spencer's (1971) declination and equation of time (an independent published fit):
/// the sun's true (unrefracted) elevation and azimuth from north, in degrees.
std::pair<double, double> spencer(double lat, double lon, int day_of_year, double ut_hours)
{
    const double g = 2 * std::numbers::pi / 365 * (day_of_year - 1 + (ut_hours - 12) / 24);
    const double decl = 0.006918 - 0.399912 * std::cos(g) + 0.070257 * std::sin(g) -
                        0.006758 * std::cos(2 * g) + 0.000907 * std::sin(2 * g) -
                        0.002697 * std::cos(3 * g) + 0.00148 * std::sin(3 * g);
    const double eot = 229.18 * (0.000075 + 0.001868 * std::cos(g) - 0.032077 * std::sin(g) -
                                 0.014615 * std::cos(2 * g) - 0.040849 * std::sin(2 * g));
    const double solar_minutes = ut_hours * 60 + eot + 4 * lon;
    const double h = (solar_minutes / 4 - 180) * deg, phi = lat * deg;
    const double el =
        std::asin(std::sin(phi) * std::sin(decl) + std::cos(phi) * std::cos(decl) * std::cos(h));
    double az =
        std::atan2(std::sin(h), std::cos(h) * std::sin(phi) - std::tan(decl) * std::cos(phi)) /
            deg +
        180;
    return {el / deg, std::fmod(az + 360, 360)};
}

}  // namespace

// At the March equinox the noon sun stands at the zenith over the equator.
TEST(SunPosition, EquinoxNoonOverTheEquatorIsNearTheZenith)
{
    // 2024's equinox: 20 March 03:06 UT; solar noon at longitude 0 about 12:07 UT
    SunPosition s = sun_position(0, 0, at(2024, 3, 20, 12, 7));
    EXPECT_GT(s.elevation_deg, 89.5);
    EXPECT_NEAR(s.declination_deg, 0.15, 0.1);
    // morning: in the east, evening: in the west
    EXPECT_NEAR(sun_position(0, 0, at(2024, 3, 20, 8, 0)).azimuth_deg, 90, 0.5);
    EXPECT_NEAR(sun_position(0, 0, at(2024, 3, 20, 16, 0)).azimuth_deg, 270, 0.5);
}

// At 52 N on the June solstice the sun culminates at 90 - 52 + 23.44 degrees, due south;
// the same moment given on a clock two hours ahead of UTC gives the same sun.
TEST(SunPosition, SolsticeNoonElevation)
{
    double best = -90, azimuth = 0;
    for (int minute = 11 * 60; minute < 13 * 60; ++minute) {
        SunPosition s = sun_position(52, 0, at(2024, 6, 20, minute / 60, minute % 60));
        if (s.elevation_deg > best) {
            best = s.elevation_deg;
            azimuth = s.azimuth_deg;
        }
    }
    EXPECT_NEAR(best, 90 - 52 + 23.44, 0.05);
    EXPECT_NEAR(azimuth, 180, 1);
    SunPosition utc = sun_position(52, 0, at(2024, 6, 20, 9, 30));
    SunPosition cest = sun_position(52, 0, at(2024, 6, 20, 11, 30, 2));
    EXPECT_DOUBLE_EQ(utc.elevation_deg, cest.elevation_deg);
    // south of the tropics the noon sun is in the north
    SunPosition sydney = sun_position(-33.87, 151.21, at(2024, 6, 21, 12, 0, 10));
    EXPECT_TRUE(sydney.azimuth_deg < 10 || sydney.azimuth_deg > 350) << sydney.azimuth_deg;
    EXPECT_NEAR(sydney.elevation_deg, 90 - 33.87 - 23.44, 0.5);
}

// The equation of time's extremes: about -14.2 minutes on 11 February, +16.4 on 3 November.
TEST(SunPosition, EquationOfTimeExtremes)
{
    EXPECT_NEAR(sun_position(0, 0, at(2024, 2, 11, 12, 0)).equation_of_time_min, -14.2, 0.3);
    EXPECT_NEAR(sun_position(0, 0, at(2024, 11, 3, 12, 0)).equation_of_time_min, 16.4, 0.3);
}

// Against Spencer's series, well above the horizon (where refraction is under 0.05 deg):
// within half a degree at places and times over the year.
TEST(SunPosition, AgreesWithSpencer)
{
    struct Case {
        double lat, lon;
        int month, day, day_of_year;
        double ut_hours;
    };
    const Case cases[] = {{40.0, -105.0, 7, 15, 197, 19.5}, {52.5, 13.4, 4, 1, 92, 9.25},
                          {-33.9, 18.4, 12, 24, 359, 8.0},  {35.7, 139.7, 10, 10, 284, 2.0},
                          {64.1, -21.9, 6, 1, 153, 13.0},   {1.3, 103.8, 9, 1, 245, 4.5}};
    for (const Case& c : cases) {
        const int h = int(c.ut_hours), m = int(std::round((c.ut_hours - h) * 60));
        SunPosition s = sun_position(c.lat, c.lon, at(2023, c.month, c.day, h, m));
        auto [el, az] = spencer(c.lat, c.lon, c.day_of_year, c.ut_hours);
        ASSERT_GT(el, 20) << c.lat;
        EXPECT_NEAR(s.elevation_deg, el, 0.5) << c.lat << " " << c.lon;
        EXPECT_NEAR(s.azimuth_deg, az, 0.5) << c.lat << " " << c.lon;
    }
}

// North is -z, east +x, up +y.
TEST(SunPosition, WorldAxes)
{
    SunPosition s;
    s.elevation_deg = 0;
    s.azimuth_deg = 90;
    Vec3f east = sun_direction(s);
    EXPECT_NEAR(east.x, 1, 1e-6);
    s.azimuth_deg = 0;
    Vec3f north = sun_direction(s);
    EXPECT_NEAR(north.z, -1, 1e-6);
    s.elevation_deg = 90;
    EXPECT_NEAR(sun_direction(s).y, 1, 1e-6);
}

TEST(SunPosition, ChecksDates)
{
    EXPECT_TRUE(valid_local_time(at(2024, 2, 29, 12, 0)));
    EXPECT_FALSE(valid_local_time(at(2023, 2, 29, 12, 0)));
    EXPECT_FALSE(valid_local_time(at(2023, 13, 1, 12, 0)));
    EXPECT_FALSE(valid_local_time(at(2023, 4, 31, 12, 0)));
    EXPECT_FALSE(valid_local_time(at(2023, 4, 1, 24, 0)));
    EXPECT_FALSE(valid_local_time(at(2023, 4, 1, 12, 0, 15)));
}
