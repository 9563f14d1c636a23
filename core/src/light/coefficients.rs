//! Sensor daylight coefficients with the interreflection folded in: many
//! skies on one model (the annual study) without a radiosity solve each.
//!
//! A sensor's interreflected light is linear in the direct light of the
//! patch sides. The adjoint of the radiosity system, solved once per sensor
//! and colour channel,
//!
//! > u = ρ (g + Fᵀ u)   (g: the sensor's form factors to the sides,
//! > F: the sides' to each other, ρ: their reflectance),
//!
//! weighs every side's direct irradiance in the sensor's interreflected light:
//!
//! > E_ind = Σ_j u_j d_j + Σ_j (u_j − ρ_j g_j) b_j + bounce,
//!
//! with d the side's sky and panel-diffused sun, b its sun beams, and
//! `bounce` the beams' first reflection where the sensor's rays land (as
//! [`super::Relight`] takes it: the sensor sees the sun patch itself, not
//! its patches' averages). The sky part folds further into the sides'
//! daylight coefficients: one coefficient per sensor and radiance slot (a
//! sky or ground bin straight or through glass, a bin through a panel
//! group, a group's diffused sun). A sky then costs one dense product; the
//! sun is traced as a relight traces it, and only the sides it reaches are
//! summed. The result equals [`LightModel::solve`] up to the tolerance.
//!
//! Cost: Jacobi iterations over the form factors for 3 × sensors right-hand
//! sides at once (in blocks, so memory stays bounded); the coefficients
//! hold sensors × slots and sensors × patch sides numbers.

use super::daylight::RadianceSlots;
use super::{LightModel, SensorReading, Surface, luminous, par_map};
use crate::sky::{LUMINOUS_EFFICACY, Sky};

/// Sensors whose adjoints are iterated together.
const BLOCK: usize = 32;

/// Each sensor's interreflected light per unit of every source, for one model.
pub struct SensorCoefficients<'a> {
    model: &'a LightModel,
    slots: RadianceSlots,
    /// Interreflected lux per unit radiance (W/m²/sr) of each slot, `[slot][sensor]`.
    sky: Vec<f32>,
    /// Interreflected lux per W/m² of sun beams on each side, beyond the
    /// first bounce, `[side][sensor]`.
    sun: Vec<f32>,
    /// Sides some sensor sees, directly or by interreflection: the sun
    /// elsewhere (on a roof, say) changes no reading and is not traced.
    seen: Vec<bool>,
    /// Jacobi iterations of the slowest block.
    pub iterations: usize,
}

