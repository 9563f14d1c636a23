//! Where the sun is: NREL's Solar Position Algorithm ([`spa`]) for a site and
//! a local standard time, ΔT from the Espenak–Meeus polynomials (as pvlib's
//! `calculate_deltat`), and the day's sunrise, solar noon and sunset.
//! Plain Rust, no Bevy types.

mod spa;
mod spa_tables;

use glam::DVec3;

pub use spa::{SpaInput, SpaOutput, incidence_angle, spa};

use crate::site::Site;
use crate::time::{Date, LocalDateTime, TimeOfDay};

/// Refraction at sunrise and sunset assumed by the SPA (degrees).
pub const SUNRISE_REFRACTION: f64 = 0.5667;
/// Geometric altitude of the sun's centre at sunrise and sunset: refraction
/// plus the sun's apparent radius (degrees).
pub const SUNRISE_ALTITUDE: f64 = -0.8333;

/// The sun seen from a site at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolarPosition {
    /// Apparent (refracted) altitude of the sun's centre, degrees.
    pub altitude: f64,
    /// Azimuth clockwise from true north (east is 90), degrees.
    pub azimuth: f64,
    /// Altitude without refraction, degrees.
    pub geometric_altitude: f64,
    /// Julian day (UT) of the instant.
    pub julian_day: f64,
    /// ΔT used, seconds.
    pub delta_t: f64,
    /// The SPA's full output, for what the fields above leave out (hour
    /// angle, declination, equation of time).
    pub spa: SpaOutput,
}

impl SolarPosition {
    /// Unit vector toward the sun in the canonical frame (x east, y north, z up).
    pub fn direction(&self) -> DVec3 {
        direction_from_angles(self.altitude, self.azimuth)
    }

    /// Whether the sun's centre is above the horizon (apparent altitude > 0°).
    pub fn is_up(&self) -> bool {
        self.altitude > 0.0
    }
}

/// Unit vector for an altitude and a clockwise-from-north azimuth (degrees).
pub fn direction_from_angles(altitude: f64, azimuth: f64) -> DVec3 {
    let (alt, az) = (altitude.to_radians(), azimuth.to_radians());
    DVec3::new(az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin())
}

/// TT − UT in seconds for a year and month: the Espenak–Meeus polynomials
/// (NASA's eclipse pages), evaluated at the middle of the month as pvlib does.
pub fn delta_t(year: i32, month: u32) -> f64 {
    let y = f64::from(year) + (f64::from(month) - 0.5) / 12.0;
    let year = f64::from(year);
    let poly = |t: f64, c: &[f64]| c.iter().rev().fold(0.0, |acc, k| acc * t + k);
    let long_term = |y: f64| -20.0 + 32.0 * ((y - 1820.0) / 100.0).powi(2);
    if year < -500.0 {
        long_term(y)
    } else if year < 500.0 {
        poly(y / 100.0, &[10583.6, -1014.41, 33.78311, -5.952053, -0.1798452, 0.022174192, 0.0090316521])
    } else if year < 1600.0 {
        poly((y - 1000.0) / 100.0, &[1574.2, -556.01, 71.23472, 0.319781, -0.8503463, -0.005050998, 0.0083572073])
    } else if year < 1700.0 {
        poly(y - 1600.0, &[120.0, -0.9808, -0.01532, 1.0 / 7129.0])
    } else if year < 1800.0 {
        poly(y - 1700.0, &[8.83, 0.1603, -0.0059285, 0.00013336, -1.0 / 1_174_000.0])
    } else if year < 1860.0 {
        poly(y - 1800.0, &[13.72, -0.332447, 0.0068612, 0.0041116, -0.00037436, 0.0000121272, -0.0000001699, 0.000000000875])
    } else if year < 1900.0 {
        poly(y - 1860.0, &[7.62, 0.5737, -0.251754, 0.01680668, -0.0004473624, 1.0 / 233_174.0])
    } else if year < 1920.0 {
        poly(y - 1900.0, &[-2.79, 1.494119, -0.0598939, 0.0061966, -0.000197])
    } else if year < 1941.0 {
        poly(y - 1920.0, &[21.20, 0.84493, -0.076100, 0.0020936])
    } else if year < 1961.0 {
        poly(y - 1950.0, &[29.07, 0.407, -1.0 / 233.0, 1.0 / 2547.0])
    } else if year < 1986.0 {
        poly(y - 1975.0, &[45.45, 1.067, -1.0 / 260.0, -1.0 / 718.0])
    } else if year < 2005.0 {
        poly(y - 2000.0, &[63.86, 0.3345, -0.060374, 0.0017275, 0.000651814, 0.00002373599])
    } else if year < 2050.0 {
        poly(y - 2000.0, &[62.92, 0.32217, 0.005589])
    } else if year < 2150.0 {
        long_term(y) - 0.5628 * (2150.0 - y)
    } else {
        long_term(y)
    }
}

