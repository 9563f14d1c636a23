//! The interactive viewer: a window on a scene with the CAD camera
//! ([`camera`]), the designer's panels ([`ui`], [`materials`]), sensors
//! ([`sensors`]), saving the view ([`capture`]) and panel lobes
//! ([`lobes`]), drawn by [`crate::render::HeliodonRenderPlugin`]. With a
//! save request (`heliodon view SCENE --screenshot FILE --hdr FILE`, and
//! `--sensor NAME [--year]` to select a sensor and wait for its plots) it
//! waits for the light to converge, saves and exits.

pub mod camera;
pub mod capture;
pub mod lobes;
pub mod materials;
pub mod sensors;
pub mod ui;

use std::path::PathBuf;
use std::process::ExitCode;

use bevy::camera::visibility::RenderLayers;
use bevy::prelude::*;

use crate::ecs::{ActiveScene, HeliodonPlugins, HeliodonSystems, OpenScene, SceneLoadFailed, SceneSpawned};
use crate::render::{HeliodonRenderPlugin, initial_view};
use camera::CadCamera;

/// The render layer of what is drawn over the model for the person looking
/// (sensor markers, lobe arrows): not in saved luminance pictures.
pub const OVERLAY_LAYER: usize = 1;

/// Window, input and camera.
pub struct ViewerPlugin {
    pub scene: PathBuf,
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
}

impl Plugin for ViewerPlugin {
    fn build(&self, app: &mut App) {
        let scene = self.scene.clone();
        app.add_systems(Startup, move |mut open: MessageWriter<OpenScene>| {
            open.write(OpenScene(scene.clone()));
        })
        .add_systems(Startup, |mut commands: Commands, mut gizmos: ResMut<GizmoConfigStore>| {
            // The person's view shows the model and the overlays; a saved
            // luminance picture shows the model alone.
            gizmos.config_mut::<DefaultGizmoConfigGroup>().0.render_layers = RenderLayers::layer(OVERLAY_LAYER);
            commands.spawn((
                crate::render::hybrid_camera(),
                CadCamera::looking(Vec3::new(-8.0, -10.0, 8.0), Vec3::ZERO),
                RenderLayers::from_layers(&[0, OVERLAY_LAYER]),
            ));
        })
        .add_systems(
            Update,
            (frame_new_scene, exit_on_failed_load).after(HeliodonSystems::SpawnScene),
        )
        .add_plugins((ui::DesignerUiPlugin, capture::CapturePlugin))
        .add_systems(Update, camera::navigate.after(frame_new_scene))
        .add_systems(Startup, apply_view_start)
        .add_systems(Update, (select_start_sensor.after(HeliodonSystems::SpawnScene), take_screenshot.after(HeliodonSystems::Lighting)))
        .init_resource::<lobes::ShownLobes>()
        .add_systems(Update, (lobes::select_panel_window, lobes::draw_lobes).chain().after(HeliodonSystems::UpdateSunSky));
    }
}

/// Opens the window on a scene; returns when the window closes (or, with
/// `screenshot`, once it is saved).
pub fn run(scene: PathBuf, add_panels: crate::ecs::AddPanels, start: Option<ViewStart>) -> ExitCode {
    let title = format!("heliodon — {}", scene.display());
    let mut app = App::new();
    app.add_plugins(
            DefaultPlugins
                .set(WindowPlugin {
                    primary_window: Some(Window { title, resolution: (1280, 800).into(), ..default() }),
                    ..default()
                })
                .set(crate::asset_plugin()),
        )
        .add_plugins((HeliodonPlugins, HeliodonRenderPlugin, ViewerPlugin { scene }));
    add_panels(&mut app);
    if let Some(request) = start {
        app.insert_resource(request);
    }
    let exit = app.run();
    match exit {
        AppExit::Success => ExitCode::SUCCESS,
        AppExit::Error(code) => ExitCode::from(code.get()),
    }
}

fn frame_new_scene(
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    mut cameras: Query<(&mut CadCamera, &mut Projection)>,
) {
    // A new scene opens on its first view; the same one with edited materials keeps the camera.
    if spawned.read().last().is_none_or(|s| s.edited) {
        return;
    }
    let Some(scene) = &active.scene else { return };
    let view = initial_view(scene);
    for (mut cad, mut projection) in &mut cameras {
        *cad = CadCamera::from_viewpoint(&view);
        *projection = Projection::Perspective(PerspectiveProjection { fov: view.fov.to_radians(), ..default() });
    }
}

fn apply_view_start(request: Option<Res<ViewStart>>, mut time: ResMut<crate::ecs::SolarTime>, mut sky: ResMut<crate::ecs::SkyChoice>) {
    let Some(request) = request else { return };
    if let Some(when) = request.when {
        time.0 = when;
    }
    if let Some(spec) = request.sky.clone() {
        sky.0 = spec;
    }
}

/// Selects the sensor `view --sensor` names when the scene opens (and asks
/// for its year with `--year`); a name the scene lacks ends the viewer with
/// one line.
fn select_start_sensor(
    request: Option<Res<ViewStart>>,
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    mut selected: ResMut<sensors::SelectedSensor>,
    mut year: ResMut<sensors::YearMap>,
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
            eprintln!("error: --sensor {name}: {} has no sensor of that name (its sensors: {}{})", scene.files.scene.display(), names.join(", "), if scene.sensors.len() > 12 { ", …" } else { "" });
            exit.write(AppExit::error());
        }
    }
}

/// Frames drawn after the light converges before the window is saved.
const SETTLE_FRAMES: u32 = 10;

/// Saves the window (and the view's luminance) once the light has
/// converged, then exits.
#[allow(clippy::too_many_arguments)]
fn take_screenshot(
    request: Option<Res<ViewStart>>,
    lighting: Option<Res<crate::ecs::LightingState>>,
    selected: Res<sensors::SelectedSensor>,
    day: Res<sensors::DaySeries>,
    year: Res<sensors::YearMap>,
    results: Res<capture::SaveResults>,
    mut saves: MessageWriter<capture::SaveView>,
    mut frames: Local<u32>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(request) = request else { return };
    let wanted: Vec<capture::SaveView> =
        request.screenshot.clone().map(capture::SaveView::Png).into_iter().chain(request.hdr.clone().map(capture::SaveView::Hdr)).collect();
    if wanted.is_empty() {
        return;
    }
    if *frames < SETTLE_FRAMES {
        // The light has converged, and the selected sensor's day (and year) are in.
        let plots_in = selected.0.is_none() || (day.0.values.is_some() && (!request.year || year.map.values.is_some()));
        *frames = if lighting.is_some_and(|l| l.converged) && plots_in { *frames + 1 } else { 0 };
        if *frames == SETTLE_FRAMES {
            saves.write_batch(wanted);
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

/// A scene that cannot be opened ends the viewer with its one-line error.
fn exit_on_failed_load(mut failed: MessageReader<SceneLoadFailed>, mut exit: MessageWriter<AppExit>) {
    if let Some(failure) = failed.read().last() {
        eprintln!("error: {}", failure.message);
        exit.write(AppExit::error());
    }
}
