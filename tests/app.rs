//! Bevy apps: the simulation plugins headless (no window, no GPU), and a
//! render smoke test on whatever Vulkan device there is (Mesa's lavapipe in CI).

#[path = "support/quick_light.rs"]
mod quick_light;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use bevy::prelude::*;
use heliodon::ecs::{
    ActiveScene, MaterialOf, OpenScene, SceneLoadFailed, SceneMaterial, SceneSensor, SceneSpawned, SceneSurface, SceneWindow, Site,
};
use std::sync::Arc;

use heliodon::light::LightModel;
use heliodon::panel::PanelCatalog;
use heliodon::render::offscreen::{self, OffscreenRequest};
use heliodon::render::reference::{self, SunComparison};
use heliodon::render::{PhysicalUnits, RenderMode, RenderSettings, overview};
use heliodon::scene::{Viewpoint, load_scene};
use heliodon::sky::{Sky, SkySpec};
use heliodon::sun::solar_position;
use heliodon::time::{Date, LocalDateTime, TimeOfDay};
use quick_light::quick_light;

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
        Expected { name: "living_room", diffuse: 5, glass: 2, windows: 16, window_area: 15.300, sensors: 28, latitude: 37.77 },
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

/// A picture that cannot be made says why, in one line: the scene's own
/// error, not that the renderer stopped.
#[test]
fn a_render_that_fails_says_why() {
    let error = offscreen::render(OffscreenRequest {
        scene: PathBuf::from("no/such/scene.toml"),
        view: None,
        fov: None,
        width: 16,
        height: 16,
        when: None,
        sky: None,
        settings: Default::default(),
        light: Default::default(),
        panels: Default::default(),
    })
    .expect_err("there is no such scene");
    assert!(error.contains("no/such/scene.toml") && !error.contains('\n'), "{error}");
}

