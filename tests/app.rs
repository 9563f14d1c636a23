//! Bevy apps: the simulation plugins headless (no window, no GPU), and a
//! render smoke test on whatever Vulkan device there is (Mesa's lavapipe in CI).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use bevy::prelude::*;
use heliodon::ecs::{
    ActiveScene, MaterialOf, OpenScene, SceneLoadFailed, SceneMaterial, SceneSensor, SceneSpawned, SceneSurface,
    SceneWindow, Site,
};
use std::sync::Arc;

use glam::DVec3;
use heliodon::light::LightModel;
use heliodon::render::offscreen::{self, OffscreenRequest};
use heliodon::render::{RenderMode, RenderSettings, initial_view};
use heliodon::scene::{MaterialKind, PanelNames, Scene, Viewpoint, load_scene};
use heliodon::sky::{Sky, SkySpec};
use heliodon::sun::solar_position;
use heliodon::time::{Date, LocalDateTime, TimeOfDay};

fn headless_app() -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, heliodon::asset_plugin(), heliodon::HeliodonPlugins));
    app
}

/// Runs the app until a scene is spawned or fails; returns the failure message.
fn open(app: &mut App, path: PathBuf) -> Result<(), String> {
    app.world_mut().write_message(OpenScene(path));
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        app.update();
        let world = app.world_mut();
        if let Some(failed) = world.resource_mut::<Messages<SceneLoadFailed>>().drain().last() {
            return Err(failed.message);
        }
        if world.resource_mut::<Messages<SceneSpawned>>().drain().last().is_some() {
            app.update(); // apply the spawn commands
            return Ok(());
        }
        assert!(Instant::now() < deadline, "scene did not load in time");
        std::thread::sleep(Duration::from_millis(2));
    }
}

struct Expected {
    name: &'static str,
    diffuse: usize,
    glass: usize,
    windows: usize,
    window_area: f32,
    sensors: usize,
    latitude: f64,
}

#[test]
fn every_bundled_scene_spawns_its_entities() {
    let expected = [
        Expected { name: "test_room", diffuse: 3, glass: 1, windows: 6, window_area: 4.59, sensors: 65, latitude: 42.36 },
        Expected { name: "office", diffuse: 7, glass: 3, windows: 12, window_area: 24.88, sensors: 150, latitude: 42.36 },
        Expected {
            name: "living_room",
            diffuse: 5,
            glass: 2,
            windows: 16,
            window_area: 15.300,
            sensors: 28,
            latitude: 37.77,
        },
    ];
    // One app opens the scenes in turn: each replaces the previous one.
    let mut app = headless_app();
    for e in expected {
        open(&mut app, heliodon::bundled_scene(e.name)).unwrap();
        let world = app.world_mut();
        let scene = world.resource::<ActiveScene>().scene.clone().expect("active scene");
        assert_eq!(world.resource::<Site>().latitude, e.latitude, "{}", e.name);

        let mut materials = world.query::<&SceneMaterial>();
        let kinds: Vec<&str> = materials.iter(world).map(|m| m.material.kind.label()).collect();
        assert_eq!(kinds.iter().filter(|k| **k == "diffuse").count(), e.diffuse, "{}", e.name);
        assert_eq!(kinds.iter().filter(|k| **k == "glass").count(), e.glass, "{}", e.name);

        let mut windows = world.query::<(&SceneWindow, &MaterialOf)>();
        let mut area = 0.0;
        let mut count = 0;
        for (window, material) in windows.iter(world) {
            area += window.window.area;
            count += 1;
            let kind = &world.get::<SceneMaterial>(material.0).expect("window material entity").material.kind;
            assert!(kind.transmits(), "{}: window of {kind:?}", e.name);
        }
        assert_eq!(count, e.windows, "{}", e.name);
        assert!((area - e.window_area).abs() < 2e-3, "{}: {area}", e.name);

        let mut surfaces = world.query::<&SceneSurface>();
        let patches: u32 = surfaces.iter(world).map(|s| s.patches.end - s.patches.start).sum();
        assert_eq!(surfaces.iter(world).count(), scene.surfaces.len(), "{}", e.name);
        assert_eq!(patches as usize, scene.patches.patches.len(), "{}", e.name);

        let mut sensors = world.query::<&SceneSensor>();
        assert_eq!(sensors.iter(world).count(), e.sensors, "{}", e.name);
    }
}

