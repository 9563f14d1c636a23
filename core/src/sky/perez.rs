//! The Perez all-weather sky (Perez, Seals & Michalsky 1993) as Radiance's
//! gendaylit builds it: clearness ε and brightness Δ from the irradiances,
//! Perez et al. (1990) luminous efficacies, the luminance normalised over
//! gendaylit's 145 directions, and perezlum.cal's sky function.

use std::f64::consts::PI;

use glam::DVec3;

use super::{LUMINOUS_EFFICACY, SunSource, elementary};
use crate::sun::direction_from_angles;

/// gendaylit's sun: a disc 0.533° across.
pub const SUN_HALF_ANGLE: f64 = 0.2665;
const SOLAR_CONSTANT: f64 = 1367.0;
/// Solar constant in klux, for gendaylit's first guess from illuminances.
const SOLAR_CONSTANT_KLUX: f64 = 127.5;
/// Precipitable water (cm) gendaylit assumes.
const PRECIPITABLE_WATER: f64 = 2.0;
const MAX_ALTITUDE: f64 = 87.0;

/// Upper bounds of the eight clearness bins.
const BIN_BOUNDS: [f64; 8] = [1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2, f64::INFINITY];

/// Perez, Seals & Michalsky (1993): per ε bin, for each of a..e, x1..x4 of
/// x1 + x2·Z + Δ·(x3 + x4·Z).
const COEFFICIENTS: [[[f64; 4]; 5]; 8] = [
    [
        [1.3525, -0.2576, -0.2690, -1.4366],
        [-0.7670, 0.0007, 1.2734, -0.1233],
        [2.8000, 0.6004, 1.2375, 1.0000],
        [1.8734, 0.6297, 0.9738, 0.2809],
        [0.0356, -0.1246, -0.5718, 0.9938],
    ],
    [
        [-1.2219, -0.7730, 1.4148, 1.1016],
        [-0.2054, 0.0367, -3.9128, 0.9156],
        [6.9750, 0.1774, 6.4477, -0.1239],
        [-1.5798, -0.5081, -1.7812, 0.1080],
        [0.2624, 0.0672, -0.2190, -0.4285],
    ],
    [
        [-1.1000, -0.2515, 0.8952, 0.0156],
        [0.2782, -0.1812, -4.5000, 1.1766],
        [24.7219, -13.0812, -37.7000, 34.8438],
        [-5.0000, 1.5218, 3.9229, -2.6204],
        [-0.0156, 0.1597, 0.4199, -0.5562],
    ],
    [
        [-0.5484, -0.6654, -0.2672, 0.7117],
        [0.7234, -0.6219, -5.6812, 2.6297],
        [33.3389, -18.3000, -62.2500, 52.0781],
        [-3.5000, 0.0016, 1.1477, 0.1062],
        [0.4659, -0.3296, -0.0876, -0.0329],
    ],
    [
        [-0.6000, -0.3566, -2.5000, 2.3250],
        [0.2937, 0.0496, -5.6812, 1.8415],
        [21.0000, -4.7656, -21.5906, 7.2492],
        [-3.5000, -0.1554, 1.4062, 0.3988],
        [0.0032, 0.0766, -0.0656, -0.1294],
    ],
    [
        [-1.0156, -0.3670, 1.0078, 1.4051],
        [0.2875, -0.5328, -3.8500, 3.3750],
        [14.0000, -0.9999, -7.1406, 7.5469],
        [-3.4000, -0.1078, -1.0750, 1.5702],
        [-0.0672, 0.4016, 0.3017, -0.4844],
    ],
    [
        [-1.0000, 0.0211, 0.5025, -0.5119],
        [-0.3000, 0.1922, 0.7023, -1.6317],
        [19.0000, -5.0000, 1.2438, -1.9094],
        [-4.0000, 0.0250, 0.3844, 0.2656],
        [1.0468, -0.3788, -2.4517, 1.4656],
    ],
    [
        [-1.0500, 0.0289, 0.4260, 0.3590],
        [-0.3250, 0.1156, 0.7781, 0.0025],
        [31.0625, -14.5000, -46.1148, 55.3750],
        [-7.2312, 0.4050, 13.3500, 0.6234],
        [1.5000, -0.6426, 1.8564, 0.5636],
    ],
];