#[test]
fn render_smoke_test_draws_the_model() {
    let request = OffscreenRequest {
        scene: heliodon::bundled_scene("test_room"),
        view: None,
        fov: None,
        width: 320,
        height: 240,
        when: None,
        sky: None,
        settings: Default::default(),
        light: Default::default(),
        panels: Default::default(),
    };
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

/// A field of view given without a view narrows the initial view (here the
/// scene's first camera, 70°): the picture is the middle of the wide one,
/// enlarged. Half the tangent of the half-angle shows the middle half each way.
#[test]
fn a_field_of_view_alone_narrows_the_initial_view() {
    let request = |fov: Option<f32>| OffscreenRequest {
        scene: heliodon::bundled_scene("test_room"),
        view: None,
        fov,
        width: 160,
        height: 120,
        when: None,
        sky: None,
        settings: RenderSettings { exposure: Some(10.0), ..Default::default() },
        light: Default::default(),
        panels: Default::default(),
    };
    let half_tangent = (35.0f32.to_radians().tan() / 2.0).atan().to_degrees() * 2.0;
    let (wide, narrow) = (offscreen::render(request(None)).unwrap(), offscreen::render(request(Some(half_tangent))).unwrap());
    let luminance = |image: &offscreen::RenderedImage, x: std::ops::Range<u32>, y: std::ops::Range<u32>| {
        let (mut sum, mut n) = (0.0, 0.0);
        for row in y {
            for column in x.clone() {
                let p = &image.rgba[4 * (row * image.width + column) as usize..][..3];
                sum += 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
                n += 1.0;
            }
        }
        sum / n
    };
    let (whole, middle, zoomed) = (luminance(&wide, 0..160, 0..120), luminance(&wide, 40..120, 30..90), luminance(&narrow, 0..160, 0..120));
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    wide.save_png(&out.join("fov_wide.png")).unwrap();
    narrow.save_png(&out.join("fov_narrow.png")).unwrap();
    println!("mean luminance: wide {whole:.1}, its middle {middle:.1}, the narrow view {zoomed:.1}");
    assert!(
        (zoomed - middle).abs() < 0.05 * middle,
        "the narrow view {zoomed:.1} against the wide one's middle {middle:.1} (whole {whole:.1})"
    );
    assert!(
        (zoomed - whole).abs() > 2.0 * (zoomed - middle).abs(),
        "the narrow view {zoomed:.1} is not the middle {middle:.1} of the whole {whole:.1}"
    );
}

/// The offscreen job switches on, once its light has arrived, only the
/// cameras waiting for it (`AwaitsLight`): one taken out of them keeps the
/// state it is given. The render bench draws the viewer's one view so; when
/// the job switched every camera, its frames drew both and took twice as long.
#[test]
fn the_offscreen_job_switches_only_its_waiting_cameras() {
    let request = OffscreenRequest {
        scene: heliodon::bundled_scene("test_room"),
        view: None,
        fov: None,
        width: 32,
        height: 24,
        when: None,
        sky: None,
        settings: RenderSettings { mode: RenderMode::Sun, ..Default::default() },
        light: Default::default(),
        panels: Default::default(),
    };
    let mut app = offscreen::offscreen_app(&request);
    app.finish();
    app.cleanup();
    let start = Instant::now();
    while !offscreen::frame_ready(&app) {
        assert!(start.elapsed() < Duration::from_secs(120), "not ready after 120 s");
        app.update();
    }
    let mut cameras = app.world_mut().query_filtered::<(Entity, Has<PhysicalUnits>), With<Camera>>();
    let cameras: Vec<(Entity, bool)> = cameras.iter(app.world()).collect();
    assert_eq!(cameras.len(), 2, "a picture and a physical camera");
    let active = |app: &App, entity: Entity| app.world().get::<Camera>(entity).expect("a camera").is_active;
    for &(entity, _) in &cameras {
        assert!(active(&app, entity), "both draw once the light is there");
    }
    let (physical, _) = *cameras.iter().find(|c| c.1).expect("the physical camera");
    let mut taken_out = app.world_mut().entity_mut(physical);
    taken_out.remove::<offscreen::AwaitsLight>();
    taken_out.get_mut::<Camera>().expect("a camera").is_active = false;
    for _ in 0..3 {
        app.update();
    }
    for &(entity, is_physical) in &cameras {
        assert_eq!(active(&app, entity), !is_physical, "the picture camera draws on, the one taken out stays off");
    }
}

/// Edges are anti-aliased after tone mapping (SMAA), the sun pass left
/// exact: against the same view drawn at 4 × 4 the resolution and
/// averaged (a supersampled reference), the picture's pixels on edges are
/// closer than point samples of that reference (one sub-pixel of each
/// 4 × 4 block: an aliased picture), and the rest is left as it was.
#[test]
fn edges_are_smoothed_toward_a_supersampled_picture() {
    let request = |width: u32, height: u32| OffscreenRequest {
        scene: heliodon::bundled_scene("office"),
        view: None,
        fov: None,
        width,
        height,
        when: Some(LocalDateTime { date: Date::new(2026, 3, 21).unwrap(), time: TimeOfDay::from_hours(14.0).unwrap() }),
        sky: Some(SkySpec::Clear { turbidity: 2.45 }),
        settings: RenderSettings { exposure: Some(10.0), ..Default::default() },
        light: Default::default(),
        panels: Default::default(),
    };
    let (width, height, k) = (320usize, 200usize, 4usize);
    let picture = offscreen::render(request(width as u32, height as u32)).expect("render");
    let fine = offscreen::render(request((k * width) as u32, (k * height) as u32)).expect("render");
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("anti_aliased_office.png");
    picture.save_png(&out).unwrap();
    // Luminance in linear units, from the 8-bit sRGB pictures.
    let linear = |c: u8| {
        let c = f32::from(c) / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    };
    let luminance =
        |rgba: &[u8], i: usize| 0.2126 * linear(rgba[4 * i]) + 0.7152 * linear(rgba[4 * i + 1]) + 0.0722 * linear(rgba[4 * i + 2]);
    let sub = |x: usize, y: usize, dx: usize, dy: usize| luminance(&fine.rgba, (k * y + dy) * k * width + k * x + dx);
    let (mut edges, mut aa_error, mut point_error, mut flat_error, mut flat) = (0, 0.0, 0.0, 0.0, 0);
    for y in 0..height {
        for x in 0..width {
            let reference = (0..k * k).map(|s| sub(x, y, s % k, s / k)).sum::<f32>() / (k * k) as f32;
            let point = sub(x, y, 1, 1);
            let drawn = luminance(&picture.rgba, y * width + x);
            if (point - reference).abs() > 0.02 {
                edges += 1;
                aa_error += (drawn - reference).abs();
                point_error += (point - reference).abs();
            } else {
                flat += 1;
                flat_error += (drawn - reference).abs();
            }
        }
    }
    let (aa_error, point_error, flat_error) = (aa_error / edges as f32, point_error / edges as f32, flat_error / flat as f32);
    println!(
        "{edges} edge pixels: anti-aliased {aa_error:.4} from the supersampled picture, point samples {point_error:.4}; elsewhere {flat_error:.4} -> {}",
        out.display()
    );
    assert!(edges > 500, "the view has edges: {edges}");
    assert!(aa_error < 0.75 * point_error, "edges: anti-aliased {aa_error} vs point samples {point_error}");
    assert!(flat_error < 0.01, "away from edges the picture is the supersampled one: {flat_error}");
}

/// The sky around the model is the sky model's luminance: looking up
/// from beside the office at a clear March afternoon, every pixel of the
/// physical image holds the sky's luminance in its direction (Perez here;
/// the cubemap's 2.8° texels blended, the sun's own disc not drawn).
#[test]
fn the_sky_drawn_around_the_model_is_the_sky_model() {
    let scene_path = heliodon::bundled_scene("office");
    let scene = load_scene(&scene_path, &PanelCatalog::new()).unwrap().scene;
    let when = LocalDateTime { date: Date::new(2026, 3, 21).unwrap(), time: TimeOfDay::from_hours(14.0).unwrap() };
    let spec = SkySpec::Clear { turbidity: 2.45 };
    let sky = heliodon::sky::sky_at(&scene.site, &spec, &when).1.unwrap();
    // Away from the building, looking north-east and up, away from the sun.
    let view = Viewpoint { name: "up".into(), eye: Vec3::new(-60.0, -60.0, 2.0), target: Vec3::new(-55.0, -50.0, 9.0), fov: 50.0 };
    let (width, height) = (160usize, 100usize);
    let request = OffscreenRequest {
        scene: scene_path,
        view: Some(view.clone()),
        fov: None,
        width: width as u32,
        height: height as u32,
        when: Some(when),
        sky: Some(spec),
        settings: RenderSettings { exposure: Some(12.0), ..Default::default() },
        light: Default::default(),
        panels: Default::default(),
    };
    let image = offscreen::render(request).expect("render");
    let forward = (view.target - view.eye).normalize().as_dvec3();
    let right = forward.cross(heliodon::glam::DVec3::Z).normalize();
    let up = right.cross(forward);
    let tan = (0.5 * f64::from(view.fov)).to_radians().tan();
    let mut errors: Vec<f64> = (0..width * height)
        .map(|k| {
            let (x, y) = ((k % width) as f64, (k / width) as f64);
            let along_x = (2.0 * (x + 0.5) / width as f64 - 1.0) * tan * width as f64 / height as f64;
            let along_y = (1.0 - 2.0 * (y + 0.5) / height as f64) * tan;
            let direction = (forward + right * along_x + up * along_y).normalize();
            let expected = sky.radiance(direction) * heliodon::sky::LUMINOUS_EFFICACY;
            let drawn = heliodon::light::luminous(image.physical[k].map(f64::from));
            (drawn / expected - 1.0).abs()
        })
        .collect();
    errors.sort_by(f64::total_cmp);
    let (median, worst) = (errors[errors.len() / 2], errors[errors.len() - 1]);
    println!("sky pixels against the sky model: median {:.2}%, worst {:.2}%", 100.0 * median, 100.0 * worst);
    assert!(median < 0.005 && worst < 0.02, "median {median}, worst {worst}");
}

/// The office drawn at 120 × 120 from `view` at (year, month, day, hour)
/// under a clear sky.
fn office_picture(view: &Viewpoint, (year, month, day, hour): (i32, u32, u32, f64), settings: RenderSettings) -> offscreen::RenderedImage {
    let request = OffscreenRequest {
        scene: heliodon::bundled_scene("office"),
        view: Some(view.clone()),
        fov: None,
        width: 120,
        height: 120,
        when: Some(LocalDateTime { date: Date::new(year, month, day).unwrap(), time: TimeOfDay::from_hours(hour).unwrap() }),
        sky: Some(SkySpec::Clear { turbidity: 2.45 }),
        settings,
        light: Default::default(),
        panels: Default::default(),
    };
    offscreen::render(request).expect("render")
}

/// The luminances (cd/m², sorted) of the middle 60 × 60 pixels of a 120 × 120 picture.
fn middle_luminances(image: &offscreen::RenderedImage) -> Vec<f64> {
    let mut values: Vec<f64> = (30..90)
        .flat_map(|y| (30..90).map(move |x| y * 120 + x))
        .map(|k| heliodon::light::luminous(image.physical[k].map(f64::from)))
        .collect();
    values.sort_by(f64::total_cmp);
    values
}

/// A horizontal section shows the rooms from above: looking straight down
/// on the office at noon, the sunlit roof fills the middle of the picture;
/// cut under the ceiling, the floor and desks inside show instead (under
/// an eighth of the roof's luminance), with the sun that the windows and
/// skylights let in on them (the sun pass still sees the whole model).
#[test]
fn a_section_shows_the_rooms_from_above() {
    let view = Viewpoint { name: "plan".into(), eye: Vec3::new(5.3, 7.0, 40.0), target: Vec3::new(5.3, 7.01, 0.0), fov: 12.0 };
    let render = |section: Option<f32>| office_picture(&view, (2026, 6, 21, 12.0), RenderSettings { section, ..Default::default() });
    let roof = middle_luminances(&render(None));
    let cut = render(Some(2.7));
    cut.save_png(&PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("office_plan_section.png")).unwrap();
    let inside = middle_luminances(&cut);
    let median = |v: &[f64]| v[v.len() / 2];
    println!(
        "median luminance: roof {:.0} cd/m², under the section {:.0}; brightest inside {:.0}",
        median(&roof),
        median(&inside),
        inside[inside.len() - 1]
    );
    assert!(median(&inside) < median(&roof) / 8.0, "roof {} vs inside {}", median(&roof), median(&inside));
    assert!(median(&inside) > 1.0, "the rooms are lit: {}", median(&inside));
    assert!(inside[inside.len() - 1] > 5.0 * median(&inside), "sun patches inside: {}", inside[inside.len() - 1]);
}

/// A vertical section opens the building to a side view: from the south at
/// a March afternoon the sunlit south wall fills the middle of the
/// picture; with the southern 4.3 m cut away, the rooms behind it show
/// instead, darker than the sunlit wall by far.
#[test]
fn a_vertical_section_opens_the_side_of_the_building() {
    let view = Viewpoint { name: "south".into(), eye: Vec3::new(5.3, -30.0, 1.5), target: Vec3::new(5.3, 7.0, 1.5), fov: 6.0 };
    let render = |vertical_section| office_picture(&view, (2026, 3, 21, 14.0), RenderSettings { vertical_section, ..Default::default() });
    let median = |values: Vec<f64>| values[values.len() / 2];
    let wall = median(middle_luminances(&render(None)));
    let image = render(Some(heliodon::render::VerticalSection { azimuth: 180.0, offset: -4.3 }));
    image.save_png(&PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("office_vertical_section.png")).unwrap();
    let inside = median(middle_luminances(&image));
    println!("median luminance: the south wall {wall:.0} cd/m², behind the section {inside:.0}");
    assert!(inside < wall / 4.0 && inside > 1.0, "wall {wall} vs inside {inside}");
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
    // Turning north on the site turns the sun (in the model's frame) and the
    // sky with it; the sun's true position stays.
    let before = app.world().resource::<SunSky>().sky.sun.unwrap().direction;
    app.world_mut().resource_mut::<Site>().0.north_turn = 90.0;
    app.update();
    assert_eq!(messages(&mut app), 1);
    let state = app.world().resource::<SunSky>();
    let after = state.sky.sun.unwrap().direction;
    let turned = heliodon::glam::DQuat::from_rotation_z(-std::f64::consts::FRAC_PI_2) * before;
    assert!((after - turned).length() < 1e-9, "{after} vs {turned}");
    assert_eq!(state.sun, solar_position(&site, &LocalDateTime { date, time: TimeOfDay::from_hours(16.25).unwrap() }));
    // A new sky is one more update, and its light shows.
    app.world_mut().resource_mut::<SkyChoice>().0 = SkySpec::Overcast;
    app.update();
    assert_eq!(messages(&mut app), 1);
    assert!(app.world().resource::<SunSky>().sky.sun.is_none());
}

/// The scene loader keeps what it makes of the model's files in the light
/// cache's folder: a second app opening the scene reads that file (the same
/// file, not one written again) and gets the same scene.
#[test]
fn opening_a_scene_goes_through_the_scene_cache() {
    use heliodon::ecs::LightCacheDir;
    use std::os::unix::fs::MetadataExt;
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("app_scene_cache");
    let _ = std::fs::remove_dir_all(&dir);
    let scene_files = || -> Vec<PathBuf> {
        std::fs::read_dir(&dir)
            .map(|entries| entries.flatten().map(|e| e.path()).filter(|p| p.to_string_lossy().contains("light-scene-")).collect())
            .unwrap_or_default()
    };
    let opened = || {
        let mut app = headless_app();
        app.insert_resource(LightCacheDir(Some(dir.clone())));
        open(&mut app, heliodon::bundled_scene("office")).unwrap();
        let scene = app.world().resource::<ActiveScene>().loaded.clone().expect("loaded scene");
        format!("{:?}", (&scene.triangles, &scene.surfaces, &scene.patches, &scene.sensors, &scene.materials))
    };
    let first = opened();
    let files = scene_files();
    assert_eq!(files.len(), 1, "{files:?}");
    let inode = std::fs::metadata(&files[0]).unwrap().ino();
    let second = opened();
    assert_eq!(scene_files(), files);
    assert_eq!(std::fs::metadata(&files[0]).unwrap().ino(), inode, "read, not written again");
    assert_eq!(first, second);
}

/// A headless app with a quick light engine and no cache, with the bundled
/// scene `name` open.
fn lit_app(name: &str) -> App {
    use heliodon::ecs::{self, LightCacheDir};
    let mut app = headless_app();
    app.insert_resource(ecs::LightSettings(quick_light())).insert_resource(LightCacheDir(None));
    open(&mut app, heliodon::bundled_scene(name)).unwrap();
    app
}

/// Updates the app until its newest relight has converged; `each` sees it
/// after every update.
fn run_until_settled(app: &mut App, mut each: impl FnMut(&mut App)) {
    use heliodon::ecs::{LightEngine, LightingState};
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        app.update();
        each(app);
        let engine = app.world().resource::<LightEngine>();
        let state = app.world().resource::<LightingState>();
        if engine.model.is_some() && state.converged && state.generation == engine.generation() {
            return;
        }
        assert!(Instant::now() < deadline, "lighting did not settle");
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn relights_run_as_tasks_and_the_last_change_wins() {
    use heliodon::ecs::{LightEngine, LightingState, LightingUpdated, SolarTime, SunSky};
    use heliodon::time::{LocalDateTime, TimeOfDay};

    let mut app = lit_app("test_room");
    let mut seen: Vec<u64> = Vec::new();
    let mut record = |app: &mut App| seen.extend(app.world_mut().resource_mut::<Messages<LightingUpdated>>().drain().map(|m| m.generation));
    run_until_settled(&mut app, &mut record);
    let first = app.world().resource::<LightingState>().generation;
    // Three changes of time in quick succession: one frame each.
    let date = app.world().resource::<SolarTime>().0.date;
    for hours in [9.0, 11.0, 15.5] {
        app.world_mut().resource_mut::<SolarTime>().0 = LocalDateTime { date, time: TimeOfDay::from_hours(hours).unwrap() };
        app.update();
        record(&mut app);
    }
    run_until_settled(&mut app, &mut record);
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

/// The viewer's light (`RefineForDisplay`): the light of the settings is
/// shown first, then a precomputation with the display's patch rays runs in
/// the background, and the light shown is that smoothed model's, as a fresh
/// solve gives it; the sensors read as the settings' own model gives them.
/// Each precomputation wakes the app (`LightWaker`) once its model is there
/// to take, and changes nothing shown while it runs.
#[test]
fn the_light_shown_is_smoothed_after_it_appears() {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use heliodon::ecs::{self, LightCacheDir, LightEngine, LightWaker, LightingState, RefineForDisplay, SunSky};

    let base = quick_light();
    let mut app = headless_app();
    app.insert_resource(ecs::LightSettings(base)).insert_resource(LightCacheDir(None)).insert_resource(RefineForDisplay(true));
    let wakes = Arc::new(AtomicUsize::new(0));
    let counted = wakes.clone();
    app.insert_resource(LightWaker(Arc::new(move || {
        counted.fetch_add(1, Ordering::SeqCst);
    })));
    open(&mut app, heliodon::bundled_scene("test_room")).unwrap();
    let (mut shown_first, mut smoothed_after) = (false, false);
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        app.update();
        let world = app.world();
        let (engine, state) = (world.resource::<LightEngine>(), world.resource::<LightingState>());
        shown_first |= state.converged && engine.model.is_some() && engine.smoothed.is_none() && engine.is_smoothing();
        smoothed_after |= shown_first && engine.smoothed.is_some();
        if engine.is_precomputing() && engine.model.is_none() {
            assert!(!engine.is_relighting(state), "nothing to show while the first precomputation runs");
            assert!(state.lighting.is_none());
        }
        if smoothed_after && !engine.is_smoothing() && !engine.is_settling(state) {
            break;
        }
        assert!(Instant::now() < deadline, "the light was not smoothed in time (shown first: {shown_first})");
        std::thread::sleep(Duration::from_millis(5));
    }
    let world = app.world();
    let engine = world.resource::<LightEngine>();
    assert_eq!(engine.model.as_ref().unwrap().settings, base, "the numbers' model");
    let model = engine.smoothed.clone().unwrap();
    assert_eq!(model.settings, base.for_display(model.scene.patches.patches.len()));
    assert_eq!(model.settings.rays_per_patch, 2048, "a room's picture takes 8 times the default patch rays");
    let sky = &world.resource::<SunSky>().sky;
    let fresh = model.solve(sky, None);
    let shown = world.resource::<LightingState>().lighting.clone().unwrap();
    for (a, b) in shown.sides.iter().zip(&fresh.sides) {
        assert!((a.indirect[1] - b.indirect[1]).abs() <= 1e-3 * b.indirect[1].max(1.0), "{a:?} vs {b:?}");
    }
    // The sensors read as `sensors` reads them, and not as the smoothed model would.
    let numbers = engine.model.as_ref().unwrap().solve(sky, None);
    assert_eq!(shown.sensors, numbers.sensors);
    assert!(shown.sensors.iter().zip(&fresh.sensors).any(|(a, b)| a.total != b.total));
    assert_eq!(wakes.load(Ordering::SeqCst), 2, "one wake per precomputation: the settings' own and the display's");
}

/// Renders the direct sun of a view and compares it with the CPU reference
/// (`render::reference`); the picture and its disagreement map go to the
/// test's temporary folder.
fn compare_direct_sun(path: &std::path::Path, view: &Viewpoint, date: &str, time: &str) -> (SunComparison, String) {
    let request = OffscreenRequest {
        scene: path.to_path_buf(),
        view: Some(view.clone()),
        fov: None,
        width: 320,
        height: 200,
        when: Some(LocalDateTime { date: Date::parse(date).unwrap(), time: TimeOfDay::parse(time).unwrap() }),
        sky: Some(SkySpec::Clear { turbidity: 2.45 }),
        settings: RenderSettings { mode: RenderMode::Sun, ..Default::default() },
        light: Default::default(),
        panels: Default::default(),
    };
    let scene_name = path.parent().and_then(|p| p.file_name()).unwrap().to_string_lossy();
    let file = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "sun_{scene_name}_{}_{}.png",
        view.name.replace(' ', "_"),
        time.replace(':', "")
    ));
    let result = reference::compare_direct_sun(&request, &file).expect("render and compare");
    let summary = format!("{scene_name} {} {date} {time}: {result} -> {}", view.name, file.display());
    println!("{summary}");
    (result, summary)
}

