//! A year of weather on a scene: daylight autonomy (DA300), useful daylight
//! illuminance (UDI 100-3000) and annual sunlight exposure (ASE1000) per
//! sensor, and the scene's sDA300/50% and ASE1000/250 (IES LM-83), as the
//! contract's "Annual climate-based daylight" defines them.
//!
//! How it works:
//! 1. Each EPW hour (ending at `h`) is evaluated at `h − 0.5` local standard
//!    time, under the Perez all-weather sky of its direct normal and diffuse
//!    horizontal irradiance: the same sky `sensors --sky perez --dni --dhi`
//!    makes, so the two agree hour by hour.
//! 2. Hours with the sun below the horizon, no diffuse light or no sky that
//!    can be made read 0 lux.
//! 3. Before the first hour, every sensor's radiosity adjoint is solved once
//!    and folded into coefficients ([`crate::light::coefficients`]): per
//!    sky bin (and panel group) and per patch side's sun beams. The year's
//!    sun is traced once per hour whose sun the study reads (sun up, direct
//!    normal irradiance, occupied or kept hourly:
//!    [`AnnualOptions::hours_with_sun`]; [`SunHours`]): the direct sun
//!    (shadow rays through glass and along panel lobes) and its first
//!    bounce where the sensors' rays land, exactly; the later bounces from
//!    a sun path of 2.5° nodes. Sun positions follow the site, not the
//!    weather, and the light is linear in the sun's strength, so the table
//!    is kept in the light cache for every weather file of the site whose
//!    sunny hours it holds. A lit hour is then one product of the
//!    coefficients, the direct sky folded in ([`TotalCoefficients`]), with
//!    the hour's bin radiances plus the table's row times the hour's direct
//!    normal irradiance: no ray, no radiosity solve. Runs of whole days go in
//!    parallel; hours are independent, so the numbers do not depend on the
//!    thread count; occupied hours are counted as they come (the others
//!    are not read unless every hour is kept). The table (sensors × traced
//!    hours: 3.9 MB for the office's 150 sensors and Chicago's year) is
//!    written as it is traced and read back an hour at a time, never held
//!    whole; with no cache folder, or past [`MAX_TABLE_BYTES`] on disk,
//!    the sun is traced hour by hour instead. Memory follows sensors × sky
//!    bins and threads, not the hours: with every hour asked for
//!    (`--hourly`), each hour's readings go out in order as a run of days
//!    is done ([`AnnualOptions::hourly`]), never held for the year.
//! 4. ASE counts the direct sun alone (no sky, no interreflection).
//!
//! 5. LM-83 operable shades (`[[shades]]`): in each occupied hour a group
//!    whose windows give more than 2% of the point sensors 1000 lux or more
//!    of direct sun is lowered; the hour's DA and UDI are read on the model
//!    with those shades drawn in (one model, coefficients and sun path per
//!    combination of lowered groups that occurs), ASE with every shade up.

mod sun_hours;

use sun_hours::YearSun;
pub use sun_hours::{MAX_TABLE_BYTES, SunHours, sun_direction, sun_directions};

use std::sync::Arc;

use glam::DVec3;

use crate::light::coefficients::SunResponse;
use crate::light::{HourSky, KnownSky, LightModel, SensorCoefficients, SkyBesidePanels, SunPath, TotalCoefficients};
use crate::parallel::par_map;
use crate::site::Site;
use crate::sky::{Sky, SkyError, SkySpec, perez, sky_at};
use crate::time::{Date, LocalDateTime, TimeOfDay};
use crate::weather::{HOURS, Weather};

/// The year the 365-day calendar's dates are placed in for sun positions
/// (not a leap year; the EPW's own year column is ignored).
const CALENDAR_YEAR: i32 = 2025;