/// Perez et al. (1990) diffuse luminous efficacy, a + b·W + c·cos Z + d·ln Δ.
const DIFFUSE_EFFICACY: [[f64; 4]; 8] = [
    [97.24, -0.46, 12.00, -8.91],
    [107.22, 1.15, 0.59, -3.95],
    [104.97, 2.96, -5.53, -8.77],
    [102.39, 5.59, -13.95, -13.90],
    [100.71, 5.94, -22.75, -23.74],
    [106.42, 3.83, -36.15, -28.83],
    [141.88, 1.90, -53.24, -14.03],
    [152.23, 0.35, -45.27, -7.98],
];

/// Perez et al. (1990) direct luminous efficacy, a + b·W + c·exp(5.73·Z − 5) + d·Δ.
const DIRECT_EFFICACY: [[f64; 4]; 8] = [
    [57.20, -4.55, -2.98, 117.12],
    [98.99, -3.46, -1.21, 12.38],
    [109.83, -4.90, -1.71, -8.81],
    [110.34, -5.84, -1.99, -4.56],
    [106.36, -3.97, -1.75, -6.16],
    [107.19, -1.25, -1.51, -26.73],
    [105.75, 0.77, -1.26, -34.44],
    [101.18, 1.58, -1.10, -8.29],
];

/// What the sky is given: irradiances (W/m²) or illuminances (lux).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Input {
    /// Radiometric, as `gendaylit -W`.
    Irradiance {
        /// Direct normal irradiance, W/m².
        direct_normal: f64,
        /// Diffuse horizontal irradiance, W/m².
        diffuse_horizontal: f64,
    },
    /// Photometric, as `gendaylit -L`.
    Illuminance {
        /// Direct normal illuminance, lux.
        direct_normal: f64,
        /// Diffuse horizontal illuminance, lux.
        diffuse_horizontal: f64,
    },
}

/// perezlum.cal's arguments.
#[derive(Debug, Clone, PartialEq)]
pub struct Perez {
    normalisation: f64,
    coefficients: [f64; 5],
    sun: DVec3,
}

/// What [`compute`] makes of a Perez sky for one sun position.
pub struct Computed {
    /// The sky function, normalised to the diffuse light.
    pub distribution: Perez,
    /// Sky clearness ε, held to [1, 12]: 1 is overcast, above 6 clear.
    pub clearness: f64,
    /// Sky brightness Δ, held to [0.01, 0.6].
    pub brightness: f64,
    /// Sky radiance at the zenith, W/sr/m².
    pub zenith_radiance: f64,
    /// Diffuse horizontal irradiance (W/m², 179 lm/W) the sky was normalised to.
    pub diffuse_horizontal: f64,
    /// Radiance of the ground glow below the horizon, W/sr/m².
    pub ground_radiance: f64,
    /// The sun as a source; `None` when ε is 1 (an overcast sky) or the sun is
    /// down.
    pub sun: Option<SunSource>,
    /// The Perez parameter b when it came out positive, a luminance that
    /// grows without bound toward the horizon (a sun within a few degrees
    /// of it, some ε and Δ): gendaylit then prints its "error sky", all
    /// dark with no sun, and so is this one.
    pub positive_b: Option<f64>,
}

fn bin(clearness: f64) -> usize {
    BIN_BOUNDS.iter().position(|&upper| clearness < upper).unwrap_or(7)
}

/// Kasten's relative air mass for a zenith angle in degrees.
fn air_mass(zenith: f64) -> f64 {
    1.0 / (zenith.to_radians().cos() + 0.15 * (93.885 - zenith).powf(-1.253))
}

/// Sun–Earth distance factor for a day of the year.
fn eccentricity(day_of_year: f64) -> f64 {
    let g = 2.0 * PI * (day_of_year - 1.0) / 365.0;
    1.00011 + 0.034221 * g.cos() + 0.00128 * g.sin() + 0.000719 * (2.0 * g).cos() + 0.000077 * (2.0 * g).sin()
}

struct Indices {
    clearness: f64,
    brightness: f64,
}

fn indices(direct: f64, diffuse: f64, zenith: f64, day_of_year: f64) -> Indices {
    let z3 = zenith.to_radians().powi(3);
    Indices {
        clearness: ((diffuse + direct) / diffuse + 1.041 * z3) / (1.0 + 1.041 * z3),
        brightness: diffuse * air_mass(zenith) / (SOLAR_CONSTANT * eccentricity(day_of_year)),
    }
}

fn diffuse_efficacy(i: &Indices, zenith: f64) -> f64 {
    let [a, b, c, d] = DIFFUSE_EFFICACY[bin(i.clearness)];
    a + b * PRECIPITABLE_WATER + c * zenith.to_radians().cos() + d * i.brightness.ln()
}

