//! The annual study in the viewer: a weather file (EPW: `view --weather`
//! or opened in the annual panel); while "sky from the weather file" is on,
//! the sky of the shown date and time is the Perez sky of that EPW hour's
//! irradiance (the hour that contains the time); the year
//! ([`crate::annual::annual`]) runs in the background with its progress; and
//! the sensors are coloured by DA300, UDI or ASE hours.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use bevy::prelude::*;

use super::background::Background;
use super::schedule::ViewerSystems;
use crate::annual::{AnnualOptions, AnnualResult, SensorYear, YearSkies, annual, missing_in_daylight_note, skipped_hours_note};
use crate::ecs::{ActiveScene, LightCacheDir, LightEngine, Site, SkyChoice, SolarTime};
use crate::sky::{SkySpec, perez};
use crate::weather::Weather;

/// The annual study's state and systems.
pub struct AnnualPlugin;

impl Plugin for AnnualPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<AnnualStudy>()
            .add_systems(Update, (sky_from_weather, update_annual).in_set(ViewerSystems::Sensors))
            .add_systems(bevy_egui::EguiPrimaryContextPass, draw_metric_markers.in_set(ViewerSystems::Overlays));
    }
}

/// What the sensors can be coloured by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// % of occupied hours with at least 300 lux.
    Da300,
    /// % of occupied hours within 100-3000 lux.
    Udi,
    /// Occupied hours with at least 1000 lux of direct sun.
    AseHours,
}

impl Metric {
    /// Every metric, for the panel's choice.
    pub const ALL: [Metric; 3] = [Metric::Da300, Metric::Udi, Metric::AseHours];

    /// Its name with its unit.
    pub fn label(self) -> &'static str {
        match self {
            Metric::Da300 => "DA300 (%)",
            Metric::Udi => "UDI 100-3000 (%)",
            Metric::AseHours => "ASE1000 (hours)",
        }
    }

    /// A sensor's value.
    pub fn of(self, sensor: &SensorYear) -> f64 {
        match self {
            Metric::Da300 => sensor.da300,
            Metric::Udi => sensor.udi,
            Metric::AseHours => sensor.ase_hours as f64,
        }
    }

    /// The top of its colour scale: 100% for shares; for ASE the largest
    /// value of the year (at least LM-83's 250 hours).
    pub fn top(self, result: &AnnualResult) -> f64 {
        match self {
            Metric::AseHours => result.sensors.iter().map(|s| s.ase_hours as f64).fold(250.0, f64::max),
            _ => 100.0,
        }
    }
}

/// A linear colour scale from dark blue (0) through green to yellow and red (1).
pub fn metric_colour(t: f64) -> [f32; 3] {
    const STOPS: [[f32; 3]; 5] = [[0.05, 0.1, 0.5], [0.1, 0.5, 0.9], [0.2, 0.8, 0.3], [0.95, 0.85, 0.1], [0.9, 0.15, 0.1]];
    let t = t.clamp(0.0, 1.0) as f32 * (STOPS.len() - 1) as f32;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f32;
    [0, 1, 2].map(|c| STOPS[i][c] * (1.0 - f) + STOPS[i + 1][c] * f)
}

/// The weather file, the sky it gives and the year's result.
#[derive(Resource, Default)]
pub struct AnnualStudy {
    /// The open weather file.
    pub weather: Option<(PathBuf, Arc<Weather>)>,
    /// Whether the sky of the shown hour comes from the weather file.
    pub weather_sky: bool,
    /// The EPW hour the sky comes from, for the panels to say.
    pub hour: Option<String>,
    /// The year, keyed by the weather file and the light model.
    pub result: Background<String, Result<AnnualResult, String>>,
    /// Days done, for the progress bar.
    done: Arc<AtomicUsize>,
    /// Set by the panel's button (or `view --annual`).
    pub requested: bool,
    /// What the sensors are coloured by, if anything.
    pub colour_by: Option<Metric>,
    /// What the open weather file means at a site ([`weather_notes`]), and
    /// the site it was worked out for.
    pub notes: Option<(crate::site::Site, Vec<String>)>,
}

impl AnnualStudy {
    /// Opens an EPW file: its sky drives the view from now on.
    pub fn open(&mut self, path: &Path) -> Result<(), String> {
        let weather = Weather::read(path)?;
        self.weather = Some((path.to_path_buf(), Arc::new(weather)));
        self.weather_sky = true;
        self.result = Background::default();
        self.notes = None;
        Ok(())
    }

    /// Share of the year done while it runs.
    pub fn progress(&self) -> Option<f32> {
        self.result.is_running().then(|| self.done.load(Ordering::Relaxed) as f32 / 365.0)
    }

    /// The finished year, if any.
    pub fn year(&self) -> Option<&AnnualResult> {
        self.result.values.as_ref().and_then(|r| r.as_ref().ok())
    }
}

/// What a weather file means at `site`, said as soon as it is open (the
/// lines `annual` warns with, for the annual study and sweeps alike):
/// daylight hours with missing irradiance, lit hours with no Perez sky.
pub fn weather_notes(site: &crate::site::Site, weather: &Weather) -> Vec<String> {
    let skipped = YearSkies::new(site, weather).skipped(weather);
    missing_in_daylight_note(site, weather).into_iter().chain(skipped.as_ref().map(skipped_hours_note)).collect()
}

