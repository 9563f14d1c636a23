//! What a year of hours reads each hour: every sensor's whole light per
//! unit radiance of every slot ([`TotalCoefficients`]), its direct sky and
//! the panels' diffused sun folded into the interreflected coefficients
//! ([`SensorCoefficients`]), so an hour's total is one dense product. The
//! direct sky was a sparse sum over each sensor's gathered keys besides
//! that product: a third of a warm year's instructions.
//!
//! The fold is linear: a key's share `w` of a slot adds π·179·w lux per
//! unit radiance to the slot's coefficient. Totals equal
//! [`SensorCoefficients::readings_with_sun`]'s to f32 rounding of the
//! folded coefficients (a relative 1e-7).

use std::f64::consts::PI;

use super::coefficients::{SunLux, SunResponse, add_products, add_products_together};
use super::daylight::RadianceSlots;
use super::{LightModel, SensorCoefficients};
use crate::sky::{LUMINOUS_EFFICACY, Sky};

/// Every sensor's lux per unit radiance (W/m²/sr) of every radiance slot,
/// direct and interreflected; for one model and any that differs from it
/// in panel models alone (as [`SensorCoefficients`]).
pub struct TotalCoefficients {
    sensors: usize,
    slots: RadianceSlots,
    /// Interreflected and direct lux per unit radiance, `[slot][sensor]`.
    total: Vec<f32>,
    /// Direct lux per unit radiance of each panel group's diffused sun,
    /// `[group][sensor]`: what of the total is direct sun.
    panel_sun: Vec<f32>,
}

/// What a caller reading one sky many times keeps of it.
#[derive(Debug, Clone, Copy, Default)]
pub struct KnownSky<'a> {
    /// Its [`LightModel::sphere_bins`].
    pub bins: Option<&'a [f64]>,
    /// Its light beside some panels ([`TotalCoefficients::sky_beside_panels`]):
    /// only what they pass is read.
    pub beside_panels: Option<&'a SkyBesidePanels>,
}

/// Every sensor's light (lux) from the slots that pass no panel of some
/// groups ([`TotalCoefficients::sky_beside_panels`]).
#[derive(Debug, Clone)]
pub struct SkyBesidePanels {
    groups: Vec<u32>,
    lux: Vec<f32>,
}

/// One hour a year reads ([`TotalCoefficients::readings_of_hours`]).
#[derive(Debug, Clone, Copy)]
pub struct HourSky<'a> {
    /// The hour's sky.
    pub sky: &'a Sky,
    /// What the caller keeps of the sky.
    pub known: KnownSky<'a>,
    /// The sun's light at every sensor per W/m² of direct normal
    /// irradiance from the hour's sun; `None` when the sun is down.
    pub response: Option<&'a SunResponse>,
}

/// A sensor's light in one hour, lux.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HourLight {
    /// Everything: sun, sky and ground, direct and interreflected.
    pub total: f64,
    /// Straight from the sun: its beams, its panel lobes and what panels
    /// diffuse of it (what ASE counts).
    pub direct_sun: f64,
}

impl SensorCoefficients {
    /// These coefficients with every sensor's direct light folded in.
    pub fn totals(&self, model: &LightModel) -> TotalCoefficients {
        let (sensors, slots) = (self.sensors, self.slots.clone());
        let groups = model.panel_groups.len();
        let first_panel_sun = slots.len() - groups;
        let mut total = self.sky.clone();
        let mut panel_sun = vec![0.0f32; groups * sensors];
        // One sensor's direct lux per slot, summed over its keys in f64.
        let mut direct = vec![0.0f64; slots.len()];
        for (i, geometry) in model.sensors.iter().enumerate() {
            for &(key, w) in &geometry.gather.daylight_coefficients {
                let (sky, sun) = slots.of(key);
                direct[sky] += PI * LUMINOUS_EFFICACY * f64::from(w);
                if let Some(sun) = sun {
                    direct[sun] += PI * LUMINOUS_EFFICACY * f64::from(w);
                }
            }
            for (slot, lux) in direct.iter_mut().enumerate().filter(|(_, lux)| **lux != 0.0) {
                total[slot * sensors + i] = (f64::from(total[slot * sensors + i]) + *lux) as f32;
                if slot >= first_panel_sun {
                    panel_sun[(slot - first_panel_sun) * sensors + i] = *lux as f32;
                }
                *lux = 0.0;
            }
        }
        TotalCoefficients { sensors, slots, total, panel_sun }
    }
}

