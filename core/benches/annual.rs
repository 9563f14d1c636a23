//! The annual study's costs on a real year of weather (Chicago TMY3 from
//! ../shared/data/weather, or the EPW named by `HELIODON_BENCH_EPW`): the
//! bundled office (150 sensors) and the validation side room (19), cold
//! (gather, coefficients, the year's sun traced, the year) and with the
//! light cache warm (what `annual` does then: the gathers and the year's
//! sun read from a cache folder, the coefficients, the year), and warm with
//! every hour's readings formatted as `--hourly` writes them. The parts are
//! printed once beside the measurements.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use heliodon_core::annual::{AnnualOptions, SunHours, annual};
use heliodon_core::light::cache::precompute_cached;
use heliodon_core::light::{LightModel, LightSettings};
use heliodon_core::panel::PanelCatalog;
use heliodon_core::scene::{Scene, load_scene};
use heliodon_core::weather::Weather;

fn weather() -> Weather {
    let path = std::env::var_os("HELIODON_BENCH_EPW")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/weather/chicago.epw"));
    Weather::read(&path).unwrap_or_else(|e| panic!("{e} (set HELIODON_BENCH_EPW to an EPW file)"))
}

fn scenes() -> Vec<(&'static str, Arc<Scene>)> {
    let load = |path: PathBuf| Arc::new(load_scene(&path, &PanelCatalog::new()).unwrap().scene);
    vec![
        ("office", load(heliodon_core::bundled_scene("office"))),
        ("side room", load(Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/sideroom/scene.toml"))),
    ]
}

fn year(model: &LightModel, weather: &Weather, cache: Option<&Path>) -> f64 {
    annual(model, &model.scene.site, weather, &AnnualOptions { sun_cache: cache, ..Default::default() }, &|_| {}).unwrap().sda()
}

/// [`year`] with every hour's readings formatted as `annual --hourly`'s
/// CSV rows (and dropped).
fn year_with_every_hour(model: &LightModel, weather: &Weather, cache: Option<&Path>) -> f64 {
    let formatted = std::sync::atomic::AtomicUsize::new(0);
    let row = |_: usize, values: &[f32]| {
        let mut line = String::from("1,1,1");
        for value in values {
            let _ = write!(line, ",{value:.1}");
        }
        formatted.fetch_add(line.len(), std::sync::atomic::Ordering::Relaxed);
        Ok(())
    };
    let options = AnnualOptions { sun_cache: cache, hourly: Some(&row), ..Default::default() };
    let sda = annual(model, &model.scene.site, weather, &options, &|_| {}).unwrap().sda();
    std::hint::black_box(formatted.into_inner());
    sda
}

fn bench(c: &mut Criterion) {
    let weather = weather();
    let cache = std::env::temp_dir().join(format!("heliodon-bench-annual-{}", std::process::id()));
    let mut group = c.benchmark_group("annual");
    group.sample_size(10).measurement_time(Duration::from_secs(60));
    for (name, scene) in scenes() {
        let start = Instant::now();
        let model = LightModel::precompute(scene.clone(), LightSettings::default()).unwrap();
        let gathered = start.elapsed();
        let coefficients = model.sensor_coefficients();
        let folded = start.elapsed() - gathered;
        let sun_dir = cache.join("sun-only");
        let hours = AnnualOptions::default().hours_with_sun(&weather);
        let sun_hours = SunHours::cached(&model, &coefficients, &scene.site, false, &hours, &hours, &sun_dir, &|_| {});
        let traced = start.elapsed() - gathered - folded;
        drop((coefficients, sun_hours));
        let _ = std::fs::remove_dir_all(&sun_dir);
        let sda = year(&model, &weather, None);
        let total = start.elapsed();
        println!(
            "{name}: {} sensors, {} patches; gather {:.2} s, coefficients {:.2} s, the year's sun {:.2} s, then a year, coefficients and sun included, {:.2} s; sDA {sda:.1}%",
            scene.sensors.len(),
            scene.patches.patches.len(),
            gathered.as_secs_f64(),
            folded.as_secs_f64(),
            traced.as_secs_f64(),
            (total - gathered - folded - traced).as_secs_f64()
        );
        let warm = || {
            let (model, _) = precompute_cached(scene.clone(), LightSettings::default(), Some(&cache), &|_| {}).unwrap();
            year(&model, &weather, Some(&cache))
        };
        warm();
        group.bench_function(format!("{name}: year, light cache warm"), |b| b.iter(warm));
        let warm_every_hour = || {
            let (model, _) = precompute_cached(scene.clone(), LightSettings::default(), Some(&cache), &|_| {}).unwrap();
            year_with_every_hour(&model, &weather, Some(&cache))
        };
        warm_every_hour();
        group.bench_function(format!("{name}: year with every hour (--hourly), light cache warm"), |b| b.iter(warm_every_hour));
        group.bench_function(format!("{name}: year, cold"), |b| {
            b.iter(|| year(&LightModel::precompute(scene.clone(), LightSettings::default()).unwrap(), &weather, None))
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&cache);
}

criterion_group!(benches, bench);
criterion_main!(benches);
