//! Skies: radiance in every direction, the sun as its own source, and the
//! ground glow, for a sun position. gensky's five skies ([`gensky`]), the
//! Perez all-weather sky as gendaylit makes it ([`perez`]) and the 15 CIE
//! standard general skies ([`cie`]); [`patches`] integrates any of them over
//! Tregenza/Reinhart sky patches. Radiance units throughout: W/sr/m² of
//! "visible watts", 179 lm/W. Plain Rust, no Bevy types.

mod cells;
pub mod cie;
mod elementary;
mod export;
pub mod gensky;
pub mod patches;
pub mod perez;

use std::f64::consts::PI;
use std::fmt;

use glam::DVec3;

use crate::site::Site;
use crate::sun::{SolarPosition, solar_position};
use crate::time::LocalDateTime;

use cells::SkyCells;
pub use export::radiance_sky;
pub use patches::SkyPatches;

/// Radiance's luminous efficacy for reporting (lm/W).
pub const LUMINOUS_EFFICACY: f64 = 179.0;
/// gensky's efficacy of sky light (lm/W).
pub const SKY_EFFICACY: f64 = 203.0;
/// gensky's efficacy of sunlight (lm/W).
pub const SUN_EFFICACY: f64 = 208.0;
/// gensky's default turbidity.
pub const DEFAULT_TURBIDITY: f64 = 2.45;
/// Turbidity of the `turbid` sky.
pub const TURBID_TURBIDITY: f64 = 5.0;
/// Direct normal irradiance cannot exceed the solar constant (W/m²).
const SOLAR_CONSTANT: f64 = 1367.0;
/// Direct normal illuminance cannot exceed the solar constant (lux).
const SOLAR_CONSTANT_LUX: f64 = 127_500.0;

/// A sky as the user chooses it; [`Sky::new`] evaluates it for a sun.
#[derive(Debug, Clone, PartialEq)]
pub enum SkySpec {
    /// CIE clear sky with sun (`gensky +s`).
    Clear {
        /// Linke-style turbidity, 1-20 (gensky's `-t`): by default 2.45 for
        /// `clear`, 5 for `turbid`.
        turbidity: f64,
    },
    /// CIE intermediate sky with sun (`gensky +i`).
    Intermediate {
        /// Linke-style turbidity, 1-20 (gensky's `-t`; 2.45 by default).
        turbidity: f64,
    },
    /// CIE overcast sky (`gensky -c`).
    Overcast,
    /// Uniform sky (`gensky -u`).
    Uniform,
    /// Perez all-weather sky (`gendaylit -W` or `-L`).
    Perez(perez::Input),
    /// CIE standard general sky 1-15 for a diffuse horizontal illuminance
    /// (lux), with a sun of a direct normal illuminance (lux, may be 0).
    Cie {
        /// The CIE type, 1-15: 1-5 overcast, 6-10 partly cloudy, 11-15 clear.
        standard_type: u8,
        /// Diffuse horizontal illuminance the sky is scaled to give, lux.
        diffuse_illuminance: f64,
        /// Direct normal illuminance of the sun, lux; 0 for no sun.
        direct_illuminance: f64,
    },
}

/// A sky that cannot be made; one line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkyError(pub String);

impl fmt::Display for SkyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SkyError {}

fn error<T>(message: impl Into<String>) -> Result<T, SkyError> {
    Err(SkyError(message.into()))
}

/// The numbers a sky name may need besides the sun.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SkyInputs {
    /// Direct normal irradiance, W/m² (Perez).
    pub direct_normal: Option<f64>,
    /// Diffuse horizontal irradiance, W/m² (Perez).
    pub diffuse_horizontal: Option<f64>,
    /// Direct normal illuminance, lux (Perez, CIE).
    pub direct_illuminance: Option<f64>,
    /// Diffuse horizontal illuminance, lux (Perez, CIE).
    pub diffuse_illuminance: Option<f64>,
    /// Linke-style turbidity for the clear and intermediate skies.
    pub turbidity: Option<f64>,
}

/// The sky names [`SkySpec::parse`] takes, for help and error messages.
pub const SKY_NAMES: &str = "clear, turbid, intermediate, overcast, uniform, perez, cie:1 … cie:15";

