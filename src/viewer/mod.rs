//! The interactive viewer: a window on a scene with the CAD camera
//! ([`camera`]), drawn by [`crate::render::HeliodonRenderPlugin`].

pub mod camera;
pub mod lobes;

use std::path::PathBuf;
use std::process::ExitCode;

use bevy::prelude::*;

use crate::ecs::{ActiveScene, HeliodonPlugins, HeliodonSystems, OpenScene, SceneLoadFailed, SceneSpawned};
use crate::render::{HeliodonRenderPlugin, initial_view};
use camera::CadCamera;

/// Window, input and camera.
pub struct ViewerPlugin {
    pub scene: PathBuf,
}

impl Plugin for ViewerPlugin {
    fn build(&self, app: &mut App) {
        let scene = self.scene.clone();
        app.add_systems(Startup, move |mut open: MessageWriter<OpenScene>| {
            open.write(OpenScene(scene.clone()));
        })
        .add_systems(Startup, |mut commands: Commands| {
            commands.spawn((crate::render::hybrid_camera(), CadCamera::looking(Vec3::new(-8.0, -10.0, 8.0), Vec3::ZERO)));
        })
        .add_systems(
            Update,
            (frame_new_scene, exit_on_failed_load).after(HeliodonSystems::SpawnScene),
        )
        .add_systems(Update, camera::navigate.after(frame_new_scene))
        .init_resource::<lobes::ShownLobes>()
        .add_systems(Update, (lobes::select_panel_window, lobes::draw_lobes).chain().after(HeliodonSystems::UpdateSunSky));
    }
}

/// Opens the window on a scene; returns when the window closes.
pub fn run(scene: PathBuf, add_panels: crate::ecs::AddPanels) -> ExitCode {
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
    if spawned.read().last().is_none() {
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