/// DA's threshold, lux.
pub const DA_LUX: f64 = 300.0;
/// UDI's band, lux: below is too little, above too much.
pub const UDI_BAND: (f64, f64) = (100.0, 3000.0);
/// ASE's threshold of direct sun, lux.
pub const ASE_LUX: f64 = 1000.0;
/// sDA: a sensor counts when its DA300 reaches this share of hours, %.
pub const SDA_SHARE: f64 = 50.0;
/// ASE1000/250: a sensor counts with at least these hours of direct sun.
pub const ASE_HOURS: usize = 250;

/// Occupied hours of each day: an EPW hour counts when its middle
/// (`h − 0.5`) lies in `[start, end)`, hours after midnight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Occupancy {
    /// Start, hours after midnight.
    pub start: f64,
    /// End, hours after midnight.
    pub end: f64,
}

impl Default for Occupancy {
    /// 08:00-18:00: EPW hours 9 to 18, 3,650 hours a year.
    fn default() -> Self {
        Self { start: 8.0, end: 18.0 }
    }
}

impl Occupancy {
    /// Parses `HH:MM-HH:MM` (the end after the start, holding the middle of
    /// at least one hour: a year of no occupied hour would read 0 everywhere).
    pub fn parse(text: &str) -> Result<Self, String> {
        let (start, end) = text.split_once('-').ok_or_else(|| format!("'{text}' is not HH:MM-HH:MM"))?;
        let start = TimeOfDay::parse(start)?.hours();
        let end = TimeOfDay::parse(end)?.hours();
        if end <= start {
            return Err(format!("'{text}': the end is not after the start"));
        }
        let occupancy = Self { start, end };
        if !(1..=24).any(|hour| occupancy.contains(hour)) {
            return Err(format!(
                "'{text}' holds no hour: an EPW hour is occupied when its middle (08:30 for the hour ending 09:00) lies in the range, its start included and its end not"
            ));
        }
        Ok(occupancy)
    }

    /// Whether EPW hour `hour` (1-24, ending at `hour`) is occupied.
    pub fn contains(&self, hour: u32) -> bool {
        let middle = hour as f64 - 0.5;
        (self.start..self.end).contains(&middle)
    }
}

/// One sensor's year.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorYear {
    /// The sensor's name.
    pub name: String,
    /// A point sensor (grid points included), not an area sensor: the
    /// scene's sDA and ASE count these.
    pub point: bool,
    /// % of occupied hours with at least [`DA_LUX`].
    pub da300: f64,
    /// % of occupied hours below [`UDI_BAND`].0.
    pub udi_low: f64,
    /// % of occupied hours within [`UDI_BAND`].
    pub udi: f64,
    /// % of occupied hours above [`UDI_BAND`].1.
    pub udi_high: f64,
    /// Occupied hours with at least [`ASE_LUX`] of direct sun.
    pub ase_hours: usize,
}

/// A year's result.
#[derive(Debug, Clone, PartialEq)]
pub struct AnnualResult {
    /// Per sensor of the scene, in its order.
    pub sensors: Vec<SensorYear>,
    /// Occupied hours of the year.
    pub occupied_hours: usize,
    /// Occupied hours with some shade group down.
    pub shaded_hours: usize,
    /// Lit hours whose sky could not be made (they read 0): how many, and
    /// the first ("month/day hour h") with why ([`YearSkies::skipped`]).
    pub skipped: Option<(usize, String)>,
}

impl AnnualResult {
    /// sDA300/50%: % of point sensors with DA300 ≥ 50%.
    pub fn sda(&self) -> f64 {
        self.share(|s| s.da300 >= SDA_SHARE)
    }

    /// ASE1000/250: % of point sensors with at least 250 hours of direct sun ≥ 1000 lux.
    pub fn ase(&self) -> f64 {
        self.share(|s| s.ase_hours >= ASE_HOURS)
    }

    /// The per-sensor table as `annual --format csv` prints it.
    pub fn csv(&self) -> String {
        let mut out = String::from("name,da300,udi_low,udi,udi_high,ase_hours\n");
        for s in &self.sensors {
            out += &format!(
                "{},{:.1},{:.1},{:.1},{:.1},{}\n",
                crate::report::csv_field(&s.name),
                s.da300,
                s.udi_low,
                s.udi,
                s.udi_high,
                s.ase_hours
            );
        }
        out
    }