impl SkySpec {
    /// A sky from its name (`clear`, `turbid`, `intermediate`, `overcast`,
    /// `uniform`, `perez`, `cie:N`) and the numbers it needs.
    pub fn parse(name: &str, inputs: &SkyInputs) -> Result<Self, SkyError> {
        let non_negative = |value: Option<f64>, what: &str| -> Result<Option<f64>, SkyError> {
            match value {
                Some(v) if !v.is_finite() || v < 0.0 => error(format!("{what} must be a non-negative number, not {v}")),
                other => Ok(other),
            }
        };
        let dni = non_negative(inputs.direct_normal, "the direct normal irradiance")?;
        let dhi = non_negative(inputs.diffuse_horizontal, "the diffuse horizontal irradiance")?;
        let dnl = non_negative(inputs.direct_illuminance, "the direct normal illuminance")?;
        let dhl = non_negative(inputs.diffuse_illuminance, "the diffuse horizontal illuminance")?;
        let turbidity = |default: f64| match inputs.turbidity {
            Some(t) if !(1.0..=20.0).contains(&t) => error(format!("turbidity {t} is outside 1-20")),
            Some(t) => Ok(t),
            None => Ok(default),
        };
        let spec = match name {
            "clear" => SkySpec::Clear { turbidity: turbidity(DEFAULT_TURBIDITY)? },
            "turbid" => SkySpec::Clear { turbidity: turbidity(TURBID_TURBIDITY)? },
            "intermediate" => SkySpec::Intermediate { turbidity: turbidity(DEFAULT_TURBIDITY)? },
            "overcast" => SkySpec::Overcast,
            "uniform" => SkySpec::Uniform,
            "perez" => match (dni, dhi, dnl, dhl) {
                (Some(direct_normal), Some(diffuse_horizontal), None, None) => {
                    SkySpec::Perez(perez::Input::Irradiance { direct_normal, diffuse_horizontal })
                }
                (None, None, Some(direct_normal), Some(diffuse_horizontal)) => {
                    SkySpec::Perez(perez::Input::Illuminance { direct_normal, diffuse_horizontal })
                }
                _ => {
                    return error(
                        "the perez sky needs a direct normal and a diffuse horizontal irradiance (W/m²), or both illuminances (lux)",
                    );
                }
            },
            other => match other.strip_prefix("cie:").map(str::parse::<u8>) {
                Some(Ok(standard_type @ 1..=15)) => {
                    let Some(diffuse_illuminance) = dhl else {
                        return error(format!("the {other} sky needs a diffuse horizontal illuminance (lux)"));
                    };
                    SkySpec::Cie { standard_type, diffuse_illuminance, direct_illuminance: dnl.unwrap_or(0.0) }
                }
                Some(_) => return error(format!("'{other}' is not a CIE sky: the types run cie:1 … cie:15")),
                None => return error(format!("unknown sky '{other}' (expected {SKY_NAMES})")),
            },
        };
        spec.check()?;
        Ok(spec)
    }

    fn check(&self) -> Result<(), SkyError> {
        match *self {
            SkySpec::Perez(perez::Input::Irradiance { direct_normal, .. }) if direct_normal > SOLAR_CONSTANT => {
                error(format!("direct normal irradiance {direct_normal} W/m² exceeds the solar constant ({SOLAR_CONSTANT})"))
            }
            SkySpec::Perez(perez::Input::Illuminance { direct_normal, .. }) if direct_normal > SOLAR_CONSTANT_LUX => {
                error(format!("direct normal illuminance {direct_normal} lux exceeds the solar constant ({SOLAR_CONSTANT_LUX})"))
            }
            SkySpec::Cie { direct_illuminance, .. } if direct_illuminance > SOLAR_CONSTANT_LUX => {
                error(format!("direct normal illuminance {direct_illuminance} lux exceeds the solar constant"))
            }
            _ => Ok(()),
        }
    }

    /// The name `parse` takes.
    pub fn name(&self) -> String {
        match self {
            SkySpec::Clear { turbidity } if *turbidity == TURBID_TURBIDITY => "turbid".into(),
            SkySpec::Clear { .. } => "clear".into(),
            SkySpec::Intermediate { .. } => "intermediate".into(),
            SkySpec::Overcast => "overcast".into(),
            SkySpec::Uniform => "uniform".into(),
            SkySpec::Perez(_) => "perez".into(),
            SkySpec::Cie { standard_type, .. } => format!("cie:{standard_type}"),
        }
    }
}

