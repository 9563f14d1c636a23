//! Sky patches: Tregenza's 145 and Reinhart's MF:n subdivision (144·n² + 1),
//! laid out exactly as Radiance's reinhartb.cal (rows of 90/(7n + 0.5)°, a
//! polar cap half a row high; patch 0 centred on north at the horizon,
//! counting toward east). Each patch's radiance is its average over its solid
//! angle, by a fixed quadrature of equal-solid-angle cells; the sun is not in
//! the patches, it stays a source of its own ([`super::Sky::sun`]).

use std::ops::Range;

use glam::DVec3;

use super::{Sky, SkyCells};
use crate::sun::direction_from_angles;

/// Patches per Tregenza row, horizon first.
const TREGENZA_ROW: [u32; 7] = [30, 30, 24, 24, 18, 12, 6];
/// Largest quadrature cell side, degrees.
const MAX_CELL: f64 = 2.0;

/// One sky patch: altitudes and azimuths in degrees (azimuth clockwise from
/// north; a patch straddling north starts below 0).
#[derive(Debug, Clone, PartialEq)]
pub struct SkyPatch {
    /// Lower and upper altitude, degrees.
    pub altitude: (f64, f64),
    /// Start and end azimuth, degrees clockwise from north.
    pub azimuth: (f64, f64),
    /// Unit vector to the patch's centre.
    pub direction: DVec3,
    /// Steradians.
    pub solid_angle: f64,
    /// ∫ cos θ dω over the patch: its weight for horizontal irradiance.
    pub projected_solid_angle: f64,
}

/// A subdivision of the sky hemisphere and its quadrature.
#[derive(Debug, Clone)]
pub struct SkyPatches {
    /// Reinhart's MF (1 for Tregenza).
    pub subdivision: u32,
    /// In reinhartb.cal's order: rows from the horizon up, each from north
    /// toward east, the zenith cap last.
    pub patches: Vec<SkyPatch>,
    /// Quadrature directions above the horizon, and their mirrors below.
    samples: SkyCells,
    mirrored: SkyCells,
    /// Each patch's cells, in both.
    sample_ranges: Vec<Range<u32>>,
}

impl SkyPatches {
    /// Tregenza's 145 patches (Reinhart MF:1).
    pub fn tregenza() -> Self {
        Self::reinhart(1)
    }

    /// Reinhart MF:n (n ≥ 1).
    pub fn reinhart(n: u32) -> Self {
        let n = n.max(1);
        let row_height = 90.0 / (7.0 * f64::from(n) + 0.5);
        let mut patches = Vec::new();
        let mut samples = Vec::new();
        let mut sample_ranges = Vec::new();
        let rows = 7 * n;
        for row in 0..=rows {
            let (alt0, alt1) = (f64::from(row) * row_height, if row == rows { 90.0 } else { f64::from(row + 1) * row_height });
            let count = if row == rows { 1 } else { n * TREGENZA_ROW[(row / n) as usize] };
            let width = 360.0 / f64::from(count);
            let (s0, s1) = (alt0.to_radians().sin(), alt1.to_radians().sin());
            let cells_alt = ((alt1 - alt0) / MAX_CELL).ceil().max(1.0) as usize;
            let cells_az = ((width * alt0.to_radians().cos()) / MAX_CELL).ceil().max(1.0) as usize;
            for k in 0..count {
                let az0 = if row == rows { 0.0 } else { (f64::from(k) - 0.5) * width };
                let start = samples.len() as u32;
                for i in 0..cells_alt {
                    let s = s0 + (s1 - s0) * (i as f64 + 0.5) / cells_alt as f64;
                    let alt = s.asin().to_degrees();
                    for j in 0..cells_az {
                        samples.push(direction_from_angles(alt, az0 + width * (j as f64 + 0.5) / cells_az as f64));
                    }
                }
                sample_ranges.push(start..samples.len() as u32);
                let centre_alt = if row == rows { 90.0 } else { (alt0 + alt1) / 2.0 };
                patches.push(SkyPatch {
                    altitude: (alt0, alt1),
                    azimuth: (az0, az0 + width),
                    direction: direction_from_angles(centre_alt, az0 + width / 2.0),
                    solid_angle: width.to_radians() * (s1 - s0),
                    projected_solid_angle: width.to_radians() * (s1 * s1 - s0 * s0) / 2.0,
                });
            }
        }
        let mirrored = SkyCells::new(samples.iter().map(|d| DVec3::new(d.x, d.y, -d.z)));
        let samples = SkyCells::new(samples);
        Self { subdivision: n, patches, samples, mirrored, sample_ranges }
    }

    /// Number of patches: 144·n² + 1.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// Whether there are no patches: never, there is always the zenith cap.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The patch a direction falls in (reinhartb.cal's rbin), or `None` below
    /// the horizon.
    pub fn patch_of(&self, d: DVec3) -> Option<usize> {
        if d.z <= 0.0 {
            return None;
        }
        let n = self.subdivision;
        let row_height = 90.0 / (7.0 * f64::from(n) + 0.5);
        let altitude = d.z.clamp(-1.0, 1.0).asin().to_degrees();
        let row = ((altitude / row_height).floor() as u32).min(7 * n);
        let first: u32 = (0..row).map(|r| if r == 7 * n { 1 } else { n * TREGENZA_ROW[(r / n) as usize] }).sum();
        if row == 7 * n {
            return Some(first as usize);
        }
        let count = n * TREGENZA_ROW[(row / n) as usize];
        let width = 360.0 / f64::from(count);
        let azimuth = d.x.atan2(d.y).to_degrees().rem_euclid(360.0);
        let k = ((azimuth + 0.5 * width) / width).floor() as u32 % count;
        Some((first + k) as usize)
    }

