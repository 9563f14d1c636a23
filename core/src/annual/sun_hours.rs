//! The year's sun on a scene at its site, traced once: for every hour of the
//! 365-day calendar with the sun up, each sensor's direct sun and
//! interreflected sun per W/m² of direct normal irradiance
//! ([`SunResponse`]), and, when shades are studied, the direct sun through
//! each shade group's windows.
//!
//! Sun positions follow the site and the calendar, not the weather (the
//! EPW gives how strong the sun is, not where it is), and the light is
//! linear in the sun's strength: so one table serves every weather file of
//! the site, and an hour of the year is a product with no ray traced. The
//! table is stored in the light cache beside the scene's precomputation
//! ([`SunHours::cached`]), keyed by what it depends on beyond it: every
//! material's light (reflectances, glass, panel keys), the site, the shade
//! groups.

use std::borrow::Cow;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DVec3;

use super::hour_time;
use crate::light::cache::{self, CacheOutcome, Fnv, Reader, Writer};
use crate::light::coefficients::SunResponse;
use crate::light::{LightModel, SensorCoefficients, SunPath, par_map};
use crate::scene::MaterialKind;
use crate::site::Site;
use crate::sky::{LUMINOUS_EFFICACY, SunSource};
use crate::sun::{direction_from_angles, solar_position};
use crate::weather::{HOURS, calendar};

/// Bump when the table or how it is traced changes.
const FORMAT: u32 = 1;

/// The most a table may hold, bytes. Past it (a grid of tens of thousands
/// of sensors) the year's sun is traced hour by hour instead
/// ([`YearSun::Traced`]) and not cached: memory then follows the sensors
/// and the threads, not the hours.
pub const MAX_TABLE_BYTES: usize = 256 << 20;

/// The sun's light at every sensor for each sun-up hour of the year.
#[derive(Debug, Clone, PartialEq)]
pub struct SunHours {
    /// What the table was traced for ([`Self::key`]).
    key: u64,
    sensors: usize,
    /// Shade groups whose windows' direct sun is kept (0 when not studied).
    shade_groups: usize,
    /// Each hour's row in `rows`, `None` when the sun is down.
    row_of_hour: Vec<Option<u32>>,
    rows: Vec<SunHour>,
}

/// One sun-up hour.
#[derive(Debug, Clone, PartialEq)]
struct SunHour {
    response: SunResponse,
    /// Direct sun through each shade group's windows, lux per W/m²,
    /// `[group][sensor]`.
    through_shades: Vec<f32>,
}

