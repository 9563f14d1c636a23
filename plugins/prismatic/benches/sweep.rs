//! Issue 16's sweep costs on the bundled prismatic room: a 13 × 13 sweep of
//! its two facet angles at one instant (21 December, 12:00, clear sky),
//! cold (the precomputation included), beside what one combination costs
//! when run on its own as `heliodon sensors` would (precomputation and a
//! relight of a scene with those keys); and one combination against a year
//! of weather (DA300 at a sensor; Chicago TMY3 from ../shared/data/weather,
//! or the EPW named by `HELIODON_BENCH_EPW`). The ratios are printed.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use heliodon_core::annual::Occupancy;
use heliodon_core::light::{LightModel, LightSettings};
use heliodon_core::panel::PanelCatalog;
use heliodon_core::scene::{Scene, load_scene};
use heliodon_core::sky::{Sky, SkySpec, sky_at};
use heliodon_core::sweep::{Axis, Grid, Target, Variation, sweep};
use heliodon_core::time::{Date, LocalDateTime, TimeOfDay};
use heliodon_core::weather::Weather;

fn catalog() -> PanelCatalog {
    PanelCatalog::new().with(heliodon_prismatic::Prismatic)
}

fn room() -> Arc<Scene> {
    Arc::new(load_scene(&heliodon_core::bundled_scene("prismatic_room"), &catalog()).unwrap().scene)
}

fn winter_noon(scene: &Scene) -> Sky {
    let when = LocalDateTime { date: Date::new(2025, 12, 21).unwrap(), time: TimeOfDay::from_hours(12.0).unwrap() };
    sky_at(&scene.site, &SkySpec::parse("clear", &Default::default()).unwrap(), &when).1.unwrap()
}

fn grid(steps: usize) -> Grid {
    let last = 5.0 * (steps - 1) as f64;
    Grid {
        axes: vec![
            Axis::parse(&format!("facet_angles[0]=0..{last}:5")).unwrap(),
            Axis::parse(&format!("facet_angles[1]=0..{last}:5")).unwrap(),
        ],
    }
}

/// A sweep of `grid`, cold: the precomputation, then every combination.
fn run_sweep(scene: &Arc<Scene>, grid: &Grid, target: Target) -> usize {
    let mut model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
    let variation = Variation::new(scene, "upper", grid, &catalog()).unwrap();
    let sensors: Vec<usize> = (0..scene.sensors.len()).collect();
    sweep(&mut model, &variation, grid, 0..grid.len(), &sensors, target, &|_, _| {}).iter().filter(|o| o.result.is_ok()).count()
}

/// One combination as a scene of its own, the way `heliodon sensors` runs it
/// (no cache): its precomputation and one relight.
fn one_scene(scene: &Arc<Scene>, sky: &Sky) -> f64 {
    let model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
    model.solve(sky, None).sensors[0].total
}

fn weather() -> Weather {
    let path = std::env::var_os("HELIODON_BENCH_EPW")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/weather/chicago.epw"));
    Weather::read(&path).unwrap_or_else(|e| panic!("{e} (set HELIODON_BENCH_EPW to an EPW file)"))
}

fn bench(c: &mut Criterion) {
    let scene = room();
    let sky = winter_noon(&scene);
    let weather = weather();
    let full = grid(13);
    let mut group = c.benchmark_group("sweep");
    group.sample_size(10).measurement_time(Duration::from_secs(60));

    let start = Instant::now();
    let built = run_sweep(&scene, &full, Target::Instant(&sky));
    let swept = start.elapsed().as_secs_f64();
    let start = Instant::now();
    one_scene(&scene, &sky);
    let once = start.elapsed().as_secs_f64();
    let start = Instant::now();
    // The scene's own facet angles (40°, 5°), as one combination.
    let own = Grid { axes: vec![Axis::parse("facet_angles[0]=40..40:5").unwrap(), Axis::parse("facet_angles[1]=5..5:5").unwrap()] };
    assert_eq!(run_sweep(&scene, &own, Target::Year(&weather, Occupancy::default())), 1);
    let year = start.elapsed().as_secs_f64();
    println!(
        "prismatic room: 13 × 13 at an instant {swept:.2} s ({built} combinations built); one scene run {once:.2} s, \
         × 169 = {:.1} s, {:.1}× the sweep; a year per combination {year:.1} s (× 169 = {:.0} min)",
        169.0 * once,
        169.0 * once / swept,
        169.0 * year / 60.0
    );

    group.bench_function("prismatic room: 13 x 13 facet angles, one instant, cold", |b| {
        b.iter(|| run_sweep(&scene, &full, Target::Instant(&sky)))
    });
    group.bench_function("prismatic room: one combination as its own scene (sensors)", |b| b.iter(|| one_scene(&scene, &sky)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