    /// Each patch's mean radiance under `sky` (sun excluded), into `out`.
    pub fn integrate_into(&self, sky: &Sky, out: &mut Vec<f64>) {
        out.clear();
        self.extend_means(sky, &self.samples, out);
    }

    /// Appends each patch's mean of `sky` over its cells in `cells` (the
    /// samples or their mirrors below the horizon).
    fn extend_means(&self, sky: &Sky, cells: &SkyCells, out: &mut Vec<f64>) {
        let mut radiances = Vec::new();
        sky.radiances_into(cells, &mut radiances);
        out.extend(
            self.sample_ranges
                .iter()
                .map(|range| radiances[range.start as usize..range.end as usize].iter().sum::<f64>() / range.len() as f64),
        );
    }

    /// Each patch's mean radiance under `sky` (sun excluded).
    pub fn integrate(&self, sky: &Sky) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.len());
        self.integrate_into(sky, &mut out);
        out
    }

    /// The sphere's bin of a direction: sky patches first, then the same
    /// layout mirrored below the horizon for the ground glow (2 × len bins).
    pub fn sphere_bin(&self, d: DVec3) -> usize {
        let up = DVec3::new(d.x, d.y, d.z.abs().max(1e-12));
        let patch = self.patch_of(up).expect("direction above the horizon");
        if d.z > 0.0 { patch } else { self.len() + patch }
    }

    /// Mean radiance of every sphere bin ([`Self::sphere_bin`]) under `sky`, sun excluded.
    pub fn integrate_sphere_into(&self, sky: &Sky, out: &mut Vec<f64>) {
        out.clear();
        self.extend_means(sky, &self.samples, out);
        self.extend_means(sky, &self.mirrored, out);
    }

    /// Total solid angle: 2π up to rounding.
    pub fn total_solid_angle(&self) -> f64 {
        self.patches.iter().map(|p| p.solid_angle).sum()
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    #[test]
    fn counts_and_solid_angles() {
        for (n, count) in [(1, 145), (2, 577), (4, 2305)] {
            let patches = SkyPatches::reinhart(n);
            assert_eq!(patches.len(), count);
            assert!((patches.total_solid_angle() - 2.0 * PI).abs() < 1e-9);
            let projected: f64 = patches.patches.iter().map(|p| p.projected_solid_angle).sum();
            assert!((projected - PI).abs() < 1e-9);
        }
    }

    /// A Perez sky's radiance over the cells, its gradation computed once
    /// per height of cells and the cells evaluated several lanes wide, gives
    /// every sphere bin's mean bit for bit as evaluating each cell alone;
    /// the quadrature's cells lie in a few rows of one height.
    #[test]
    fn sphere_bins_are_the_means_of_each_cell_evaluated_alone() {
        let patches = SkyPatches::reinhart(4);
        assert!(patches.samples.height_count() + patches.mirrored.height_count() < 150);
        let input = crate::sky::perez::Input::Irradiance { direct_normal: 420.0, diffuse_horizontal: 180.0 };
        let perez = Sky::new(&crate::sky::SkySpec::Perez(input), 23.0, 131.0, 0.2, 172).unwrap();
        let clear = Sky::new(&crate::sky::SkySpec::Clear { turbidity: 2.45 }, 23.0, 131.0, 0.2, 172).unwrap();
        for sky in [perez, clear] {
            let mut bins = Vec::new();
            patches.integrate_sphere_into(&sky, &mut bins);
            let each_alone = |cells: &SkyCells| -> Vec<f64> {
                let radiances: Vec<f64> = cells.directions().map(|d| sky.radiance(d)).collect();
                let mean = |r: &Range<u32>| radiances[r.start as usize..r.end as usize].iter().sum::<f64>() / r.len() as f64;
                patches.sample_ranges.iter().map(mean).collect()
            };
            let alone: Vec<f64> = each_alone(&patches.samples).into_iter().chain(each_alone(&patches.mirrored)).collect();
            assert_eq!(bins.len(), 2 * patches.len());
            assert!(bins.iter().zip(&alone).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    #[test]
    fn every_patch_centre_bins_to_itself() {
        for n in [1, 2, 4] {
            let patches = SkyPatches::reinhart(n);
            for (i, p) in patches.patches.iter().enumerate() {
                assert_eq!(patches.patch_of(p.direction), Some(i), "MF:{n} patch {i}");
            }
        }
        // Patch 0 faces north at the horizon; patch 1 is east of it.
        let t = SkyPatches::tregenza();
        assert_eq!(t.patch_of(direction_from_angles(3.0, 2.0)), Some(0));
        assert_eq!(t.patch_of(direction_from_angles(3.0, 358.0)), Some(0));
        assert_eq!(t.patch_of(direction_from_angles(3.0, 12.0)), Some(1));
        assert_eq!(t.patch_of(direction_from_angles(89.0, 100.0)), Some(144));
        assert_eq!(t.patch_of(DVec3::NEG_Z), None);
    }
}
