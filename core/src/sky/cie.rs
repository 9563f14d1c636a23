//! The 15 CIE standard general skies (CIE S 011/E:2003, ISO 15469): relative
//! luminance from a gradation and an indicatrix function, scaled so that the
//! sky gives a chosen diffuse horizontal illuminance. Radiance has no such
//! sky; the ground glow and the horizon blend follow gensky's.

use std::f64::consts::PI;

use glam::DVec3;

use super::{LUMINOUS_EFFICACY, SunSource, blend_weight, integrate_hemisphere};
use crate::sun::direction_from_angles;

/// Per type: gradation a, b; indicatrix c, d, e.
pub const PARAMETERS: [[f64; 5]; 15] = [
    [4.0, -0.70, 0.0, -1.0, 0.00],
    [4.0, -0.70, 2.0, -1.5, 0.15],
    [1.1, -0.80, 0.0, -1.0, 0.00],
    [1.1, -0.80, 2.0, -1.5, 0.15],
    [0.0, -1.00, 0.0, -1.0, 0.00],
    [0.0, -1.00, 2.0, -1.5, 0.15],
    [0.0, -1.00, 5.0, -2.5, 0.30],
    [0.0, -1.00, 10.0, -3.0, 0.45],
    [-1.0, -0.55, 2.0, -1.5, 0.15],
    [-1.0, -0.55, 5.0, -2.5, 0.30],
    [-1.0, -0.55, 10.0, -3.0, 0.45],
    [-1.0, -0.32, 10.0, -3.0, 0.45],
    [-1.0, -0.32, 16.0, -3.0, 0.30],
    [-1.0, -0.15, 16.0, -3.0, 0.30],
    [-1.0, -0.15, 24.0, -2.8, 0.15],
];

/// A CIE sky's distribution: L = Lz · f(χ)·φ(Z) / (f(Zs)·φ(0)).
#[derive(Debug, Clone, PartialEq)]
pub struct Cie {
    parameters: [f64; 5],
    sun: DVec3,
    zenith: f64,
    /// f(Zs)·φ(0): the relative luminance at the zenith.
    at_zenith: f64,
}

/// What [`compute`] makes of a CIE sky for one sun position.
pub struct Computed {
    /// The sky function, scaled to the diffuse illuminance.
    pub distribution: Cie,
    /// Sky radiance at the zenith, W/sr/m².
    pub zenith_radiance: f64,
    /// Radiance of the ground glow below the horizon, W/sr/m²: the ground's
    /// reflectance × the horizontal irradiance from sky and sun, over π.
    pub ground_radiance: f64,
    /// The sun as a source; `None` when it is down or its direct illuminance is 0.
    pub sun: Option<SunSource>,
}

/// Quadrature for the normalisation: fine enough for 0.1% on the sharpest
/// corona (type 15).
const NORMALISATION_STEPS: (usize, usize) = (60, 120);

/// ∫ (1 − w)·cos dω over the upper hemisphere: the ground glow's share of
/// the horizontal light, the same for every sky.
fn ground_share() -> f64 {
    static SHARE: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *SHARE.get_or_init(|| integrate_hemisphere(|d| 1.0 - blend_weight(d.z), (400, 8)).1)
}

impl Cie {
    fn gradation(&self, cos_z: f64) -> f64 {
        let [a, b, ..] = self.parameters;
        if cos_z > 0.0 { 1.0 + a * (b / cos_z).exp() } else { 1.0 }
    }

    fn indicatrix(&self, chi: f64) -> f64 {
        let [_, _, c, d, e] = self.parameters;
        1.0 + c * ((d * chi).exp() - (d * PI / 2.0).exp()) + e * chi.cos().powi(2)
    }

    /// Luminance relative to the zenith's.
    pub fn relative(&self, d: DVec3) -> f64 {
        let chi = d.dot(self.sun).clamp(-1.0, 1.0).acos();
        self.indicatrix(chi) * self.gradation(d.z) / self.at_zenith
    }

    /// Scale (Lz / (f(Zs)·φ(0))), the parameters and the sun: a .cal file's arguments.
    pub fn arguments(&self) -> (f64, [f64; 5], DVec3) {
        (self.zenith / self.at_zenith, self.parameters, self.sun)
    }

    /// The sky term (before the blend into the ground glow).
    pub fn sky(&self, d: DVec3) -> f64 {
        self.zenith * self.relative(d)
    }
}

/// A CIE sky of `standard_type` (1-15) giving `diffuse_illuminance` lux on
/// the horizontal, with a sun of `direct_illuminance` lux (normal) when the
/// sun is up and that is positive.
pub fn compute(
    standard_type: u8,
    diffuse_illuminance: f64,
    direct_illuminance: f64,
    altitude: f64,
    azimuth: f64,
    ground_reflectance: f64,
) -> Computed {
    let sun = direction_from_angles(altitude, azimuth);
    let mut cie = Cie { parameters: PARAMETERS[standard_type as usize - 1], sun, zenith: 1.0, at_zenith: 1.0 };
    let zenith_angle = (90.0 - altitude).to_radians();
    cie.at_zenith = cie.indicatrix(zenith_angle) * cie.gradation(1.0);
    let sz = altitude.to_radians().sin();
    let solid_angle = 2.0 * PI * (1.0 - super::perez::SUN_HALF_ANGLE.to_radians().cos());
    let solar = if sz > 0.0 && direct_illuminance > 0.0 { direct_illuminance / LUMINOUS_EFFICACY / solid_angle } else { 0.0 };
    let diffuse = diffuse_illuminance / LUMINOUS_EFFICACY;
    let ground = ground_reflectance * (diffuse + solar * solid_angle * sz.max(0.0)) / PI;
    // The blended sky (sky term and ground glow) must give `diffuse` on the
    // horizontal: diffuse = Lz·∫ w·rel·cos + ground·∫ (1−w)·cos.
    let (_, sky_part) = integrate_hemisphere(|d| blend_weight(d.z) * cie.relative(d), NORMALISATION_STEPS);
    cie.zenith = ((diffuse - ground * ground_share()) / sky_part).max(0.0);
    Computed {
        zenith_radiance: cie.zenith,
        distribution: cie,
        ground_radiance: ground,
        sun: (solar > 0.0).then_some(SunSource { direction: sun, solid_angle, radiance: solar }),
    }
}
