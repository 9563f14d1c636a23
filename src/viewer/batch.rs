//! The viewer as a batch job (`heliodon view SCENE --screenshot FILE`,
//! `--hdr FILE`, `--sensor NAME [--year]`, `--date`, `--time`, `--sky`,
//! `--weather FILE [--annual]`):
//! start at the given time and sky, select the sensor, wait until the light
//! has converged (and the sensor's plots are in), save, and exit.

use std::path::PathBuf;

use bevy::prelude::*;

use super::annual::{AnnualStudy, Metric};
use super::capture::{SaveResults, SaveView};
use super::sensors::{DaySeries, SelectedSensor, YearMap};
use crate::ecs::{ActiveScene, HeliodonSystems, LightEngine, LightingState, SceneSpawned, SkyChoice, SolarTime};

/// Starts the viewer as [`ViewStart`] says, when that resource is there.
pub struct BatchPlugin;

impl Plugin for BatchPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(Startup, apply_view_start).add_systems(
            Update,
            (
                select_start_sensor.after(HeliodonSystems::SpawnScene),
                refuse_a_start_sky_that_cannot_be_made,
                start_on_plan.after(HeliodonSystems::Lighting),
                take_screenshot.after(HeliodonSystems::Lighting),
            ),
        );
    }
}

/// How `view` starts: the time and sky to show and, for `--screenshot`,
/// where to save the window once the light has converged.
#[derive(Resource, Debug, Clone)]
pub struct ViewStart {
    pub screenshot: Option<PathBuf>,
    /// With or without `screenshot`: the 3D view's luminance as a Radiance picture.
    pub hdr: Option<PathBuf>,
    /// The sensor to select (its day is plotted, and waited for before saving).
    pub sensor: Option<String>,
    /// Also compute the selected sensor's year map (and wait for it).
    pub year: bool,
    pub when: Option<crate::time::LocalDateTime>,
    pub sky: Option<crate::sky::SkySpec>,
    /// A weather file to open (its hour's sky drives the view).
    pub weather: Option<PathBuf>,
    /// Run the year at once (and wait for it before saving).
    pub annual: bool,
    /// Open on the plan view once the light model is there.
    pub plan: bool,
}

fn apply_view_start(
    request: Option<Res<ViewStart>>,
    mut time: ResMut<SolarTime>,
    mut sky: ResMut<SkyChoice>,
    mut study: ResMut<AnnualStudy>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(request) = request else { return };
    if let Some(when) = request.when {
        time.0 = when;
    }
    if let Some(spec) = request.sky.clone() {
        sky.0 = spec;
    }
    if let Some(path) = &request.weather {
        if let Err(e) = study.open(path) {
            eprintln!("error: --weather {e}");
            exit.write(AppExit::error());
        }
        study.requested = request.annual;
        if request.annual {
            study.colour_by = Some(Metric::Da300);
        }
    }
}

/// Selects the sensor `view --sensor` names when the scene opens (and asks
/// for its year with `--year`); a name the scene lacks ends the viewer with
/// one line.
fn select_start_sensor(
    request: Option<Res<ViewStart>>,
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    mut selected: ResMut<SelectedSensor>,
    mut year: ResMut<YearMap>,
    mut exit: MessageWriter<AppExit>,
) {
    if spawned.read().last().is_none_or(|s| s.edited) {
        return;
    }
    let (Some(request), Some(scene)) = (request, &active.scene) else { return };
    let Some(name) = &request.sensor else { return };
    match scene.sensors.iter().position(|s| s.name == *name) {
        Some(index) => {
            selected.0 = Some(index);
            year.requested = request.year;
        }
        None => {
            let names: Vec<&str> = scene.sensors.iter().map(|s| s.name.as_str()).take(12).collect();
            eprintln!(
                "error: --sensor {name}: {} has no sensor of that name (its sensors: {}{})",
                scene.files.scene.display(),
                names.join(", "),
                if scene.sensors.len() > 12 { ", …" } else { "" }
            );
            exit.write(AppExit::error());
        }
    }
}

