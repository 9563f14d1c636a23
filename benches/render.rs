//! Frame time of the hybrid renderer, headless on whatever Vulkan device
//! there is (Mesa's lavapipe on the CI machines): the bundled scenes in full
//! mode, and a generated hall of 100k triangles with direct sun only (its
//! sky and indirect light are one vertex-coloured mesh draw; the stencil
//! passes are what grows with the model). Prints the passes and shadow-volume
//! triangles drawn per frame.

#[path = "../tests/support/quad_obj.rs"]
mod quad_obj;

use quad_obj::QuadObj;
use std::path::{Path, PathBuf};
use std::time::Duration;

use bevy::prelude::*;
use criterion::{Criterion, criterion_group, criterion_main};
use heliodon::render::offscreen::{OffscreenRequest, frame_ready, offscreen_app};
use heliodon::render::sun_pass::SunPassInput;
use heliodon::render::{RenderMode, RenderSettings};
use heliodon::sky::SkySpec;
use heliodon::time::{Date, LocalDateTime, TimeOfDay};

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;

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
    let request = OffscreenRequest {
        scene,
        view: None,
        width: WIDTH,
        height: HEIGHT,
        when: Some(LocalDateTime { date: Date::new(2026, 3, 21).unwrap(), time: TimeOfDay::from_hours(10.0).unwrap() }),
        sky: Some(SkySpec::Clear { turbidity: 2.45 }),
        settings: RenderSettings { mode, ..Default::default() },
        light: Default::default(),
        panels: Default::default(),
    };
    let mut app = offscreen_app(&request);
    app.finish();
    app.cleanup();
    while !frame_ready(&app) {
        app.update();
    }
    let counts = match &app.world().resource::<SunPassInput>().0 {
        Some(frame) => format!(
            "{} draws per frame ({} direction passes, {} lights), {} shadow-volume triangles, {} lit triangles drawn once per light",
            frame.draw_count(),
            frame.passes.len(),
            frame.lights().count(),
            frame.volumes.len() / 3,
            frame.lit.len() / 27,
        ),
        None => "no sun pass".into(),
    };
    (app, counts)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    group.sample_size(10).measurement_time(Duration::from_secs(15));
    let mut cases: Vec<(String, PathBuf, RenderMode)> =
        heliodon::BUNDLED_SCENES.iter().map(|name| (format!("{name} full"), heliodon::bundled_scene(name), RenderMode::Full)).collect();
    cases.push(("hall 100k triangles sun".into(), hall(&std::env::temp_dir().join("heliodon-bench-hall")), RenderMode::Sun));
    for (label, scene, mode) in cases {
        let (mut app, counts) = ready_app(scene, mode);
        println!("{label}: {counts}");
        group.bench_function(format!("frame {label} {WIDTH}x{HEIGHT}"), |b| b.iter(|| app.update()));
    }
    settling(&mut group);
    group.finish();
}

/// The office while its light settles: frames drawn while relights run
/// (each converged relight is followed by a new time, ten minutes on), and
/// the frames around a material edit (respawn and a new precomputation).
fn settling(group: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>) {
    use heliodon::ecs::{ActiveScene, EditMaterial, LightingState, SolarTime};
    use std::time::Instant;
    let (mut app, _) = ready_app(heliodon::bundled_scene("office"), RenderMode::Full);
    let converged = |app: &App| app.world().get_resource::<LightingState>().is_some_and(|l| l.converged);
    let mut relights = 0u32;
    group.bench_function(format!("frame office full while the light settles {WIDTH}x{HEIGHT}"), |b| {
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
                app.update();
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
        app.update();
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