fn spa_at(site: &Site, julian_day: f64, delta_t: f64) -> SpaOutput {
    spa(&SpaInput {
        julian_day,
        delta_t,
        latitude: site.latitude,
        longitude: site.longitude,
        elevation: site.elevation,
        pressure: site.pressure,
        temperature: site.temperature,
        atmospheric_refraction: SUNRISE_REFRACTION,
    })
}

/// The sun's position at a local standard time.
pub fn solar_position(site: &Site, when: &LocalDateTime) -> SolarPosition {
    let julian_day = when.julian_day(site.timezone);
    let delta_t = delta_t(when.date.year, when.date.month);
    let spa = spa_at(site, julian_day, delta_t);
    SolarPosition { altitude: spa.elevation, azimuth: spa.azimuth, geometric_altitude: spa.elevation_geometric, julian_day, delta_t, spa }
}

/// Sunrise, solar noon and sunset of one local day.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunDay {
    /// Local standard time of the sun's transit (solar noon).
    pub noon: TimeOfDay,
    /// Apparent altitude at solar noon, degrees.
    pub noon_altitude: f64,
    /// `None` when the sun does not rise (or set) this day.
    pub sunrise: Option<TimeOfDay>,
    /// Local standard time of sunset; `None` when the sun does not set (or
    /// rise) this day.
    pub sunset: Option<TimeOfDay>,
    /// Whether the sun is up at noon: with no sunrise and sunset, a polar day
    /// when true, a polar night when false.
    pub up_at_noon: bool,
}

/// Sunrise and sunset (the sun's upper limb on a refracted horizon: centre at
/// −0.8333° geometric altitude) and solar noon (local hour angle zero), found
/// on the full SPA by bracketing and bisection within the local day.
pub fn sun_day(site: &Site, date: Date) -> SunDay {
    let delta_t = delta_t(date.year, date.month);
    let midnight = LocalDateTime { date, time: TimeOfDay::from_seconds(0.0).expect("midnight") }.julian_day(site.timezone);
    let at = |hours: f64| spa_at(site, midnight + hours / 24.0, delta_t);
    let altitude_above_horizon = |hours: f64| at(hours).elevation_geometric - SUNRISE_ALTITUDE;
    let hour_angle = |hours: f64| at(hours).hour_angle;
    const STEPS: usize = 48;
    let grid: Vec<f64> = (0..=STEPS).map(|i| 24.0 * i as f64 / STEPS as f64).collect();
    let to_time = |hours: f64| TimeOfDay::from_hours(hours.clamp(0.0, 24.0)).expect("clamped");

    let mut noon = None;
    for pair in grid.windows(2) {
        let (h0, h1) = (hour_angle(pair[0]), hour_angle(pair[1]));
        // The hour angle rises through zero at transit (and jumps from +180 to −180 at the antitransit).
        if h0 <= 0.0 && h1 > 0.0 && h1 - h0 < 90.0 {
            noon = Some(bisect(hour_angle, pair[0], pair[1]));
            break;
        }
    }
    // Far from the time zone's meridian transit can fall just outside the day: take the nearer edge.
    let noon = noon.unwrap_or_else(|| if hour_angle(12.0) > 0.0 { 0.0 } else { 24.0 });
    let (mut sunrise, mut sunset) = (None, None);
    for pair in grid.windows(2) {
        let (a0, a1) = (altitude_above_horizon(pair[0]), altitude_above_horizon(pair[1]));
        if a0 < 0.0 && a1 >= 0.0 && sunrise.is_none() {
            sunrise = Some(to_time(bisect(altitude_above_horizon, pair[0], pair[1])));
        } else if a0 >= 0.0 && a1 < 0.0 {
            sunset = Some(to_time(bisect(altitude_above_horizon, pair[0], pair[1])));
        }
    }
    SunDay { noon: to_time(noon), noon_altitude: at(noon).elevation, sunrise, sunset, up_at_noon: altitude_above_horizon(noon) >= 0.0 }
}

