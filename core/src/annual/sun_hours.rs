//! The year's sun on a scene at its site, traced once: for every hour of the
//! 365-day calendar a study reads the sun of (the sun up, with direct
//! normal irradiance in the weather, in the occupied hours or every hour
//! when hourly values are kept: [`super::AnnualOptions::hours_with_sun`]),
//! each sensor's direct sun and interreflected sun per W/m² of direct
//! normal irradiance ([`SunResponse`]), and, when shades are studied, the
//! direct sun through each shade group's windows.
//!
//! Sun positions follow the site and the calendar, not the weather (the
//! EPW gives how strong the sun is, not where it is), and the light is
//! linear in the sun's strength: so an hour of the year is a product with
//! no ray traced, and a table serves every weather file of the site whose
//! sunny hours it holds. An overcast hour's sun is not traced. The table
//! is stored in the light cache beside the scene's precomputation
//! ([`SunHours::cached`]), keyed by what it depends on beyond it: every
//! material's light (reflectances, glass, panel keys), the site, the shade
//! groups. A study that stores a table traces every sunny hour, occupied
//! or not, where the table fits, so that the next study of the site
//! (`--hourly`, other occupied hours) reads it as it is: the unoccupied
//! quarter of Chicago's sunny hours costs the office's cold year 0.5 s
//! and spares its `--hourly` year after a plain one 1.1 s (2 cores). A
//! study that reads hours the stored table lacks traces those hours alone
//! and stores a table of both (the stored rows copied), so two weather
//! files of one site settle on one table.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DVec3;

use super::hour_time;
use crate::light::cache::{self, CacheOutcome, StableHash, StreamedReader, StreamedWriter};
use crate::light::coefficients::SunResponse;
use crate::light::{LightModel, SensorCoefficients, SunPath};
use crate::parallel::par_map;
use crate::scene::MaterialKind;
use crate::site::Site;
use crate::sky::{LUMINOUS_EFFICACY, SunSource};
use crate::sun::{direction_from_angles, solar_position};
use crate::weather::{HOURS, calendar};

/// Bump when the table or how it is traced changes.
const FORMAT: u32 = 4;

/// The most a table may take on disk, bytes. Past it (a grid of tens of
/// thousands of sensors) the year's sun is traced hour by hour instead
/// ([`YearSun::Traced`]) and not cached.
pub const MAX_TABLE_BYTES: usize = 256 << 20;

/// Hours traced together, then written out: memory while tracing follows
/// sensors × these hours (about five days), not the year.
const HOURS_PER_BATCH: usize = 64;

/// The sun's light at every sensor for each traced hour of the year, kept
/// in a file of the light cache and read an hour at a time: memory follows
/// the sensors, not the hours.
///
/// The file's payload: sensors, shade groups and rows (`u32` each), each
/// hour's row ([`SUN_DOWN`], [`NOT_TRACED`] or the row's index), then the
/// rows, each the sensors' direct sun, their interreflected sun and the
/// direct sun through each shade group's windows (`f32`, lux per W/m² of
/// direct normal irradiance).
pub struct SunHours {
    /// What the table was traced for ([`Self::key`]).
    key: u64,
    sensors: usize,
    /// Shade groups whose windows' direct sun is kept (0 when not studied).
    shade_groups: usize,
    /// Each hour of the year's row in the file.
    row_of_hour: Vec<HourRow>,
    file: StreamedReader,
}

/// What the table holds of an hour.
#[derive(Debug, Clone, Copy, PartialEq)]
enum HourRow {
    /// Traced: the sun was down.
    SunDown,
    /// Not traced: no study read it yet.
    NotTraced,
    /// Traced, in this row of the file.
    Row(u32),
}

/// An hour's word in the file with the sun down.
const SUN_DOWN: u32 = u32::MAX;
/// An hour's word in the file when it was not traced.
const NOT_TRACED: u32 = u32::MAX - 1;

/// Why a stored table was traced again.
const LACKS_HOURS: &str = "it lacks hours of sun this study reads";