/// A batch run (`--screenshot`, `--hdr`) whose sky cannot be made before
/// any sky was (Perez light with the sun down at `--time`, say) would wait
/// for light forever: it ends with the reason in one line.
fn refuse_a_start_sky_that_cannot_be_made(
    request: Option<Res<ViewStart>>,
    sun_sky: Option<Res<crate::ecs::SunSky>>,
    mut rejected: MessageReader<crate::ecs::SkyRejected>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(rejected) = rejected.read().last() else { return };
    let batch = request.is_some_and(|r| r.screenshot.is_some() || r.hdr.is_some());
    if batch && sun_sky.is_none() {
        eprintln!("error: --sky: {}", rejected.message);
        exit.write(AppExit::error());
    }
}

/// Turns to the plan view (`view --plan`) once the scene's light model is
/// there: the section under the ceiling of the storey the first view is
/// in, false colour, the top view.
fn start_on_plan(
    request: Option<Res<ViewStart>>,
    engine: Res<crate::ecs::LightEngine>,
    eyes: Query<&GlobalTransform, With<crate::viewer::camera::CadCamera>>,
    mut settings: ResMut<crate::render::RenderSettings>,
    mut camera: ResMut<crate::viewer::camera::CameraControl>,
    mut done: Local<bool>,
) {
    if *done || !request.is_some_and(|r| r.plan) {
        return;
    }
    let (Some(model), Some(eye)) = (&engine.model, eyes.iter().next()) else { return };
    *done = true;
    settings.section = model.storey_section(eye.translation()).or(Some(2.5));
    settings.mode = crate::render::RenderMode::FalseColour;
    camera.request = Some(crate::viewer::camera::CameraRequest::Top);
}

/// Frames drawn after the light converges before the window is saved.
const SETTLE_FRAMES: u32 = 10;

/// Saves the window (and the view's luminance) once the light has
/// converged, then exits.
#[allow(clippy::too_many_arguments)]
fn take_screenshot(
    request: Option<Res<ViewStart>>,
    lighting: Option<Res<LightingState>>,
    engine: Option<Res<LightEngine>>,
    selected: Res<SelectedSensor>,
    day: Res<DaySeries>,
    year: Res<YearMap>,
    study: Res<AnnualStudy>,
    results: Res<SaveResults>,
    mut saves: MessageWriter<SaveView>,
    mut frames: Local<u32>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(request) = request else { return };
    let wanted: Vec<SaveView> =
        request.screenshot.clone().map(SaveView::Png).into_iter().chain(request.hdr.clone().map(SaveView::Hdr)).collect();
    if wanted.is_empty() {
        return;
    }
    if *frames < SETTLE_FRAMES {
        // The light has converged, and the selected sensor's day (and year) are in.
        let plots_in = selected.0.is_none() || (day.0.values.is_some() && (!request.year || year.map.values.is_some()));
        let year_in = !request.annual || study.result.values.is_some();
        let light_in =
            lighting.as_deref().is_some_and(|l| l.converged && engine.as_deref().is_none_or(|e| !e.is_settling(l) && !e.is_smoothing()));
        *frames = if light_in && plots_in && year_in { *frames + 1 } else { 0 };
        if *frames == SETTLE_FRAMES {
            saves.write_batch(wanted);
            match &study.result.values {
                Some(Ok(year)) => {
                    println!("sDA300/50% {:.1}%, ASE1000/250 {:.1}%, {} occupied hours", year.sda(), year.ase(), year.occupied_hours)
                }
                Some(Err(e)) => eprintln!("error: the year: {e}"),
                None => {}
            }
        }
        return;
    }
    *frames += 1;
    if results.0.len() >= wanted.len() {
        let failures: Vec<&String> = results.0.iter().filter_map(|r| r.as_ref().err()).collect();
        for failure in &failures {
            eprintln!("error: {failure}");
        }
        exit.write(if failures.is_empty() { AppExit::Success } else { AppExit::error() });
    } else if *frames > SETTLE_FRAMES + 600 {
        // A capture that never arrives must not keep the viewer open forever.
        eprintln!("error: the view was not captured");
        exit.write(AppExit::error());
    }
}