/// Every bundled scene from its first camera at two sun positions and from
/// outside at a third; and from high above in a low afternoon sun, where
/// the building's shadow falls long on the ground around it.
#[test]
fn direct_sun_images_agree_with_a_ray_traced_reference() {
    for name in heliodon::BUNDLED_SCENES {
        let path = heliodon::bundled_scene(name);
        let scene = load_scene(&path, &PanelCatalog::new()).unwrap().scene;
        let overview = overview(&scene);
        let above = Viewpoint {
            name: "above".into(),
            eye: overview.target + Vec3::new(0.0, -0.3, 1.0) * 2.0 * (overview.eye - overview.target).length(),
            ..overview.clone()
        };
        let cases = [
            (&scene.viewpoints[0], "2026-03-21", "10:00"),
            (&scene.viewpoints[0], "2026-11-10", "14:30"),
            (&overview, "2026-12-21", "12:00"),
            (&above, "2026-03-21", "16:30"),
        ];
        for (view, date, time) in cases {
            let (result, summary) = compare_direct_sun(&path, view, date, time);
            assert!(result.compared > 320 * 200 / 10, "{summary}");
            assert!(result.lit > 200, "too few sunlit pixels to compare: {summary}");
            assert!(result.agreement >= 0.99 && result.within >= 0.99, "{summary}");
            if view.name == "above" {
                // The view is all model and ground; the shadow is a good part of it.
                assert!(result.compared > 320 * 200 * 99 / 100 && result.compared - result.lit > 320 * 200 / 50, "{summary}");
            }
        }
    }
}