/// The weather file's sky for the shown date and time: the EPW hour that
/// contains it (hour h covers h − 1 to h), as a Perez sky of its direct
/// normal and diffuse horizontal irradiance; dark while the sun is below
/// the horizon (the hour of a sunset is lit up to it), as `annual` reads
/// such a time: a Perez sky cannot be made with the sun down.
fn sky_from_weather(mut study: ResMut<AnnualStudy>, time: Res<SolarTime>, site: Option<Res<Site>>, mut sky: ResMut<SkyChoice>) {
    if !study.weather_sky {
        study.hour = None;
        return;
    }
    let (Some((path, weather)), Some(site)) = (&study.weather, site) else { return };
    let when = time.0;
    let day = when.date.day_of_year().min(365) as usize - 1;
    let hour = (when.time.hours().floor() as usize).min(23);
    let row = &weather.hours[day * 24 + hour];
    let sun_down = crate::sun::solar_position(&site.0, &when).altitude <= 0.0;
    let (direct_normal, diffuse_horizontal) = if sun_down { (0.0, 0.0) } else { (row.direct_normal, row.diffuse_horizontal) };
    let spec = SkySpec::Perez(perez::Input::Irradiance { direct_normal, diffuse_horizontal });
    let label = format!(
        "Perez sky from {}: {}/{} hour {} (DNI {:.0}, DHI {:.0} W/m²){}",
        path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned()),
        row.month,
        row.day,
        row.hour,
        row.direct_normal,
        row.diffuse_horizontal,
        if sun_down && row.diffuse_horizontal > 0.0 { ", dark now: the sun is down" } else { "" }
    );
    if sky.0 != spec {
        sky.0 = spec;
    }
    if study.hour.as_ref() != Some(&label) {
        study.hour = Some(label);
    }
}

/// Starts the year when asked (once the light model is there), and collects it.
fn update_annual(mut study: ResMut<AnnualStudy>, engine: Option<Res<LightEngine>>, site: Option<Res<Site>>, cache_dir: Res<LightCacheDir>) {
    study.result.collect();
    let (Some(model), Some(site)) = (engine.and_then(|e| e.model.clone()), site) else { return };
    let key = study.weather.as_ref().map(|(path, _)| format!("{} {:?} {:?}", path.display(), Arc::as_ptr(&model), site.0));
    if study.result.key.is_some() && study.result.key != key && !study.result.is_running() {
        // The result no longer fits the weather, site or light model.
        study.result = Background::default();
    }
    if !study.requested {
        return;
    }
    let Some((_, weather)) = study.weather.clone() else { return };
    study.requested = false;
    let done = Arc::new(AtomicUsize::new(0));
    study.done = done.clone();
    let (site, dir) = (site.0, cache_dir.0.clone());
    study.result.start(key, move || {
        // The year's sun is traced once per scene and site, then read from the light cache.
        let progress = move |share: f64| done.store((share * 365.0).round() as usize, Ordering::Relaxed);
        annual(&model, &site, &weather, &AnnualOptions { sun_cache: dir.as_deref(), ..Default::default() }, &progress)
    });
}

/// With a metric chosen and the year in: each sensor a dot in the metric's
/// colour, labelled with its value when there are few.
fn draw_metric_markers(
    mut gizmos: Gizmos,
    study: Res<AnnualStudy>,
    active: Res<ActiveScene>,
    mut contexts: bevy_egui::EguiContexts,
    camera: Query<(&Camera, &GlobalTransform), crate::render::PictureCamera>,
) -> Result {
    let (Some(metric), Some(year), Some(scene)) = (study.colour_by, study.year(), &active.scene) else { return Ok(()) };
    let Ok((camera, transform)) = camera.single() else { return Ok(()) };
    let ctx = contexts.ctx_mut()?.clone();
    let top = metric.top(year);
    for (i, (sensor, result)) in scene.sensors.iter().zip(&year.sensors).enumerate() {
        let value = metric.of(result);
        let [r, g, b] = metric_colour(value / top);
        let iso = Isometry3d::new(sensor.position + sensor.normal * 0.01, Quat::from_rotation_arc(Vec3::Z, sensor.normal));
        for radius in [0.04, 0.08, 0.12] {
            gizmos.circle(iso, radius, Color::srgb(r, g, b));
        }
        if scene.sensors.len() <= 24
            && let Ok(screen) = camera.world_to_viewport(transform, sensor.position)
        {
            bevy_egui::egui::Area::new(bevy_egui::egui::Id::new(("annual", i)))
                .fixed_pos(bevy_egui::egui::pos2(screen.x + 6.0, screen.y + 4.0))
                .interactable(false)
                .show(&ctx, |ui| {
                    ui.label(
                        bevy_egui::egui::RichText::new(format!("{value:.0}"))
                            .small()
                            .background_color(bevy_egui::egui::Color32::from_black_alpha(160)),
                    );
                });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewer::files::epw;

    /// The panel says what `annual` warns about as soon as the file is
    /// open: a lit hour whose Perez sky gendaylit refuses (13 May 04:30 in
    /// Boston, the sun 0.5° up) is named; 9° further west, where the sun is
    /// not up yet at that hour, the same file says nothing.
    #[test]
    fn a_weather_files_hours_without_a_sky_are_said_when_it_opens() {
        let weather = Weather::parse_epw(&epw::boston_refused_dawn_epw(), Path::new("boston.epw")).unwrap();
        let notes = weather_notes(&crate::site::Site::new(42.37, -71.01, -5.0), &weather);
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].starts_with("1 lit hours gave no Perez sky") && notes[0].contains("5/13 hour 5"), "{notes:?}");
        let west = weather_notes(&crate::site::Site::new(42.37, -80.0, -5.0), &weather);
        assert!(west.is_empty(), "{west:?}");
    }
}
