//! Offscreen rendering: a headless app (no window, no event loop) that opens a
//! scene, draws it from a viewpoint into an image and hands back the pixels.
//! Works on any GPU or on Mesa's software Vulkan driver.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::app::ScheduleRunnerPlugin;
use bevy::camera::RenderTarget;
use bevy::log::LogPlugin;
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;

use super::{HeliodonRenderPlugin, initial_view};
use crate::ecs::{ActiveScene, HeliodonPlugins, OpenScene, SceneLoadFailed, SceneSpawned};
use crate::scene::Viewpoint;

/// What to draw.
#[derive(Debug, Clone)]
pub struct OffscreenRequest {
    pub scene: PathBuf,
    /// `None`: the scene's initial view ([`initial_view`]).
    pub view: Option<Viewpoint>,
    pub width: u32,
    pub height: u32,
}

/// An 8-bit sRGB image, row-major RGBA.
#[derive(Debug, Clone)]
pub struct RenderedImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl RenderedImage {
    pub fn save_png(&self, path: &std::path::Path) -> Result<(), String> {
        let buffer = image::RgbaImage::from_raw(self.width, self.height, self.rgba.clone())
            .ok_or("image size does not match its pixels")?;
        buffer.save(path).map_err(|e| format!("{}: cannot write image: {e}", path.display()))
    }
}

/// Frames to draw before capturing: pipelines queued in one frame are usable
/// only in a later one.
const WARM_UP_FRAMES: u32 = 5;

#[derive(Resource)]
struct Job {
    request: OffscreenRequest,
    target: Option<Handle<Image>>,
    frames_drawn: u32,
    capture_requested: bool,
    result: Arc<Mutex<Option<Result<RenderedImage, String>>>>,
}

/// Renders one image of a scene. Errors are one line.
pub fn render(request: OffscreenRequest) -> Result<RenderedImage, String> {
    let result = Arc::new(Mutex::new(None));
    App::new()
        .add_plugins(
            DefaultPlugins
                .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
                .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() })
                .set(crate::asset_plugin())
                .disable::<WinitPlugin>()
                .disable::<LogPlugin>(),
        )
        .add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO))
        .add_plugins((HeliodonPlugins, HeliodonRenderPlugin))
        .insert_resource(Job {
            request: request.clone(),
            target: None,
            frames_drawn: 0,
            capture_requested: false,
            result: result.clone(),
        })
        .add_systems(Startup, |job: Res<Job>, mut open: MessageWriter<OpenScene>| {
            open.write(OpenScene(job.request.scene.clone()));
        })
        .add_systems(Update, (spawn_camera, capture, finish).chain().after(crate::ecs::HeliodonSystems::SpawnScene))
        .run();
    let outcome = result.lock().expect("offscreen result lock").take();
    outcome.unwrap_or_else(|| Err("the renderer stopped before producing an image".into()))
}

fn spawn_camera(
    mut commands: Commands,
    mut spawned: MessageReader<SceneSpawned>,
    mut failed: MessageReader<SceneLoadFailed>,
    active: Res<ActiveScene>,
    mut job: ResMut<Job>,
    mut images: ResMut<Assets<Image>>,
) {
    if let Some(failure) = failed.read().last() {
        *job.result.lock().expect("offscreen result lock") = Some(Err(failure.message.clone()));
    }
    if spawned.read().last().is_none() {
        return;
    }
    let Some(scene) = &active.scene else { return };
    let view = job.request.view.clone().unwrap_or_else(|| initial_view(scene));
    let target = images.add(Image::new_target_texture(
        job.request.width,
        job.request.height,
        TextureFormat::Rgba8UnormSrgb,
        None,
    ));
    commands.spawn((
        Camera3d::default(),
        RenderTarget::Image(target.clone().into()),
        Projection::Perspective(PerspectiveProjection { fov: view.fov.to_radians(), ..default() }),
        Transform::from_translation(view.eye).looking_at(view.target, Vec3::Z),
    ));
    job.target = Some(target);
}

fn capture(mut commands: Commands, mut job: ResMut<Job>) {
    let Some(target) = job.target.clone() else { return };
    job.frames_drawn += 1;
    if job.frames_drawn < WARM_UP_FRAMES || job.capture_requested {
        return;
    }
    job.capture_requested = true;
    let result = job.result.clone();
    commands.spawn(Screenshot::image(target)).observe(move |captured: On<ScreenshotCaptured>| {
        let image = match captured.image.clone().try_into_dynamic() {
            Ok(dynamic) => {
                let rgba = dynamic.to_rgba8();
                Ok(RenderedImage { width: rgba.width(), height: rgba.height(), rgba: rgba.into_raw() })
            }
            Err(error) => Err(format!("cannot read back the rendered image: {error}")),
        };
        *result.lock().expect("offscreen result lock") = Some(image);
    });
}

fn finish(job: Res<Job>, mut exit: MessageWriter<AppExit>) {
    if job.result.lock().expect("offscreen result lock").is_some() {
        exit.write(AppExit::Success);
    }
}
