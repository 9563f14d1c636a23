//! The interactive viewer: a window on a scene, drawn by
//! [`crate::render::HeliodonRenderPlugin`], with
//! - the CAD camera and its requests ([`camera`]),
//! - the designer's panels, one file per egui panel ([`ui`]), with the
//!   number widgets and their note ([`widgets`]) and who has the pointer
//!   ([`focus`]),
//! - sensors: markers, picking, a sensor's day and year ([`sensors`]),
//! - panel lobes ([`lobes`]), saving the view ([`capture`]),
//! - the batch flow of `view --screenshot/--hdr/--sensor` ([`batch`]).
//!
//! The modules form a one-way graph: `focus` and `widgets` are leaves;
//! `camera`, `capture`, `sensors` and `lobes` read them; `ui` reads
//! everything and nothing imports `ui`.

pub mod batch;
pub mod camera;
pub mod capture;
pub mod focus;
pub mod lobes;
pub mod sensors;
pub mod ui;
pub mod widgets;

use std::path::PathBuf;
use std::process::ExitCode;

use bevy::camera::visibility::RenderLayers;
use bevy::prelude::*;

pub use batch::ViewStart;

use crate::ecs::{ActiveScene, HeliodonPlugins, HeliodonSystems, OpenScene, RegisterPanel, SceneLoadFailed, SceneSpawned};
use crate::render::{HeliodonRenderPlugin, initial_view};
use camera::CadCamera;

/// The render layer of what is drawn over the model for the person looking
/// (sensor markers, lobe arrows): not in saved luminance pictures.
pub const OVERLAY_LAYER: usize = 1;

/// The viewer's systems, in order. In `Update`, after the scene is spawned:
/// 1. `Camera`: the camera panel's requests, then navigation;
/// 2. `Sensors`: picking, and the selected sensor's day and year tasks;
/// 3. `Overlays`: lobe arrows (after the sun and sky are updated).
///
/// In bevy_egui's `EguiPrimaryContextPass`: `Panels` (the egui panels and
/// the 3D view's viewport), then `Overlays` (sensor markers and labels).
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ViewerSystems {
    Camera,
    Sensors,
    Panels,
    Overlays,
}

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
                crate::render::hybrid_camera(),
                CadCamera::looking(Vec3::new(-8.0, -10.0, 8.0), Vec3::ZERO),
                RenderLayers::from_layers(&[0, OVERLAY_LAYER]),
            ));
        })
        .add_systems(Update, (frame_new_scene.before(ViewerSystems::Camera), exit_on_failed_load).after(HeliodonSystems::SpawnScene))
        .init_resource::<focus::PanelFocus>()
        .init_resource::<widgets::Note>()
        .add_plugins((
            ui::DesignerUiPlugin,
            camera::CameraPlugin,
            capture::CapturePlugin,
            sensors::SensorsPlugin,
            lobes::LobesPlugin,
            batch::BatchPlugin,
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

/// A scene that cannot be opened ends the viewer with its one-line error.
fn exit_on_failed_load(mut failed: MessageReader<SceneLoadFailed>, mut exit: MessageWriter<AppExit>) {
    if let Some(failure) = failed.read().last() {
        eprintln!("error: {}", failure.message);
        exit.write(AppExit::error());
    }
}