/// Depth-fail stencil counting: a camera standing in the sunbeam of a
/// window, and one in the room's shadow, both see the sun patches right.
#[test]
fn cameras_inside_a_sunbeam_and_inside_a_shadow_see_the_sun_right() {
    let path = heliodon::bundled_scene("test_room");
    let scene = Arc::new(load_scene(&path, &PanelCatalog::new()).unwrap().scene);
    let model = LightModel::unlit(scene.clone());
    let when = LocalDateTime { date: Date::parse("2026-03-21").unwrap(), time: TimeOfDay::parse("10:00").unwrap() };
    let position = solar_position(&scene.site, &when);
    let sky = Sky::new(&SkySpec::Clear { turbidity: 2.45 }, position.altitude, position.azimuth, 0.2, 80).unwrap();
    let sun = sky.sun.unwrap();
    // Half a metre in from the middle of the lower middle pane, along the beam.
    let pane = scene
        .windows
        .iter()
        .min_by(|a, b| (a.centroid.x - 2.0).abs().total_cmp(&(b.centroid.x - 2.0).abs()).then(a.centroid.z.total_cmp(&b.centroid.z)))
        .unwrap();
    let in_beam = pane.centroid.as_dvec3() - sun.direction * 0.5;
    let floor_patch = in_beam - sun.direction * (in_beam.z / sun.direction.z);
    assert!(model.sun_irradiance(in_beam, sun.direction, &sun) > 0.0, "the eye is in the beam");
    let in_shadow = glam::DVec3::new(0.6, 5.0, 2.5);
    assert_eq!(model.sun_irradiance(in_shadow, sun.direction, &sun), 0.0, "the eye is in shadow");
    for (name, eye, target) in [("in beam", in_beam, floor_patch), ("in shadow", in_shadow, floor_patch)] {
        let view = Viewpoint { name: name.into(), eye: eye.as_vec3(), target: target.as_vec3(), fov: 75.0 };
        let (result, summary) = compare_direct_sun(&path, &view, "2026-03-21", "10:00");
        assert!(result.lit > 1000, "the floor patch fills much of the view: {summary}");
        assert!(result.agreement >= 0.99 && result.within >= 0.99, "{summary}");
    }
}

