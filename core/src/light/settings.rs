//! The light engine's knobs ([`LightSettings`]): rays, sky subdivision,
//! iteration budget. The defaults reach the accuracy targets.

/// Knobs of the simulation; the defaults reach the accuracy targets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSettings {
    /// Hemisphere rays from each side of each patch (form factors, sky coefficients).
    pub rays_per_patch: usize,
    /// Rays from each patch side aimed at the windows it sees (next-event
    /// estimation of the sky through them, see [`super::gather`]): a far,
    /// small window is a small solid angle that hemisphere rays find by
    /// chance, and a near one a bright part of the hemisphere they sample
    /// unevenly; aimed rays find each every time. 0: hemisphere rays alone.
    pub window_rays_per_patch: usize,
    /// Hemisphere rays from each sensor point whose landings keep the
    /// sun's first bounce (traced there every relight and every hour of a
    /// year).
    pub rays_per_sensor: usize,
    /// Hemisphere rays from each sensor point for its sky and form factors,
    /// the first `rays_per_sensor` included (so at least those). The sky a
    /// deep sensor sees through distant windows is a small solid angle: at
    /// 4,096 rays the validation room's mirror-image sensors read up to 6%
    /// apart under an overcast sky; at 16,384 its overcast p90 against
    /// Radiance went from 3.1% to 1.9%. Only the gather costs more; nothing
    /// per relight.
    pub sky_rays_per_sensor: usize,
    /// Shadow rays toward the sun per patch side. A sample toggles as a
    /// shadow edge crosses it, so the sun's bounced light moves in steps of
    /// 1/n of a side's beam: at 64 an hour read between sun positions (the
    /// annual sun path) stays within 2% of one traced at it, where 16 gave
    /// 2.6% (the office); relights cost little more (enclosed sides are
    /// mostly spared by the openings). The sun path's nodes give these to
    /// the sides that matter to the sensors, fewer to the others
    /// (`SensorCoefficients::path_sun_samples`).
    pub sun_samples_per_patch: usize,
    /// Points per side of an area sensor's grid for the direct sun (sky and
    /// indirect use a 4 × 4 grid).
    pub area_sensor_sun_grid: usize,
    /// Reinhart MF:n of the sky bins.
    pub sky_subdivision: u32,
    /// Jacobi iterations at most.
    pub max_iterations: usize,
    /// Stop when no patch side's indirect irradiance changes by more than
    /// this fraction of its own irradiance in an iteration.
    pub tolerance: f64,
    /// Worker threads; `None` for all cores. Results do not depend on it.
    pub threads: Option<usize>,
}

impl Default for LightSettings {
    fn default() -> Self {
        Self {
            rays_per_patch: 256,
            window_rays_per_patch: 64,
            rays_per_sensor: 4096,
            sky_rays_per_sensor: 16384,
            sun_samples_per_patch: 64,
            area_sensor_sun_grid: 32,
            sky_subdivision: 4,
            max_iterations: 200,
            tolerance: 1e-4,
            threads: None,
        }
    }
}

impl LightSettings {
    /// These settings with `factor` times the patch rays (hemisphere and
    /// aimed at windows): a smoother indirect light, or a converged
    /// reference to measure the default's noise against.
    pub fn with_more_patch_rays(self, factor: usize) -> Self {
        Self { rays_per_patch: self.rays_per_patch * factor, window_rays_per_patch: self.window_rays_per_patch * factor, ..self }
    }

    /// One line naming the first setting that cannot work.
    pub fn check(&self) -> Result<(), String> {
        let positive = [
            (self.rays_per_patch, "rays_per_patch"),
            (self.rays_per_sensor, "rays_per_sensor"),
            (self.sun_samples_per_patch, "sun_samples_per_patch"),
            (self.area_sensor_sun_grid, "area_sensor_sun_grid"),
            (self.max_iterations, "max_iterations"),
        ];
        if let Some((_, name)) = positive.iter().find(|(v, _)| *v == 0) {
            return Err(format!("lighting setting {name} must be at least 1"));
        }
        if self.sky_subdivision == 0 || self.sky_subdivision > 16 {
            return Err(format!("sky subdivision MF:{} is outside 1-16", self.sky_subdivision));
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(format!("tolerance {} must lie in (0, 1)", self.tolerance));
        }
        Ok(())
    }
}
