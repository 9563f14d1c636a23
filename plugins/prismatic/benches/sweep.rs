//! Issue 16's sweep costs on the bundled prismatic room: a 13 × 13 sweep of
//! its two facet angles at one instant (21 December, 12:00, clear sky),
//! cold (the precomputation included), beside what one combination costs
//! when run on its own as `heliodon sensors` would (precomputation and a
//! relight of a scene with those keys); and the same against a year of
//! weather (DA300 at every sensor and the sDA; Chicago TMY3 from
//! ../shared/data/weather, or the EPW named by `HELIODON_BENCH_EPW`), beside
//! one combination run on its own as `heliodon annual` would. The 13 × 13
//! year is timed once and printed with the ratios (a criterion sample of it
//! would take a quarter of an hour); criterion times 13 × 1 against the year.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use heliodon_core::annual::{AnnualOptions, Occupancy, annual};
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

/// One combination's year as a scene of its own, the way `heliodon annual`
/// runs it with no cache: its precomputation and the year.
fn one_scene_year(scene: &Arc<Scene>, weather: &Weather) -> f64 {
    let model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
    annual(&model, &scene.site, weather, &AnnualOptions::default(), &|_| {}).unwrap().sda()
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
    one_scene_year(&scene, &weather);
    let year_once = start.elapsed().as_secs_f64();
    let year = Target::Year(&weather, Occupancy::default());
    let start = Instant::now();
    assert_eq!(run_sweep(&scene, &full, year), built);
    let year_swept = start.elapsed().as_secs_f64();
    println!(
        "prismatic room: 13 × 13 at an instant {swept:.2} s ({built} combinations built); one scene run {once:.2} s, \
         × 169 = {:.1} s, {:.1}× the sweep",
        169.0 * once,
        169.0 * once / swept,
    );
    println!(
        "prismatic room: 13 × 13 against a year {year_swept:.1} s; one scene's year run {year_once:.1} s, × 169 = {:.1} min, {:.1}× the sweep",
        169.0 * year_once / 60.0,
        169.0 * year_once / year_swept
    );

    group.bench_function("prismatic room: 13 x 13 facet angles, one instant, cold", |b| {
        b.iter(|| run_sweep(&scene, &full, Target::Instant(&sky)))
    });
    group.bench_function("prismatic room: one combination as its own scene (sensors)", |b| b.iter(|| one_scene(&scene, &sky)));
    let column = Grid { axes: vec![Axis::parse("facet_angles[0]=0..60:5").unwrap(), Axis::parse("facet_angles[1]=5..5:5").unwrap()] };
    group.bench_function("prismatic room: 13 x 1 facet angles against a year, cold", |b| b.iter(|| run_sweep(&scene, &column, year)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
