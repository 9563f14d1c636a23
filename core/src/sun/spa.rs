//! NREL's Solar Position Algorithm (Reda & Andreas 2004, NREL/TP-560-34302),
//! in full: Earth heliocentric position from the periodic terms, nutation,
//! aberration, apparent sidereal time, parallax and atmospheric refraction.
//! Angles in degrees.

use super::spa_tables::*;

/// Where and when, in the paper's terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpaInput {
    /// Julian day (UT).
    pub julian_day: f64,
    /// TT − UT in seconds.
    pub delta_t: f64,
    /// North positive.
    pub latitude: f64,
    /// East positive.
    pub longitude: f64,
    /// Metres.
    pub elevation: f64,
    /// Millibars.
    pub pressure: f64,
    /// °C.
    pub temperature: f64,
    /// Refraction at sunrise and sunset (the paper's 0.5667°): below
    /// −(sun radius + this) no refraction is applied.
    pub atmospheric_refraction: f64,
}

/// The paper's outputs that heliodon uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpaOutput {
    /// Topocentric elevation without refraction (e0).
    pub elevation_geometric: f64,
    /// Topocentric elevation with refraction (e).
    pub elevation: f64,
    /// Topocentric azimuth, clockwise from north (Φ).
    pub azimuth: f64,
    /// Astronomers' azimuth, westward from south (Γ).
    pub azimuth_astronomical: f64,
    /// Topocentric local hour angle (H'), degrees in (−180, 180].
    pub hour_angle: f64,
    /// Topocentric declination (δ').
    pub declination: f64,
    /// Earth–Sun distance in AU.
    pub radius: f64,
    /// Equation of time in minutes.
    pub equation_of_time: f64,
}

fn series(terms: &[[f64; 3]], jme: f64) -> f64 {
    terms.iter().map(|[a, b, c]| a * (b + c * jme).cos()).sum()
}

/// Σ series_i · jmeⁱ / 10⁸ (radians).
fn periodic(tables: &[&[[f64; 3]]], jme: f64) -> f64 {
    let mut power = 1.0;
    let mut total = 0.0;
    for table in tables {
        total += series(table, jme) * power;
        power *= jme;
    }
    total / 1e8
}

fn polynomial(c: [f64; 4], t: f64) -> f64 {
    c[0] + t * (c[1] + t * c[2]) + t * t * t / c[3]
}

