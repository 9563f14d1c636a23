//! Offscreen rendering: a headless app (no window, no event loop) that opens a
//! scene, lets the light engine converge, draws it from a viewpoint with the
//! hybrid renderer and hands back two images of the same frame: the picture
//! (exposed, tone-mapped, 8-bit sRGB) and the physical values (linear RGB in
//! cd/m², no exposure, no tone mapping). Works on any GPU or on Mesa's
//! software Vulkan driver.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::app::ScheduleRunnerPlugin;
use bevy::camera::{Exposure, RenderTarget};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::log::LogPlugin;
use bevy::prelude::*;
use bevy::render::render_resource::{CachedPipelineState, PipelineCache, TextureFormat};
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::render::{Render, RenderApp, RenderPlugin, RenderSystems};
use bevy::shader::ShaderCacheError;
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;

use super::sun_pass::SunPassInput;
use super::{HeliodonRenderPlugin, PhysicalUnits, RenderMode, RenderSettings, hybrid_camera, initial_view, picture_camera};
use crate::ecs::{
    ActiveScene, HeliodonPlugins, LightingFailed, LightingPlugin, LightingState, OpenScene, RayModel, RegisterPanel, SceneLoadFailed,
    SceneSpawned, SkyChoice, SolarTime, SunSky,
};
use crate::scene::Viewpoint;
use crate::sky::{LUMINOUS_EFFICACY, SkySpec};
use crate::time::LocalDateTime;

/// What to draw.
#[derive(Debug, Clone)]
pub struct OffscreenRequest {
    pub scene: PathBuf,
    /// `None`: the scene's initial view ([`initial_view`]).
    pub view: Option<Viewpoint>,
    /// The vertical field of view (degrees) in place of the view's own,
    /// the initial view's too: it is found as the scene spawns, from the
    /// light model the picture is drawn with.
    pub fov: Option<f32>,
    pub width: u32,
    pub height: u32,
    /// Local time at the site; `None`: the app's default.
    pub when: Option<LocalDateTime>,
    /// `None`: the app's default sky.
    pub sky: Option<SkySpec>,
    pub settings: RenderSettings,
    /// The light engine's settings (a converged reference draws with more rays).
    pub light: crate::light::LightSettings,
    /// The panel types the scene may name.
    pub panels: crate::panel::PanelCatalog,
}

/// One rendered frame.
#[derive(Debug, Clone)]
pub struct RenderedImage {
    pub width: u32,
    pub height: u32,
    /// The picture: 8-bit sRGB, row-major RGBA.
    pub rgba: Vec<u8>,
    /// The physical image: linear RGB luminance per channel, cd/m², row-major.
    pub physical: Vec<[f32; 3]>,
}

impl RenderedImage {
    pub fn save_png(&self, path: &Path) -> Result<(), String> {
        let buffer =
            image::RgbaImage::from_raw(self.width, self.height, self.rgba.clone()).ok_or("image size does not match its pixels")?;
        buffer.save(path).map_err(|e| format!("{}: cannot write image: {e}", path.display()))
    }

    /// Writes the physical image as a Radiance picture (RGBE): radiance in
    /// W/sr/m² per channel, so Radiance's tools (ximage, pcond, pvalue)
    /// read the same luminance (179 lm/W).
    pub fn save_hdr(&self, path: &Path) -> Result<(), String> {
        save_hdr(path, self.width, self.height, &self.physical)
    }
}

/// Writes luminance pixels (cd/m², row-major) as a Radiance picture (RGBE,
/// run-length encoded by `image`'s HDR encoder) in W/sr/m² per channel
/// (179 lm/W), as Radiance's tools expect.
pub fn save_hdr(path: &Path, width: u32, height: u32, physical: &[[f32; 3]]) -> Result<(), String> {
    let radiance: Vec<image::Rgb<f32>> =
        physical.iter().map(|p| image::Rgb(p.map(|c| if c.is_finite() { c.max(0.0) / LUMINOUS_EFFICACY as f32 } else { 0.0 }))).collect();
    let fail = |e: &dyn std::fmt::Display| format!("{}: cannot write image: {e}", path.display());
    let file = std::fs::File::create(path).map_err(|e| fail(&e))?;
    let mut writer = std::io::BufWriter::new(file);
    image::codecs::hdr::HdrEncoder::new(&mut writer).encode(&radiance, width as usize, height as usize).map_err(|e| fail(&e))?;
    writer.flush().map_err(|e| fail(&e))
}