/// The sun as a light source: a small disc of uniform radiance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunSource {
    /// Unit vector toward the sun (canonical frame).
    pub direction: DVec3,
    /// Steradians.
    pub solid_angle: f64,
    /// W/sr/m².
    pub radiance: f64,
}

impl SunSource {
    /// A sun of 1 W/m² normal irradiance from `direction`: light is linear
    /// in the sun's strength, so responses to it scale to any hour's sun.
    pub fn unit(direction: DVec3) -> Self {
        Self { direction, solid_angle: 1.0, radiance: 1.0 }
    }

    /// Irradiance on a plane facing the sun, W/m².
    pub fn normal_irradiance(&self) -> f64 {
        self.radiance * self.solid_angle
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Distribution {
    /// No light at all (night under the Perez sky).
    Dark,
    Gensky(gensky::Gensky),
    Perez(perez::Perez),
    Cie(cie::Cie),
}

/// A sky evaluated for one sun position.
#[derive(Debug, Clone, PartialEq)]
pub struct Sky {
    /// The sky as chosen.
    pub spec: SkySpec,
    /// Unit vector toward the sun's true position.
    pub sun_direction: DVec3,
    /// The sun, when it is up and the sky has one.
    pub sun: Option<SunSource>,
    /// Radiance of the ground glow below the horizon.
    pub ground_radiance: f64,
    /// Sky radiance at the zenith, W/sr/m².
    pub zenith_radiance: f64,
    /// The model's own horizontal irradiance from the sky alone (W/m²):
    /// π × gensky's "ground ambient level", or what a Perez or CIE sky was
    /// scaled to.
    pub diffuse_horizontal: f64,
    /// Perez clearness ε and brightness Δ (Perez skies only).
    pub perez_indices: Option<(f64, f64)>,
    /// Why the sky is dark though light was given, as gendaylit warns:
    /// a Perez sky with a positive parameter b ([`perez::Computed::positive_b`]).
    pub refused: Option<String>,
    distribution: Distribution,
}

/// A direction with the terms of the sky functions that depend on it alone,
/// so that integrating a sky over fixed directions computes them once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyDirection {
    /// The unit direction (canonical frame: x east, y north, z up).
    pub d: DVec3,
    /// [`blend_weight`] of `d.z`.
    blend: f64,
    /// Zenith angle, radians.
    eta: f64,
    /// The clear sky's horizon term, 1 − exp(−0.32/Dz) above Dz = 0.01.
    clear_horizon: f64,
    /// The intermediate sky's 1.35·sin(5.631 − 3.59η) + 3.12.
    intermediate_eta: f64,
}

impl SkyDirection {
    /// The terms for the unit direction `d`.
    pub fn new(d: DVec3) -> Self {
        let eta = d.z.clamp(-1.0, 1.0).acos();
        Self {
            d,
            blend: blend_weight(d.z),
            eta,
            clear_horizon: if d.z > 0.01 { 1.0 - (-0.32 / d.z).exp() } else { 1.0 },
            intermediate_eta: 1.35 * (5.631 - 3.59 * eta).sin() + 3.12,
        }
    }
}

/// Below this weight of the sky term, a direction sees the ground glow alone.
const NEGLIGIBLE_SKY_WEIGHT: f64 = 1e-9;

/// Weight of the sky term against the ground glow (skybright.cal):
/// (Dz+1.01)^10 / ((Dz+1.01)^10 + (Dz+1.01)^−10).
pub fn blend_weight(dz: f64) -> f64 {
    let up = (dz + 1.01).powi(20);
    up / (up + 1.0)
}

impl Sky {
    /// The sun, when the sky has one above the horizon: what sheds direct light.
    pub fn sun_up(&self) -> Option<SunSource> {
        self.sun.filter(|s| s.direction.z > 0.0)
    }