/// Real models are rarely clean: an open box, a duplicated face and
/// T-junctions still cast exact shadows, with no holes or streaks.
#[test]
fn non_manifold_models_cast_shadows_without_holes_or_streaks() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("non_manifold");
    std::fs::create_dir_all(&dir).unwrap();
    let obj = "\
mtllib model.mtl
usemtl ground
v -4 -4 0
v 8 -4 0
v 8 8 0
v -4 8 0
f 1 2 3 4
usemtl wall
# An open box (no lid, no floor), single-sided walls.
v 0 0 0
v 2 0 0
v 2 2 0
v 0 2 0
v 0 0 1.5
v 2 0 1.5
v 2 2 1.5
v 0 2 1.5
f 5 6 10 9
f 6 7 11 10
f 7 8 12 11
f 8 5 9 12
# The east wall again, duplicated.
f 6 7 11 10
# A screen whose long top edge meets two short panels below it: T-junctions.
v 4 0 2
v 6 0 2
v 6 0 3
v 4 0 3
v 5 0 2
v 4 0 1
v 5 0 1
v 6 0 1
f 13 14 15 16
f 18 19 17 13
f 19 20 14 17
";
    std::fs::write(dir.join("model.obj"), obj).unwrap();
    std::fs::write(dir.join("model.mtl"), "newmtl ground\nKd 0.3 0.3 0.3\nnewmtl wall\nKd 0.6 0.6 0.6\n").unwrap();
    let scene_text =
        "name = \"Non-manifold\"\n[site]\nlatitude = 42.36\nlongitude = -71.06\ntimezone = -5.0\n[model]\nobj = \"model.obj\"\n";
    std::fs::write(dir.join("scene.toml"), scene_text).unwrap();
    let path = dir.join("scene.toml");
    let views = [
        Viewpoint { name: "above".into(), eye: glam::Vec3::new(1.0, -6.0, 9.0), target: glam::Vec3::new(2.0, 2.0, 0.0), fov: 60.0 },
        // From the south-east, with the duplicated wall's face in the sun.
        Viewpoint { name: "low".into(), eye: glam::Vec3::new(5.0, -3.0, 1.2), target: glam::Vec3::new(1.0, 1.0, 0.7), fov: 70.0 },
    ];
    for (view, time) in views.iter().zip(["15:00", "10:00"]) {
        let (result, summary) = compare_direct_sun(&path, view, "2026-03-21", time);
        assert!(result.lit > 1000, "{summary}");
        assert!(result.agreement >= 0.99 && result.within >= 0.99, "{summary}");
    }
}