/// Frames to draw once the light is ready before capturing: pipelines
/// queued in one frame are usable only in a later one, and new vertex
/// values reach the GPU a frame later.
const WARM_UP_FRAMES: u32 = 5;

/// Exposure value at which the view's exposure factor is 1 (Bevy: 2^-EV / 1.2).
pub fn unit_exposure() -> Exposure {
    Exposure { ev100: (1.0f32 / 1.2).log2() }
}

#[derive(Resource)]
struct Job {
    request: OffscreenRequest,
    targets: Option<[Handle<Image>; 2]>,
    frames_drawn: u32,
    capture_requested: bool,
    picture: Arc<Mutex<Option<Vec<u8>>>>,
    physical: Arc<Mutex<Option<Vec<[f32; 3]>>>>,
    /// Why no picture will come (shared: the app is gone when `render` reads it).
    failure: Arc<Mutex<Option<String>>>,
}

impl Job {
    fn fail(&self, why: String) {
        self.failure.lock().expect("offscreen failure lock").get_or_insert(why);
    }

    fn failed(&self) -> bool {
        self.failure.lock().expect("offscreen failure lock").is_some()
    }
}

/// A headless app that opens the request's scene and draws its view into
/// two images every update. [`render`] runs it until one frame is captured;
/// a benchmark drives it with `update()`.
pub fn offscreen_app(request: &OffscreenRequest) -> App {
    let mut app = App::new();
    let plugins = DefaultPlugins
        .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
        .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() })
        .set(crate::asset_plugin())
        .disable::<WinitPlugin>();
    // Errors only (a shader that fails to build, say), and only where no
    // logger is set yet: a process drawing many pictures sets it once.
    app.add_plugins(if bevy::log::tracing::dispatcher::has_been_set() {
        plugins.disable::<LogPlugin>()
    } else {
        plugins.set(LogPlugin { level: bevy::log::Level::ERROR, filter: "error".into(), ..default() })
    });
    // Direct sun alone needs no light engine: skip its precomputation.
    if request.settings.mode == RenderMode::Sun {
        app.add_plugins(HeliodonPlugins.build().disable::<LightingPlugin>());
    } else {
        app.add_plugins(HeliodonPlugins);
    }
    let failed = PipelineFailed::default();
    app.insert_resource(failed.clone());
    if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
        render_app.insert_resource(failed).add_systems(Render, watch_pipelines.in_set(RenderSystems::Cleanup));
    }
    app.register_panels(&request.panels);
    app.add_plugins(HeliodonRenderPlugin)
        .insert_resource(request.settings)
        .insert_resource(crate::ecs::LightSettings(request.light))
        .insert_resource(Job {
            request: request.clone(),
            targets: None,
            frames_drawn: 0,
            capture_requested: false,
            picture: Arc::default(),
            physical: Arc::default(),
            failure: Arc::default(),
        })
        .add_systems(
            Startup,
            |job: Res<Job>, mut open: MessageWriter<OpenScene>, mut time: ResMut<SolarTime>, mut sky: ResMut<SkyChoice>| {
                open.write(OpenScene(job.request.scene.clone()));
                if let Some(when) = job.request.when {
                    time.0 = when;
                }
                if let Some(spec) = job.request.sky.clone() {
                    sky.0 = spec;
                }
            },
        )
        .add_systems(Update, (spawn_cameras, count_ready_frames).chain().after(crate::ecs::HeliodonSystems::SpawnScene));
    app
}

/// Whether the app of [`offscreen_app`] draws its final picture: the light
/// it shows has arrived and enough frames have passed for it to be drawn.
pub fn frame_ready(app: &App) -> bool {
    app.world().get_resource::<Job>().is_some_and(|job| job.frames_drawn >= WARM_UP_FRAMES)
}

