//! The radiosity solver: the interreflected light of every patch side,
//! E_ind(i) = Σ_j F_ij ρ_j (E_direct(j) + E_ind(j)), by Jacobi iterations
//! over the sparse form factors F (rows of [`super::Gather`]), in RGB.
//!
//! - [`Interreflection`] is the solver alone: rows of form factors,
//!   reflectances and direct irradiance in, indirect irradiance out; tested
//!   here against closed forms.
//! - [`LightModel::relight`] computes the direct light of a sun and sky
//!   (sun by shadow rays, sky by daylight coefficients) and hands it to the
//!   solver; [`Relight`] steps it and reads sensors at any time.
//!
//! Every product of form factors and exitance, for patch sides and for
//! sensors alike, is [`form_factor_product`].

use super::{Channels, LightModel, Lighting, SensorReading, par_map};
use crate::sky::{LUMINOUS_EFFICACY, Sky};

/// `start` + Σ_j F_ij M_j over one sparse row of form factors: the
/// irradiance (RGB, or one channel standing for grey RGB) that receiver i
/// gets from sides leaving `exitance` M, added to what it already has.
pub fn form_factor_product<const N: usize>(start: [f64; N], row: &[(u32, f32)], exitance: &[[f64; N]]) -> [f64; N] {
    let mut sum = start;
    for &(j, f) in row {
        for (s, m) in sum.iter_mut().zip(exitance[j as usize]) {
            *s += f64::from(f) * m;
        }
    }
    sum
}

/// Jacobi iterations of E_ind = F ρ (E_direct + E_ind), alone: no geometry,
/// just sparse rows of form factors.
#[derive(Debug, Clone)]
pub struct Interreflection {
    /// Direct irradiance of each side (W/m²), the source of the interreflection.
    pub direct: Vec<f64>,
    /// Diffuse reflectance of each side, RGB.
    pub reflectance: Vec<[f64; 3]>,
    /// Interreflected irradiance of each side, RGB: the state.
    pub indirect: Vec<[f64; 3]>,
    /// Irradiance below which a side counts as dark (for relative convergence).
    floor: f64,
    /// Every side grey and the state too: the three channels are the same
    /// numbers through every step, and one is iterated for them.
    grey: bool,
    tolerance: f64,
    max_iterations: usize,
    /// Iterations done.
    pub iterations: usize,
    /// The last iteration's largest change of a side's indirect light,
    /// relative to its irradiance (infinite before the first).
    pub residual: f64,
    converged: bool,
}

impl Interreflection {
    /// Starts from `warm` (an earlier indirect solution of the same sides,
    /// scaled by the caller) or from darkness; stops when no side changes by
    /// more than `tolerance` of its own irradiance, or after `max_iterations`.
    pub fn new(direct: Vec<f64>, reflectance: Vec<[f64; 3]>, warm: Option<Vec<[f64; 3]>>, tolerance: f64, max_iterations: usize) -> Self {
        let mean = direct.iter().sum::<f64>() / direct.len().max(1) as f64;
        let indirect = warm.filter(|w| w.len() == direct.len()).unwrap_or_else(|| vec![[0.0; 3]; direct.len()]);
        let same = |[r, g, b]: &[f64; 3]| r == g && g == b;
        Self {
            floor: 1e-3 * mean.max(1e-12),
            grey: reflectance.iter().all(same) && indirect.iter().all(same),
            direct,
            reflectance,
            indirect,
            tolerance,
            max_iterations,
            iterations: 0,
            residual: f64::INFINITY,
            converged: false,
        }
    }

    /// Radiant exitance ρ (E + E_ind) of each side, RGB, with `irradiance(j)`
    /// as side j's direct part.
    pub fn exitance(&self, irradiance: impl Fn(usize) -> f64) -> Vec<[f64; 3]> {
        (0..self.direct.len()).map(|j| [0, 1, 2].map(|c| self.reflectance[j][c] * (irradiance(j) + self.indirect[j][c]))).collect()
    }