/// Where the rows start in the payload.
const ROWS_AT: u64 = 4 * (3 + HOURS as u64);

impl SunHours {
    /// The year's sun of `model` at `site` (`shades`: with each shade
    /// group's direct sun) in the `hours` of the year a study reads, from
    /// the light cache in `dir`, traced and stored there first when it is
    /// not; `progress` hears the share of the hours traced (from any
    /// thread). A table traced anew holds the hours `worth_keeping` too
    /// where it fits with them (every sunny hour, say, so that the site's
    /// next study, `--hourly` or other occupied hours, reads it as it is).
    /// `None` when the table would take more than [`MAX_TABLE_BYTES`] or
    /// cannot be stored: the year then traces its sun hour by hour
    /// ([`YearSun::Traced`], the same numbers).
    #[allow(clippy::too_many_arguments)]
    pub fn cached(
        model: &LightModel,
        coefficients: &SensorCoefficients,
        site: &Site,
        shades: bool,
        hours: &[bool],
        worth_keeping: &[bool],
        dir: &Path,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Option<(Self, CacheOutcome)> {
        let shade_groups = shade_groups(model, shades);
        let row_bytes = row_bytes(model.scene.sensors.len(), shade_groups);
        let fits = |suns: &[Option<Option<DVec3>>]| suns.iter().flatten().flatten().count() * row_bytes <= MAX_TABLE_BYTES;
        let read = sun_directions(site, hours);
        if !fits(&read) {
            return None;
        }
        let keep: Vec<bool> = hours.iter().zip(worth_keeping).map(|(read, kept)| *read || *kept).collect();
        let kept = sun_directions(site, &keep);
        let (traced_hours, ours) = if fits(&kept) { (&keep[..], kept) } else { (hours, read) };
        let key = Self::key(model, site, shades);
        // A stored table lacking some of our hours: its rows are kept, ours added.
        let stored = std::cell::RefCell::new(None);
        cache::through_streamed_cache(
            dir,
            &format!("{key:016x}-sun-hours"),
            key,
            |file| {
                let table = Self::open(file, key, model, shades).ok_or(cache::DOES_NOT_FIT)?;
                if table.holds(hours) {
                    return Ok(table);
                }
                *stored.borrow_mut() = Some(table);
                Err(LACKS_HOURS.to_string())
            },
            |out| {
                // Both tables' hours, unless the union would not fit: then ours alone.
                let stored = stored.take().and_then(|table| {
                    let both: Vec<bool> =
                        traced_hours.iter().zip(&table.row_of_hour).map(|(ours, row)| *ours || *row != HourRow::NotTraced).collect();
                    let suns = sun_directions(site, &both);
                    fits(&suns).then_some((table, suns))
                });
                match &stored {
                    Some((table, suns)) => Self::trace(model, coefficients, site, suns, Some(table), shade_groups, out, progress),
                    None => Self::trace(model, coefficients, site, &ours, None, shade_groups, out, progress),
                }
            },
        )
    }

    /// Writes into `out` a table of the sun-up hours of `suns` (one per hour
    /// of the year, `None` where not traced, `Some(None)` with the sun
    /// down): the rows of `stored` copied as they are (their hours keep
    /// their row numbers), the other hours traced after them, a batch of
    /// hours at a time.
    #[allow(clippy::too_many_arguments)]
    fn trace(
        model: &LightModel,
        coefficients: &SensorCoefficients,
        site: &Site,
        suns: &[Option<Option<DVec3>>],
        stored: Option<&SunHours>,
        shade_groups: usize,
        out: &mut StreamedWriter,
        progress: &(dyn Fn(f64) + Sync),
    ) -> std::io::Result<()> {
        let stored_row = |k: usize| stored.map(|table| table.row_of_hour[k]).filter(|row| *row != HourRow::NotTraced);
        let stored_rows = stored.map_or(0, SunHours::rows);
        let mut up = Vec::new();
        let row_of_hour: Vec<u32> = (0..HOURS)
            .map(|k| match (stored_row(k), suns[k]) {
                (Some(HourRow::Row(row)), _) => row,
                (Some(_), _) | (None, Some(None)) => SUN_DOWN,
                (None, Some(Some(sun))) => {
                    up.push(sun);
                    (stored_rows + up.len() - 1) as u32
                }
                (None, None) => NOT_TRACED,
            })
            .collect();
        let counts = [model.scene.sensors.len(), shade_groups, stored_rows + up.len()].map(|n| n as u32);
        out.append(&counts.into_iter().chain(row_of_hour).flat_map(u32::to_le_bytes).collect::<Vec<u8>>())?;
        if let Some(table) = stored {
            table.copy_rows(out)?;
        }
        let path = SunPath::new(model, coefficients, site, &up, None);
        let done = AtomicUsize::new(0);
        for batch in up.chunks(HOURS_PER_BATCH) {
            let rows = par_map(None, batch.len(), |r| {
                let response = coefficients.sun_response(model, batch[r], &path, Some(1));
                let through = through_shades(model, batch[r], shade_groups);
                progress((done.fetch_add(1, Ordering::Relaxed) + 1) as f64 / up.len() as f64);
                let values = response.direct.iter().chain(&response.interreflected).chain(&through);
                values.flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>()
            });
            for row in rows {
                out.append(&row)?;
            }
        }
        Ok(())
    }

    /// How many rows the file holds.
    fn rows(&self) -> usize {
        ((self.file.len() - ROWS_AT) / row_bytes(self.sensors, self.shade_groups) as u64) as usize
    }

    /// Appends every row of the file to `out`, a piece at a time.
    fn copy_rows(&self, out: &mut StreamedWriter) -> std::io::Result<()> {
        let mut piece = vec![0u8; 1 << 20];
        let mut at = ROWS_AT;
        while at < self.file.len() {
            let n = piece.len().min((self.file.len() - at) as usize);
            self.file.read_at(at, &mut piece[..n])?;
            out.append(&piece[..n])?;
            at += n as u64;
        }
        Ok(())
    }

    /// The table in `file`; `None` when it does not fit the model.
    fn open(file: StreamedReader, key: u64, model: &LightModel, shades: bool) -> Option<Self> {
        let mut head = vec![0u8; ROWS_AT as usize];
        file.read_at(0, &mut head).ok()?;
        let words: Vec<u32> = head.chunks_exact(4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes"))).collect();
        let (sensors, groups, row_count) = (words[0] as usize, words[1] as usize, words[2] as usize);
        if sensors != model.scene.sensors.len() || groups != shade_groups(model, shades) || row_count > HOURS {
            return None;
        }
        let row_of_hour = words[3..]
            .iter()
            .map(|&row| match row {
                SUN_DOWN => Some(HourRow::SunDown),
                NOT_TRACED => Some(HourRow::NotTraced),
                row if (row as usize) < row_count => Some(HourRow::Row(row)),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        (file.len() == ROWS_AT + (row_count * row_bytes(sensors, groups)) as u64).then_some(Self {
            key,
            sensors,
            shade_groups: groups,
            row_of_hour,
            file,
        })
    }

    /// What the table depends on: the scene's precomputation
    /// ([`cache::key`]), every material's light, the site, the shade groups.
    pub fn key(model: &LightModel, site: &Site, shades: bool) -> u64 {
        let scene = &model.scene;
        let mut hash = StableHash::new();
        hash.u64(model.cache_key()).u64(u64::from(FORMAT));
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
        hash.finish()
    }

    /// Whether the table was traced for this model at this site.
    pub fn fits(&self, model: &LightModel, site: &Site, shades: bool) -> bool {
        self.key == Self::key(model, site, shades) && self.sensors == model.scene.sensors.len()
    }

    /// Whether every hour of `hours` (one per hour of the year) was traced.
    pub fn holds(&self, hours: &[bool]) -> bool {
        self.row_of_hour.iter().zip(hours).all(|(row, &read)| !read || *row != HourRow::NotTraced)
    }

    /// Hour `k`'s response (hour of the 365-day year), `Ok(None)` with the
    /// sun down; an error when the hour was not traced or the file cannot
    /// be read.
    pub fn response(&self, k: usize) -> Result<Option<SunResponse>, String> {
        Ok(self.read_row(k, 0..2 * self.sensors)?.map(|mut direct| {
            let interreflected = direct.split_off(self.sensors);
            SunResponse { direct, interreflected }
        }))
    }

    /// Hour `k`'s direct sun through each shade group's windows, lux per
    /// W/m², `[group][sensor]`; `Ok(None)` with the sun down.
    pub fn through_shades(&self, k: usize) -> Result<Option<Vec<f32>>, String> {
        self.read_row(k, 2 * self.sensors..(2 + self.shade_groups) * self.sensors)
    }

    /// The values `range` of hour `k`'s row.
    fn read_row(&self, k: usize, range: std::ops::Range<usize>) -> Result<Option<Vec<f32>>, String> {
        let row = match self.row_of_hour.get(k) {
            Some(HourRow::Row(row)) => *row,
            Some(HourRow::SunDown) => return Ok(None),
            Some(HourRow::NotTraced) | None => return Err(not_traced(k)),
        };
        let offset = ROWS_AT + (row as usize * row_bytes(self.sensors, self.shade_groups) + range.start * size_of::<f32>()) as u64;
        let mut bytes = vec![0u8; range.len() * size_of::<f32>()];
        self.file.read_at(offset, &mut bytes).map_err(|e| format!("cannot read the year's sun from the light cache: {e}"))?;
        Ok(Some(bytes.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes"))).collect()))
    }
}

/// The shade groups whose direct sun a table keeps: every group of the
/// model's scene when `shades` are studied, none otherwise.
pub(super) fn shade_groups(model: &LightModel, shades: bool) -> usize {
    if shades { model.scene.shades.len() } else { 0 }
}

/// Bytes of one hour's row: each sensor's direct and interreflected sun,
/// then its direct sun through each of `shade_groups` groups' windows.
fn row_bytes(sensors: usize, shade_groups: usize) -> usize {
    (2 + shade_groups) * sensors * size_of::<f32>()
}

/// Where a year's hours get their sun: the cached table, or traced hour by
/// hour where none is kept ([`SunHours::cached`]).
pub(super) enum YearSun<'a> {
    Table(&'a SunHours),
    /// Given by the caller ([`super::AnnualOptions::sun`]); no shades.
    Given(super::HourlySun<'a>),
    Traced {
        model: &'a LightModel,
        coefficients: &'a SensorCoefficients,
        site: &'a Site,
        /// The sun's later bounces around every hour it may be asked for.
        path: SunPath,
        /// The hours it may be asked for.
        hours: Vec<bool>,
        shade_groups: usize,
    },
}

impl<'a> YearSun<'a> {
    /// Hour by hour: the sun path around the sun of the `hours` of the
    /// year at `site` (the only hours it may be asked for).
    pub(super) fn traced(
        model: &'a LightModel,
        coefficients: &'a SensorCoefficients,
        site: &'a Site,
        shades: bool,
        hours: &[bool],
    ) -> Self {
        let up: Vec<DVec3> = sun_directions(site, hours).into_iter().flatten().flatten().collect();
        let path = SunPath::new(model, coefficients, site, &up, None);
        let shade_groups = shade_groups(model, shades);
        YearSun::Traced { model, coefficients, site, path, hours: hours.to_vec(), shade_groups }
    }

    /// Hour `k`'s response, `Ok(None)` with the sun down; an error for an
    /// hour it was not made for, as the table's.
    pub(super) fn response(&self, k: usize) -> Result<Option<SunResponse>, String> {
        match self {
            YearSun::Table(table) => table.response(k),
            YearSun::Given(sun) => Ok(sun(k)),
            YearSun::Traced { model, coefficients, site, path, hours, .. } => {
                Ok(traced_sun(site, hours, k)?.map(|sun| coefficients.sun_response(model, sun, path, Some(1))))
            }
        }
    }

    /// Hour `k`'s direct sun through each shade group's windows
    /// ([`SunHours::through_shades`]), `Ok(None)` with the sun down.
    pub(super) fn through_shades(&self, k: usize) -> Result<Option<Vec<f32>>, String> {
        match self {
            YearSun::Table(table) => table.through_shades(k),
            YearSun::Given(_) => Ok(Some(Vec::new())),
            YearSun::Traced { model, site, hours, shade_groups, .. } => {
                Ok(traced_sun(site, hours, k)?.map(|sun| through_shades(model, sun, *shade_groups)))
            }
        }
    }
}

/// Hour `k`'s sun direction (`None` when down) where `hours` holds it.
fn traced_sun(site: &Site, hours: &[bool], k: usize) -> Result<Option<DVec3>, String> {
    match hours.get(k) {
        Some(true) => Ok(sun_direction(site, k)),
        _ => Err(not_traced(k)),
    }
}

/// Why hour `k` of the year's sun cannot be read.
fn not_traced(k: usize) -> String {
    format!("hour {k} of the year's sun was not traced")
}

/// The sun's direction at the middle of every hour of the year among
/// `hours` ([`sun_direction`]; `Some(None)` with the sun down), `None` for
/// the others.
pub fn sun_directions(site: &Site, hours: &[bool]) -> Vec<Option<Option<DVec3>>> {
    par_map(None, HOURS, |k| hours[k].then(|| sun_direction(site, k)))
}

/// The sun's direction in the model's frame at the middle of hour `k` of the
/// 365-day year, as [`super::hour_sky`]'s sky places it; `None` when down.
pub fn sun_direction(site: &Site, k: usize) -> Option<DVec3> {
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
    let measured = model.measured_sun(&beams);
    for i in 0..sensors {
        for (window, e) in model.sensor_sun_by_window(i, &beams, &measured) {
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

    /// The bundled test room lit, its sensor coefficients, its site and an
    /// empty cache folder named for the test.
    fn test_room(test: &str) -> (LightModel, SensorCoefficients, Site, std::path::PathBuf) {
        let scene = crate::scene::load_scene(&crate::bundled_scene("test_room"), &PanelCatalog::new()).unwrap().scene;
        let site = scene.site;
        let model = LightModel::precompute(Arc::new(scene), LightSettings::default()).unwrap();
        let coefficients = model.sensor_coefficients();
        let dir = std::env::temp_dir().join(format!("heliodon-sun-hours-{test}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        (model, coefficients, site, dir)
    }

    /// Traced hour by hour (where no table is kept) the year's sun is the
    /// cached table's, hour for hour; the table written and the same table
    /// read back are one.
    #[test]
    fn hours_traced_one_by_one_are_the_tables() {
        let (model, coefficients, site, dir) = test_room("unit");
        let every = [true; HOURS];
        let (written, outcome) =
            SunHours::cached(&model, &coefficients, &site, false, &every, &[false; HOURS], &dir, &|_| {}).expect("a small table is kept");
        assert!(matches!(outcome, CacheOutcome::Stored(_)), "{outcome:?}");
        let (read, outcome) =
            SunHours::cached(&model, &coefficients, &site, false, &every, &[false; HOURS], &dir, &|_| {}).expect("a small table is kept");
        assert!(matches!(outcome, CacheOutcome::Hit(_)), "{outcome:?}");
        let traced = YearSun::traced(&model, &coefficients, &site, false, &every);
        let mut lit = 0;
        for k in (0..HOURS).step_by(97) {
            let from_table = written.response(k).unwrap();
            assert_eq!(from_table, read.response(k).unwrap(), "hour {k}");
            assert_eq!(from_table, traced.response(k).unwrap(), "hour {k}");
            lit += usize::from(from_table.is_some_and(|r| r.direct.iter().any(|&e| e > 0.0)));
        }
        assert!(lit > 10, "{lit} sunny hours compared");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A table holds the hours it was traced for: a study reading others
    /// traces those alone and keeps the hours of both, with the same
    /// numbers as tables traced for each; an hour nobody asked for is an
    /// error, never a dark hour, from the table and from the year traced
    /// hour by hour alike. Hours worth keeping are traced with those read
    /// where the table is new, so a later study of them reads it as it is.
    #[test]
    fn a_table_traced_for_some_hours_is_traced_again_for_more_and_keeps_both() {
        let (model, coefficients, site, dir) = test_room("union");
        let month = |m: u32| -> Vec<bool> { (0..HOURS).map(|k| calendar(k).0 == m).collect() };
        let (january, july) = (month(1), month(7));
        let traced_hours = AtomicUsize::new(0);
        let cached_keeping = |hours: &[bool], worth_keeping: &[bool]| {
            traced_hours.store(0, Ordering::Relaxed);
            let count = |_| {
                traced_hours.fetch_add(1, Ordering::Relaxed);
            };
            SunHours::cached(&model, &coefficients, &site, false, hours, worth_keeping, &dir, &count).expect("kept")
        };
        let cached = |hours: &[bool]| cached_keeping(hours, &[false; HOURS]);
        let sun_up = |hours: &[bool]| (0..HOURS).filter(|&k| hours[k] && sun_direction(&site, k).is_some()).count();
        let (first, outcome) = cached(&january);
        assert!(matches!(outcome, CacheOutcome::Stored(_)), "{outcome:?}");
        assert!(first.holds(&january) && !first.holds(&july));
        let noon_in = |m: u32| (0..HOURS).find(|&k| calendar(k) == (m, 15, 13)).unwrap();
        assert!(first.response(noon_in(7)).is_err(), "an hour not traced is not read as dark");
        let traced = YearSun::traced(&model, &coefficients, &site, false, &january);
        assert!(traced.response(noon_in(7)).is_err(), "nor when the year's sun is traced hour by hour");
        assert_eq!(traced.response(noon_in(1)).unwrap(), first.response(noon_in(1)).unwrap());
        assert_eq!(traced_hours.load(Ordering::Relaxed), sun_up(&january));
        let (both, outcome) = cached(&july);
        assert!(matches!(&outcome, CacheOutcome::Rebuilt(_, why) if why == LACKS_HOURS), "{outcome:?}");
        assert!(both.holds(&january) && both.holds(&july));
        assert_eq!(traced_hours.load(Ordering::Relaxed), sun_up(&july), "January's hours are copied, not traced again");
        let (_, outcome) = cached(&january);
        assert!(matches!(outcome, CacheOutcome::Hit(_)), "{outcome:?}");
        for k in (0..HOURS).filter(|&k| january[k]) {
            assert_eq!(first.response(k).unwrap(), both.response(k).unwrap(), "hour {k}");
        }
        let july_alone = YearSun::traced(&model, &coefficients, &site, false, &july);
        for k in (0..HOURS).filter(|&k| july[k]).step_by(7) {
            assert_eq!(july_alone.response(k).unwrap(), both.response(k).unwrap(), "hour {k}");
        }
        let july_noon = both.response(noon_in(7)).unwrap().expect("the sun is up at a July noon");
        assert!(july_noon.direct.iter().chain(&july_noon.interreflected).any(|&e| e > 0.0));

        let _ = std::fs::remove_dir_all(&dir);
        let (kept, outcome) = cached_keeping(&january, &july);
        assert!(matches!(outcome, CacheOutcome::Stored(_)), "{outcome:?}");
        assert!(kept.holds(&january) && kept.holds(&july));
        assert_eq!(traced_hours.load(Ordering::Relaxed), sun_up(&january) + sun_up(&july));
        let (_, outcome) = cached(&july);
        assert!(matches!(outcome, CacheOutcome::Hit(_)), "the hours kept serve the next study: {outcome:?}");
        assert_eq!(kept.response(noon_in(7)).unwrap(), both.response(noon_in(7)).unwrap());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
