//! Frame time of the hybrid renderer, headless on whatever Vulkan device
//! there is (Mesa's lavapipe on the CI machines), each frame drawn to the end
//! (the update, then a wait for the device): the bundled scenes and the
//! rooms with panels in full mode; the large models, a generated hall of 100k triangles (direct sun
//! alone, where the stencil passes are what grows with the model, and in
//! full), the furnished floor of offices from its automatic first view and a
//! room on a 400 × 300 m ground; the office orbiting, orbiting from above
//! with the section on, and while its light settles. Prints the passes and
//! shadow-volume triangles drawn per frame.
//!
//! 1280 × 720 unless `HELIODON_BENCH_FRAME=WxH` says otherwise (1920x1080
//! on a GPU machine). `HELIODON_BENCH_SCENES` adds scene files (separated as
//! in `PATH`, each named by its folder): real models, drawn in full from their
//! first view. `HELIODON_BENCH_SECONDS` is each case's measurement time (15 s),
//! shorter where device time is scarce. `HELIODON_BENCH_GPU_TIMES=1` records
//! the GPU's time per render pass (Bevy's and the sun pass's, that one per
//! light too) and prints their means after each case, where the device has
//! timestamp queries (Bevy keeps 256 a frame: four per light, so a scene
//! with many panel lobes loses the last passes' times).

#[path = "../../tests/support/office_floor.rs"]
mod office_floor;
#[path = "../../tests/support/quad_obj.rs"]
mod quad_obj;
#[path = "../../tests/support/room_on_ground.rs"]
mod room_on_ground;

use quad_obj::QuadObj;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use heliodon::bevy::diagnostic::DiagnosticsStore;
use heliodon::bevy::prelude::*;
use heliodon::bevy::render::diagnostic::RenderDiagnosticsPlugin;
use heliodon::bevy::render::render_resource::PollType;
use heliodon::bevy::render::renderer::RenderDevice;
use heliodon::ecs::{ActiveScene, RayModel, SunSky};
use heliodon::render::offscreen::{AwaitsLight, OffscreenRequest, frame_ready, offscreen_app};
use heliodon::render::sun_pass::{SunPassFrame, SunPassInput};
use heliodon::render::{PhysicalUnits, RenderMode, RenderSettings, framing};
use heliodon::sky::SkySpec;
use heliodon::time::{Date, LocalDateTime, TimeOfDay};

/// The bundled rooms with panels: one lobe pass pair per fake sun.
const PANEL_ROOMS: &[&str] = &["prismatic_room", "laser_cut_room", "venetian_room", "bsdf_room"];

/// The frame's size: `HELIODON_BENCH_FRAME=WxH`, or 1280 × 720.
fn frame_size() -> (u32, u32) {
    let size = std::env::var("HELIODON_BENCH_FRAME").ok().and_then(|text| {
        let (w, h) = text.split_once('x')?;
        Some((w.trim().parse().ok()?, h.trim().parse().ok()?))
    });
    size.unwrap_or((1280, 720))
}

fn gpu_times() -> bool {
    std::env::var_os("HELIODON_BENCH_GPU_TIMES").is_some()
}

/// The mean GPU time of each render pass and span over the last frames, and
/// each pass's pipeline statistics (fragments shaded, primitives drawn).
fn print_gpu_times(app: &App, label: &str) {
    let store = app.world().resource::<DiagnosticsStore>();
    let mut lines: Vec<String> = store
        .iter()
        .filter(|d| ["elapsed_gpu", "fragment_shader_invocations", "clipper_primitives_out"].iter().any(|f| d.path().as_str().ends_with(f)))
        .filter_map(|d| Some(format!("  {} {:.3}", d.path().as_str(), d.average()?)))
        .collect();
    lines.sort();
    println!("{label}: GPU time per pass (ms) and pipeline statistics, mean of the last frames\n{}", lines.join("\n"));
}

/// One frame drawn to the end: the app's update, then a wait until the
/// device has done what it was given (an offscreen target has no swap chain
/// to hold the next frame back, so the update alone times the CPU's part).
fn draw(app: &mut App) {
    app.update();
    let _ = app.world().resource::<RenderDevice>().poll(PollType::wait_indefinitely());
}