    /// One Jacobi iteration over the rows `row(i)` of form factors (`threads`
    /// as [`par_map`]). Returns whether the solution has converged (or the
    /// iteration budget is spent).
    pub fn step<'r>(&mut self, row: impl Fn(usize) -> &'r [(u32, f32)] + Sync, threads: Option<usize>) -> bool {
        if self.converged {
            return true;
        }
        let next: Vec<[f64; 3]> = if self.grey {
            // The first channel's products alone, in the same order: the same bits.
            let exitance: Vec<[f64; 1]> =
                (0..self.direct.len()).map(|j| [self.reflectance[j][0] * (self.direct[j] + self.indirect[j][0])]).collect();
            let next = par_map(threads, self.direct.len(), |i| form_factor_product([0.0], row(i), &exitance));
            next.into_iter().map(|[e]| [e; 3]).collect()
        } else {
            let exitance = self.exitance(|j| self.direct[j]);
            par_map(threads, self.direct.len(), |i| form_factor_product([0.0; 3], row(i), &exitance))
        };
        // The largest change relative to each side's own irradiance (dark
        // corners converge as well as sunlit floors).
        let change = next
            .iter()
            .zip(&self.indirect)
            .zip(&self.direct)
            .map(|((a, b), d)| {
                let level = (d + a.iter().copied().fold(0.0, f64::max)).max(self.floor);
                (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max) / level
            })
            .fold(0.0, f64::max);
        self.indirect = next;
        self.iterations += 1;
        self.residual = change;
        self.converged = change <= self.tolerance || self.iterations >= self.max_iterations;
        self.converged
    }

    /// Whether the iterations have converged or spent their budget.
    pub fn is_converged(&self) -> bool {
        self.converged
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct SensorDirect {
    sun: f64,
    sky: f64,
    /// RGB irradiance from the sun's first reflection off patches.
    sun_bounce: [f64; 3],
}

impl LightModel {
    /// The light for a sky (and its sun), iterated to convergence. `warm` is
    /// an earlier solution of the same model to start from.
    pub fn solve(&self, sky: &Sky, warm: Option<&Lighting>) -> Lighting {
        let mut relight = self.relight(sky, warm);
        while !relight.step() {}
        relight.lighting()
    }

    /// Starts relighting for a sky: the direct light (sun and sky on every
    /// patch side and sensor) is computed now; [`Relight::step`] then iterates
    /// the interreflection, and [`Relight::lighting`] reads the state at any time.
    pub fn relight(&self, sky: &Sky, warm: Option<&Lighting>) -> Relight<'_> {
        let patches = &self.scene.patches.patches;
        let sun = sky.sun_up();
        let seen = self.key_radiance(sky);
        let beams = sun.map(|s| self.sun_beams(&s)).unwrap_or_default();
        let sides_sun = self.sun_on_sides(&beams, &|side| self.sun_samples(side), true, self.settings.threads);
        let measured = self.measured_sun(&beams);
        let direct_sun = self.sensors_sun(&beams, &measured);
        let direct: Vec<Channels> = par_map(self.settings.threads, patches.len() * 2, |side| {
            let gather = &self.side_gathers[side];
            if self.side_reflectance(side).is_none() {
                return Channels::default();
            }
            let diffuse_sun = seen.panel_sun_irradiance(gather);
            Channels {
                sky: seen.sky_irradiance(gather),
                sun: diffuse_sun + sides_sun.irradiance[side],
                sun_diffuse: diffuse_sun,
                ..Default::default()
            }
        });
        let reflectance: Vec<[f64; 3]> = (0..patches.len() * 2).map(|side| self.side_reflectance(side).unwrap_or_default()).collect();
        // Each sensor's direct light and the first bounce of sun where its rays land.
        let sensors: Vec<SensorDirect> = par_map(self.settings.threads, self.sensors.len(), |i| {
            let geometry = &self.sensors[i];
            let sun = seen.panel_sun_irradiance(&geometry.gather) + self.sensor_direct_sun(i, &direct_sun);
            SensorDirect {
                sky: seen.sky_irradiance(&geometry.gather),
                sun,
                sun_bounce: self.sensor_sun_bounce(i, &beams, &sides_sun.reach),
            }
        });
        let warm = warm.filter(|w| w.sides.len() == direct.len()).map(|w| {
            // Scaled by how much the direct light changed: close when the
            // sun moves a little, and dark at once when the light is gone
            // (unscaled, a day's light would fade over every iteration
            // the budget allows and leave a glow in the night).
            let before: f64 = w.sides.iter().map(|c| c.sun + c.sky).sum();
            let now: f64 = direct.iter().map(|c| c.sun + c.sky).sum();
            let scale = if before > 0.0 { now / before } else { 0.0 };
            w.sides.iter().map(|c| c.indirect.map(|e| e * scale)).collect()
        });
        let solver = Interreflection::new(
            direct.iter().map(|c| c.sun + c.sky).collect(),
            reflectance,
            warm,
            self.settings.tolerance,
            self.settings.max_iterations,
        );
        Relight { model: self, direct, solver, sensors }
    }
}