impl SunHours {
    /// Traces every sun-up hour of the year at `site` (`shades`: keep each
    /// shade group's direct sun too), `threads` as [`par_map`]; `progress`
    /// hears the share of hours done (from any thread).
    pub fn trace(
        model: &LightModel,
        coefficients: &SensorCoefficients,
        site: &Site,
        shades: bool,
        threads: Option<usize>,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Self {
        let directions: Vec<Option<DVec3>> = par_map(threads, HOURS, |k| sun_direction(site, k));
        let up: Vec<DVec3> = directions.iter().flatten().copied().collect();
        let path = SunPath::new(model, coefficients, site, &up, threads);
        let shade_groups = if shades { model.scene.shades.len() } else { 0 };
        let done = AtomicUsize::new(0);
        let rows = par_map(threads, up.len(), |r| {
            let row = SunHour {
                response: coefficients.sun_response(model, up[r], &path, Some(1)),
                through_shades: through_shades(model, up[r], shade_groups),
            };
            progress((done.fetch_add(1, Ordering::Relaxed) + 1) as f64 / up.len() as f64);
            row
        });
        let mut next = 0;
        let row_of_hour = directions
            .iter()
            .map(|d| {
                d.map(|_| {
                    next += 1;
                    next - 1
                })
            })
            .collect();
        Self { key: Self::key(model, site, shades), sensors: model.scene.sensors.len(), shade_groups, row_of_hour, rows }
    }

    /// [`Self::trace`] through the light cache in `dir` (none: traced each
    /// time); `None` when the table would hold more than
    /// [`MAX_TABLE_BYTES`] (the year then traces its sun hour by hour).
    pub fn cached(
        model: &LightModel,
        coefficients: &SensorCoefficients,
        site: &Site,
        shades: bool,
        dir: Option<&Path>,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<Option<(Self, CacheOutcome)>, String> {
        if !Self::fits_in_memory(model, site, shades) {
            return Ok(None);
        }
        let key = Self::key(model, site, shades);
        cache::through_cache(
            dir,
            &format!("{key:016x}-sun-hours"),
            key,
            |payload| Self::read(payload, key, model, shades),
            || Ok(Self::trace(model, coefficients, site, shades, None, progress)),
            Self::write,
        )
        .map(Some)
    }

    /// What the table depends on: the scene's precomputation
    /// ([`cache::key`]), every material's light, the site, the shade groups.
    pub fn key(model: &LightModel, site: &Site, shades: bool) -> u64 {
        let scene = &model.scene;
        let mut hash = Fnv::new();
        hash.u64(cache::key(scene, &model.settings)).u64(u64::from(FORMAT));
        for material in &scene.materials {
            match &material.kind {
                MaterialKind::Diffuse { reflectance } => reflectance.0.iter().fold(hash.u64(0), |h, c| h.u64(u64::from(c.to_bits()))),
                MaterialKind::Glass { transmittance } => hash.u64(1).u64(u64::from(transmittance.to_bits())),
                MaterialKind::Panel { panel, up, parameters, .. } => {
                    hash.u64(2).bytes(panel.as_bytes()).bytes(format!("{up:?}").as_bytes()).bytes(parameters.to_string().as_bytes())
                }
            };
        }
        let Site { latitude, longitude, timezone, elevation, pressure, temperature, ground_reflectance, north_turn } = *site;
        for value in [latitude, longitude, timezone, elevation, pressure, temperature, ground_reflectance, north_turn] {
            hash.f64(value);
        }
        hash.u64(u64::from(shades));
        if shades {
            for group in &scene.shades {
                hash.u64(u64::from(group.windows));
            }
        }
        hash.0
    }

    /// Whether the table was traced for this model at this site.
    pub fn fits(&self, model: &LightModel, site: &Site, shades: bool) -> bool {
        self.key == Self::key(model, site, shades) && self.sensors == model.scene.sensors.len()
    }

    /// Hour `k`'s response (hour of the 365-day year), `None` with the sun down.
    pub fn response(&self, k: usize) -> Option<&SunResponse> {
        self.row(k).map(|row| &row.response)
    }

    /// Hour `k`'s direct sun through each shade group's windows, lux per
    /// W/m², `[group][sensor]`; `None` with the sun down.
    pub fn through_shades(&self, k: usize) -> Option<&[f32]> {
        self.row(k).map(|row| row.through_shades.as_slice())
    }

    /// Whether a table of `model` at `site` stays within [`MAX_TABLE_BYTES`].
    fn fits_in_memory(model: &LightModel, site: &Site, shades: bool) -> bool {
        let groups = if shades { model.scene.shades.len() } else { 0 };
        let sun_up = par_map(None, HOURS, |k| sun_direction(site, k).is_some()).into_iter().filter(|&up| up).count();
        model.scene.sensors.len() * (2 + groups) * sun_up * size_of::<f32>() <= MAX_TABLE_BYTES
    }

    fn row(&self, k: usize) -> Option<&SunHour> {
        self.row_of_hour.get(k).copied().flatten().map(|r| &self.rows[r as usize])
    }

    fn write(&self) -> Vec<u8> {
        let mut w = Writer::default();
        for n in [self.sensors, self.shade_groups, self.rows.len()] {
            w.u32(n as u32);
        }
        for row in &self.row_of_hour {
            w.u32(row.unwrap_or(u32::MAX));
        }
        for row in &self.rows {
            for value in row.response.direct.iter().chain(&row.response.interreflected).chain(&row.through_shades) {
                w.f32(*value);
            }
        }
        w.0
    }

    /// The table from the cache; `None` when it does not fit the model.
    fn read(payload: &[u8], key: u64, model: &LightModel, shades: bool) -> Option<Self> {
        let mut r = Reader(payload);
        let (sensors, shade_groups, row_count) = (r.u32()? as usize, r.u32()? as usize, r.u32()? as usize);
        let expected_groups = if shades { model.scene.shades.len() } else { 0 };
        if sensors != model.scene.sensors.len() || shade_groups != expected_groups || row_count > HOURS {
            return None;
        }
        let row_of_hour = (0..HOURS)
            .map(|_| match r.u32()? {
                u32::MAX => Some(None),
                row if (row as usize) < row_count => Some(Some(row)),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        let mut floats = |n: usize| (0..n).map(|_| r.f32()).collect::<Option<Vec<f32>>>();
        let rows = (0..row_count)
            .map(|_| {
                let response = SunResponse { direct: floats(sensors)?, interreflected: floats(sensors)? };
                Some(SunHour { response, through_shades: floats(shade_groups * sensors)? })
            })
            .collect::<Option<Vec<_>>>()?;
        r.is_empty().then_some(Self { key, sensors, shade_groups, row_of_hour, rows })
    }
}

/// Where a year's hours get their sun: a table, or traced hour by hour where
/// a table would not fit in memory ([`SunHours::fits_in_memory`]).
pub(super) enum YearSun<'a> {
    Table(&'a SunHours),
    Traced {
        model: &'a LightModel,
        coefficients: &'a SensorCoefficients,
        site: &'a Site,
        /// The sun's later bounces around every sun-up hour.
        path: SunPath,
        shade_groups: usize,
    },
}

impl<'a> YearSun<'a> {
    /// Hour by hour: the sun path of the year at `site`.
    pub(super) fn traced(model: &'a LightModel, coefficients: &'a SensorCoefficients, site: &'a Site, shades: bool) -> Self {
        let up: Vec<DVec3> = par_map(None, HOURS, |k| sun_direction(site, k)).into_iter().flatten().collect();
        let path = SunPath::new(model, coefficients, site, &up, None);
        let shade_groups = if shades { model.scene.shades.len() } else { 0 };
        YearSun::Traced { model, coefficients, site, path, shade_groups }
    }

    /// Hour `k`'s response, `None` with the sun down.
    pub(super) fn response(&self, k: usize) -> Option<Cow<'_, SunResponse>> {
        match self {
            YearSun::Table(table) => table.response(k).map(Cow::Borrowed),
            YearSun::Traced { model, coefficients, site, path, .. } => {
                sun_direction(site, k).map(|sun| Cow::Owned(coefficients.sun_response(model, sun, path, Some(1))))
            }
        }
    }

    /// Hour `k`'s direct sun through each shade group's windows
    /// ([`SunHours::through_shades`]), `None` with the sun down.
    pub(super) fn through_shades(&self, k: usize) -> Option<Cow<'_, [f32]>> {
        match self {
            YearSun::Table(table) => table.through_shades(k).map(Cow::Borrowed),
            YearSun::Traced { model, site, shade_groups, .. } => {
                sun_direction(site, k).map(|sun| Cow::Owned(through_shades(model, sun, *shade_groups)))
            }
        }
    }
}

/// The sun's direction in the model's frame at the middle of hour `k` of the
/// 365-day year, as [`super::hour_sky`]'s sky places it; `None` when down.
fn sun_direction(site: &Site, k: usize) -> Option<DVec3> {
    let (month, day, hour) = calendar(k);
    let sun = solar_position(site, &hour_time(month, day, hour));
    (sun.altitude > 0.0).then(|| direction_from_angles(sun.altitude, sun.azimuth + site.north_turn))
}

/// Direct sun through each of the first `groups` shade groups' windows at
/// every sensor, lux per W/m² from `direction`, `[group][sensor]`.
fn through_shades(model: &LightModel, direction: DVec3, groups: usize) -> Vec<f32> {
    let scene = &model.scene;
    let sensors = scene.sensors.len();
    let mut through = vec![0.0f32; groups * sensors];
    if groups == 0 {
        return through;
    }
    let beams = model.sun_beams(&SunSource::unit(direction));
    for i in 0..sensors {
        for (window, e) in model.sensor_sun_by_window(i, &beams) {
            let Some(window) = window else { continue };
            for (g, group) in scene.shades.iter().enumerate().take(groups) {
                if scene.windows[window as usize].material == group.windows {
                    through[g * sensors + i] += (e * LUMINOUS_EFFICACY) as f32;
                }
            }
        }
    }
    through
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::light::LightSettings;
    use crate::panel::PanelCatalog;

    /// Traced hour by hour (a table too big for memory) the year's sun is
    /// the table's, hour for hour.
    #[test]
    fn hours_traced_one_by_one_are_the_tables() {
        let scene = crate::scene::load_scene(&crate::bundled_scene("test_room"), &PanelCatalog::new()).unwrap().scene;
        let site = scene.site;
        let model = LightModel::precompute(Arc::new(scene), LightSettings::default()).unwrap();
        let coefficients = model.sensor_coefficients();
        let table = SunHours::trace(&model, &coefficients, &site, false, None, &|_| {});
        assert!(SunHours::fits_in_memory(&model, &site, false));
        let traced = YearSun::traced(&model, &coefficients, &site, false);
        let mut lit = 0;
        for k in (0..HOURS).step_by(97) {
            let (from_table, one_by_one) = (table.response(k), traced.response(k));
            assert_eq!(from_table, one_by_one.as_deref(), "hour {k}");
            lit += usize::from(from_table.is_some_and(|r| r.direct.iter().any(|&e| e > 0.0)));
        }
        assert!(lit > 10, "{lit} sunny hours compared");
    }
}