/// A root of `f` in [a, b], where `f` changes sign, to about 0.01 s.
fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let fa = f(a);
    for _ in 0..30 {
        let m = 0.5 * (a + b);
        if (f(m) < 0.0) == (fa < 0.0) {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reda & Andreas (2004), table A5.1, to the printed precision.
    #[test]
    fn spa_paper_reference_case() {
        // 2003-10-17 12:30:30 at UTC-7; the Julian day is checked in `time`.
        let when = LocalDateTime { date: Date::new(2003, 10, 17).unwrap(), time: TimeOfDay::parse("12:30:30").unwrap() };
        let out = spa(&SpaInput {
            julian_day: when.julian_day(-7.0),
            delta_t: 67.0,
            latitude: 39.742476,
            longitude: -105.1786,
            elevation: 1830.14,
            pressure: 820.0,
            temperature: 11.0,
            atmospheric_refraction: SUNRISE_REFRACTION,
        });
        assert!((90.0 - out.elevation - 50.11162).abs() < 5e-6, "zenith {}", 90.0 - out.elevation);
        assert!((out.azimuth - 194.34024).abs() < 5e-6, "azimuth {}", out.azimuth);
        assert!((incidence_angle(&out, 30.0, -10.0) - 25.18700).abs() < 5e-6);
    }

    #[test]
    fn delta_t_matches_known_values() {
        // pvlib.spa.calculate_deltat(2003, 10) and (2026, 3).
        assert!((delta_t(2003, 10) - 64.507_826).abs() < 1e-5, "{}", delta_t(2003, 10));
        assert!((delta_t(2026, 3) - 75.202_493).abs() < 1e-5, "{}", delta_t(2026, 3));
    }

    /// References found with pvlib's `spa_python` by bisection: sunrise and
    /// sunset where its geometric elevation is −0.8333°, transit where its
    /// azimuth is 180°. (pvlib's `sun_rise_set_transit_spa`, the paper's
    /// interpolated appendix A.2, is up to 12 s off these.)
    /// (date, timezone, latitude, longitude, sunrise, transit, sunset)
    #[test]
    fn sunrise_noon_and_sunset_agree_with_pvlib() {
        let cases = [
            ((2026, 3, 21), -5.0, 42.36, -71.06, "05:45:41.79", "11:51:19.26", "17:57:40.69"),
            ((2026, 6, 21), -8.0, 37.77, -122.42, "04:48:06.51", "12:11:34.31", "19:35:01.59"),
            ((2026, 12, 21), 1.0, 52.52, 13.4, "08:14:55.77", "12:04:26.72", "15:53:57.23"),
        ];
        for ((y, m, d), tz, lat, lon, rise, noon, set) in cases {
            let day = sun_day(&Site::new(lat, lon, tz), Date::new(y, m, d).unwrap());
            let seconds = |t: &str| TimeOfDay::parse(t).unwrap().seconds();
            let dr = day.sunrise.unwrap().seconds() - seconds(rise);
            let dn = day.noon.seconds() - seconds(noon);
            let ds = day.sunset.unwrap().seconds() - seconds(set);
            assert!(dr.abs() < 0.5 && dn.abs() < 0.5 && ds.abs() < 0.5, "{y}-{m}-{d}: {dr:.2} {dn:.2} {ds:.2} s");
            assert!(day.up_at_noon);
        }
    }

    #[test]
    fn polar_day_and_night() {
        let tromso = Site::new(69.65, 18.96, 1.0);
        let summer = sun_day(&tromso, Date::new(2026, 6, 21).unwrap());
        assert!(summer.sunrise.is_none() && summer.sunset.is_none() && summer.up_at_noon);
        let winter = sun_day(&tromso, Date::new(2026, 12, 21).unwrap());
        assert!(winter.sunrise.is_none() && winter.sunset.is_none() && !winter.up_at_noon);
    }
}