/// Renders one frame of a scene. Errors are one line.
pub fn render(request: OffscreenRequest) -> Result<RenderedImage, String> {
    let mut app = offscreen_app(&request);
    let (picture, physical, failure) = {
        let job = app.world().resource::<Job>();
        (job.picture.clone(), job.physical.clone(), job.failure.clone())
    };
    app.add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO))
        .add_systems(Update, (capture, finish).chain().after(count_ready_frames))
        .run();
    if let Some(failure) = failure.lock().expect("offscreen failure lock").take() {
        return Err(failure);
    }
    let rgba = picture.lock().expect("offscreen picture lock").take();
    let physical = physical.lock().expect("offscreen physical lock").take();
    let pixels = (request.width * request.height) as usize;
    match (rgba, physical) {
        (Some(mut rgba), Some(physical)) if rgba.len() == 4 * pixels && physical.len() == pixels => {
            if request.settings.mode == RenderMode::FalseColour {
                super::legend::draw_legend(&mut rgba, request.width, request.height, request.settings.false_colour_max_lux);
            }
            Ok(RenderedImage { width: request.width, height: request.height, rgba, physical })
        }
        (Some(_), Some(_)) => Err("cannot read back the rendered image: unexpected size or format".into()),
        _ => Err("the renderer stopped before producing an image".into()),
    }
}

/// The picture's camera and, beside it, one with the same view writing
/// physical values into a float image. The automatic first view traces the
/// scene's ray-query model ([`RayModel`], made as the scene spawned).
#[allow(clippy::too_many_arguments)]
fn spawn_cameras(
    mut commands: Commands,
    ray_model: Option<Res<RayModel>>,
    mut spawned: MessageReader<SceneSpawned>,
    mut failed: MessageReader<SceneLoadFailed>,
    mut light_failed: Option<MessageReader<LightingFailed>>,
    active: Res<ActiveScene>,
    mut job: ResMut<Job>,
    mut images: ResMut<Assets<Image>>,
) {
    let lighting_failure = light_failed.as_mut().and_then(|m| m.read().last().map(|f| f.message.clone()));
    if let Some(message) = failed.read().last().map(|f| f.message.clone()).or(lighting_failure) {
        job.fail(message);
    }
    if spawned.read().last().is_none() {
        return;
    }
    let Some(scene) = &active.scene else { return };
    let model = ray_model.as_ref().and_then(|m| m.of(scene));
    let mut view = job.request.view.clone().unwrap_or_else(|| initial_view(scene, model.map(|m| m.as_ref())));
    view.fov = job.request.fov.unwrap_or(view.fov);
    let (width, height) = (job.request.width, job.request.height);
    let picture = images.add(Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None));
    let physical = images.add(Image::new_target_texture(width, height, TextureFormat::Rgba32Float, None));
    let placement = (
        Projection::Perspective(PerspectiveProjection { fov: view.fov.to_radians(), ..default() }),
        Transform::from_translation(view.eye).looking_at(view.target, Vec3::Z),
    );
    // Both draw once what they show has arrived (`count_ready_frames`).
    let waiting = |order| (Camera { order, is_active: false, ..default() }, AwaitsLight);
    commands.spawn((picture_camera(), waiting(0), RenderTarget::Image(picture.clone().into()), placement.clone()));
    commands
        .spawn((hybrid_camera(), waiting(1), PhysicalUnits, RenderTarget::Image(physical.clone().into()), placement))
        .insert((Tonemapping::None, unit_exposure()));
    job.targets = Some([picture, physical]);
}

/// An offscreen camera that draws only while what the mode shows has
/// arrived (`count_ready_frames` switches it). One taken out of the job
/// (the render bench's physical camera, which a viewer does not draw) keeps
/// the state it is given.
#[derive(Component)]
pub struct AwaitsLight;