#[test]
fn a_failed_load_reports_one_line_and_keeps_the_previous_scene() {
    let mut app = headless_app();
    open(&mut app, heliodon::bundled_scene("test_room")).unwrap();
    let missing = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("missing/scene.toml");
    let message = open(&mut app, missing.clone()).unwrap_err();
    assert!(message.contains("missing/scene.toml") && message.contains("not found"), "{message}");
    assert!(!message.contains('\n'));
    let world = app.world_mut();
    assert_eq!(world.resource::<ActiveScene>().scene.as_ref().unwrap().name, "Small test room");
    assert_eq!(world.query::<&SceneWindow>().iter(world).count(), 6);
}

#[test]
fn render_smoke_test_draws_the_model() {
    let request = OffscreenRequest { scene: heliodon::bundled_scene("test_room"), view: None, width: 320, height: 240, when: None, sky: None, settings: Default::default() };
    let image = offscreen::render(request).expect("render");
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("render_smoke_test_room.png");
    image.save_png(&out).unwrap();
    println!("wrote {}", out.display());
    assert_eq!((image.width, image.height), (320, 240));
    let pixels: Vec<[u8; 4]> = image.rgba.chunks_exact(4).map(|p| [p[0], p[1], p[2], p[3]]).collect();
    // From inside the closed room (the scene's first camera) nearly every
    // pixel is a surface: the clear colour shows only through the glass.
    let clear = [209u8, 219, 230];
    let background = pixels.iter().filter(|p| p[..3].iter().zip(clear).all(|(a, b)| a.abs_diff(b) <= 2)).count();
    assert!(background < pixels.len() / 10, "{background} background pixels of {}", pixels.len());
    // Walls, floor and ceiling face different ways and have different
    // reflectances: the image has distinct shades, neither black nor flat.
    let luminance: Vec<f32> = pixels.iter().map(|p| 0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32).collect();
    let mean = luminance.iter().sum::<f32>() / luminance.len() as f32;
    let spread = (luminance.iter().map(|l| (l - mean).powi(2)).sum::<f32>() / luminance.len() as f32).sqrt();
    assert!(mean > 30.0 && mean < 240.0, "mean luminance {mean}");
    assert!(spread > 10.0, "luminance spread {spread}");
    let mut levels: Vec<u8> = luminance.iter().map(|l| (*l / 16.0) as u8).collect();
    levels.sort_unstable();
    levels.dedup();
    assert!(levels.len() >= 4, "shades {levels:?}");
}

#[test]
fn the_sun_and_sky_follow_the_clock_once_per_change() {
    use heliodon::ecs::{LightChanged, SkyChoice, SolarTime, SunSky};
    use heliodon::sky::{Sky, SkySpec};
    use heliodon::sun::solar_position;
    use heliodon::time::{LocalDateTime, TimeOfDay};

    let mut app = headless_app();
    let site = heliodon::site::Site::new(42.36, -71.06, -5.0);
    app.world_mut().insert_resource(Site(site));
    let messages = |app: &mut App| app.world_mut().resource_mut::<Messages<LightChanged>>().drain().count();
    app.update();
    assert_eq!(messages(&mut app), 1, "the first sun and sky");
    for _ in 0..3 {
        app.update();
    }
    assert_eq!(messages(&mut app), 0, "nothing changed, nothing recomputed");

    let date = app.world().resource::<SolarTime>().0.date;
    for (k, hours) in [9.0, 12.5, 16.25].into_iter().enumerate() {
        let when = LocalDateTime { date, time: TimeOfDay::from_hours(hours).unwrap() };
        app.world_mut().resource_mut::<SolarTime>().0 = when;
        app.update();
        app.update();
        assert_eq!(messages(&mut app), 1, "one update for the change to {hours} h");
        let state = app.world().resource::<SunSky>();
        let expected = solar_position(&site, &when);
        assert_eq!(state.sun, expected);
        assert_eq!(state.generation, k as u64 + 1);
        let sky = Sky::new(&SkySpec::Clear { turbidity: 2.45 }, expected.altitude, expected.azimuth, 0.2, date.day_of_year()).unwrap();
        assert_eq!(state.sky, sky);
        assert_eq!(state.patch_radiance, state.patches.integrate(&sky));
        assert_eq!(state.patch_radiance.len(), 2305);
    }
    // A new sky is one more update, and its light shows.
    app.world_mut().resource_mut::<SkyChoice>().0 = SkySpec::Overcast;
    app.update();
    assert_eq!(messages(&mut app), 1);
    assert!(app.world().resource::<SunSky>().sky.sun.is_none());
}

