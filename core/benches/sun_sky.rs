//! What one change of time costs: the sun (SPA), the sky, and the sky's
//! radiance integrated over Reinhart MF:4 patches (2305), as the ECS does it.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use heliodon_core::site::Site;
use heliodon_core::sky::{Sky, SkyPatches, SkySpec, perez};
use heliodon_core::sun::solar_position;
use heliodon_core::time::{Date, LocalDateTime, TimeOfDay};

fn update(site: &Site, when: &LocalDateTime, spec: &SkySpec, patches: &SkyPatches, out: &mut Vec<f64>) {
    let sun = solar_position(site, when);
    let sky = Sky::new(spec, sun.altitude, sun.azimuth, site.ground_reflectance, when.date.day_of_year()).unwrap();
    patches.integrate_into(&sky, out);
}

fn bench(c: &mut Criterion) {
    let site = Site::new(42.36, -71.06, -5.0);
    let when = LocalDateTime { date: Date::new(2026, 3, 21).unwrap(), time: TimeOfDay::from_hours(10.5).unwrap() };
    let patches = SkyPatches::reinhart(4);
    let mut out = Vec::with_capacity(patches.len());
    c.bench_function("spa", |b| b.iter(|| solar_position(black_box(&site), black_box(&when))));
    let skies = [
        SkySpec::Clear { turbidity: 2.45 },
        SkySpec::Intermediate { turbidity: 2.45 },
        SkySpec::Overcast,
        SkySpec::Perez(perez::Input::Irradiance { direct_normal: 600.0, diffuse_horizontal: 120.0 }),
        SkySpec::Cie { standard_type: 12, diffuse_illuminance: 15_000.0, direct_illuminance: 60_000.0 },
    ];
    for spec in &skies {
        c.bench_function(&format!("sun + {} sky + MF:4 patches", spec.name()), |b| {
            b.iter(|| update(black_box(&site), black_box(&when), spec, &patches, &mut out))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