/// A relight in progress: direct light computed, interreflection iterating.
pub struct Relight<'a> {
    model: &'a LightModel,
    direct: Vec<Channels>,
    solver: Interreflection,
    sensors: Vec<SensorDirect>,
}

impl Relight<'_> {
    /// One Jacobi iteration over the model's form factors. Returns whether
    /// the solution has converged (or the iteration budget is spent).
    pub fn step(&mut self) -> bool {
        let gathers = &self.model.side_gathers;
        self.solver.step(|i| gathers[i].form_factors.as_slice(), self.model.settings.threads)
    }

    /// Whether the interreflection has converged or spent its budget.
    pub fn is_converged(&self) -> bool {
        self.solver.is_converged()
    }

    /// The light as it stands.
    pub fn lighting(&self) -> Lighting {
        let model = self.model;
        let sides = self.direct.iter().zip(&self.solver.indirect).map(|(d, i)| Channels { indirect: *i, ..*d }).collect();
        // Sensors take the sun's first bounce from where their rays land, so
        // the sides' exitance here leaves out their sun beams (the panels'
        // diffuse sunlight still counts).
        let without_sun = self.solver.exitance(|j| self.direct[j].sun_diffuse + self.direct[j].sky);
        let sensors = model
            .scene
            .sensors
            .iter()
            .zip(model.sensors.iter())
            .zip(&self.sensors)
            .map(|((sensor, geometry), direct)| {
                let rgb = form_factor_product(direct.sun_bounce, &geometry.gather.form_factors, &without_sun);
                let indirect = Channels { indirect: rgb, ..Default::default() }.indirect_luminous();
                let lux = |e: f64| e * LUMINOUS_EFFICACY;
                SensorReading::new(sensor.name.clone(), lux(direct.sun), lux(direct.sky), lux(indirect))
            })
            .collect();
        Lighting { sides, sensors, iterations: self.solver.iterations, residual: self.solver.residual }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solve(mut solver: Interreflection, rows: &[Vec<(u32, f32)>]) -> Interreflection {
        while !solver.step(|i| rows[i].as_slice(), Some(1)) {}
        solver
    }

    /// The furnace test: inside a closed box every row of form factors sums
    /// to 1, and a uniform direct irradiance E with reflectance ρ everywhere
    /// gives a total irradiance of E / (1 − ρ) on every side.
    #[test]
    fn a_closed_box_reaches_the_furnace_value() {
        let n = 12;
        // Uneven but closed rows: side i sees side j in proportion to 1 + (i + j) % 3.
        let rows: Vec<Vec<(u32, f32)>> = (0..n)
            .map(|i| {
                let weights: Vec<f64> = (0..n).map(|j| 1.0 + ((i + j) % 3) as f64).collect();
                let total: f64 = weights.iter().sum();
                weights.iter().enumerate().map(|(j, w)| (j as u32, (w / total) as f32)).collect()
            })
            .collect();
        for rho in [0.2, 0.5, 0.8] {
            let e = 100.0;
            let solver = solve(Interreflection::new(vec![e; n], vec![[rho; 3]; n], None, 1e-9, 10_000), &rows);
            for side in &solver.indirect {
                let total = e + side[1];
                assert!((total - e / (1.0 - rho)).abs() < 1e-4 * e / (1.0 - rho), "ρ {rho}: {total} vs {}", e / (1.0 - rho));
            }
        }
    }

    /// Two plates facing each other (F12 from 1 to 2, F21 back), only plate
    /// 1 lit: H1 = E1 / (1 − ρ1 ρ2 F12 F21), H2 = ρ1 F21 H1 (total
    /// irradiances), per colour channel.
    #[test]
    fn two_plates_match_the_closed_form() {
        let (f12, f21) = (0.2, 0.2);
        let rows = vec![vec![(1, f12 as f32)], vec![(0, f21 as f32)]];
        let rho1 = [0.7, 0.5, 0.3];
        let rho2 = [0.6, 0.6, 0.2];
        let e1 = 1000.0;
        let solver = solve(Interreflection::new(vec![e1, 0.0], vec![rho1, rho2], None, 1e-12, 10_000), &rows);
        for c in 0..3 {
            let h1 = e1 / (1.0 - rho1[c] * rho2[c] * f64::from(f12 as f32) * f64::from(f21 as f32));
            let h2 = rho1[c] * f64::from(f21 as f32) * h1;
            assert!((e1 + solver.indirect[0][c] - h1).abs() < 1e-6 * h1, "channel {c}: plate 1");
            assert!((solver.indirect[1][c] - h2).abs() < 1e-6 * h1, "channel {c}: plate 2");
        }
    }

    /// Grey sides iterated in one channel give the three channels' light
    /// bit for bit, step for step.
    #[test]
    fn grey_sides_iterate_one_channel_for_three() {
        let rows: Vec<Vec<(u32, f32)>> = (0..40u32).map(|i| vec![((i + 1) % 40, 0.3), ((i + 7) % 40, 0.2), ((i + 3) % 40, 0.1)]).collect();
        let direct: Vec<f64> = (0..40).map(|i| f64::from(i % 5) * 50.0 + 0.1).collect();
        let reflectance: Vec<[f64; 3]> = (0..40).map(|i| [0.2 + 0.015 * f64::from(i); 3]).collect();
        let grey = Interreflection::new(direct, reflectance, None, 1e-10, 1000);
        assert!(grey.grey);
        let three = Interreflection { grey: false, ..grey.clone() };
        let (grey, three) = (solve(grey, &rows), solve(three, &rows));
        assert_eq!((grey.indirect, grey.iterations), (three.indirect, three.iterations));
        assert!(three.iterations > 3);
        assert!(!Interreflection::new(vec![1.0], vec![[0.5, 0.5, 0.4]], None, 1e-6, 10).grey, "a coloured side is not");
    }

    /// A warm start at the solution is already converged after one step,
    /// and the solution does not depend on the thread count.
    #[test]
    fn warm_starts_and_threads_do_not_change_the_solution() {
        let rows: Vec<Vec<(u32, f32)>> = (0..40u32).map(|i| vec![((i + 1) % 40, 0.3), ((i + 7) % 40, 0.2)]).collect();
        let direct: Vec<f64> = (0..40).map(|i| f64::from(i % 5) * 50.0).collect();
        let cold = solve(Interreflection::new(direct.clone(), vec![[0.5; 3]; 40], None, 1e-10, 1000), &rows);
        let mut threaded = Interreflection::new(direct.clone(), vec![[0.5; 3]; 40], None, 1e-10, 1000);
        while !threaded.step(|i| rows[i].as_slice(), Some(3)) {}
        assert_eq!(cold.indirect, threaded.indirect);
        let mut warm = Interreflection::new(direct, vec![[0.5; 3]; 40], Some(cold.indirect.clone()), 1e-6, 1000);
        assert!(warm.step(|i| rows[i].as_slice(), Some(1)));
        assert_eq!(warm.iterations, 1);
    }
}