#[test]
fn relights_run_as_tasks_and_the_last_change_wins() {
    use heliodon::ecs::{LightCacheDir, LightEngine, LightingSettings, LightingState, LightingUpdated, SolarTime, SunSky};
    use heliodon::light::LightSettings;
    use heliodon::time::{LocalDateTime, TimeOfDay};

    let mut app = headless_app();
    let settings = LightSettings { rays_per_patch: 64, rays_per_sensor: 512, sun_samples_per_patch: 4, area_sensor_sun_grid: 4, ..Default::default() };
    app.insert_resource(LightingSettings(settings)).insert_resource(LightCacheDir(None));
    open(&mut app, heliodon::bundled_scene("test_room")).unwrap();
    let mut seen: Vec<u64> = Vec::new();
    let run_until_settled = |app: &mut App, seen: &mut Vec<u64>| {
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            app.update();
            seen.extend(app.world_mut().resource_mut::<Messages<LightingUpdated>>().drain().map(|m| m.generation));
            let engine = app.world().resource::<LightEngine>();
            let state = app.world().resource::<LightingState>();
            if engine.model.is_some() && state.converged && state.generation == engine.generation() {
                return;
            }
            assert!(Instant::now() < deadline, "lighting did not settle");
            std::thread::sleep(Duration::from_millis(5));
        }
    };
    run_until_settled(&mut app, &mut seen);
    let first = app.world().resource::<LightingState>().generation;
    // Three changes of time in quick succession: one frame each.
    let date = app.world().resource::<SolarTime>().0.date;
    for hours in [9.0, 11.0, 15.5] {
        app.world_mut().resource_mut::<SolarTime>().0 = LocalDateTime { date, time: TimeOfDay::from_hours(hours).unwrap() };
        app.update();
        seen.extend(app.world_mut().resource_mut::<Messages<LightingUpdated>>().drain().map(|m| m.generation));
    }
    run_until_settled(&mut app, &mut seen);
    // Results arrived in order: never an older relight after a newer one.
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
    let world = app.world();
    let state = world.resource::<LightingState>();
    assert!(state.generation > first);
    // The final light is that of the last time, as a fresh solve gives it.
    let model = world.resource::<LightEngine>().model.clone().unwrap();
    let sky = &world.resource::<SunSky>().sky;
    let fresh = model.solve(sky, None);
    for (a, b) in state.lighting.as_ref().unwrap().sensors.iter().zip(&fresh.sensors) {
        assert_eq!(a.name, b.name);
        assert!((a.total - b.total).abs() <= 1e-3 * b.total.max(1.0), "{a:?} vs {b:?}");
        assert_eq!(a.direct_sun, b.direct_sun);
    }
}

/// Pixel centres' rays of a perspective camera as Bevy draws it (vertical
/// field of view, the model's z up), row by row from the top.
fn camera_rays(view: &Viewpoint, width: u32, height: u32) -> Vec<DVec3> {
    let forward = (view.target - view.eye).normalize().as_dvec3();
    let right = forward.cross(DVec3::Z).normalize();
    let up = right.cross(forward);
    let tan = (f64::from(view.fov).to_radians() / 2.0).tan();
    let aspect = f64::from(width) / f64::from(height);
    (0..height)
        .flat_map(|j| (0..width).map(move |i| (i, j)))
        .map(|(i, j)| {
            let x = (2.0 * (f64::from(i) + 0.5) / f64::from(width) - 1.0) * tan * aspect;
            let y = (1.0 - 2.0 * (f64::from(j) + 0.5) / f64::from(height)) * tan;
            (forward + right * x + up * y).normalize()
        })
        .collect()
}

