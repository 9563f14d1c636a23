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
//! summed. The result equals [`LightModel::solve`] up to the tolerance
//! ([`SensorCoefficients::readings`]).
//!
//! For a year of hours the sun's later bounces (the b-term) come from a
//! [`SunPath`]: traced once per node of a 2.5° grid of sun positions along
//! the site's sun path and read between nodes; the direct sun and its first
//! bounce are still traced every hour ([`SensorCoefficients::readings_on_path`]).
//!
//! Cost: Jacobi iterations over the form factors for 3 × sensors right-hand
//! sides (1 × sensors where every side is grey), a block of sensors at once
//! so memory stays bounded; the coefficients hold sensors × slots numbers,
//! and sensors × patch sides numbers for the sun where those fit (past
//! that the adjoints are solved again for the sun's light).

use std::io;
use std::path::Path;

use glam::DVec3;

use super::cache::{self, BlockWriter, Blocks, CacheOutcome, Reader, StableHash};
use super::daylight::{KeyRadiance, RadianceSlots};
use super::sun::SidesReach;
use super::{LightModel, SensorReading, SunBeam, luminous, par_map};
use crate::site::Site;
use crate::sky::{LUMINOUS_EFFICACY, Sky, SunSource};

/// Sensors whose adjoints are iterated together.
const BLOCK: usize = 32;

/// Bump when the coefficients or how they are stored change.
const FORMAT: u32 = 2;

/// A side passes its importance on to the sides it sees only where it is
/// above this share of the largest importance of the same sensor and
/// channel. Far from a sensor's room the importance falls by orders of
/// magnitude per bounce (out by a window, off a façade, in by another
/// window), yet the exact iteration spreads it over the building. Below a
/// millionth it changes no reading beyond rounding: on
/// AC20-Institute-Var-2 with one office's sensors a block's importance
/// reaches 11,724 of 86,872 sides (61,934 without it), the year's
/// sun is traced on those alone, a cold `annual` takes 17.3 s (33.7 s) and
/// its hourly values move by 0.016% at the 99th percentile (one lux of
/// rounding at most).
const IMPORTANCE_FLOOR: f32 = 1e-6;

/// The most coefficients kept in the light cache, bytes: past it (a grid of
/// tens of thousands of sensors) they are solved each run instead.
const MAX_CACHED_BYTES: usize = 256 << 20;
/// The most bytes the sun's later-bounce coefficients are held in, a number
/// per sensor and patch side: past it (a whole building's grids) the sun's
/// light is folded through the adjoints solved again instead
/// ([`SensorCoefficients::add_later_bounces`]), for what the sun lights
/// then, and memory follows the sensors, not sensors × sides (Revit's
/// Office_A, 10,244 sensors and 242,154 sides: 9.9 GB).
const MAX_SUN_ROW_BYTES: usize = 512 << 20;
/// Coefficients per block of their cache file (4 MB).
const VALUES_PER_BLOCK: usize = 1 << 20;

/// Each sensor's interreflected light per unit of every source, for one
/// model. They hold for the model they were made from and for any that
/// differs from it only in panel models ([`LightModel::set_panel_model`]:
/// panels change what the sky and sun send through the windows, not how
/// the room passes it on), which is what sweeps of panel keys rely on, as
/// long as the panels reflect the room's light back as before
/// ([`LightModel::panel_back_reflectance`]).
pub struct SensorCoefficients {
    pub(super) sensors: usize,
    pub(super) slots: RadianceSlots,
    /// Interreflected lux per unit radiance (W/m²/sr) of each slot, `[slot][sensor]`.
    pub(super) sky: Vec<f32>,
    /// Interreflected lux per W/m² of sun beams on each side, beyond the
    /// first bounce, `[side][sensor]`; `None` past [`MAX_SUN_ROW_BYTES`].
    sun: Option<Vec<f32>>,
    /// Per side, the largest of its sun coefficients: the most a W/m² of
    /// sun on it changes any sensor's later bounces.
    importance: Vec<f64>,
    /// Sides some sensor sees, directly or by interreflection: the sun
    /// elsewhere (on a roof, say) changes no reading and is not traced.
    seen: Vec<bool>,
    /// Jacobi iterations of the slowest block.
    pub iterations: usize,
}

impl LightModel {
    /// Solves every sensor's adjoint and folds it into coefficients (the
    /// sun's later bounces only where they fit, [`MAX_SUN_ROW_BYTES`]).
    pub fn sensor_coefficients(&self) -> SensorCoefficients {
        self.solve_coefficients(self.holds_sun_rows())
    }

