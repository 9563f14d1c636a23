//! Direct sky and ground light by daylight coefficients: each receiver's
//! gathered shares of sky and ground bins ([`super::Gather`]) times the
//! bins' radiance under the current sky. A bin seen through a panel window
//! carries what the panel makes of the sky and sun instead (its group's sky
//! transfer, [`super::panels`]).

use std::f64::consts::PI;

use super::LightModel;
use super::gather::{Gather, SkyKey};
use crate::sky::{LUMINOUS_EFFICACY, Sky};

/// Radiance behind gather keys ([`SkyKey`]) for one sky.
pub(super) struct KeyRadiance {
    bin_count: u32,
    /// Per sphere bin.
    bins: Vec<f64>,
    /// Per panel group, per sphere bin: sky and ground seen through its windows.
    panels: Vec<Vec<f64>>,
    /// Per panel group: its diffusely transmitted sunlight's radiance.
    panel_sun: Vec<f64>,
    /// Per scene window: its panel group.
    window_panel: Vec<Option<u32>>,
}

impl KeyRadiance {
    /// Sky and ground radiance behind `key`.
    pub(super) fn of(&self, key: u32) -> f64 {
        let key = SkyKey::unpack(key, self.bin_count);
        match key.window.and_then(|w| self.window_panel[w as usize]) {
            Some(group) => self.panels[group as usize][key.bin as usize],
            None => self.bins[key.bin as usize],
        }
    }

    /// Diffusely transmitted sunlight behind `key` (through panels only).
    pub(super) fn sun_of(&self, key: u32) -> f64 {
        let key = SkyKey::unpack(key, self.bin_count);
        key.window.and_then(|w| self.window_panel[w as usize]).map_or(0.0, |group| self.panel_sun[group as usize])
    }

    /// Sky and ground irradiance (W/m²) of a receiver with `gather`.
    pub(super) fn sky_irradiance(&self, gather: &Gather) -> f64 {
        PI * gather.daylight_coefficients.iter().map(|&(k, w)| f64::from(w) * self.of(k)).sum::<f64>()
    }

    /// Sunlight that panels transmit diffusely (W/m²), seen through them.
    pub(super) fn panel_sun_irradiance(&self, gather: &Gather) -> f64 {
        // No panel diffuses sun (none in the scene, or no sun on them): the
        // sum would be 0 (read for every sensor every hour of a year).
        if self.panel_sun.iter().all(|&radiance| radiance == 0.0) {
            return 0.0;
        }
        PI * gather.daylight_coefficients.iter().map(|&(k, w)| f64::from(w) * self.sun_of(k)).sum::<f64>()
    }

    /// What panel group `group` passes: per sphere bin the sky and ground
    /// seen through it, and its diffusely transmitted sunlight's radiance.
    pub(super) fn through_panel(&self, group: usize) -> (&[f64], f64) {
        (&self.panels[group], self.panel_sun[group])
    }

    /// Every distinct radiance a key can carry, in [`RadianceSlots`] order.
    pub(super) fn slots(&self) -> Vec<f64> {
        let mut slots = self.bins.clone();
        self.panels.iter().for_each(|group| slots.extend(group));
        slots.extend(&self.panel_sun);
        slots
    }
}

/// The distinct radiances behind gather keys, numbered: sphere bins seen
/// straight or through glass, then the bins through each panel group, then
/// each group's diffusely transmitted sun.
#[derive(Debug, Clone)]
pub(super) struct RadianceSlots {
    bin_count: u32,
    groups: usize,
    /// Per scene window: its panel group.
    window_panel: Vec<Option<u32>>,
}

impl RadianceSlots {
    pub(super) fn len(&self) -> usize {
        self.bin_count as usize * (1 + self.groups) + self.groups
    }