/// A 60 × 40 m hall with a glazed south façade and 8,400 boxes (desks,
/// cabinets) on its floor: about 100k triangles.
fn hall(dir: &Path) -> PathBuf {
    let mut obj = QuadObj::new("model.mtl");
    let (w, d, h) = (60.0, 40.0, 4.0);
    obj.quad("floor", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, d, 0.0], [0.0, d, 0.0]]);
    obj.quad("ceiling", [[0.0, 0.0, h], [0.0, d, h], [w, d, h], [w, 0.0, h]]);
    obj.quad("wall", [[0.0, d, 0.0], [w, d, 0.0], [w, d, h], [0.0, d, h]]);
    obj.quad("wall", [[0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, d, h], [0.0, 0.0, h]]);
    obj.quad("wall", [[w, d, 0.0], [w, 0.0, 0.0], [w, 0.0, h], [w, d, h]]);
    obj.quad("wall", [[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, 0.0, 1.0], [0.0, 0.0, 1.0]]);
    obj.quad("wall", [[0.0, 0.0, 3.0], [w, 0.0, 3.0], [w, 0.0, h], [0.0, 0.0, h]]);
    obj.quad("glass", [[0.0, 0.0, 1.0], [w, 0.0, 1.0], [w, 0.0, 3.0], [0.0, 0.0, 3.0]]);
    for i in 0..120 {
        for j in 0..70 {
            let (x, y) = (0.5 + 0.49 * f64::from(i), 2.0 + 0.54 * f64::from(j));
            let (a, b, top) = ([x, y], [x + 0.3, y + 0.3], 0.5 + 0.25 * f64::from((i + j) % 3));
            let c = |p: [f64; 2], z: f64| [p[0], p[1], z];
            let (p00, p10, p11, p01) = ([a[0], a[1]], [b[0], a[1]], [b[0], b[1]], [a[0], b[1]]);
            obj.quad("box", [c(p00, top), c(p10, top), c(p11, top), c(p01, top)]);
            obj.quad("box", [c(p00, 0.0), c(p10, 0.0), c(p10, top), c(p00, top)]);
            obj.quad("box", [c(p10, 0.0), c(p11, 0.0), c(p11, top), c(p10, top)]);
            obj.quad("box", [c(p11, 0.0), c(p01, 0.0), c(p01, top), c(p11, top)]);
            obj.quad("box", [c(p01, 0.0), c(p00, 0.0), c(p00, top), c(p01, top)]);
            obj.quad("box", [c(p00, 0.0), c(p01, 0.0), c(p11, 0.0), c(p10, 0.0)]);
        }
    }
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("model.obj"), obj.text()).unwrap();
    std::fs::write(
        dir.join("model.mtl"),
        "newmtl floor\nKd 0.3 0.3 0.3\nnewmtl ceiling\nKd 0.8 0.8 0.8\nnewmtl wall\nKd 0.6 0.6 0.6\nnewmtl box\nKd 0.5 0.45 0.4\nnewmtl glass\nd 0.7\n",
    )
    .unwrap();
    let scene = "name = \"Hall of boxes\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"model.obj\"\n[lighting]\npatch_size = 4.0\n\n[[cameras]]\nname = \"hall\"\neye = [5.0, 38.0, 3.5]\ntarget = [35.0, 5.0, 0.0]\nfov = 60.0\n";
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    dir.join("scene.toml")
}

