//! The light engine's costs: precomputation and relighting for the bundled
//! scenes, a generated floor of offices (≥ 50,000 patches), the same floor
//! furnished (≈ 100,000 triangles of clutter), and the peak memory.

#[path = "../../tests/support/office_floor.rs"]
mod office_floor;
#[path = "../../tests/support/quad_obj.rs"]
mod quad_obj;
#[path = "../../tests/support/room_on_ground.rs"]
mod room_on_ground;

use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use heliodon_core::light::{LightModel, LightSettings, Lighting};
use heliodon_core::panel::PanelCatalog;
use heliodon_core::scene::{Scene, load_scene};
use heliodon_core::sky::{Sky, SkySpec};
use heliodon_core::sun::solar_position;
use heliodon_core::time::{Date, LocalDateTime, TimeOfDay};

fn sky_at(scene: &Scene, hours: f64) -> Sky {
    let when = LocalDateTime { date: Date::new(2026, 3, 21).unwrap(), time: TimeOfDay::from_hours(hours).unwrap() };
    let sun = solar_position(&scene.site, &when);
    Sky::new(&SkySpec::Clear { turbidity: 2.45 }, sun.altitude, sun.azimuth, scene.site.ground_reflectance, 80).unwrap()
}

fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    Some(line.split_whitespace().nth(1)?.parse::<f64>().ok()? / 1024.0)
}

fn relight(model: &LightModel, scene: &Scene, previous: &Lighting, hours: f64) -> Lighting {
    model.solve(&sky_at(scene, hours), Some(previous))
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("light");
    group.sample_size(10).measurement_time(Duration::from_secs(20));
    for name in heliodon_core::BUNDLED_SCENES {
        let scene = Arc::new(load_scene(&heliodon_core::bundled_scene(name), &PanelCatalog::new()).unwrap().scene);
        group.bench_function(format!("precompute {name} ({} patches)", scene.patches.patches.len()), |b| {
            b.iter(|| LightModel::precompute(scene.clone(), LightSettings::default()).unwrap())
        });
        let model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
        let before = model.solve(&sky_at(&scene, 10.0), None);
        group.bench_function(format!("relight {name} (sun moves 10 min)"), |b| {
            b.iter(|| relight(&model, &scene, &before, 10.0 + 1.0 / 6.0))
        });
    }
    // A room on a 400 × 300 m ground (as Radiance's tutorial room stands).
    let path = room_on_ground::room_on_a_ground(&std::env::temp_dir().join("heliodon-bench-room-on-ground"), 400.0, 300.0, true);
    let scene = Arc::new(load_scene(&path, &PanelCatalog::new()).unwrap().scene);
    let patches = scene.patches.patches.len();
    group.bench_function(format!("precompute room on a 400 x 300 m ground ({patches} patches)"), |b| {
        b.iter(|| LightModel::precompute(scene.clone(), LightSettings::default()).unwrap())
    });
    let model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
    let before = model.solve(&sky_at(&scene, 10.0), None);
    group.bench_function("relight room on a 400 x 300 m ground (sun moves 10 min)", |b| {
        b.iter(|| relight(&model, &scene, &before, 10.0 + 1.0 / 6.0))
    });
    let path = office_floor::office_floor(&std::env::temp_dir().join("heliodon-bench-office-floor"), false);
    let scene = Arc::new(load_scene(&path, &PanelCatalog::new()).unwrap().scene);
    let patches = scene.patches.patches.len();
    let start = Instant::now();
    let model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
    println!("large building: {patches} patches, {} sensors, precompute {:.1} s", scene.sensors.len(), start.elapsed().as_secs_f64());
    let before = model.solve(&sky_at(&scene, 10.0), None);
    group.bench_function(format!("relight large building ({patches} patches, sun moves 10 min)"), |b| {
        b.iter(|| relight(&model, &scene, &before, 10.0 + 1.0 / 6.0))
    });
    drop(model);
    // The same floor furnished (about 100,000 triangles of clutter), at the
    // default patch size: clutter gathers into clusters.
    let path = office_floor::office_floor(&std::env::temp_dir().join("heliodon-bench-furnished-floor"), true);
    let scene = Arc::new(load_scene(&path, &PanelCatalog::new()).unwrap().scene);
    let (triangles, patches) = (scene.triangles.len(), scene.patches.patches.len());
    let start = Instant::now();
    let model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
    println!(
        "furnished floor: {triangles} triangles, {patches} patches, precompute {:.1} s ({})",
        start.elapsed().as_secs_f64(),
        path.display()
    );
    let before = model.solve(&sky_at(&scene, 10.0), None);
    group.bench_function(format!("relight furnished floor ({triangles} triangles, {patches} patches, sun moves 10 min)"), |b| {
        b.iter(|| relight(&model, &scene, &before, 10.0 + 1.0 / 6.0))
    });
    group.finish();
    if let Some(mib) = peak_memory_mib() {
        println!("peak memory (VmHWM) after the large building: {mib:.0} MiB");
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