    fn share(&self, counts: impl Fn(&SensorYear) -> bool) -> f64 {
        let points: Vec<&SensorYear> = self.sensors.iter().filter(|s| s.point).collect();
        if points.is_empty() {
            return 0.0;
        }
        100.0 * points.iter().filter(|s| counts(s)).count() as f64 / points.len() as f64
    }
}

/// Occupied hours counted per sensor: DA300, UDI low, UDI, UDI high, ASE.
#[derive(Debug, Clone, Default)]
struct Tally {
    counts: Vec<[u32; 5]>,
    occupied: usize,
    /// Occupied hours with some shade down.
    shaded: usize,
}

impl Tally {
    fn new(sensors: usize) -> Self {
        Self { counts: vec![[0; 5]; sensors], ..Default::default() }
    }

    /// One occupied hour: each sensor's (total, direct sun) lux, `None`
    /// when dark; `shaded` when some shade was down.
    fn count(&mut self, readings: Option<&[(f64, f64)]>, shaded: bool) {
        self.occupied += 1;
        self.shaded += usize::from(shaded);
        for (s, count) in self.counts.iter_mut().enumerate() {
            let (total, sun) = readings.map_or((0.0, 0.0), |r| r[s]);
            count[0] += u32::from(total >= DA_LUX);
            count[1] += u32::from(total < UDI_BAND.0);
            count[2] += u32::from((UDI_BAND.0..=UDI_BAND.1).contains(&total));
            count[3] += u32::from(total > UDI_BAND.1);
            count[4] += u32::from(sun >= ASE_LUX);
        }
    }

    /// Counts are whole numbers: merging in any order gives the same tally.
    fn merge(mut self, other: &Tally) -> Self {
        for (mine, theirs) in self.counts.iter_mut().zip(&other.counts) {
            for (a, b) in mine.iter_mut().zip(theirs) {
                *a += b;
            }
        }
        self.occupied += other.occupied;
        self.shaded += other.shaded;
        self
    }
}

/// The local time an EPW hour is evaluated at: its middle.
pub fn hour_time(month: u32, day: u32, hour: u32) -> LocalDateTime {
    LocalDateTime {
        date: Date::new(CALENDAR_YEAR, month, day).expect("a day of the 365-day calendar"),
        time: TimeOfDay::from_hours(hour as f64 - 0.5).expect("an hour of the day"),
    }
}

/// What is said (the CLI's warnings, the viewer's annual panel) of the
/// hours of `weather` with the sun up at `site` and missing irradiance
/// (9999), if any: they are read as 0.
pub fn missing_in_daylight_note(site: &Site, weather: &Weather) -> Option<String> {
    let missing = weather
        .hours
        .iter()
        .filter(|h| h.missing && crate::sun::solar_position(site, &hour_time(h.month, h.day, h.hour)).altitude > 0.0)
        .count();
    (missing > 0)
        .then(|| format!("{missing} daylight hours have no direct or diffuse irradiance (9999); their missing values are taken as 0"))
}

/// What is said of the lit hours with no Perez sky, given as
/// [`YearSkies::skipped`] gives them.
pub fn skipped_hours_note((count, first): &(usize, String)) -> String {
    format!("{count} lit hours gave no Perez sky; they read 0 lux (the first, {first})")
}