fn direct_efficacy(i: &Indices, zenith: f64) -> f64 {
    let [a, b, c, d] = DIRECT_EFFICACY[bin(i.clearness)];
    (a + b * PRECIPITABLE_WATER + c * (5.73 * zenith.to_radians() - 5.0).exp() + d * i.brightness).max(0.0)
}

/// The five coefficients a..e for a sun zenith angle (radians).
fn coefficients(zenith: f64, clearness: f64, brightness: f64) -> [f64; 5] {
    let delta = if clearness > 1.065 && clearness < 2.8 { brightness.max(0.2) } else { brightness };
    let row = bin(clearness);
    // gendaylit keeps this table in single precision; so do we, to print its numbers.
    let x = COEFFICIENTS[row].map(|c| c.map(|v| f64::from(v as f32)));
    let linear = |k: usize| x[k][0] + x[k][1] * zenith + delta * (x[k][2] + x[k][3] * zenith);
    if row == 0 {
        [
            linear(0),
            linear(1),
            (delta * (x[2][0] + x[2][1] * zenith)).powf(x[2][2]).exp() - x[2][3],
            -(delta * (x[3][0] + x[3][1] * zenith)).exp() + x[3][2] + delta * x[3][3],
            linear(4),
        ]
    } else {
        [linear(0), linear(1), linear(2), linear(3), linear(4)]
    }
}

/// Relative luminance for a point at zenith angle `dzeta` and angle `gamma`
/// from the sun (radians).
fn relative_luminance(c: &[f64; 5], cos_dzeta: f64, gamma: f64) -> f64 {
    gradation(c, cos_dzeta) * indicatrix(c, gamma, gamma.cos())
}

/// The relative luminance's factor of the zenith angle alone (Perez's
/// gradation, 1 + a·exp(b / cos ζ)).
fn gradation(c: &[f64; 5], cos_dzeta: f64) -> f64 {
    1.0 + c[0] * (c[1] / cos_dzeta).exp()
}

/// The relative luminance's factor of the angle to the sun alone (Perez's
/// indicatrix, 1 + c·exp(d·γ) + e·cos²γ), the `exp` that a loop over
/// cells runs several lanes wide.
#[inline(always)]
fn indicatrix(c: &[f64; 5], gamma: f64, cos_gamma: f64) -> f64 {
    1.0 + c[2] * elementary::exp(c[3] * gamma) + c[4] * cos_gamma * cos_gamma
}

/// gendaylit's normalisation integral: Σ lv·cos θ · 2π/145 over its 145
/// directions (Tregenza patch centres, azimuths from the sun's).
fn gendaylit_integral(c: &[f64; 5], sun_zenith: f64) -> f64 {
    const BANDS: [(f64, usize); 8] = [(84.0, 30), (72.0, 30), (60.0, 24), (48.0, 24), (36.0, 18), (24.0, 12), (12.0, 6), (0.0, 1)];
    let mut sum = 0.0;
    for (theta_deg, count) in BANDS {
        let theta = theta_deg.to_radians();
        for k in 0..count {
            let phi = (360.0 * k as f64 / count as f64).to_radians();
            let cos_gamma = sun_zenith.cos() * theta.cos() + sun_zenith.sin() * theta.sin() * phi.cos();
            let gamma = if cos_gamma > 1.0 { 0.0 } else { cos_gamma.acos() };
            sum += relative_luminance(c, theta.cos(), gamma) * theta.cos();
        }
    }
    sum * 2.0 * PI / 145.0
}

