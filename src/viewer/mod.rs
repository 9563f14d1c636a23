//! The interactive viewer: a window on a scene, drawn by
//! [`crate::render::HeliodonRenderPlugin`], with
//! - the CAD camera and its requests ([`camera`]),
//! - the designer's panels, one file per egui panel ([`ui`]), with the
//!   number widgets and their note ([`widgets`]) and who has the pointer
//!   ([`focus`]),
//! - sensors: markers, picking, a sensor's day and year ([`sensors`]),
//! - the annual study: a weather file, its hour's sky, the year in the
//!   background and the sensors coloured by a metric ([`annual`]),
//! - sweeps of a window material's keys, applied by a click ([`sweep`]),
//! - panel lobes ([`lobes`]), saving the view ([`capture`]),
//! - drawing only when something changes ([`redraw`]),
//! - the batch flow of `view --screenshot/--hdr/--sensor` ([`batch`]),
//! - opening and saving files: the File menu, drops, recent scenes ([`files`]),
//!
//! The modules form a one-way graph: `schedule` (the system sets),
//! `focus`, `widgets` and `background` are leaves;
//! `camera`, `capture`, `sensors`, `annual`, `sweep` and `lobes` read them;
//! `files` reads `camera` and `annual`; `ui`, `batch` and `redraw` read
//! everything and nothing imports them.

pub mod annual;
pub mod background;
pub mod batch;
pub mod camera;
pub mod capture;
pub mod files;
pub mod focus;
pub mod lobes;
pub mod redraw;
pub mod schedule;
pub mod sensors;
pub mod sweep;
pub mod ui;
pub mod widgets;

use std::path::PathBuf;
use std::process::ExitCode;

use bevy::camera::visibility::RenderLayers;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;

pub use batch::ViewStart;
pub use schedule::ViewerSystems;

use crate::ecs::{ActiveScene, HeliodonPlugins, HeliodonSystems, OpenScene, RegisterPanel, SceneLoadFailed, SceneSpawned};
use crate::render::{HeliodonRenderPlugin, initial_view};
use camera::CadCamera;

/// The render layer of what is drawn over the model for the person looking
/// (sensor markers, lobe arrows): not in saved luminance pictures.
pub const OVERLAY_LAYER: usize = 1;

/// Window, input, camera, panels.
pub struct ViewerPlugin {
    pub scene: PathBuf,
}

impl Plugin for ViewerPlugin {
    fn build(&self, app: &mut App) {
        let scene = self.scene.clone();
        app.configure_sets(
            Update,
            (
                ViewerSystems::Camera.after(HeliodonSystems::SpawnScene),
                ViewerSystems::Sensors.after(HeliodonSystems::SpawnScene),
                ViewerSystems::Overlays.after(HeliodonSystems::UpdateSunSky),
            ),
        )
        .configure_sets(bevy_egui::EguiPrimaryContextPass, ViewerSystems::Panels.before(ViewerSystems::Overlays))
        .add_systems(Startup, move |mut open: MessageWriter<OpenScene>| {
            open.write(OpenScene(scene.clone()));
        })
        .add_systems(Startup, |mut commands: Commands, mut gizmos: ResMut<GizmoConfigStore>| {
            // The person's view shows the model and the overlays; a saved
            // luminance picture shows the model alone.
            gizmos.config_mut::<DefaultGizmoConfigGroup>().0.render_layers = RenderLayers::layer(OVERLAY_LAYER);
            commands.spawn((
                crate::render::picture_camera(),
                CadCamera::looking(Vec3::new(-8.0, -10.0, 8.0), Vec3::ZERO),
                RenderLayers::from_layers(&[0, OVERLAY_LAYER]),
            ));
        })
        .add_systems(
            Update,
            (frame_new_scene.before(ViewerSystems::Camera), title_names_the_scene, failed_load).after(HeliodonSystems::SpawnScene),
        )
        // The light appears as soon as the settings' own precomputation is
        // in, then smooths as the display's one replaces it.
        .insert_resource(crate::ecs::RefineForDisplay(true))
        .init_resource::<focus::PanelFocus>()
        .init_resource::<widgets::Note>()
        .add_plugins((
            ui::DesignerUiPlugin,
            camera::CameraPlugin,
            capture::CapturePlugin,
            sensors::SensorsPlugin,
            annual::AnnualPlugin,
            sweep::SweepPlugin,
            lobes::LobesPlugin,
            batch::BatchPlugin,
            files::FilesPlugin,
            redraw::RedrawPlugin,
        ));
    }
}

/// Opens the window on a scene; returns when the window closes (or, with
/// `screenshot`, once it is saved).
pub fn run(scene: PathBuf, panels: &crate::panel::PanelCatalog, start: Option<ViewStart>) -> ExitCode {
    let title = format!("heliodon — {}", scene.display());
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin { primary_window: Some(Window { title, resolution: (1280, 800).into(), ..default() }), ..default() })
            .set(crate::asset_plugin()),
    )
    .add_plugins((HeliodonPlugins, HeliodonRenderPlugin, ViewerPlugin { scene }));
    app.register_panels(panels);
    if let Some(request) = start {
        app.insert_resource(request);
    }
    let exit = app.run();
    match exit {
        AppExit::Success => ExitCode::SUCCESS,
        AppExit::Error(code) => ExitCode::from(code.get()),
    }
}

/// A new scene opens on its first view, once its ray model is there (the
/// automatic view looks for the room behind the windows); the same scene
/// with edited materials keeps the camera.
fn frame_new_scene(
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    ray_model: Option<Res<crate::ecs::RayModel>>,
    mut pending: Local<bool>,
    mut cameras: Query<(&mut CadCamera, &mut Projection)>,
) {
    if spawned.read().last().is_some_and(|s| !s.edited) {
        *pending = true;
    }
    let Some(scene) = &active.scene else { return };
    let model = ray_model.as_ref().and_then(|m| m.of(scene));
    if !*pending || (model.is_none() && scene.viewpoints.is_empty()) {
        return;
    }
    *pending = false;
    let view = initial_view(scene, model.map(|m| m.as_ref()));
    for (mut cad, mut projection) in &mut cameras {
        *cad = CadCamera::from_viewpoint(&view);
        *projection = Projection::Perspective(PerspectiveProjection { fov: view.fov.to_radians(), ..default() });
    }
}

/// The window's title names the scene file shown.
fn title_names_the_scene(
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    mut windows: Query<&mut Window, With<PrimaryWindow>>,
) {
    if spawned.read().last().is_none() {
        return;
    }
    let Some(path) = &active.path else { return };
    for mut window in &mut windows {
        window.title = format!("heliodon — {}", path.display());
    }
}

/// The first scene that cannot be opened ends the viewer with its one-line
/// error; a later one (a dropped file) leaves the open scene and says why.
fn failed_load(
    mut failed: MessageReader<SceneLoadFailed>,
    active: Res<ActiveScene>,
    mut note: ResMut<widgets::Note>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(failure) = failed.read().last() else { return };
    if active.scene.is_some() {
        note.0 = Some(format!("not opened: {}", failure.message));
    } else {
        eprintln!("error: {}", failure.message);
        exit.write(AppExit::error());
    }
}
