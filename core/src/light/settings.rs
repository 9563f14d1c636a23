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
    /// Rays from each sensor aimed at the windows it sees, for the sky
    /// through them, as [`Self::window_rays_per_patch`] for patch sides. The
    /// sky a deep sensor sees through distant windows is a small solid
    /// angle that hemisphere rays find by chance: at 4,096 hemisphere rays
    /// alone the validation room's mirror-image sensors read up to 6% apart
    /// under an overcast sky, and the validation set read p90 2.4% against
    /// Radiance (16,384: 1.6%, and 2.7 times the rays); with 2,048 aimed
    /// rays beside 4,096 hemisphere rays, 1.3% (median 0.46%, max 2.7%).
    pub window_rays_per_sensor: usize,
    /// Hemisphere rays from each sensor point for its sky (where no aimed
    /// ray draws it) and form factors, the first `rays_per_sensor`
    /// included (so at least those): more refine the sky seen outdoors and
    /// the interreflected light. Only the gather costs more; nothing per
    /// relight.
    pub sky_rays_per_sensor: usize,
    /// The share of the patch rays (hemisphere and aimed) at most that a
    /// side no sensor sees traces per bounce its light is from the sensors,
    /// where a scene has sensors (farther from them, the sizing's smaller
    /// share: `PatchSizing::ray_share`): one bounce away twice this share
    /// (`gather.rs`'s `ONE_BOUNCE_FACTOR`), then this share again for each
    /// bounce farther (up to three: a sixty-fourth). Such a side reaches the
    /// sensors only after one more bounce (or more), where its noise
    /// averages over the many sides each seen side gathers from. At a
    /// quarter, AC20-Institute-Var-2 with one office's sensors precomputes
    /// in 4.5 s instead of 7.6 s (2 cores), and the office's mean reading
    /// over five seeds moves by 0.4% where the seeds spread 1.2% (standard
    /// deviation); the validation set reads median 0.49% (0.48% with all
    /// rays). Pictures show those sides: [`Self::for_display`] gives them
    /// all their rays (1).
    pub unseen_ray_share: f64,
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
    /// Which sample of the rays the gathers draw (patch sides' and
    /// sensors'): another seed is another, equally valid, Monte Carlo
    /// estimate of the same light, so the readings' spread over seeds is
    /// their noise. 0 is the default sample.
    pub seed: u64,
}

/// Hemisphere rays per patch side times patches that
/// [`LightSettings::for_display`] spends at most: 8× the default up to 6,250
/// patches, 2× on a 23,000-patch house, the default on the 29,000-patch
/// furnished floor of offices, and past 50,000 patches, where even the
/// default rays on every side would overspend it, the settings as they are.
const DISPLAY_PATCH_RAYS: usize = 12_800_000;

/// The most [`LightSettings::for_display`] multiplies the default patch rays by.
const DISPLAY_MAX_FACTOR: usize = 8;

impl Default for LightSettings {
    fn default() -> Self {
        Self {
            rays_per_patch: 256,
            window_rays_per_patch: 64,
            rays_per_sensor: 4096,
            window_rays_per_sensor: 2048,
            sky_rays_per_sensor: 4096,
            unseen_ray_share: 0.25,
            sun_samples_per_patch: 64,
            area_sensor_sun_grid: 32,
            sky_subdivision: 4,
            max_iterations: 200,
            tolerance: 1e-4,
            threads: None,
            seed: 0,
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

    /// These settings for the light a picture shows of a model of
    /// `patches` patches: as many hemisphere rays per patch side as 12.8
    /// million over the patches, between the default's 256 and 8 times
    /// that (2,048), so that a room's walls and ceilings show no Monte
    /// Carlo blotches while a large model, whose patches are many and small
    /// on screen, keeps the default; the rays aimed at windows grow alike,
    /// and settings with more patch rays keep theirs. The office (3,054
    /// patches) gets 8×: its walls under a clear sky go from 4.4% to 1.4%
    /// relative RMS against 32× the rays, the precomputation from 1.1 to
    /// 4.0 s on 2 cores and a relight from 16 to 25 ms. Sensors and annual
    /// studies keep the settings as they are (a sensor's own rays carry its
    /// accuracy). Every side a picture shows keeps all its rays
    /// ([`Self::unseen_ray_share`]), unless the default rays on every side
    /// are past the budget: a model that large keeps the settings, as a
    /// second model of it beside the first would cost more than it smooths
    /// (Revit's Office_A, 121,077 patches and 10,244 sensors: a cold view
    /// traced every sensor again, with every side's rays, and peaked at
    /// 2.98 GB).
    pub fn for_display(self, patches: usize) -> Self {
        let default = Self::default().rays_per_patch;
        if patches.saturating_mul(default) > DISPLAY_PATCH_RAYS {
            return self;
        }
        let wanted = (DISPLAY_PATCH_RAYS / patches.max(1)).clamp(default, DISPLAY_MAX_FACTOR * default);
        Self { unseen_ray_share: 1.0, ..self.with_more_patch_rays((wanted / self.rays_per_patch.max(1)).max(1)) }
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
        if !(self.unseen_ray_share > 0.0 && self.unseen_ray_share <= 1.0) {
            return Err(format!("unseen ray share {} must lie in (0, 1]", self.unseen_ray_share));
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(format!("tolerance {} must lie in (0, 1)", self.tolerance));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pictures of rooms take up to 8× the default patch rays; a large model
    /// keeps the default, and settings that already have more keep theirs.
    #[test]
    fn pictures_take_more_patch_rays_within_a_budget() {
        let base = LightSettings::default();
        let factor = |settings: LightSettings| settings.rays_per_patch / base.rays_per_patch;
        assert_eq!(factor(base.for_display(452)), 8, "test room");
        assert_eq!(factor(base.for_display(3_054)), 8, "office");
        assert_eq!(factor(base.for_display(6_250)), 8);
        assert_eq!(factor(base.for_display(12_500)), 4);
        assert_eq!(factor(base.for_display(29_442)), 1, "furnished floor of offices");
        assert_eq!(base.for_display(29_442).unseen_ray_share, 1.0, "its unseen sides smoothed");
        assert_eq!(base.for_display(121_077), base, "Office_A: past the budget, the settings' own");
        let display = base.for_display(3_054);
        assert_eq!(display.window_rays_per_patch, 8 * base.window_rays_per_patch);
        assert_eq!(display.rays_per_sensor, base.rays_per_sensor, "a sensor's rays are its own");
        assert_eq!(factor(base.with_more_patch_rays(2).for_display(3_054)), 8);
        assert_eq!(display.unseen_ray_share, 1.0, "a picture shows the sides no sensor sees");
        assert_eq!(
            base.with_more_patch_rays(16).for_display(452),
            LightSettings { unseen_ray_share: 1.0, ..base.with_more_patch_rays(16) }
        );
    }
}