/// The viewer's day plot: a sensor's light over the day is dark at night,
/// rises after sunrise and peaks around noon.
#[test]
fn the_day_series_of_a_sensor_follows_the_sun() {
    use heliodon::day::{DAY_STEPS, day_series};
    let scene = Arc::new(load_scene(&heliodon::bundled_scene("test_room"), &PanelCatalog::new()).unwrap().scene);
    let settings = heliodon::light::LightSettings {
        rays_per_patch: 32,
        rays_per_sensor: 256,
        sky_rays_per_sensor: 256,
        window_rays_per_sensor: 128,
        sun_samples_per_patch: 4,
        area_sensor_sun_grid: 4,
        ..Default::default()
    };
    let model = Arc::new(LightModel::precompute(scene.clone(), settings).unwrap());
    let centre = scene.sensors.iter().position(|s| s.name == "room-centre").unwrap();
    let values = day_series(&model, centre, &scene.site, Date::new(2026, 3, 21).unwrap(), &SkySpec::Overcast);
    assert_eq!(values.len(), DAY_STEPS);
    let at = |hours: f64| values[(hours * DAY_STEPS as f64 / 24.0) as usize];
    assert_eq!(at(2.0), 0.0, "night");
    assert!(at(9.0) > 50.0 && at(12.0) > at(9.0) && at(12.0) > at(16.0), "{values:?}");
}