impl TotalCoefficients {
    /// Every sensor's light in each of `hours`, each hour's sun scaled by
    /// its sky's sun: no ray is traced. The hours are read together, each
    /// coefficient row fetched once for all of them (a row of the office is
    /// 600 bytes, all of them 2.8 MB); every hour's sums are what it alone
    /// would make, bit for bit.
    pub fn readings_of_hours(&self, model: &LightModel, hours: &[HourSky]) -> Vec<Vec<HourLight>> {
        let width = self.sensors.max(1);
        let first_panel_sun = self.slots.len() - model.panel_groups.len();
        let mut sources = Vec::with_capacity(hours.len());
        let mut straight = Vec::with_capacity(hours.len());
        let mut direct_sun = Vec::with_capacity(hours.len());
        let mut total = Vec::with_capacity(hours.len());
        for hour in hours {
            let SunLux { direct: beams, interreflected: mut sum } = SunLux::scaled(hour.response, hour.sky, self.sensors);
            let mut radiance = model.key_radiance_in(hour.sky, hour.known.bins).slots();
            let mut sun = beams.clone();
            add_products(&mut sun, radiance[first_panel_sun..].iter().zip(self.panel_sun.chunks_exact(width)));
            if let Some(beside) = hour.known.beside_panels {
                // Kept: the slots beside the panels; read: theirs alone.
                sum.iter_mut().zip(&beside.lux).for_each(|(e, &b)| *e += f64::from(b));
                let through = |slot: usize| self.slots.group(slot).is_some_and(|g| beside.groups.contains(&g));
                radiance.iter_mut().enumerate().filter(|(slot, _)| !through(*slot)).for_each(|(_, r)| *r = 0.0);
            }
            sources.push(radiance);
            straight.push(beams);
            direct_sun.push(sun);
            total.push(sum);
        }
        // The products hold the direct sky and the panels' diffused sun; the beams and lobes are added.
        add_products_together(&mut total, &sources, &self.total, width);
        let hour_light = |((total, straight), direct_sun): ((Vec<f64>, Vec<f64>), Vec<f64>)| {
            // + 0.0: a dark sensor reads 0, not −0.
            (0..self.sensors).map(|i| HourLight { total: total[i] + straight[i] + 0.0, direct_sun: direct_sun[i] + 0.0 }).collect()
        };
        total.into_iter().zip(straight).zip(direct_sun).map(hour_light).collect()
    }

    /// Every sensor's light under `sky` (`bins`: its
    /// [`LightModel::sphere_bins`], when kept) from the slots that pass no
    /// panel of `groups`: read once for a sky that models differing only in
    /// those panels read again ([`KnownSky::beside_panels`]).
    pub fn sky_beside_panels(&self, model: &LightModel, sky: &Sky, bins: Option<&[f64]>, groups: &[u32]) -> SkyBesidePanels {
        let radiance = model.key_radiance_in(sky, bins).slots();
        let beside = |slot: usize| self.slots.group(slot).is_none_or(|g| !groups.contains(&g));
        let mut lux = vec![0.0; self.sensors];
        let rows = radiance.iter().zip(self.total.chunks_exact(self.sensors.max(1))).enumerate();
        add_products(&mut lux, rows.filter(|(slot, _)| beside(*slot)).map(|(_, term)| term));
        SkyBesidePanels { groups: groups.to_vec(), lux: lux.iter().map(|&v| v as f32).collect() }
    }
}