/// A warmed-up app drawing `scene`'s first camera, and what the sun pass draws per frame.
fn ready_app(scene: PathBuf, mode: RenderMode) -> (App, String) {
    let (width, height) = frame_size();
    let request = OffscreenRequest {
        scene,
        view: None,
        fov: None,
        width,
        height,
        when: Some(LocalDateTime { date: Date::new(2026, 3, 21).unwrap(), time: TimeOfDay::from_hours(10.0).unwrap() }),
        sky: Some(SkySpec::Clear { turbidity: 2.45 }),
        settings: RenderSettings { mode, ..Default::default() },
        light: Default::default(),
        panels: heliodon_app::builtin_panels(),
    };
    let mut app = offscreen_app(&request);
    if gpu_times() {
        app.add_plugins(RenderDiagnosticsPlugin);
    }
    app.finish();
    app.cleanup();
    let start = std::time::Instant::now();
    while !frame_ready(&app) {
        // A scene that fails to load never gets ready (Bevy has logged why).
        assert!(start.elapsed() < Duration::from_secs(300), "{}: not ready after 300 s", request.scene.display());
        app.update();
    }
    // The viewer draws one view; the offscreen app has a second camera
    // writing physical values beside the picture, which the frame time leaves out.
    // Taken out of the job's waiting cameras, so it stays off.
    let mut physical = app.world_mut().query_filtered::<Entity, With<PhysicalUnits>>();
    for entity in physical.iter(app.world()).collect::<Vec<_>>() {
        let mut camera = app.world_mut().entity_mut(entity);
        camera.remove::<AwaitsLight>();
        camera.get_mut::<Camera>().expect("the physical camera is a camera").is_active = false;
    }
    let counts = match &app.world().resource::<SunPassInput>().0 {
        Some(frame) => format!(
            "{} draws per frame ({} direction passes, {} lights), {} shadow-volume triangles, {} lit triangles ({} drawn per frame, each light's share); made in {:.1} ms when the sun moves",
            frame.draw_count(),
            frame.passes.len(),
            frame.lights().count(),
            frame.volumes.len() / 3,
            frame.surfaces.lit_triangles(),
            frame.lit_triangles_drawn(),
            sun_pass_geometry_ms(&app, frame),
        ),
        None => "no sun pass".into(),
    };
    (app, counts)
}