/// Whether what the mode shows has arrived: the converged light, or for
/// direct sun alone, the sun pass's frame.
fn light_ready(mode: RenderMode, lighting: Option<&LightingState>, sun_pass: &SunPassInput, sun_sky: Option<&SunSky>) -> bool {
    match mode {
        RenderMode::Sun => {
            sun_sky.is_some() && (sun_pass.0.is_some() || sun_sky.is_some_and(|s| s.sky.sun.is_none_or(|sun| sun.direction.z <= 0.0)))
        }
        _ => lighting.is_some_and(|l| l.converged),
    }
}

/// Set from the render world when a pipeline cannot be built at all (a
/// shader that does not compile): the picture would lack what it draws.
#[derive(Resource, Clone, Default)]
struct PipelineFailed(Arc<AtomicBool>);

/// Watches the render world's pipelines for one that failed for good (not
/// one waiting for its shader to load).
fn watch_pipelines(cache: Res<PipelineCache>, failed: Res<PipelineFailed>) {
    let broken = |state: &CachedPipelineState| {
        matches!(state, CachedPipelineState::Err(ShaderCacheError::ProcessShaderError(_) | ShaderCacheError::CreateShaderModule(_)))
    };
    if cache.pipelines().any(|p| broken(&p.state)) {
        failed.0.store(true, Ordering::Relaxed);
    }
}

/// Counts the frames drawn with what the mode shows, and draws none before
/// it has arrived: frames queued behind a long precomputation fill a
/// software rasterizer's memory (3 GB on lavapipe for
/// AC20-Institute-Var-2) and take its cores from the light engine.
fn count_ready_frames(
    mut job: ResMut<Job>,
    mut cameras: Query<&mut Camera, With<AwaitsLight>>,
    lighting: Option<Res<LightingState>>,
    sun_pass: Res<SunPassInput>,
    sun_sky: Option<Res<SunSky>>,
    failed: Res<PipelineFailed>,
) {
    if failed.0.load(Ordering::Relaxed) {
        job.fail("a shader failed to build (its error is above): the picture would be wrong".into());
    }
    let ready = job.targets.is_some() && light_ready(job.request.settings.mode, lighting.as_deref(), &sun_pass, sun_sky.as_deref());
    job.frames_drawn = if ready { job.frames_drawn + 1 } else { 0 };
    for mut camera in cameras.iter_mut().filter(|camera| camera.is_active != ready) {
        camera.is_active = ready;
    }
}

fn capture(mut commands: Commands, mut job: ResMut<Job>) {
    let Some([picture, physical]) = job.targets.clone() else { return };
    if job.frames_drawn < WARM_UP_FRAMES || job.capture_requested {
        return;
    }
    job.capture_requested = true;
    let out = job.picture.clone();
    commands.spawn(Screenshot::image(picture)).observe(move |captured: On<ScreenshotCaptured>| {
        let rgba = captured.image.clone().try_into_dynamic().map(|d| d.to_rgba8().into_raw()).unwrap_or_default();
        *out.lock().expect("offscreen picture lock") = Some(rgba);
    });
    let out = job.physical.clone();
    commands.spawn(Screenshot::image(physical)).observe(move |captured: On<ScreenshotCaptured>| {
        *out.lock().expect("offscreen physical lock") = Some(float_pixels(&captured.image));
    });
}

/// The RGB of an Rgba32Float image, row-major. Rows read back from the GPU
/// may be padded (to 256 bytes): the padding is skipped.
pub fn float_pixels(image: &Image) -> Vec<[f32; 3]> {
    let data = image.data.as_deref().unwrap_or_default();
    let (width, height) = (image.width() as usize, image.height().max(1) as usize);
    let row = (data.len() / height).max(width * 16);
    data.chunks(row)
        .flat_map(|line| line[..(width * 16).min(line.len())].chunks_exact(16))
        .map(|p| [0, 4, 8].map(|o| f32::from_le_bytes([p[o], p[o + 1], p[o + 2], p[o + 3]])))
        .collect()
}

fn finish(job: Res<Job>, mut exit: MessageWriter<AppExit>) {
    let done =
        job.picture.lock().expect("offscreen picture lock").is_some() && job.physical.lock().expect("offscreen physical lock").is_some();
    if done || job.failed() {
        exit.write(AppExit::Success);
    }
}