/// `gendaylit -ang ALT AZ -W|-L …` for a day of the year (`-ang` alone
/// uses day 0). ε is held to gendaylit's range [1, 12] and Δ to [0.01, 0.6]:
/// the shape comes from the nearest valid Perez sky, the totals from the
/// given light.
pub fn compute(input: Input, altitude: f64, azimuth: f64, day_of_year: f64, ground_reflectance: f64) -> Computed {
    let clamped = altitude.min(MAX_ALTITUDE);
    let zenith = 90.0 - clamped;
    let sun = direction_from_angles(clamped, azimuth);
    let sz = clamped.to_radians().sin();
    let limit = |i: Indices| Indices { clearness: i.clearness.clamp(1.0, 12.0), brightness: i.brightness.clamp(0.01, 0.6) };
    let (idx, diffuse_lux, direct_lux) = match input {
        Input::Irradiance { direct_normal, diffuse_horizontal } => {
            let idx = limit(indices(direct_normal, diffuse_horizontal, zenith, day_of_year));
            let diffuse_lux = diffuse_horizontal * diffuse_efficacy(&idx, zenith);
            let direct_lux = direct_normal * direct_efficacy(&idx, zenith);
            (idx, diffuse_lux, direct_lux)
        }
        Input::Illuminance { direct_normal, diffuse_horizontal } => {
            // gendaylit's illu_to_irra_index: five rounds of efficacy and indices.
            let scale = SOLAR_CONSTANT / (SOLAR_CONSTANT_KLUX * 1000.0);
            let (mut diffuse, mut direct) = (diffuse_horizontal * scale, direct_normal * scale);
            let guard = |i: Indices| Indices {
                clearness: i.clearness.min(12.0),
                brightness: if i.brightness < 0.05 { 0.01 } else { i.brightness },
            };
            let mut idx = guard(indices(direct, diffuse, zenith, day_of_year));
            for _ in 0..5 {
                diffuse = diffuse_horizontal / diffuse_efficacy(&idx, zenith);
                direct = direct_normal / direct_efficacy(&idx, zenith).max(f64::MIN_POSITIVE);
                idx = guard(indices(direct, diffuse, zenith, day_of_year));
            }
            (limit(idx), diffuse_horizontal, direct_normal)
        }
    };
    let sun_zenith = zenith.to_radians();
    let c = coefficients(sun_zenith, idx.clearness, idx.brightness);
    if c[1] > 0.0 {
        return Computed {
            distribution: Perez { normalisation: 0.0, coefficients: [0.0; 5], sun },
            clearness: idx.clearness,
            brightness: idx.brightness,
            zenith_radiance: 0.0,
            diffuse_horizontal: 0.0,
            ground_radiance: 0.0,
            sun: None,
            positive_b: Some(c[1]),
        };
    }
    let normalisation = diffuse_lux / gendaylit_integral(&c, sun_zenith) / LUMINOUS_EFFICACY;
    let sun_solid_angle = 2.0 * PI * (1.0 - SUN_HALF_ANGLE.to_radians().cos());
    let solar = direct_lux / sun_solid_angle / LUMINOUS_EFFICACY;
    let zenith_radiance = relative_luminance(&c, 1.0, sun_zenith) * normalisation;
    let normfactor = if idx.clearness <= 1.0 {
        0.777778
    } else {
        let kind = if idx.clearness >= 6.0 { super::gensky::Kind::Clear } else { super::gensky::Kind::Intermediate };
        super::gensky::normfactor(kind, clamped.to_radians())
    };
    let has_sun = idx.clearness > 1.0 && sz > 0.0;
    let mut ground = zenith_radiance * normfactor;
    if has_sun {
        ground += 6.8e-5 / PI * solar * sz;
    }
    Computed {
        distribution: Perez { normalisation, coefficients: c, sun },
        clearness: idx.clearness,
        brightness: idx.brightness,
        zenith_radiance,
        diffuse_horizontal: diffuse_lux / LUMINOUS_EFFICACY,
        ground_radiance: ground * ground_reflectance,
        sun: has_sun.then(|| SunSource {
            direction: direction_from_angles(altitude, azimuth),
            solid_angle: sun_solid_angle,
            radiance: solar,
        }),
        positive_b: None,
    }
}

impl Perez {
    /// perezlum.cal's sky term (before the blend into the ground glow).
    pub fn sky(&self, d: DVec3) -> f64 {
        self.sky_with_gradation(d, self.gradation(d.z))
    }

    /// The sky term's factor of a direction's height `z` alone: directions
    /// of one height share it (a quadrature's row of cells), so it is
    /// computed once for them.
    pub fn gradation(&self, z: f64) -> f64 {
        gradation(&self.coefficients, z.max(0.01))
    }

    /// [`Self::sky`] with the direction's [`Self::gradation`] known.
    #[inline(always)]
    pub fn sky_with_gradation(&self, d: DVec3, gradation: f64) -> f64 {
        let cos_gamma = d.dot(self.sun).clamp(-1.0, 1.0);
        self.normalisation * (gradation * indicatrix(&self.coefficients, elementary::acos(cos_gamma), cos_gamma))
    }

    /// The sun direction the sky function uses (lowered to 87°).
    pub fn sun_for_sky(&self) -> DVec3 {
        self.sun
    }

    /// The skyfunc arguments gendaylit prints: normalisation and a..e.
    pub fn arguments(&self) -> (f64, [f64; 5]) {
        (self.normalisation, self.coefficients)
    }
}