/// The Perez sky of one EPW hour at the site, or `None` when the hour is
/// dark (sun below the horizon, no diffuse light); an error when the hour is
/// lit but its sky cannot be made, or is gendaylit's dark error sky
/// ([`Sky::refused`]): such an hour reads 0 lux, as `sensors` reads it,
/// and is counted ([`AnnualResult::skipped`]).
pub fn hour_sky(site: &Site, when: &LocalDateTime, direct_normal: f64, diffuse_horizontal: f64) -> Result<Option<Sky>, SkyError> {
    // Most dark hours (nights) have no diffuse light: no sun position or sky is needed for them.
    if diffuse_horizontal <= 0.0 {
        return Ok(None);
    }
    let spec = SkySpec::Perez(perez::Input::Irradiance { direct_normal, diffuse_horizontal });
    let (sun, sky) = sky_at(site, &spec, when);
    if sun.altitude <= 0.0 {
        return Ok(None);
    }
    match sky? {
        Sky { refused: Some(why), .. } => Err(SkyError(why)),
        sky => Ok(Some(sky)),
    }
}

/// Makes the light model of the scene with the given shade groups down
/// (indices into [`crate::scene::Scene::shades`]), as
/// [`crate::scene::Scene::with_shades_down`] draws it.
pub type ShadedModel<'a> = &'a (dyn Fn(&[usize]) -> Result<LightModel, String> + Sync);

/// The share of a year's progress given to tracing its sun, when a run
/// makes the table (most of the work; the hours are the rest).
pub const SUN_TRACING_SHARE: f64 = 0.95;

/// LM-83's rule: a shade group goes down when more than this share of the
/// point sensors get [`ASE_LUX`] or more of direct sun through its windows.
const SHADE_SENSOR_SHARE: f64 = 0.02;

/// How a year is studied, beyond the model and the weather.
#[derive(Clone, Copy, Default)]
pub struct AnnualOptions<'a> {
    /// The occupied hours of each day.
    pub occupancy: Occupancy,
    /// The scene's `[[shades]]` (LM-83), when studied: makes the models
    /// with shades down.
    pub shades: Option<ShadedModel<'a>>,
    /// Where every hour's total lux goes, when asked for ([`HourlyReadings`]).
    pub hourly: Option<HourlyReadings<'a>>,
    /// The model's sensor coefficients, when the caller has them already
    /// (a sweep of panel keys keeps one set for every combination).
    pub coefficients: Option<&'a SensorCoefficients>,
    /// The year's sun on the model at the site, when the caller has it
    /// ([`SunHours::cached`]); made by the run otherwise (through
    /// `sun_cache`). With shades
    /// studied it must keep the shade groups' sun, and it must hold the
    /// study's [`Self::hours_with_sun`].
    pub sun_hours: Option<&'a SunHours>,
    /// Where the run keeps the year's sun and the sensor coefficients it
    /// makes (the light cache folder), so the next year of the same scene
    /// and site reads them; `None`: made for this run only.
    pub sun_cache: Option<&'a std::path::Path>,
    /// The year's sun given hour by hour instead of traced or read from
    /// `sun_hours`, for the study's [`Self::hours_with_sun`]: a sweep of
    /// panel keys reads its lobes' bounces from a [`crate::light::LobeTable`].
    /// Not with shades studied.
    pub sun: Option<HourlySun<'a>>,
    /// The year's skies, when the caller has them ([`YearSkies::new`] of
    /// the same site and weather, or [`YearSkies::binned`] and
    /// [`YearSkies::beside_panels`] on this model or one that differs from
    /// it in those panels alone); made by the run otherwise.
    pub skies: Option<&'a YearSkies>,
}

/// Every hour's Perez sky of a year of weather at a site ([`hour_sky`]),
/// and, for studies of one room, what they read of each lit sky alike
/// ([`Self::binned`], [`Self::beside_panels`]): what many studies of one
/// year on one room share (a sweep's combinations).
/// A clone shares the skies and bins (a year of MF:4 bins is about 160 MB).
#[derive(Clone)]
pub struct YearSkies {
    skies: Arc<Vec<Result<Option<Sky>, SkyError>>>,
    /// Per hour, [`LightModel::sphere_bins`] of its sky, when kept.
    bins: Arc<Vec<Option<Vec<f64>>>>,
    /// Per hour, its sky light beside some panels, when kept.
    beside: Vec<Option<SkyBesidePanels>>,
}