/// Editing materials as the materials panel does: the scene is spawned
/// again and relit. Darker glass lets less light in; a wall cannot become
/// a window (the edit is refused with a message).
#[test]
fn material_edits_relight_and_impossible_ones_are_refused() {
    use heliodon::ecs::{ActiveScene, EditMaterial, LightingState, MaterialEditRejected};
    use heliodon::scene::MaterialKind;

    let mut app = lit_app("test_room");
    // The room's total light once settled.
    let settle = |app: &mut App| -> f64 {
        run_until_settled(app, |_| {});
        app.world().resource::<LightingState>().lighting.as_ref().unwrap().sensors.iter().map(|s| s.total).sum()
    };
    let before = settle(&mut app);
    let materials = app.world().resource::<ActiveScene>().scene.clone().unwrap().materials.clone();
    let glass = materials.iter().position(|m| matches!(m.kind, MaterialKind::Glass { .. })).unwrap() as u32;
    let wall = materials.iter().position(|m| m.name == "wall").unwrap() as u32;
    app.world_mut().write_message(EditMaterial { index: glass, kind: MaterialKind::Glass { transmittance: 0.44 } });
    app.world_mut().write_message(EditMaterial { index: wall, kind: MaterialKind::Glass { transmittance: 0.5 } });
    app.update();
    let refused: Vec<String> = app.world_mut().resource_mut::<Messages<MaterialEditRejected>>().drain().map(|m| m.message).collect();
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert!(refused[0].contains("'wall' is a diffuse"), "{}", refused[0]);
    let after = settle(&mut app);
    let scene = app.world().resource::<ActiveScene>().scene.clone().unwrap();
    assert_eq!(scene.materials[glass as usize].kind, MaterialKind::Glass { transmittance: 0.44 });
    assert!(matches!(scene.materials[wall as usize].kind, MaterialKind::Diffuse { .. }));
    // Half the glass transmittance at normal incidence: about half the daylight.
    assert!(after < 0.6 * before && after > 0.4 * before, "{before} -> {after}");
}