impl LightModel {
    /// Solves every sensor's adjoint and folds it into coefficients.
    pub fn sensor_coefficients(&self) -> SensorCoefficients<'_> {
        let sensors = self.sensors.len();
        let sides = self.side_gathers.len();
        let slots = self.radiance_slots();
        let reflectance: Vec<[f32; 3]> = (0..sides)
            .map(|side| match self.surfaces[self.scene.patches.patches[side / 2].material as usize] {
                Surface::Diffuse(rho) => rho.map(|r| r as f32),
                _ => [0.0; 3],
            })
            .collect();
        let transposed = self.transposed_form_factors();
        let mut sky = vec![0.0f32; slots.len() * sensors];
        let mut sun = vec![0.0f32; sides * sensors];
        let mut seen = vec![false; sides];
        let mut iterations = 0;
        for first in (0..sensors).step_by(BLOCK) {
            let block = first..(first + BLOCK).min(sensors);
            let (weights, n) = self.adjoint_block(block.clone(), &transposed, &reflectance);
            iterations = iterations.max(n);
            let width = block.len();
            for side in 0..sides {
                let row = &weights[side * width..(side + 1) * width];
                let gather = &self.side_gathers[side];
                for (k, &(u, beam)) in row.iter().enumerate() {
                    sun[side * sensors + first + k] = (beam * LUMINOUS_EFFICACY) as f32;
                    if u == 0.0 {
                        continue;
                    }
                    seen[side] = true;
                    for &(key, w) in &gather.daylight_coefficients {
                        let c = (std::f64::consts::PI * f64::from(w) * u * LUMINOUS_EFFICACY) as f32;
                        let (slot, panel_sun) = slots.of(key);
                        sky[slot * sensors + first + k] += c;
                        if let Some(slot) = panel_sun {
                            sky[slot * sensors + first + k] += c;
                        }
                    }
                }
            }
        }
        SensorCoefficients { model: self, slots, sky, sun, seen, iterations }
    }

    /// Column lists of the form factors: for side j, every (i, F_ij).
    fn transposed_form_factors(&self) -> Vec<Vec<(u32, f32)>> {
        let mut columns: Vec<Vec<(u32, f32)>> = vec![Vec::new(); self.side_gathers.len()];
        for (i, gather) in self.side_gathers.iter().enumerate() {
            for &(j, f) in &gather.form_factors {
                columns[j as usize].push((i as u32, f));
            }
        }
        columns
    }

    /// The adjoints of `block`'s sensors, luminous: per side and sensor,
    /// (Σ_c w_c u_c, Σ_c w_c (u_c − ρ_c g)), `[side][sensor]`, and the
    /// iterations taken.
    fn adjoint_block(
        &self,
        block: std::ops::Range<usize>,
        columns: &[Vec<(u32, f32)>],
        reflectance: &[[f32; 3]],
    ) -> (Vec<(f64, f64)>, usize) {
        let sides = columns.len();
        let width = 3 * block.len();
        // ρ g per side and right-hand side (sensor × channel): the source.
        let mut source = vec![0.0f32; sides * width];
        for (k, sensor) in block.clone().enumerate() {
            for &(j, f) in &self.sensors[sensor].gather.form_factors {
                for c in 0..3 {
                    source[j as usize * width + 3 * k + c] = f * reflectance[j as usize][c];
                }
            }
        }
        let tolerance = 0.1 * self.settings.tolerance as f32;
        let mut u = source.clone();
        let mut iterations = 0;
        loop {
            let rows_per_task = sides.div_ceil(64).max(1);
            let next: Vec<f32> = par_map(self.settings.threads, sides.div_ceil(rows_per_task), |task| {
                let rows = task * rows_per_task..((task + 1) * rows_per_task).min(sides);
                let mut out = source[rows.start * width..rows.end * width].to_vec();
                let mut gathered = vec![0.0f32; width];
                for (local, j) in rows.enumerate() {
                    let row = &mut out[local * width..(local + 1) * width];
                    gathered.fill(0.0);
                    for &(i, f) in &columns[j] {
                        for (g, &x) in gathered.iter_mut().zip(&u[i as usize * width..(i as usize + 1) * width]) {
                            *g += f * x;
                        }
                    }
                    for (r, (o, g)) in row.iter_mut().zip(&gathered).enumerate() {
                        *o += reflectance[j][r % 3] * g;
                    }
                }
                out
            })
            .into_iter()
            .flatten()
            .collect();
            iterations += 1;
            // Converged when no right-hand side changed by more than the
            // tolerance of its largest weight.
            let mut change = vec![0.0f32; width];
            let mut size = vec![0.0f32; width];
            for (k, (a, b)) in next.iter().zip(&u).enumerate() {
                change[k % width] = change[k % width].max((a - b).abs());
                size[k % width] = size[k % width].max(a.abs());
            }
            u = next;
            if change.iter().zip(&size).all(|(c, s)| *c <= tolerance * s) || iterations >= self.settings.max_iterations {
                break;
            }
        }
        let weights = (0..sides)
            .flat_map(|j| {
                let (u, source) = (&u[j * width..(j + 1) * width], &source[j * width..(j + 1) * width]);
                (0..block.len()).map(move |k| {
                    let channel = |v: &[f32]| [0, 1, 2].map(|c| f64::from(v[3 * k + c]));
                    (luminous(channel(u)), luminous(channel(u)) - luminous(channel(source)))
                })
            })
            .collect();
        (weights, iterations)
    }
}

impl SensorCoefficients<'_> {
    /// Every sensor's reading under `sky` (`threads` as [`par_map`]): equal
    /// to [`LightModel::solve`]'s up to its tolerance.
    pub fn readings(&self, sky: &Sky, threads: Option<usize>) -> Vec<SensorReading> {
        let model = self.model;
        let count = model.sensors.len();
        let seen = model.key_radiance(sky);
        let beams = sky.sun.filter(|s| s.direction.z > 0.0).map(|s| model.sun_beams(&s)).unwrap_or_default();
        let sides_sun = model.sun_on_sides(&beams, Some(&self.seen), threads);
        let mut indirect = vec![0.0f64; count];
        let slot_radiance = seen.slots();
        debug_assert_eq!(slot_radiance.len(), self.slots.len());
        let sources = slot_radiance.iter().zip(self.sky.chunks_exact(count.max(1)));
        let beams_on_sides = sides_sun.irradiance.iter().zip(self.sun.chunks_exact(count.max(1)));
        for (&radiance, row) in sources.chain(beams_on_sides) {
            if radiance != 0.0 {
                for (e, &c) in indirect.iter_mut().zip(row) {
                    *e += radiance * f64::from(c);
                }
            }
        }
        par_map(threads, count, |i| {
            let geometry = &model.sensors[i];
            let (sun, bounce) = model.sensor_sun(i, &beams, &sides_sun.reach);
            let direct_sun = (seen.panel_sun_irradiance(&geometry.gather) + sun) * LUMINOUS_EFFICACY;
            let direct_sky = seen.sky_irradiance(&geometry.gather) * LUMINOUS_EFFICACY;
            let indirect = indirect[i] + luminous(bounce) * LUMINOUS_EFFICACY;
            SensorReading {
                name: model.scene.sensors[i].name.clone(),
                total: direct_sun + direct_sky + indirect,
                direct_sun,
                direct_sky,
                indirect,
            }
        })
    }
}