impl YearSkies {
    /// The skies of `weather`'s hours at `site`.
    pub fn new(site: &Site, weather: &Weather) -> Self {
        let skies = par_map(None, HOURS, |k| {
            let hour = &weather.hours[k];
            hour_sky(site, &hour_time(hour.month, hour.day, hour.hour), hour.direct_normal, hour.diffuse_horizontal)
        });
        Self { skies: Arc::new(skies), bins: Arc::default(), beside: Vec::new() }
    }

    /// How many lit hours have no sky ([`hour_sky`]'s errors: they read
    /// 0), and the first of them ("month/day hour h") with why; `None`
    /// when every lit hour has its sky.
    pub fn skipped(&self, weather: &Weather) -> Option<(usize, String)> {
        let mut refused = self.skies.iter().enumerate().filter_map(|(k, sky)| sky.as_ref().err().map(|why| (k, why)));
        let (k, why) = refused.next()?;
        let hour = &weather.hours[k];
        Some((1 + refused.count(), format!("{}/{} hour {}: {why}", hour.month, hour.day, hour.hour)))
    }

    /// The skies with their radiance over `model`'s sphere bins, for
    /// studies on `model` and on models that differ from it in panels alone.
    pub fn binned(site: &Site, weather: &Weather, model: &LightModel) -> Self {
        let mut year = Self::new(site, weather);
        year.bins = Arc::new(par_map(None, HOURS, |k| year.sky(k).map(|sky| model.sphere_bins(sky))));
        year
    }

    /// Keeps every lit hour's sky light beside the panels of `groups`
    /// ([`TotalCoefficients::sky_beside_panels`]), for studies on models
    /// that differ from `model` only in those panels: they read only what
    /// the panels pass.
    pub fn beside_panels(mut self, model: &LightModel, totals: &TotalCoefficients, groups: &[u32]) -> Self {
        self.beside = par_map(None, HOURS, |k| {
            let sky = self.sky(k)?;
            Some(totals.sky_beside_panels(model, sky, self.bins.get(k).and_then(Option::as_deref), groups))
        });
        self
    }

    fn sky(&self, k: usize) -> Option<&Sky> {
        self.skies[k].as_ref().ok().and_then(Option::as_ref)
    }

    /// What hour `k`'s readings take from here.
    fn known(&self, k: usize) -> KnownSky<'_> {
        KnownSky { bins: self.bins.get(k).and_then(Option::as_deref), beside_panels: self.beside.get(k).and_then(Option::as_ref) }
    }
}

/// Hour `k` of the year's sun at every sensor per W/m² of direct normal
/// irradiance; `None` with the sun down.
pub type HourlySun<'a> = &'a (dyn Fn(usize) -> Option<SunResponse> + Sync);

/// Takes hour `k` of the year's total lux at every sensor (0 in the dark),
/// called for every hour in order, from the thread running the year; an
/// error stops the year with it.
pub type HourlyReadings<'a> = &'a (dyn Fn(usize, &[f32]) -> Result<(), String> + Sync);

/// Days read together before their hours go out in order
/// ([`AnnualOptions::hourly`]): memory follows sensors × these days' hours,
/// not the year, and the cores share the days of a run.
const DAYS_PER_RUN: usize = 16;

impl AnnualOptions<'_> {
    /// The hours of `weather`'s year whose sun the study reads (one per
    /// hour): lit, with direct normal irradiance, and occupied, or any such
    /// hour when every hour is kept. Without a light cache the year's sun
    /// is traced for these alone; a table stored there holds every sunny
    /// hour ([`SunHours`]).
    pub fn hours_with_sun(&self, weather: &Weather) -> Vec<bool> {
        weather.hours.iter().map(|h| has_sun(h) && (self.hourly.is_some() || self.occupancy.contains(h.hour))).collect()
    }
}

/// Whether an hour of weather has sun a study may read: direct normal
/// irradiance, and diffuse light (an hour without is dark).
fn has_sun(hour: &crate::weather::WeatherHour) -> bool {
    hour.direct_normal > 0.0 && hour.diffuse_horizontal > 0.0
}