    /// The panel group whose light a slot carries (`None`: a bin seen
    /// straight or through glass).
    pub(super) fn group(&self, slot: usize) -> Option<u32> {
        let bins = self.bin_count as usize;
        match slot {
            s if s < bins => None,
            s if s < bins * (1 + self.groups) => Some((s / bins - 1) as u32),
            s => Some((s - bins * (1 + self.groups)) as u32),
        }
    }

    /// The slot of a key's sky radiance, and of its diffuse panel sun if it
    /// looks through a panel.
    pub(super) fn of(&self, key: u32) -> (usize, Option<usize>) {
        let key = SkyKey::unpack(key, self.bin_count);
        let bins = self.bin_count as usize;
        match key.window.and_then(|w| self.window_panel[w as usize]) {
            Some(g) => (bins * (1 + g as usize) + key.bin as usize, Some(bins * (1 + self.groups) + g as usize)),
            None => (key.bin as usize, None),
        }
    }
}

impl LightModel {
    /// Each sensor's direct sky and ground light in lux, split by where it
    /// comes from: `(None, lux)` straight from outside, `(Some(k), lux)`
    /// through window `k` of [`Scene::windows`]. Sums to `direct_sky`.
    pub fn sky_through_windows(&self, sky: &Sky) -> Vec<Vec<(Option<u32>, f64)>> {
        let seen = self.key_radiance(sky);
        self.sensors
            .iter()
            .map(|geometry| {
                let mut by_window: Vec<(Option<u32>, f64)> = Vec::new();
                for &(k, w) in &geometry.gather.daylight_coefficients {
                    let key = SkyKey::unpack(k, self.bin_count());
                    let lux = PI * f64::from(w) * seen.of(k) * LUMINOUS_EFFICACY;
                    match by_window.last_mut() {
                        Some(last) if last.0 == key.window => last.1 += lux,
                        _ => by_window.push((key.window, lux)),
                    }
                }
                by_window
            })
            .collect()
    }

    /// How [`KeyRadiance::slots`] are numbered for this model.
    pub(super) fn radiance_slots(&self) -> RadianceSlots {
        RadianceSlots { bin_count: self.bin_count(), groups: self.panel_groups.len(), window_panel: self.window_panels() }
    }

    fn window_panels(&self) -> Vec<Option<u32>> {
        self.scene.windows.iter().map(|w| self.group_of_surface[w.surface as usize]).collect()
    }

    /// The radiance behind each gather key under `sky`: a bin's own, or
    /// through a panel window what the panel makes of the sky and sun.
    pub(super) fn key_radiance(&self, sky: &Sky) -> KeyRadiance {
        self.key_radiance_in(sky, None)
    }

    /// `sky`'s mean radiance in each sphere bin of the model's sky bins
    /// (sky, then ground): integrated once for a sky read many times.
    pub fn sphere_bins(&self, sky: &Sky) -> Vec<f64> {
        let mut bins = Vec::with_capacity(self.bin_count() as usize);
        self.sky_bins.integrate_sphere_into(sky, &mut bins);
        bins
    }

    /// [`Self::key_radiance`] with `sky`'s [`Self::sphere_bins`] given,
    /// when the caller keeps them.
    pub(super) fn key_radiance_in(&self, sky: &Sky, bins: Option<&[f64]>) -> KeyRadiance {
        let bins = bins.map_or_else(|| self.sphere_bins(sky), <[f64]>::to_vec);
        let sun = sky.sun_up();
        let panels = self.panel_groups.iter().map(|g| g.radiance_through(&self.sky_bins, &bins)).collect();
        // What shades a panel's windows from the sun shades what it diffuses.
        let panel_sun = (self.panel_groups.iter().enumerate())
            .map(|(k, g)| match (g.sun_diffuse_radiance(sun.as_ref()), &sun) {
                (radiance, Some(s)) if radiance > 0.0 => radiance * self.panel_sunlit(k, s.direction),
                _ => 0.0,
            })
            .collect();
        KeyRadiance { bin_count: self.bin_count(), bins, panels, panel_sun, window_panel: self.window_panels() }
    }
}