/// The main world's share of a sun move: the sun pass's volumes and each
/// light's lit triangles made again (the median of five).
fn sun_pass_geometry_ms(app: &App, frame: &SunPassFrame) -> f64 {
    let scene = app.world().resource::<ActiveScene>().scene.clone().expect("the scene is loaded");
    let model = app.world().resource::<RayModel>().0.clone();
    let sun = app.world().resource::<SunSky>().sky.sun_up().expect("the sun is up");
    let mut times: Vec<f64> = (0..5)
        .map(|_| {
            let start = std::time::Instant::now();
            std::hint::black_box(SunPassFrame::new(&scene, &model, frame.surfaces.clone(), &sun, 0));
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[2]
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    let seconds = std::env::var("HELIODON_BENCH_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(15);
    group.sample_size(10).measurement_time(Duration::from_secs(seconds));
    let (width, height) = frame_size();
    let temp = std::env::temp_dir();
    let mut cases: Vec<(String, PathBuf, RenderMode)> = heliodon::BUNDLED_SCENES
        .iter()
        .chain(PANEL_ROOMS)
        .map(|name| (format!("{name} full"), heliodon::bundled_scene(name), RenderMode::Full))
        .collect();
    let hall = hall(&temp.join("heliodon-bench-hall"));
    cases.push(("hall 100k triangles sun".into(), hall.clone(), RenderMode::Sun));
    cases.push(("hall 100k triangles full".into(), hall, RenderMode::Full));
    let floor = office_floor::office_floor(&temp.join("heliodon-bench-furnished-floor"), true);
    cases.push(("furnished office floor full".into(), floor, RenderMode::Full));
    let ground = room_on_ground::room_on_a_ground(&temp.join("heliodon-bench-room-on-ground"), 400.0, 300.0, true);
    cases.push(("room on a 400 x 300 m ground full".into(), ground, RenderMode::Full));
    for scene in std::env::var_os("HELIODON_BENCH_SCENES").iter().flat_map(std::env::split_paths) {
        let folder = scene.parent().and_then(Path::file_name).map(|name| name.to_string_lossy().into_owned());
        cases.push((format!("{} full", folder.unwrap_or_else(|| scene.display().to_string())), scene, RenderMode::Full));
    }
    for (label, scene, mode) in cases {
        // Loaded on the first call, so a case left out by the bench's
        // filter loads nothing.
        let mut ready: Option<App> = None;
        group.bench_function(format!("frame {label} {width}x{height}"), |b| {
            let app = ready.get_or_insert_with(|| {
                let (app, counts) = ready_app(scene.clone(), mode);
                println!("{label}: {counts}");
                app
            });
            b.iter(|| draw(app))
        });
        if gpu_times()
            && let Some(app) = &ready
        {
            print_gpu_times(app, &label);
        }
    }
    orbiting(&mut group);
    settling(&mut group);
    group.finish();
}

/// The office while the camera orbits (half a degree a frame about the
/// vertical through the middle of what matters): from its own camera, and
/// from above with the section on (cut 2.5 m over the floor).
fn orbiting(group: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>) {
    let (width, height) = frame_size();
    let (mut app, _) = ready_app(heliodon::bundled_scene("office"), RenderMode::Full);
    let focus = app.world().resource::<ActiveScene>().scene.as_ref().expect("the office is loaded").focus;
    let (centre, distance) = framing(focus, heliodon::scene::DEFAULT_FOV);
    let turn = Quat::from_rotation_z(0.5f32.to_radians());
    let orbit = |app: &mut App| {
        let mut cameras = app.world_mut().query_filtered::<&mut Transform, With<Camera3d>>();
        for mut transform in cameras.iter_mut(app.world_mut()) {
            transform.rotate_around(centre, turn);
        }
        draw(app);
    };
    group.bench_function(format!("frame office full orbiting {width}x{height}"), |b| b.iter(|| orbit(&mut app)));
    let above = centre + distance * Vec3::new(0.0, -0.5, 0.85).normalize();
    let mut cameras = app.world_mut().query_filtered::<&mut Transform, With<Camera3d>>();
    for mut transform in cameras.iter_mut(app.world_mut()) {
        *transform = Transform::from_translation(above).looking_at(centre, Vec3::Z);
    }
    app.world_mut().resource_mut::<RenderSettings>().section = Some(focus.0.z + 2.5);
    group.bench_function(format!("frame office full orbiting from above, section on {width}x{height}"), |b| b.iter(|| orbit(&mut app)));
}

/// The office while its light settles: frames drawn while relights run
/// (each converged relight is followed by a new time, ten minutes on), and
/// the frames around a material edit (respawn and a new precomputation).
fn settling(group: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>) {
    use heliodon::ecs::{EditMaterial, LightingState, SolarTime};
    use std::time::Instant;
    let (width, height) = frame_size();
    let (mut app, _) = ready_app(heliodon::bundled_scene("office"), RenderMode::Full);
    let converged = |app: &App| app.world().get_resource::<LightingState>().is_some_and(|l| l.converged);
    let mut relights = 0u32;
    group.bench_function(format!("frame office full while the light settles {width}x{height}"), |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                if converged(&app) {
                    let mut time = app.world_mut().resource_mut::<SolarTime>();
                    let minutes = (time.0.time.hours() * 60.0 + 10.0).rem_euclid(8.0 * 60.0) + 8.0 * 60.0;
                    time.0.time = TimeOfDay::from_hours(minutes / 60.0).unwrap();
                    relights += 1;
                }
                let start = Instant::now();
                draw(&mut app);
                total += start.elapsed();
            }
            total
        })
    });
    println!("{relights} relights started while measuring");
    // One glass edit: the frames until the light has converged again.
    let scene = app.world().resource::<ActiveScene>().scene.clone().unwrap();
    let index = scene.materials.iter().position(|m| m.name == "upper_glass").unwrap() as u32;
    app.world_mut().write_message(EditMaterial { index, kind: heliodon::scene::MaterialKind::Glass { transmittance: 0.5 } });
    let mut frames = Vec::new();
    let start = Instant::now();
    while frames.is_empty() || !converged(&app) || frames.len() < 3 {
        let frame = Instant::now();
        draw(&mut app);
        frames.push(frame.elapsed().as_secs_f64() * 1e3);
    }
    let worst = frames.iter().copied().fold(0.0, f64::max);
    let median = {
        let mut sorted = frames.clone();
        sorted.sort_by(f64::total_cmp);
        sorted[sorted.len() / 2]
    };
    println!(
        "office, upper_glass edited: light back after {:.2} s and {} frames; frame median {median:.0} ms, worst {worst:.0} ms (frame 1: {:.0} ms)",
        start.elapsed().as_secs_f64(),
        frames.len(),
        frames[0]
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