/// Runs the year. With `options.shades`, every occupied hour lowers the
/// groups whose windows let too much direct sun onto the point sensors and
/// reads DA and UDI with them down (ASE always with every shade up).
/// `progress` hears the share of days done (from any thread). Fails only
/// when a shaded model cannot be made, the cached year's sun cannot be
/// read or `options.hourly` fails.
pub fn annual(
    model: &LightModel,
    site: &Site,
    weather: &Weather,
    options: &AnnualOptions,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<AnnualResult, String> {
    let AnnualOptions { occupancy, shades, hourly, .. } = *options;
    let scene = &model.scene;
    let sensor_count = scene.sensors.len();
    // Through the light cache where the run has one.
    let solve = |model: &LightModel| match options.sun_cache {
        Some(dir) => model.sensor_coefficients_cached(dir).0,
        None => model.sensor_coefficients(),
    };
    let own;
    let coefficients = match options.coefficients {
        Some(coefficients) => coefficients,
        None => {
            own = solve(model);
            &own
        }
    };
    let groups = sun_hours::shade_groups(model, shades.is_some());
    if groups > 16 {
        return Err(format!("{} shade groups: at most 16 are studied together", groups));
    }
    // Tracing the year's sun, when it falls to us, is most of the work.
    let with_sun = options.hours_with_sun(weather);
    let own_table;
    let year_sun = match (options.sun_hours, options.sun) {
        (_, Some(_)) if shades.is_some() => return Err("a year's sun given hour by hour cannot study shades".into()),
        (_, Some(given)) => YearSun::Given(given),
        (Some(table), _) if !table.fits(model, site, shades.is_some()) => {
            return Err("the year's sun was traced for another scene, site or shade study".into());
        }
        (Some(table), _) if !table.holds(&with_sun) => return Err("the year's sun was traced for other hours than this study reads".into()),
        (Some(table), _) => YearSun::Table(table),
        (None, None) => match options.sun_cache.and_then(|dir| {
            // A stored table serves the site's next studies too (`--hourly`,
            // other occupied hours): every sunny hour is worth keeping.
            let sunny: Vec<bool> = weather.hours.iter().map(has_sun).collect();
            let progress = |done| progress(SUN_TRACING_SHARE * done);
            SunHours::cached(model, coefficients, site, shades.is_some(), &with_sun, &sunny, dir, &progress)
        }) {
            Some((table, _)) => {
                own_table = table;
                YearSun::Table(&own_table)
            }
            None => YearSun::traced(model, coefficients, site, shades.is_some(), &with_sun),
        },
    };
    let tracing_share = if options.sun_hours.is_none() && matches!(year_sun, YearSun::Table(_)) { SUN_TRACING_SHARE } else { 0.0 };
    let own_skies;
    let year_skies = match options.skies {
        Some(skies) => skies,
        None => {
            own_skies = YearSkies::new(site, weather);
            &own_skies
        }
    };
    let skies = &year_skies.skies;
    let lit = |k: usize| skies[k].as_ref().ok().and_then(Option::as_ref);

    // Which shade groups are down in each hour (a bit per group), and the
    // light with each combination that occurs: a model, its coefficients
    // and its sun path around the suns of the hours it reads.
    let down: Vec<u32> = par_map(None, HOURS, |k| match lit(k) {
        Some(sky) if groups > 0 && with_sun[k] && occupancy.contains(weather.hours[k].hour) => {
            Ok(shades_down(model, year_sun.through_shades(k)?.as_deref(), sky))
        }
        _ => Ok(0),
    })
    .into_iter()
    .collect::<Result<_, String>>()?;
    let combinations: std::collections::BTreeSet<u32> = down.iter().copied().filter(|&m| m != 0).collect();
    let shaded_models: Vec<(u32, LightModel)> = combinations
        .into_iter()
        .map(|mask| {
            let lowered: Vec<usize> = (0..groups).filter(|g| mask & (1 << g) != 0).collect();
            Ok((mask, shades.expect("shades are studied")(&lowered)?))
        })
        .collect::<Result<_, String>>()?;
    let shaded: Vec<(u32, &LightModel, SensorCoefficients, SunPath)> = shaded_models
        .iter()
        .map(|(mask, model)| {
            let coefficients = solve(model);
            let suns: Vec<DVec3> = (0..HOURS).filter(|&k| down[k] == *mask).filter_map(|k| lit(k)?.sun).map(|s| s.direction).collect();
            let path = SunPath::new(model, &coefficients, site, &suns, None);
            (*mask, model, coefficients, path)
        })
        .collect();

    let totals = coefficients.totals(model);
    let days = HOURS / 24;
    // A day's hours: per sensor (total with the hour's shades, direct sun
    // with every shade up); `None` when the hour is dark or not read. The
    // open room's hours are read together ([`TotalCoefficients::readings_of_hours`]).
    type SensorsHour = Vec<(f64, f64)>;
    let day_readings = |d: usize| -> Result<Vec<Option<SensorsHour>>, String> {
        let read = |k: usize| hourly.is_some() || occupancy.contains(weather.hours[k].hour);
        let lit_hours: Vec<(usize, &Sky)> = (d * 24..(d + 1) * 24).filter(|&k| read(k)).filter_map(|k| Some((k, lit(k)?))).collect();
        let suns =
            lit_hours.iter().map(|&(k, _)| if with_sun[k] { year_sun.response(k) } else { Ok(None) }).collect::<Result<Vec<_>, _>>()?;
        let hours: Vec<HourSky> = (lit_hours.iter().zip(&suns))
            .map(|(&(k, sky), sun)| HourSky { sky, known: year_skies.known(k), response: sun.as_ref() })
            .collect();
        let mut readings = vec![None; 24];
        for ((k, sky), open) in lit_hours.into_iter().zip(totals.readings_of_hours(model, &hours)) {
            readings[k - d * 24] = Some(match shaded.iter().find(|(mask, ..)| *mask == down[k]) {
                Some((_, shaded_model, coefficients, path)) => {
                    let lowered = coefficients.readings_on_path(shaded_model, sky, path, Some(1));
                    lowered.iter().zip(&open).map(|(l, o)| (l.total, o.direct_sun)).collect()
                }
                None => open.iter().map(|r| (r.total, r.direct_sun)).collect(),
            });
        }
        Ok(readings)
    };
    // One day: its tally of occupied hours and, when every hour is asked
    // for, its hours' totals.
    let day = |d: usize| -> Result<(Tally, Vec<Vec<f32>>), String> {
        let mut tally = Tally::new(sensor_count);
        let mut hours = Vec::new();
        let readings = day_readings(d)?;
        for ((hour, &lowered), readings) in weather.hours.iter().zip(&down).skip(d * 24).take(24).zip(readings) {
            if occupancy.contains(hour.hour) {
                tally.count(readings.as_deref(), lowered != 0);
            }
            if hourly.is_some() {
                hours.push(readings.map_or_else(|| vec![0.0; sensor_count], |r| r.iter().map(|v| v.0 as f32).collect()));
            }
        }
        Ok((tally, hours))
    };
    // Runs of days on every core; hours are independent, so the split does
    // not change a number, and each run's hours go out before the next.
    let mut tally = Tally::new(sensor_count);
    for first in (0..days).step_by(DAYS_PER_RUN) {
        let run = par_map(None, DAYS_PER_RUN.min(days - first), |d| day(first + d));
        for (d, result) in run.into_iter().enumerate() {
            let (day_tally, hours) = result?;
            tally = tally.merge(&day_tally);
            if let Some(hourly) = hourly {
                for (h, readings) in hours.iter().enumerate() {
                    hourly((first + d) * 24 + h, readings)?;
                }
            }
        }
        progress(tracing_share + (1.0 - tracing_share) * (first + DAYS_PER_RUN).min(days) as f64 / days as f64);
    }
    let occupied_hours = tally.occupied;
    let percent = |n: u32| if occupied_hours == 0 { 0.0 } else { 100.0 * f64::from(n) / occupied_hours as f64 };
    let sensors = scene
        .sensors
        .iter()
        .zip(&tally.counts)
        .map(|(sensor, c)| SensorYear {
            name: sensor.name.clone(),
            point: sensor.size.is_none(),
            da300: percent(c[0]),
            udi_low: percent(c[1]),
            udi: percent(c[2]),
            udi_high: percent(c[3]),
            ase_hours: c[4] as usize,
        })
        .collect();
    Ok(AnnualResult { sensors, occupied_hours, shaded_hours: tally.shaded, skipped: year_skies.skipped(weather) })
}

/// The shade groups (a bit each) that LM-83 lowers under `sky`, given the
/// hour's direct sun through each group's windows per W/m² (`[group][sensor]`,
/// `None` with the sun down): more than 2% of the point sensors get at
/// least [`ASE_LUX`] of direct sun through the group's windows.
fn shades_down(model: &LightModel, through_shades: Option<&[f32]>, sky: &Sky) -> u32 {
    let scene = &model.scene;
    let (Some(sun), Some(through_shades)) = (sky.sun_up(), through_shades) else { return 0 };
    let sensors = scene.sensors.len();
    let points: Vec<usize> = (0..sensors).filter(|&i| scene.sensors[i].size.is_none()).collect();
    (0..scene.shades.len())
        .filter(|&g| {
            let through = &through_shades[g * sensors..(g + 1) * sensors];
            let sunny = points.iter().filter(|&&i| sun.normal_irradiance() * f64::from(through[i]) >= ASE_LUX).count();
            sunny as f64 > SHADE_SENSOR_SHARE * points.len() as f64
        })
        .fold(0, |mask, g| mask | 1 << g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_occupancy_is_epw_hours_9_to_18() {
        let occupied: Vec<u32> = (1..=24).filter(|&h| Occupancy::default().contains(h)).collect();
        assert_eq!(occupied, (9..=18).collect::<Vec<_>>());
        let evening = Occupancy::parse("17:00-21:30").unwrap();
        assert_eq!((1..=24).filter(|&h| evening.contains(h)).collect::<Vec<_>>(), vec![18, 19, 20, 21]);
        assert!(Occupancy::parse("18:00-08:00").is_err());
        assert!(Occupancy::parse("08:00-08:30").is_err_and(|e| e.contains("holds no hour")));
        assert_eq!((1..=24).filter(|&h| Occupancy::parse("08:00-08:31").unwrap().contains(h)).collect::<Vec<_>>(), vec![9]);
        assert!(Occupancy::parse("8-18").is_err());
    }

    #[test]
    fn hours_are_evaluated_at_their_middle() {
        let when = hour_time(6, 21, 13);
        assert_eq!((when.date.month, when.date.day), (6, 21));
        assert_eq!(when.time.hours(), 12.5);
    }

    #[test]
    fn dark_hours_have_no_sky() {
        let site = Site::new(41.98, -87.92, -6.0);
        let night = hour_time(1, 15, 2);
        assert!(matches!(hour_sky(&site, &night, 0.0, 50.0), Ok(None)));
        let noon = hour_time(6, 21, 13);
        assert!(matches!(hour_sky(&site, &noon, 700.0, 0.0), Ok(None)));
        assert!(matches!(hour_sky(&site, &noon, 700.0, 200.0), Ok(Some(_))));
        // Sydney, 13 November 18:30: the sun 0.5° up, a sky gendaylit refuses (b > 0).
        let sydney = Site::new(-33.87, 151.21, 10.0);
        let sunset = hour_time(11, 13, 19);
        let refused = hour_sky(&sydney, &sunset, 260.0, 23.0).expect_err("gendaylit's error sky is no sky");
        assert!(refused.0.contains("positive parameter b"), "{refused}");
    }
}