    /// [`Self::sensor_coefficients`], with the sun's rows held or not.
    fn solve_coefficients(&self, sun_rows: bool) -> SensorCoefficients {
        let sensors = self.sensors.len();
        let sides = self.side_gathers.len();
        let slots = self.radiance_slots();
        let mut sky = vec![0.0f32; slots.len() * sensors];
        let mut sun = sun_rows.then(|| vec![0.0f32; sides * sensors]);
        let mut importance = vec![0.0f64; sides];
        let mut seen = vec![false; sides];
        let iterations = self.adjoint_blocks(|block, weights| {
            let (first, width) = (block.start, block.len());
            for side in 0..sides {
                let row = &weights[side * width..(side + 1) * width];
                let gather = &self.side_gathers[side];
                for (k, &(u, beam)) in row.iter().enumerate() {
                    let coefficient = sun_coefficient(beam);
                    importance[side] = importance[side].max(f64::from(coefficient));
                    if let Some(sun) = &mut sun {
                        sun[side * sensors + first + k] = coefficient;
                    }
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
        });
        SensorCoefficients { sensors, slots, sky, sun, importance, seen, iterations }
    }

    /// Solves the sensors' adjoints [`BLOCK`] sensors at a time, handing
    /// each block's weights ([`Self::adjoint_block`]) to `each`; the most
    /// iterations a block took.
    fn adjoint_blocks(&self, mut each: impl FnMut(std::ops::Range<usize>, &[(f64, f64)])) -> usize {
        let sides = self.side_gathers.len();
        let reflectance: Vec<[f32; 3]> = (0..sides).map(|side| self.side_reflectance(side).unwrap_or_default().map(|r| r as f32)).collect();
        let transposed = self.transposed_form_factors();
        // Grey sides pass every colour on alike: one channel stands for three.
        let channels = if reflectance.iter().all(|[r, g, b]| r == g && g == b) { 1 } else { 3 };
        let mut iterations = 0;
        for first in (0..self.sensors.len()).step_by(BLOCK) {
            let block = first..(first + BLOCK).min(self.sensors.len());
            let (weights, n) = self.adjoint_block(block.clone(), &transposed, &reflectance, channels);
            iterations = iterations.max(n);
            each(block, &weights);
        }
        iterations
    }

    /// How many of the sensors' rays land on each side: where the sun's
    /// first bounce is traced, hour by hour.
    pub(super) fn landings_on_sides(&self) -> &[u32] {
        self.landings_on_sides.get_or_init(|| {
            let mut landed = vec![0; self.side_gathers.len()];
            for (side, shares, _) in self.sensors.iter().flat_map(|sensor| sensor.landings.by_side()) {
                landed[side as usize] += shares.len() as u32;
            }
            landed
        })
    }

    /// [`Self::sensor_coefficients`] through the light cache in `dir`:
    /// read when it holds them for this model, else solved and stored
    /// (not past [`MAX_CACHED_BYTES`]). What they depend on beyond the
    /// gathers is every patch side's reflectance, so a model whose panels
    /// were swapped ([`Self::set_panel_model`]) finds its own.
    pub fn sensor_coefficients_cached(&self, dir: &Path) -> (SensorCoefficients, CacheOutcome) {
        let sides = self.side_gathers.len();
        if self.coefficient_bytes() > MAX_CACHED_BYTES || !self.holds_sun_rows() {
            return (self.sensor_coefficients(), CacheOutcome::Skipped("too large to keep".into()));
        }
        let mut hash = StableHash::new();
        hash.u64(self.cache_key()).u64(u64::from(FORMAT));
        for side in 0..sides {
            match self.side_reflectance(side) {
                Some(rho) => rho.iter().fold(hash.u64(1), |h, r| h.f64(*r)),
                None => hash.u64(0),
            };
        }
        let key = hash.finish();
        let stored = cache::through_cache(
            Some(dir),
            &format!("{key:016x}-coefficients"),
            key,
            |blocks| SensorCoefficients::load(self, blocks),
            || Ok(self.sensor_coefficients()),
            SensorCoefficients::save,
        );
        stored.unwrap_or_else(|why| (self.sensor_coefficients(), CacheOutcome::Skipped(why)))
    }

    /// The bytes [`Self::sensor_coefficients`] holds: a number per sensor
    /// and radiance slot, and per sensor and patch side where those fit
    /// ([`MAX_SUN_ROW_BYTES`]).
    pub fn coefficient_bytes(&self) -> usize {
        let sun = if self.holds_sun_rows() { self.sun_row_bytes() } else { 0 };
        self.radiance_slots().len() * self.sensors.len() * size_of::<f32>() + sun
    }

    /// The bytes of the sun's later-bounce coefficients, a number per
    /// sensor and patch side.
    fn sun_row_bytes(&self) -> usize {
        self.side_gathers.len() * self.sensors.len() * size_of::<f32>()
    }

    /// Whether the sun's later-bounce coefficients are held
    /// ([`MAX_SUN_ROW_BYTES`]), not solved again for each batch of suns.
    fn holds_sun_rows(&self) -> bool {
        self.sun_row_bytes() <= MAX_SUN_ROW_BYTES
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
    /// iterations taken. With `channels` 1 (every side grey) the one
    /// channel iterated is each of the three's, number for number: the
    /// same weights, bit for bit, in a third of the work (a model from
    /// `tools/ifc_to_obj.py` is grey: a reflectance from each colour).
    fn adjoint_block(
        &self,
        block: std::ops::Range<usize>,
        columns: &[Vec<(u32, f32)>],
        reflectance: &[[f32; 3]],
        channels: usize,
    ) -> (Vec<(f64, f64)>, usize) {
        let sides = columns.len();
        let width = channels * block.len();
        // ρ g per side and right-hand side (sensor × channel): the source.
        let mut source = vec![0.0f32; sides * width];
        for (k, sensor) in block.clone().enumerate() {
            for &(j, f) in &self.sensors[sensor].gather.form_factors {
                for c in 0..channels {
                    source[j as usize * width + channels * k + c] = f * reflectance[j as usize][c];
                }
            }
        }
        let tolerance = 0.1 * self.settings.tolerance as f32;
        let mut u = source.clone();
        let mut iterations = 0;
        // Only rows that a passing side gathers into (and the sources) can
        // change; every other row is 0. `live`: the rows that may not be.
        let sourced: Vec<u32> = (0..sides as u32).filter(|&j| row_of(&source, j, width).iter().any(|&x| x != 0.0)).collect();
        let mut live = sourced.clone();
        let mut passing = importance_passed_on(&u, width, &live);
        loop {
            let mut target = vec![false; sides];
            sourced.iter().for_each(|&j| target[j as usize] = true);
            for &i in live.iter().filter(|&&i| passing[i as usize]) {
                self.side_gathers[i as usize].form_factors.iter().for_each(|&(j, _)| target[j as usize] = true);
            }
            let rows: Vec<u32> = (0..sides as u32).filter(|&j| target[j as usize]).collect();
            let rows_per_task = rows.len().div_ceil(64).max(1);
            let next: Vec<f32> = par_map(self.settings.threads, rows.len().div_ceil(rows_per_task), |task| {
                let rows = &rows[task * rows_per_task..((task + 1) * rows_per_task).min(rows.len())];
                let mut out = Vec::with_capacity(rows.len() * width);
                let mut gathered = vec![0.0f32; width];
                for &j in rows {
                    gathered.fill(0.0);
                    for &(i, f) in columns[j as usize].iter().filter(|&&(i, _)| passing[i as usize]) {
                        for (g, &x) in gathered.iter_mut().zip(row_of(&u, i, width)) {
                            *g += f * x;
                        }
                    }
                    let row = row_of(&source, j, width).iter().zip(&gathered).enumerate();
                    out.extend(row.map(|(r, (o, g))| o + reflectance[j as usize][r % channels] * g));
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
            for &j in live.iter().filter(|&&j| !target[j as usize]) {
                let old = &mut u[j as usize * width..(j as usize + 1) * width];
                old.iter().zip(&mut change).for_each(|(b, c)| *c = c.max(b.abs()));
                old.fill(0.0);
            }
            for (&j, new) in rows.iter().zip(next.chunks_exact(width)) {
                let old = &mut u[j as usize * width..(j as usize + 1) * width];
                for (k, (a, b)) in new.iter().zip(old.iter_mut()).enumerate() {
                    change[k] = change[k].max((a - *b).abs());
                    size[k] = size[k].max(a.abs());
                    *b = *a;
                }
            }
            live = rows;
            passing = importance_passed_on(&u, width, &live);
            if change.iter().zip(&size).all(|(c, s)| *c <= tolerance * s) || iterations >= self.settings.max_iterations {
                break;
            }
        }
        let weights = (0..sides)
            .flat_map(|j| {
                let (u, source) = (&u[j * width..(j + 1) * width], &source[j * width..(j + 1) * width]);
                (0..block.len()).map(move |k| {
                    let channel = |v: &[f32]| [0, 1, 2].map(|c| f64::from(v[channels * k + c.min(channels - 1)]));
                    (luminous(channel(u)), luminous(channel(u)) - luminous(channel(source)))
                })
            })
            .collect();
        (weights, iterations)
    }
}

/// Row `j` of `values` (rows of `width`).
fn row_of(values: &[f32], j: u32, width: usize) -> &[f32] {
    &values[j as usize * width..(j as usize + 1) * width]
}

/// Per side, whether its importance `u` (rows of `width` right-hand sides,
/// zero but on the rows `live`) is passed on: above [`IMPORTANCE_FLOOR`]
/// of its column's largest for some right-hand side.
fn importance_passed_on(u: &[f32], width: usize, live: &[u32]) -> Vec<bool> {
    let mut largest = vec![0.0f32; width];
    for &j in live {
        largest.iter_mut().zip(row_of(u, j, width)).for_each(|(l, x)| *l = l.max(x.abs()));
    }
    let floor: Vec<f32> = largest.iter().map(|l| IMPORTANCE_FLOOR * l).collect();
    let mut passing = vec![false; u.len() / width.max(1)];
    for &j in live {
        passing[j as usize] = row_of(u, j, width).iter().zip(&floor).any(|(x, f)| x.abs() > *f);
    }
    passing
}

/// The sun's light at every sensor per W/m² of direct normal irradiance,
/// for one sun direction: what an hour's sun scales (the light is linear in
/// it), so a year of hours can keep one response per sun position.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SunResponse {
    /// Straight from the sun and its panel lobes, lux per W/m².
    pub direct: Vec<f32>,
    /// Interreflected: the first bounce traced where the sensors' rays
    /// land, the later bounces read from a [`SunPath`]; lux per W/m².
    pub interreflected: Vec<f32>,
}

/// The sun's light at every sensor, lux: straight (beams and lobes, not
/// what panels diffuse) and interreflected.
pub(super) struct SunLux {
    pub(super) direct: Vec<f64>,
    pub(super) interreflected: Vec<f64>,
}

impl SunLux {
    /// `response` (per W/m² of direct normal irradiance) scaled by `sky`'s
    /// sun, for `count` sensors; 0 with the sun down or no response.
    pub(super) fn scaled(response: Option<&SunResponse>, sky: &Sky, count: usize) -> Self {
        let normal_irradiance = sky.sun_up().map_or(0.0, |s| s.normal_irradiance());
        let scaled = |per_unit: Option<&Vec<f32>>| match per_unit {
            Some(values) if normal_irradiance > 0.0 => values.iter().map(|&v| normal_irradiance * f64::from(v)).collect(),
            _ => vec![0.0; count],
        };
        Self { direct: scaled(response.map(|r| &r.direct)), interreflected: scaled(response.map(|r| &r.interreflected)) }
    }
}

impl SensorCoefficients {
    /// Stores the coefficients in the light cache.
    fn save(&self, out: &mut BlockWriter) -> io::Result<()> {
        out.block(|w| {
            w.u32(self.sensors as u32);
            w.u32(self.iterations as u32);
        })?;
        // Only coefficients with their sun rows are kept (`sensor_coefficients_cached`).
        for values in [&self.sky[..], self.sun.as_deref().unwrap_or_default()] {
            out.items(values, VALUES_PER_BLOCK, |w, &v| w.f32(v))?;
        }
        out.items(&self.seen, VALUES_PER_BLOCK, |w, &seen| w.u32(u32::from(seen)))
    }

    /// Coefficients read back from the light cache; `None` when they do not
    /// fit `model`.
    fn load(model: &LightModel, blocks: &mut Blocks) -> Option<Self> {
        let (sensors, sides, slots) = (model.sensors.len(), model.side_gathers.len(), model.radiance_slots());
        let head = blocks.next()?;
        let mut r = Reader(&head);
        if r.u32()? as usize != sensors {
            return None;
        }
        let iterations = r.u32()? as usize;
        let sky = blocks.items(slots.len() * sensors, |r| r.f32())?;
        let sun = blocks.items(sides * sensors, |r| r.f32())?;
        let seen = blocks.items(sides, |r| r.u32().map(|v| v != 0))?;
        let row = |side: usize| &sun[side * sensors..(side + 1) * sensors];
        let importance = (0..sides).map(|side| row(side).iter().map(|&c| f64::from(c)).fold(0.0, f64::max)).collect();
        r.is_empty().then_some(Self { sensors, slots, sky, sun: Some(sun), importance, seen, iterations })
    }

    /// Every sensor's reading under `sky` (`threads` as [`par_map`]): equal
    /// to [`LightModel::solve`]'s up to its tolerance.
    pub fn readings(&self, model: &LightModel, sky: &Sky, threads: Option<usize>) -> Vec<SensorReading> {
        let beams = sky.sun_up().map(|s| model.sun_beams(&s)).unwrap_or_default();
        let measured = model.measured_sun(&beams);
        let direct_sun = model.sensors_sun(&beams, &measured);
        let direct = par_map(threads, model.sensors.len(), |i| model.sensor_direct_sun(i, &direct_sun) * LUMINOUS_EFFICACY);
        let sun = SunLux { direct, interreflected: self.interreflected_sun(model, &beams, threads) };
        self.read(model, model.key_radiance(sky), sun, threads)
    }

    /// [`Self::readings`] with the sun's light beyond its first bounce read
    /// from a [`SunPath`] instead of traced; the direct sun and its first
    /// bounce where the sensors' rays land are still traced.
    pub fn readings_on_path(&self, model: &LightModel, sky: &Sky, path: &SunPath, threads: Option<usize>) -> Vec<SensorReading> {
        let response = sky.sun_up().map(|s| self.sun_response(model, s.direction, path, threads));
        self.readings_with_sun(model, sky, response.as_ref(), threads)
    }

    /// The readings under `sky` with the sun's light from `response` (its
    /// sun's direction; `None` when the sun is down), scaled by the sky's
    /// sun: no ray is traced.
    pub fn readings_with_sun(
        &self,
        model: &LightModel,
        sky: &Sky,
        response: Option<&SunResponse>,
        threads: Option<usize>,
    ) -> Vec<SensorReading> {
        let sun = SunLux::scaled(response, sky, model.sensors.len());
        self.read(model, model.key_radiance(sky), sun, threads)
    }

    /// The sun's light at every sensor for a sun of 1 W/m² normal
    /// irradiance from `direction`: the beams and their first bounce traced,
    /// the later bounces from `path`.
    pub fn sun_response(&self, model: &LightModel, direction: DVec3, path: &SunPath, threads: Option<usize>) -> SunResponse {
        let beams = model.sun_beams(&SunSource::unit(direction));
        let reach = model.sides_reach(&beams, threads);
        let first = self.first_bounce(model, &beams, &reach, threads);
        let measured = model.measured_sun(&beams);
        let direct_sun = model.sensors_sun(&beams, &measured);
        let direct = par_map(threads, model.sensors.len(), |i| (model.sensor_direct_sun(i, &direct_sun) * LUMINOUS_EFFICACY) as f32);
        let interreflected = first.iter().zip(path.later_bounces(direction)).map(|(first, later)| (first + later) as f32).collect();
        SunResponse { direct, interreflected }
    }

    /// The readings with what the gather keys see (`seen`) and the sun's
    /// light at every sensor given.
    fn read(&self, model: &LightModel, seen: KeyRadiance, sun: SunLux, threads: Option<usize>) -> Vec<SensorReading> {
        let count = model.sensors.len();
        let mut indirect = sun.interreflected;
        let slot_radiance = seen.slots();
        debug_assert_eq!(slot_radiance.len(), self.slots.len());
        add_products(&mut indirect, slot_radiance.iter().zip(self.sky.chunks_exact(count.max(1))));
        par_map(threads, count, |i| {
            let geometry = &model.sensors[i];
            let direct_sun = seen.panel_sun_irradiance(&geometry.gather) * LUMINOUS_EFFICACY + sun.direct[i];
            let direct_sky = seen.sky_irradiance(&geometry.gather) * LUMINOUS_EFFICACY;
            SensorReading::new(model.scene.sensors[i].name.clone(), direct_sun, direct_sky, indirect[i])
        })
    }

    /// The beams' interreflected light at every sensor, lux: traced on the
    /// sides some sensor sees and where the sensors' rays land.
    fn interreflected_sun(&self, model: &LightModel, beams: &[SunBeam], threads: Option<usize>) -> Vec<f64> {
        let sides_sun = model.sun_on_sides(beams, &|side| if self.seen[side] { model.sun_samples(side) } else { 0 }, true, threads);
        let mut lux = [self.first_bounce(model, beams, &sides_sun.reach, threads)];
        self.add_later_bounces(model, &mut lux, &[lit_sides(&sides_sun.irradiance)]);
        let [lux] = lux;
        lux
    }

    /// The beams' first bounce where each sensor's rays land, lux.
    pub(super) fn first_bounce(&self, model: &LightModel, beams: &[SunBeam], reach: &SidesReach, threads: Option<usize>) -> Vec<f64> {
        par_map(threads, model.sensors.len(), |i| luminous(model.sensor_sun_bounce(i, beams, reach)) * LUMINOUS_EFFICACY)
    }

    /// Sun samples per side at the sun path's nodes (0: seen by no sensor),
    /// by importance: a side's importance is its largest later-bounce
    /// coefficient, the most a W/m² of sun on it changes any sensor. Sides
    /// at [`PATH_IMPORTANCE_SHARE`] of the most important side's or more
    /// get all `full` samples (what `sensors` traces everywhere); the
    /// others fewer in proportion, at least [`PATH_MIN_SAMPLES`]. A
    /// side's error is bounded by its importance, so the readings keep
    /// their accuracy while the nodes trace half the rays on the office
    /// (office hours against `sensors`: max 1.57% where all samples gave
    /// 1.66%).
    pub(super) fn path_sun_samples(&self, full: usize) -> Vec<usize> {
        let enough = PATH_IMPORTANCE_SHARE * self.importance.iter().copied().fold(0.0, f64::max);
        self.importance
            .iter()
            .zip(&self.seen)
            .map(|(&importance, &seen)| match seen {
                false => 0,
                true if importance >= enough => full,
                true => ((full as f64 * importance / enough).ceil() as usize).clamp(PATH_MIN_SAMPLES.min(full), full),
            })
            .collect()
    }

    /// Adds each source's light beyond its first bounce at every sensor to
    /// its sum, lux; a source is the beams' irradiance on the sides they
    /// light ([`lit_sides`]). With the sun rows held, their products; else
    /// the adjoints are solved again and each block's weights folded with
    /// every source at once, the same sums bit for bit: a year's sun path
    /// is one more solve, not a number per sensor and side.
    pub(super) fn add_later_bounces(&self, model: &LightModel, sums: &mut [Vec<f64>], sources: &[LitSides]) {
        if self.sensors == 0 {
            return;
        }
        let Some(rows) = &self.sun else {
            model.adjoint_blocks(|block, weights| {
                let width = block.len();
                let before: &[Vec<f64>] = sums;
                let parts = par_map(model.settings.threads, sources.len(), |s| {
                    let mut part = before[s][block.clone()].to_vec();
                    for &(side, irradiance) in &sources[s] {
                        let row = &weights[side as usize * width..(side as usize + 1) * width];
                        for (sum, &(_, beam)) in part.iter_mut().zip(row) {
                            *sum += irradiance * f64::from(sun_coefficient(beam));
                        }
                    }
                    part
                });
                for (sum, part) in sums.iter_mut().zip(parts) {
                    sum[block.clone()].copy_from_slice(&part);
                }
            });
            return;
        };
        for (sum, source) in sums.iter_mut().zip(sources) {
            let terms = source.iter().map(|(side, irradiance)| (irradiance, &rows[*side as usize * self.sensors..][..self.sensors]));
            add_products(sum, terms);
        }
    }
}

/// A sun coefficient as held: lux per W/m² of beams on a side, from its
/// adjoint's beam weight.
fn sun_coefficient(beam: f64) -> f32 {
    (beam * LUMINOUS_EFFICACY) as f32
}

/// The sides a sun lights and its beams' irradiance on each, W/m², in
/// order: a source of [`SensorCoefficients::add_later_bounces`].
pub(super) type LitSides = Vec<(u32, f64)>;

/// The sides `irradiance` (per side) lights, as [`LitSides`].
pub(super) fn lit_sides(irradiance: &[f64]) -> LitSides {
    irradiance.iter().enumerate().filter(|(_, e)| **e != 0.0).map(|(side, &e)| (side as u32, e)).collect()
}

/// `sum` += Σ source × row, over (source, row of coefficients per sensor).
///
/// A year reads every lit hour's sky through these products (4,610 rows
/// of the office's 150 sensors an hour, a third of a warm year): the loop
/// runs as wide as the CPU allows ([`crate::lanes`]), each lane the
/// scalar's own multiply and add, so the sums are the same bit for bit on
/// any x86-64.
pub(super) fn add_products<'r>(sum: &mut [f64], terms: impl Iterator<Item = (&'r f64, &'r [f32])>) {
    crate::lanes::widest(
        #[inline(always)]
        || terms.for_each(|(&source, row)| add_row(sum, source, row)),
    )
}

/// [`add_products`] into several sums at once, `sums[h] += Σ_slot
/// sources[h][slot] · rows[slot]` (`rows` of `width` values each): each row
/// is read once for every sum, and each sum is what [`add_products`] makes
/// of it alone, bit for bit (the same order over slots).
pub(super) fn add_products_together(sums: &mut [Vec<f64>], sources: &[Vec<f64>], rows: &[f32], width: usize) {
    crate::lanes::widest(
        #[inline(always)]
        || {
            for (slot, row) in rows.chunks_exact(width).enumerate() {
                for (sum, source) in sums.iter_mut().zip(sources) {
                    add_row(sum, source[slot], row);
                }
            }
        },
    )
}

/// `sum += source · row`, skipped for a dark source.
#[inline(always)]
fn add_row(sum: &mut [f64], source: f64, row: &[f32]) {
    if source != 0.0 {
        for (e, &c) in sum.iter_mut().zip(row) {
            *e += source * f64::from(c);
        }
    }
}

/// Sun coefficients: the sun's light beyond its first bounce at every
/// sensor, per W/m² of direct normal irradiance, traced once per node of a
/// grid of sun positions (declination × hour angle, so a year's sun path is
/// a band of it) and read between nodes bilinearly. Radiance's 5-phase
/// method does this with Reinhart sun positions; here the nodes follow the
/// sun's own path, and what is sharp is never interpolated: the direct sun
/// and its first bounce where each sensor's rays land are traced every
/// hour (a sun patch beside a sensor moves with the hour). A node samples
/// the sun on each side by the side's importance to the sensors
/// ([`SensorCoefficients::path_sun_samples`]).
pub struct SunPath {
    /// Sine and cosine of the site's latitude.
    latitude: (f64, f64),
    /// The site's `north_turn`, radians.
    north_turn: f64,
    /// Lux per sensor per W/m² at each node, by (declination, hour angle) index.
    nodes: std::collections::HashMap<(i32, i32), Vec<f64>>,
}

/// The grid's step in declination and hour angle, degrees.
pub const SUN_PATH_STEP: f64 = 2.5;

/// A side whose sun can change any sensor's later bounces by less than this
/// share of what the most telling side's can ([`SensorCoefficients::path_sun_samples`])
/// gets its sun samples at the nodes in proportion.
const PATH_IMPORTANCE_SHARE: f64 = 0.1;
/// The fewest sun samples a side some sensor sees gets at the nodes.
const PATH_MIN_SAMPLES: usize = 8;

impl SunPath {
    /// Traces the nodes around every sun direction in `suns` (directions in
    /// the model's frame, as the site's skies give them).
    pub fn new(model: &LightModel, coefficients: &SensorCoefficients, site: &Site, suns: &[DVec3], threads: Option<usize>) -> Self {
        let latitude = site.latitude.to_radians();
        let mut path = Self { latitude: latitude.sin_cos(), north_turn: site.north_turn.to_radians(), nodes: Default::default() };
        // Each node once, in order (a BTreeSet's order), so threads split the same work.
        let needed: Vec<(i32, i32)> =
            suns.iter().flat_map(|&sun| path.cell(sun).0).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        let samples = coefficients.path_sun_samples(model.settings.sun_samples_per_patch);
        let sources = par_map(threads, needed.len(), |k| {
            let beams = model.sun_beams(&SunSource::unit(path.direction(needed[k])));
            lit_sides(&model.sun_on_sides(&beams, &|side| samples[side], false, Some(1)).irradiance)
        });
        let mut values = vec![vec![0.0; model.sensors.len()]; needed.len()];
        coefficients.add_later_bounces(model, &mut values, &sources);
        path.nodes = needed.into_iter().zip(values).collect();
        path
    }

    /// The sun's light beyond its first bounce per W/m² of direct normal
    /// irradiance at each sensor, for a sun direction whose nodes were traced.
    pub fn later_bounces(&self, sun: DVec3) -> Vec<f64> {
        let (corners, weights) = self.cell(sun);
        let mut lux = vec![0.0; self.nodes.values().next().map_or(0, Vec::len)];
        for (corner, weight) in corners.iter().zip(weights) {
            let node = &self.nodes[corner];
            for (e, v) in lux.iter_mut().zip(node) {
                *e += weight * v;
            }
        }
        lux
    }

    /// The four nodes around a sun direction and their bilinear weights.
    fn cell(&self, sun: DVec3) -> ([(i32, i32); 4], [f64; 4]) {
        let (sin_lat, cos_lat) = self.latitude;
        let (s, c) = self.north_turn.sin_cos();
        // Back to true north, then to the equatorial frame.
        let (x, y, z) = (sun.x * c - sun.y * s, sun.y * c + sun.x * s, sun.z);
        let declination = (y * cos_lat + z * sin_lat).clamp(-1.0, 1.0).asin();
        let hour_angle = (-x).atan2(z * cos_lat - y * sin_lat);
        let step = SUN_PATH_STEP.to_radians();
        let (d, h) = (declination / step, hour_angle / step);
        let (d0, h0) = (d.floor(), h.floor());
        let (fd, fh) = (d - d0, h - h0);
        let (d0, h0) = (d0 as i32, h0 as i32);
        ([(d0, h0), (d0 + 1, h0), (d0, h0 + 1), (d0 + 1, h0 + 1)], [(1.0 - fd) * (1.0 - fh), fd * (1.0 - fh), (1.0 - fd) * fh, fd * fh])
    }

    /// A node's sun direction in the model's frame; below the horizon,
    /// lifted just above it (the light near sunrise is read between a node
    /// above and one below, and should not fade to the node's darkness).
    fn direction(&self, (d, h): (i32, i32)) -> DVec3 {
        let (sin_lat, cos_lat) = self.latitude;
        let step = SUN_PATH_STEP.to_radians();
        let (declination, hour_angle) = (f64::from(d) * step, f64::from(h) * step);
        let x = -declination.cos() * hour_angle.sin();
        let y = cos_lat * declination.sin() - sin_lat * declination.cos() * hour_angle.cos();
        let z = (sin_lat * declination.sin() + cos_lat * declination.cos() * hour_angle.cos()).max(MIN_SUN_HEIGHT);
        let (s, c) = self.north_turn.sin_cos();
        DVec3::new(x * c + y * s, y * c - x * s, z).normalize()
    }
}

/// The sine of the lowest altitude a node's sun is traced at.
const MIN_SUN_HEIGHT: f64 = 0.01;

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::light::LightSettings;
    use crate::panel::PanelCatalog;
    use crate::sky::SkySpec;
    use crate::time::LocalDateTime;

    /// On a grey room (the test room's floor, walls and ceiling) one
    /// channel iterated gives the three's weights bit for bit.
    #[test]
    fn a_grey_rooms_adjoints_take_one_channel_for_three() {
        let scene = crate::scene::load_scene(&crate::bundled_scene("test_room"), &PanelCatalog::new()).unwrap().scene;
        let model = LightModel::precompute(Arc::new(scene), LightSettings::default()).unwrap();
        let sides = model.side_gathers.len();
        let reflectance: Vec<[f32; 3]> =
            (0..sides).map(|side| model.side_reflectance(side).unwrap_or_default().map(|r| r as f32)).collect();
        assert!(reflectance.iter().all(|[r, g, b]| r == g && g == b) && reflectance.iter().any(|r| r[0] > 0.0));
        let transposed = model.transposed_form_factors();
        let block = 0..BLOCK.min(model.sensors.len());
        let (one, three) =
            (model.adjoint_block(block.clone(), &transposed, &reflectance, 1), model.adjoint_block(block, &transposed, &reflectance, 3));
        assert_eq!(one, three);
        assert!(one.0.iter().any(|&(u, beam)| u > 0.0 && beam > 0.0));
    }

    /// Past the memory they may take, the sun's later bounces are folded
    /// through the adjoints solved again: the readings under a clear sky
    /// and a sun path's nodes are those of the coefficients held, bit for
    /// bit, and the sun's later bounces are there to compare.
    #[test]
    fn folded_sun_coefficients_read_as_held_ones() {
        let scene = crate::scene::load_scene(&crate::bundled_scene("test_room"), &PanelCatalog::new()).unwrap().scene;
        let site = scene.site;
        let model = LightModel::precompute(Arc::new(scene), LightSettings::default()).unwrap();
        let (held, folded) = (model.solve_coefficients(true), model.solve_coefficients(false));
        assert!(held.sun.is_some() && folded.sun.is_none());
        assert_eq!((&held.sky, &held.importance, &held.seen), (&folded.sky, &folded.importance, &folded.seen));
        let when =
            LocalDateTime { date: crate::time::Date::new(2026, 3, 21).unwrap(), time: crate::time::TimeOfDay::from_hours(10.0).unwrap() };
        let sky = crate::sky::sky_at(&site, &SkySpec::Clear { turbidity: 2.45 }, &when).1.unwrap();
        let sun = sky.sun_up().expect("the sun is up").direction;
        let (a, b) = (held.readings(&model, &sky, None), folded.readings(&model, &sky, None));
        assert_eq!(a, b);
        let path = |coefficients| SunPath::new(&model, coefficients, &site, &[sun], None);
        let (a, b) = (path(&held), path(&folded));
        assert_eq!(a.nodes, b.nodes);
        let later = a.later_bounces(sun);
        assert!(later.iter().all(|&lux| lux > 0.0), "every sensor sees the sun's later bounces: {later:?}");
    }

    /// Sun directions map to (declination, hour angle) and back, on a turned
    /// site too; the bilinear weights sum to 1.
    #[test]
    fn the_sun_path_grid_maps_directions_both_ways() {
        for (latitude, turn) in [(42.36, 0.0), (-33.9, 25.0), (64.1, -140.0)] {
            let site = Site { north_turn: turn, ..Site::new(latitude, 0.0, 0.0) };
            let path = SunPath { latitude: site.latitude.to_radians().sin_cos(), north_turn: turn.to_radians(), nodes: Default::default() };
            for (altitude, azimuth) in [(10.0, 95.0), (45.0, 180.0), (70.0, 250.0), (3.0, 300.0)] {
                let sun = crate::sun::direction_from_angles(altitude, azimuth + turn);
                let (corners, weights) = path.cell(sun);
                assert!((weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                // Bilinear in (declination, hour angle): the corners' directions,
                // weighted, land near the sun (the grid is fine).
                let blended: DVec3 = corners.iter().zip(weights).map(|(&c, w)| path.direction(c) * w).sum();
                assert!(
                    blended.normalize().angle_between(sun).to_degrees() < 0.2,
                    "{latitude} {turn} {altitude} {azimuth}: {blended} vs {sun}"
                );
            }
        }
    }
}
