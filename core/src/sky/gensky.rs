//! Radiance's gensky skies (gensky.c and skybright.cal, Radiance 6): CIE
//! clear, intermediate and overcast, and uniform, with gensky's zenith
//! brightness, normalisation, ground glow and sun.

use std::f64::consts::PI;

use glam::DVec3;

use super::{SKY_EFFICACY, SUN_EFFICACY, SkyDirection, SunSource};
use crate::sun::direction_from_angles;

/// gensky's sun: a disc 0.5° across.
pub const SUN_SOLID_ANGLE: f64 = 5.981_4e-5;
/// The solid angle gensky uses for the sun's light on the ground.
const GROUND_SUN_SOLID_ANGLE: f64 = 6e-5;
/// gensky lowers the sun to 87° for the sky formulas of sunny skies.
const MAX_ALTITUDE: f64 = 87.0;

/// Which of gensky's skies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// CIE clear sky with sun (`+s`).
    Clear,
    /// CIE intermediate sky with sun (`+i`).
    Intermediate,
    /// CIE overcast sky (`-c`): three times as bright at the zenith as at the
    /// horizon, the same all round.
    Overcast,
    /// Uniform sky (`-u`): the same radiance in every direction.
    Uniform,
}

/// The sky function's arguments (skybright.cal's A2, A4, A5-A7).
#[derive(Debug, Clone, PartialEq)]
pub struct Gensky {
    kind: Kind,
    zenith: f64,
    f2: f64,
    sun: DVec3,
    /// Zenith angle of the (clamped) sun.
    sun_zenith: f64,
}

/// What gensky computes for a sun position.
pub struct Computed {
    /// The sky function's arguments.
    pub distribution: Gensky,
    /// Sky radiance at the zenith, W/sr/m².
    pub zenith_radiance: f64,
    /// gensky's "ground ambient level": zenith radiance × normalisation, the
    /// sky's horizontal irradiance over π.
    pub ambient: f64,
    /// Radiance of the ground glow below the horizon, W/sr/m²: the ground's
    /// reflectance × the horizontal irradiance from sky and sun, over π.
    pub ground_radiance: f64,
    /// The sun as a source; `None` for the overcast and uniform skies and when
    /// the sun is down.
    pub sun: Option<SunSource>,
}

/// The sky function at the zenith (F2) for sunny skies; 0 for the others.
fn f2(kind: Kind, alt: f64) -> f64 {
    match kind {
        Kind::Clear => 0.274 * (0.91 + 10.0 * (-3.0 * (PI / 2.0 - alt)).exp() + 0.45 * alt.sin().powi(2)),
        Kind::Intermediate => (2.739 + 0.9891 * (0.3119 + 2.6 * alt).sin()) * (-(PI / 2.0 - alt) * (0.4441 + 1.48 * alt)).exp(),
        Kind::Overcast | Kind::Uniform => 0.0,
    }
}

/// Horizontal sky irradiance over π × zenith radiance, for a sun altitude in radians.
pub fn normfactor(kind: Kind, alt: f64) -> f64 {
    match kind {
        Kind::Uniform => 1.0,
        Kind::Overcast => 0.777778,
        Kind::Clear | Kind::Intermediate => normsc(kind, alt) / f2(kind, alt) / PI,
    }
}

/// normsc(): horizontal-to-zenith factor fit (E0·F2/L0).
fn normsc(kind: Kind, altitude: f64) -> f64 {
    let c: [f64; 5] = match kind {
        Kind::Intermediate => [3.5556, -2.7152, -1.3081, 1.0660, 0.60227],
        _ => [2.766521, 0.547665, -0.369832, 0.009237, 0.059229],
    };
    let x = (altitude - PI / 4.0) / (PI / 4.0);
    c.iter().rev().fold(0.0, |acc, k| acc * x + k)
}

/// gensky for a sun at `altitude`/`azimuth` (degrees; azimuth clockwise from
/// north), as `gensky -ang`. The sky formulas see the sun lowered to 87° as
/// gensky's do; the sun source stays where it is.
pub fn compute(kind: Kind, turbidity: f64, altitude: f64, azimuth: f64, ground_reflectance: f64) -> Computed {
    let sunny = matches!(kind, Kind::Clear | Kind::Intermediate);
    let clamped = if sunny { altitude.min(MAX_ALTITUDE) } else { altitude };
    let alt = clamped.to_radians();
    let sun = direction_from_angles(clamped, azimuth);
    let sz = alt.sin();
    let f2 = f2(kind, alt);
    let normfactor = normfactor(kind, alt);
    let overcast_zenith = 8.6 * sz + 0.123;
    let mut zenith = match kind {
        Kind::Overcast | Kind::Uniform => overcast_zenith,
        Kind::Clear => (1.376 * turbidity - 1.81) * alt.tan() + 0.38,
        Kind::Intermediate => ((1.376 * turbidity - 1.81) * alt.tan() + 0.38 + overcast_zenith) / 2.0,
    };
    zenith = if zenith < 0.0 { 0.0 } else { zenith * 1000.0 / SKY_EFFICACY };
    let ambient = zenith * normfactor;
    let mut ground = ambient;
    let mut source = None;
    if sunny && sz > 0.0 {
        let mut solar = 1.5e9 / SUN_EFFICACY * (1.147 - 0.147 / sz.max(0.16));
        if kind == Kind::Intermediate {
            solar *= 0.15;
        }
        ground += GROUND_SUN_SOLID_ANGLE / PI * solar * sz;
        source = Some(SunSource { direction: direction_from_angles(altitude, azimuth), solid_angle: SUN_SOLID_ANGLE, radiance: solar });
    }
    Computed {
        distribution: Gensky { kind, zenith, f2, sun, sun_zenith: sz.clamp(-1.0, 1.0).acos() },
        zenith_radiance: zenith,
        ambient,
        ground_radiance: ground * ground_reflectance,
        sun: source,
    }
}

impl Gensky {
    /// skybright.cal's sky term (before the blend into the ground glow).
    pub fn sky(&self, direction: &SkyDirection) -> f64 {
        let d = direction.d;
        match self.kind {
            Kind::Uniform => self.zenith,
            Kind::Overcast => self.zenith * (1.0 + 2.0 * d.z) / 3.0,
            Kind::Clear => {
                let cos_gamma = d.dot(self.sun).clamp(-1.0, 1.0);
                let gamma = cos_gamma.acos();
                self.zenith * (0.91 + 10.0 * (-3.0 * gamma).exp() + 0.45 * cos_gamma * cos_gamma) * direction.clear_horizon / self.f2
            }
            Kind::Intermediate => {
                let gamma = d.dot(self.sun).clamp(-1.0, 1.0).acos();
                let eta = direction.eta;
                let zt = self.sun_zenith;
                let sun_term = (4.396 - 2.6 * zt).sin();
                self.zenith * (direction.intermediate_eta * sun_term + 6.37 - eta) / 2.326
                    * (gamma * -0.563 * ((2.629 - eta) * (1.562 - zt) + 0.812)).exp()
                    / self.f2
            }
        }
    }

    /// The sun direction the sky function uses (lowered to 87° for sunny skies).
    pub fn sun_for_sky(&self) -> DVec3 {
        self.sun
    }

    /// The skyfunc arguments gensky prints (A2, A4), for comparisons.
    pub fn arguments(&self) -> (f64, f64) {
        (self.zenith, self.f2)
    }
}