    /// Irradiance on an unobstructed horizontal plane, sun and sky, W/m².
    pub fn global_horizontal(&self) -> f64 {
        self.diffuse_horizontal + self.sun_up().map_or(0.0, |s| s.normal_irradiance() * s.direction.z)
    }

    /// Evaluates a sky for a sun at `altitude` and `azimuth` (degrees,
    /// apparent altitude, azimuth clockwise from north). `day_of_year` enters
    /// the Perez sky's brightness (gendaylit's `-ang` uses 0).
    pub fn new(spec: &SkySpec, altitude: f64, azimuth: f64, ground_reflectance: f64, day_of_year: u32) -> Result<Self, SkyError> {
        if !altitude.is_finite() || !(-90.0..=90.0).contains(&altitude) || !azimuth.is_finite() {
            return error(format!("sun altitude {altitude}° / azimuth {azimuth}° is not a direction"));
        }
        if !(0.0..=1.0).contains(&ground_reflectance) {
            return error(format!("ground reflectance {ground_reflectance} is outside 0-1"));
        }
        spec.check()?;
        let sun_direction = crate::sun::direction_from_angles(altitude, azimuth);
        let mut sky = Sky {
            spec: spec.clone(),
            sun_direction,
            sun: None,
            ground_radiance: 0.0,
            zenith_radiance: 0.0,
            diffuse_horizontal: 0.0,
            perez_indices: None,
            refused: None,
            distribution: Distribution::Dark,
        };
        match *spec {
            SkySpec::Clear { .. } | SkySpec::Intermediate { .. } | SkySpec::Overcast | SkySpec::Uniform => {
                let (kind, turbidity) = match *spec {
                    SkySpec::Clear { turbidity } => (gensky::Kind::Clear, turbidity),
                    SkySpec::Intermediate { turbidity } => (gensky::Kind::Intermediate, turbidity),
                    SkySpec::Overcast => (gensky::Kind::Overcast, DEFAULT_TURBIDITY),
                    _ => (gensky::Kind::Uniform, DEFAULT_TURBIDITY),
                };
                let g = gensky::compute(kind, turbidity, altitude, azimuth, ground_reflectance);
                sky.sun = g.sun;
                sky.ground_radiance = g.ground_radiance;
                sky.zenith_radiance = g.zenith_radiance;
                sky.diffuse_horizontal = PI * g.ambient;
                sky.distribution = Distribution::Gensky(g.distribution);
            }
            SkySpec::Perez(input) => {
                let (direct, diffuse) = match input {
                    perez::Input::Irradiance { direct_normal, diffuse_horizontal }
                    | perez::Input::Illuminance { direct_normal, diffuse_horizontal } => (direct_normal, diffuse_horizontal),
                };
                if direct == 0.0 && diffuse == 0.0 {
                    return Ok(sky);
                }
                if altitude <= 0.0 {
                    return error(format!(
                        "perez: the sun is below the horizon (altitude {altitude:.2}°), so direct and diffuse light must both be 0"
                    ));
                }
                if diffuse == 0.0 {
                    return error("perez: direct sunlight without any diffuse light is not a sky (the diffuse value must be > 0)");
                }
                let p = perez::compute(input, altitude, azimuth, f64::from(day_of_year), ground_reflectance);
                sky.sun = p.sun;
                sky.ground_radiance = p.ground_radiance;
                sky.zenith_radiance = p.zenith_radiance;
                sky.diffuse_horizontal = p.diffuse_horizontal;
                sky.perez_indices = Some((p.clearness, p.brightness));
                match p.positive_b {
                    Some(b) => {
                        sky.refused = Some(format!(
                            "the Perez sky with the sun {altitude:.2}° high has a positive parameter b ({b:.4}): dark, as gendaylit's error sky"
                        ))
                    }
                    None => sky.distribution = Distribution::Perez(p.distribution),
                }
            }
            SkySpec::Cie { standard_type, diffuse_illuminance, direct_illuminance } => {
                let c = cie::compute(standard_type, diffuse_illuminance, direct_illuminance, altitude, azimuth, ground_reflectance);
                sky.sun = c.sun;
                sky.ground_radiance = c.ground_radiance;
                sky.zenith_radiance = c.zenith_radiance;
                sky.diffuse_horizontal = diffuse_illuminance / LUMINOUS_EFFICACY;
                sky.distribution = Distribution::Cie(c.distribution);
            }
        }
        Ok(sky)
    }