/// The sun's position seen from `input`'s site at its instant: the paper's
/// algorithm, ±0.0003° over the years −2000..6000.
pub fn spa(input: &SpaInput) -> SpaOutput {
    let jd = input.julian_day;
    let jc = (jd - 2_451_545.0) / 36_525.0;
    let jde = jd + input.delta_t / 86_400.0;
    let jce = (jde - 2_451_545.0) / 36_525.0;
    let jme = jce / 10.0;

    // Earth heliocentric longitude, latitude, radius (3.2).
    let l = periodic(&[&L0, &L1, &L2, &L3, &L4, &L5], jme).to_degrees().rem_euclid(360.0);
    let b = periodic(&[&B0, &B1], jme).to_degrees();
    let r = periodic(&[&R0, &R1, &R2, &R3, &R4], jme);
    // Geocentric (3.3).
    let theta = (l + 180.0).rem_euclid(360.0);
    let beta = -b;
    // Nutation (3.4): the fundamental arguments.
    let x = [
        polynomial([297.85036, 445_267.111_480, -0.001_914_2, 189_474.0], jce),
        polynomial([357.52772, 35_999.050_340, -0.000_160_3, -300_000.0], jce),
        polynomial([134.96298, 477_198.867_398, 0.008_697_2, 56_250.0], jce),
        polynomial([93.27191, 483_202.017_538, -0.003_682_5, 327_270.0], jce),
        polynomial([125.04452, -1_934.136_261, 0.002_070_8, 450_000.0], jce),
    ];
    let (mut delta_psi, mut delta_epsilon) = (0.0, 0.0);
    for (y, [a, b, c, d]) in NUTATION_Y.iter().zip(NUTATION_ABCD.iter()) {
        let argument: f64 = y.iter().zip(x.iter()).map(|(&yi, xi)| f64::from(yi) * xi).sum::<f64>().to_radians();
        delta_psi += (a + b * jce) * argument.sin();
        delta_epsilon += (c + d * jce) * argument.cos();
    }
    delta_psi /= 36_000_000.0;
    delta_epsilon /= 36_000_000.0;
    // True obliquity of the ecliptic (3.5).
    let u = jme / 10.0;
    let epsilon0 = [84_381.448, -4_680.93, -1.55, 1_999.25, -51.38, -249.67, -39.05, 7.12, 27.87, 5.79, 2.45]
        .iter()
        .rev()
        .fold(0.0, |acc, c| acc * u + c);
    let epsilon = epsilon0 / 3600.0 + delta_epsilon;
    // Aberration, apparent sun longitude (3.6, 3.7).
    let delta_tau = -20.4898 / (3600.0 * r);
    let lambda = theta + delta_psi + delta_tau;
    // Apparent sidereal time at Greenwich (3.8).
    let nu0 = (280.460_618_37 + 360.985_647_366_29 * (jd - 2_451_545.0) + 0.000_387_933 * jc * jc - jc * jc * jc / 38_710_000.0)
        .rem_euclid(360.0);
    let nu = nu0 + delta_psi * epsilon.to_radians().cos();
    // Geocentric right ascension and declination (3.9, 3.10).
    let (lambda_r, epsilon_r, beta_r) = (lambda.to_radians(), epsilon.to_radians(), beta.to_radians());
    let alpha = (lambda_r.sin() * epsilon_r.cos() - beta_r.tan() * epsilon_r.sin()).atan2(lambda_r.cos()).to_degrees().rem_euclid(360.0);
    let delta = (beta_r.sin() * epsilon_r.cos() + beta_r.cos() * epsilon_r.sin() * lambda_r.sin()).asin();
    // Local hour angle (3.11).
    let h = (nu + input.longitude - alpha).rem_euclid(360.0).to_radians();
    // Parallax (3.12).
    let xi = (8.794 / (3600.0 * r)).to_radians();
    let phi = input.latitude.to_radians();
    let u = (0.996_647_19 * phi.tan()).atan();
    let x_term = u.cos() + input.elevation / 6_378_140.0 * phi.cos();
    let y_term = 0.996_647_19 * u.sin() + input.elevation / 6_378_140.0 * phi.sin();
    let delta_alpha = (-x_term * xi.sin() * h.sin()).atan2(delta.cos() - x_term * xi.sin() * h.cos());
    let delta_prime = ((delta.sin() - y_term * xi.sin()) * delta_alpha.cos()).atan2(delta.cos() - x_term * xi.sin() * h.cos());
    let h_prime = h - delta_alpha;
    // Topocentric elevation and refraction (3.13, 3.14).
    let e0 = (phi.sin() * delta_prime.sin() + phi.cos() * delta_prime.cos() * h_prime.cos()).asin().to_degrees();
    let refraction = if e0 >= -(0.26667 + input.atmospheric_refraction) {
        (input.pressure / 1010.0) * (283.0 / (273.0 + input.temperature)) * 1.02 / (60.0 * (e0 + 10.3 / (e0 + 5.11)).to_radians().tan())
    } else {
        0.0
    };
    let elevation = e0 + refraction;
    // Azimuth (3.15).
    let gamma = h_prime.sin().atan2(h_prime.cos() * phi.sin() - delta_prime.tan() * phi.cos()).to_degrees().rem_euclid(360.0);
    let azimuth = (gamma + 180.0).rem_euclid(360.0);
    // Equation of time (A.1).
    let mean_longitude = [280.466_456_7, 360_007.698_277_9, 0.030_320_28, 1.0 / 49_931.0, -1.0 / 15_300.0, -1.0 / 2_000_000.0]
        .iter()
        .rev()
        .fold(0.0, |acc, c| acc * jme + c);
    let mut eot = 4.0 * (mean_longitude - 0.005_718_3 - alpha + delta_psi * epsilon_r.cos()).rem_euclid(360.0);
    if eot > 20.0 {
        eot -= 1440.0;
    }
    let mut hour_angle = h_prime.to_degrees().rem_euclid(360.0);
    if hour_angle > 180.0 {
        hour_angle -= 360.0;
    }
    SpaOutput {
        elevation_geometric: e0,
        elevation,
        azimuth,
        azimuth_astronomical: gamma,
        hour_angle,
        declination: delta_prime.to_degrees(),
        radius: r,
        equation_of_time: eot,
    }
}

/// Incidence angle on a surface tilted `slope` degrees from horizontal whose
/// normal's horizontal projection is `rotation` degrees from south (west
/// positive), as in the paper's section 3.16.
pub fn incidence_angle(output: &SpaOutput, slope: f64, rotation: f64) -> f64 {
    let zenith = (90.0 - output.elevation).to_radians();
    let slope = slope.to_radians();
    (zenith.cos() * slope.cos() + slope.sin() * zenith.sin() * (output.azimuth_astronomical - rotation).to_radians().cos())
        .acos()
        .to_degrees()
}