/// The camera panel's requests, as its buttons make them: a preset looks at
/// the whole model from where it says, a saved view joins the list and can
/// be gone back to.
#[test]
fn camera_requests_move_the_camera_and_save_views() {
    use heliodon::viewer::camera::{CadCamera, CameraControl, CameraRequest, apply_camera_request};

    let mut app = headless_app();
    app.init_resource::<CameraControl>().add_systems(Update, apply_camera_request);
    open(&mut app, heliodon::bundled_scene("test_room")).unwrap();
    let camera = app.world_mut().spawn(CadCamera::looking(Vec3::new(2.0, 5.0, 1.6), Vec3::new(2.0, 0.0, 1.2))).id();
    let scene = app.world().resource::<ActiveScene>().scene.clone().unwrap();
    let (centre, distance) = heliodon::render::framing(scene.focus, heliodon::scene::DEFAULT_FOV);
    app.world_mut().resource_mut::<CameraControl>().request = Some(CameraRequest::Top);
    app.update();
    let top = *app.world().get::<CadCamera>(camera).unwrap();
    assert!((top.focus - centre).length() < 1e-5 && (top.distance - distance).abs() < 1e-4);
    assert!(top.eye().z > centre.z + 0.99 * distance, "from above: {:?}", top.eye());
    app.world_mut().resource_mut::<CameraControl>().request = Some(CameraRequest::Save);
    app.update();
    let saved = app.world().resource::<CameraControl>().saved_views.clone();
    assert_eq!(saved.len(), 1);
    assert!((saved[0].eye - top.eye()).length() < 1e-4);
    app.world_mut().resource_mut::<CameraControl>().request = Some(CameraRequest::Front);
    app.update();
    let front = *app.world().get::<CadCamera>(camera).unwrap();
    assert!(front.eye().y < centre.y - 0.99 * distance, "from the south: {:?}", front.eye());
    app.world_mut().resource_mut::<CameraControl>().request = Some(CameraRequest::Viewpoint(saved[0].clone()));
    app.update();
    let back = *app.world().get::<CadCamera>(camera).unwrap();
    assert!((back.eye() - top.eye()).length() < 1e-3);
}

/// The viewer's sweep, as its panel starts it: the cells fill in from the
/// background (more glass transmittance, more light at the sensor, about in
/// proportion), and a clicked cell's keys become the material's.
#[test]
fn the_viewer_sweep_fills_in_and_applies_a_clicked_cell() {
    use heliodon::ecs::ActiveScene;
    use heliodon::scene::MaterialKind;
    use heliodon::viewer::annual::AnnualStudy;
    use heliodon::viewer::sensors::SelectedSensor;
    use heliodon::viewer::sweep::{KeyRange, SweepPlugin, SweepStudy};

    let mut app = lit_app("test_room");
    app.init_resource::<SelectedSensor>().init_resource::<AnnualStudy>().add_plugins(SweepPlugin);
    run_until_settled(&mut app, |_| {});
    let scene = app.world().resource::<ActiveScene>().scene.clone().unwrap();
    let glass = scene.materials.iter().position(|m| matches!(m.kind, MaterialKind::Glass { .. })).unwrap() as u32;
    app.world_mut().resource_mut::<SelectedSensor>().0 = scene.sensors.iter().position(|s| s.name == "room-centre");
    {
        let mut study = app.world_mut().resource_mut::<SweepStudy>();
        study.material = Some(glass);
        study.ranges = vec![KeyRange { key: "transmittance".into(), lo: 0.3, hi: 0.6, step: 0.3 }];
        study.requested = true;
    }
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        app.update();
        let study = app.world().resource::<SweepStudy>();
        assert!(study.error.is_none(), "{:?}", study.error);
        if !study.is_running() && study.progress() == (2, 2) {
            break;
        }
        assert!(Instant::now() < deadline, "the sweep did not finish");
        std::thread::sleep(Duration::from_millis(5));
    }
    let cells: Vec<f64> =
        app.world().resource::<SweepStudy>().cells.lock().unwrap().iter().map(|c| *c.as_ref().unwrap().as_ref().unwrap()).collect();
    assert!(cells[0] > 20.0 && cells[1] > 1.6 * cells[0] && cells[1] < 2.4 * cells[0], "{cells:?}");
    app.world_mut().resource_mut::<SweepStudy>().apply = Some(0);
    // The click becomes an edit, the edit a new scene, the scene new light.
    for _ in 0..3 {
        app.update();
    }
    run_until_settled(&mut app, |_| {});
    let scene = app.world().resource::<ActiveScene>().scene.clone().unwrap();
    assert_eq!(scene.materials[glass as usize].kind, MaterialKind::Glass { transmittance: 0.3 });
}