    /// Radiance of the sky (or, below the horizon, the ground glow) in the
    /// unit direction `d`, without the sun: the sky term blended into the
    /// ground glow around the horizon as skybright.cal does.
    pub fn radiance(&self, d: DVec3) -> f64 {
        self.radiance_toward(&SkyDirection::new(d), None)
    }

    /// [`Self::radiance`] for a direction whose own terms are computed already.
    /// `height_term`: the sky's [`Self::height_terms`] of the direction's
    /// height, when known.
    pub fn radiance_toward(&self, d: &SkyDirection, height_term: Option<f64>) -> f64 {
        // Deep below the horizon the sky's weight (under 1e-9) would not
        // show in any reading: the ground glow alone, without evaluating
        // the sky (the annual study asks for every bin every hour).
        if d.blend < NEGLIGIBLE_SKY_WEIGHT {
            return self.ground_radiance;
        }
        let sky = match &self.distribution {
            Distribution::Dark => return 0.0,
            Distribution::Gensky(g) => g.sky(d),
            Distribution::Perez(p) => p.sky_with_gradation(d.d, height_term.unwrap_or_else(|| p.gradation(d.d.z))),
            Distribution::Cie(c) => c.sky(d.d),
        };
        d.blend * sky + (1.0 - d.blend) * self.ground_radiance
    }

    /// What the sky's radiance toward every direction of each height in
    /// `heights` (unit vectors' z) shares, for [`Self::radiance_toward`]:
    /// the Perez sky's gradation (half its exponentials, where a quadrature
    /// evaluates a whole row of cells of one height); empty for the others,
    /// whose own terms of a direction [`SkyDirection`] holds.
    pub fn height_terms(&self, heights: &[f64]) -> Vec<f64> {
        match &self.distribution {
            Distribution::Perez(p) => heights.iter().map(|&z| p.gradation(z)).collect(),
            _ => Vec::new(),
        }
    }

    /// The gensky distribution's printed arguments, for comparisons.
    pub fn gensky_arguments(&self) -> Option<(f64, f64)> {
        match &self.distribution {
            Distribution::Gensky(g) => Some(g.arguments()),
            _ => None,
        }
    }

    /// The Perez distribution's printed arguments (normalisation, a..e).
    pub fn perez_arguments(&self) -> Option<(f64, [f64; 5])> {
        match &self.distribution {
            Distribution::Perez(p) => Some(p.arguments()),
            _ => None,
        }
    }
}

/// The sun at a site and local time (its true angles), and the sky it makes
/// in the model's frame: turned by the site's `north_turn`. Every sky
/// distribution depends only on the angle to the sun and the zenith, so
/// moving the sun's azimuth turns the whole sky.
pub fn sky_at(site: &Site, spec: &SkySpec, when: &LocalDateTime) -> (SolarPosition, Result<Sky, SkyError>) {
    let sun = solar_position(site, when);
    let sky = Sky::new(spec, sun.altitude, sun.azimuth + site.north_turn, site.ground_reflectance, when.date.day_of_year());
    (sun, sky)
}

/// ∫ f dω and ∫ f·cos θ dω over the upper hemisphere, by the midpoint rule
/// on (cos θ, φ) cells of equal solid angle (`steps` = cells in cos θ and φ).
pub fn integrate_hemisphere(f: impl Fn(DVec3) -> f64, steps: (usize, usize)) -> (f64, f64) {
    let (n_mu, n_phi) = steps;
    let cell = (1.0 / n_mu as f64) * (2.0 * PI / n_phi as f64);
    let (mut plain, mut cosine) = (0.0, 0.0);
    for i in 0..n_mu {
        let mu = (i as f64 + 0.5) / n_mu as f64;
        let sin_theta = (1.0 - mu * mu).sqrt();
        for j in 0..n_phi {
            let phi = 2.0 * PI * (j as f64 + 0.5) / n_phi as f64;
            let value = f(DVec3::new(sin_theta * phi.sin(), sin_theta * phi.cos(), mu));
            plain += value;
            cosine += value * mu;
        }
    }
    (plain * cell, cosine * cell)
}