/// The direct-sun image (mode `sun`) against a CPU ray tracer: each pixel's
/// ray finds its surface, then a shadow ray from there toward the sun goes
/// through glass (Radiance's transmittance) or meets an opaque surface.
/// Pixels whose ray meets glass or nothing are not compared.
#[test]
fn direct_sun_images_agree_with_a_ray_traced_reference() {
    let (width, height) = (320u32, 200u32);
    let out_dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let mut report = Vec::new();
    for name in heliodon::BUNDLED_SCENES {
        let path = heliodon::bundled_scene(name);
        let scene = Arc::new(load_scene(&path, &PanelNames::new()).unwrap().scene);
        let model = LightModel::unlit(scene.clone());
        let overview = Viewpoint { name: "overview".into(), ..initial_view(&Scene { viewpoints: Vec::new(), ..(*scene).clone() }) };
        let cases = [(scene.viewpoints[0].clone(), "2026-03-21", "10:00"), (scene.viewpoints[0].clone(), "2026-11-10", "14:30"), (overview, "2026-12-21", "12:00")];
        for (view, date, time) in cases {
            let when = LocalDateTime { date: Date::parse(date).unwrap(), time: TimeOfDay::parse(time).unwrap() };
            let sun = solar_position(&scene.site, &when);
            let sky = Sky::new(&SkySpec::Clear { turbidity: 2.45 }, sun.altitude, sun.azimuth, scene.site.ground_reflectance, when.date.day_of_year()).unwrap();
            let sun = sky.sun.expect("the sun is up in every case");
            let request = OffscreenRequest {
                scene: path.clone(),
                view: Some(view.clone()),
                width,
                height,
                when: Some(when),
                sky: Some(SkySpec::Clear { turbidity: 2.45 }),
                settings: RenderSettings { mode: RenderMode::Sun, ..Default::default() },
            };
            let image = offscreen::render(request).expect("render");
            let file = out_dir.join(format!("sun_{name}_{}_{}.png", view.name.replace(' ', "_"), time.replace(':', "")));
            image.save_png(&file).unwrap();
            let (mut compared, mut agree, mut lit, mut within) = (0usize, 0usize, 0usize, 0usize);
            let mut worst: f64 = 0.0;
            // Disagreements for a person to look at: red where only the
            // reference is lit, green where only the image is.
            let mut disagreement = image::RgbImage::new(width, height);
            for (k, (ray, gpu)) in camera_rays(&view, width, height).into_iter().zip(&image.physical).enumerate() {
                let eye = view.eye.as_dvec3();
                let Some((patch, distance)) = model.trace(eye, ray) else { continue };
                let patch = &scene.patches.patches[patch as usize];
                let MaterialKind::Diffuse { reflectance } = &scene.materials[patch.material as usize].kind else { continue };
                let mut normal = patch.normal.as_dvec3();
                if normal.dot(ray) > 0.0 {
                    normal = -normal;
                }
                let irradiance = model.sun_irradiance(eye + ray * distance, normal, &sun);
                let expected = f64::from(reflectance.0[1]) / std::f64::consts::PI * irradiance * 179.0;
                let got = f64::from(gpu[1]);
                compared += 1;
                let (cpu_lit, gpu_lit) = (expected > 1.0, got > 1.0);
                agree += usize::from(cpu_lit == gpu_lit);
                let shade = if cpu_lit == gpu_lit { [40 + 80 * u8::from(cpu_lit); 3] } else if cpu_lit { [255, 0, 0] } else { [0, 255, 0] };
                disagreement.put_pixel(k as u32 % width, k as u32 / width, image::Rgb(shade));
                if cpu_lit && gpu_lit {
                    lit += 1;
                    let error = (got / expected - 1.0).abs();
                    within += usize::from(error <= 0.02);
                    worst = worst.max(error);
                }
            }
            disagreement.save(file.with_extension("diff.png")).unwrap();
            let agreement = agree as f64 / compared as f64;
            let within = within as f64 / lit.max(1) as f64;
            report.push(format!(
                "{name} {} {date} {time}: {compared} pixels, lit/unlit agree {:.2}%, {lit} lit, {:.2}% within 2% (worst {:.1}%) -> {}",
                view.name,
                100.0 * agreement,
                100.0 * within,
                100.0 * worst,
                file.display()
            ));
            println!("{}", report.last().unwrap());
            assert!(compared > (width * height / 10) as usize, "{}", report.last().unwrap());
            assert!(lit > 200, "too few sunlit pixels to compare: {}", report.last().unwrap());
            assert!(agreement >= 0.99 && within >= 0.99, "{}", report.last().unwrap());
        }
    }
}
