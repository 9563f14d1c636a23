//! Where a room's light comes from: a tool for models whose dark rooms read
//! too bright (light leaking through a patch that spans a wall, a door or
//! a crack).
//!
//! `cargo run --release -p heliodon-core --example light_into_room -- SCENE ROOM [clear|overcast] [YYYY-MM-DD HH:MM]`
//!
//! ROOM is a prefix of sensor names (a grid's name). The sides the room's
//! sensors see are the room's surfaces, H; the light H gathers from sides
//! outside H came into the room, and is listed by the surface it reached
//! and the surface it came from. In a closed room all of it is leakage, or
//! light through gaps; a patch listed on both sides of a wall is a leak.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use heliodon_core::light::{LightModel, LightSettings, luminous};
use heliodon_core::panel::PanelCatalog;
use heliodon_core::scene::{Scene, load_scene};
use heliodon_core::sky::{SkySpec, sky_at};
use heliodon_core::time::{Date, LocalDateTime, TimeOfDay};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene_path, room, rest @ ..] = &args[..] else {
        return Err("usage: light_into_room SCENE ROOM [clear|overcast] [YYYY-MM-DD HH:MM]".into());
    };
    let spec = match rest.first().map(String::as_str) {
        None | Some("clear") => SkySpec::Clear { turbidity: 2.45 },
        Some("overcast") => SkySpec::Overcast,
        Some(other) => return Err(format!("sky '{other}': clear or overcast")),
    };
    let when = LocalDateTime {
        date: Date::parse(rest.get(1).map_or("2026-06-21", String::as_str))?,
        time: TimeOfDay::parse(rest.get(2).map_or("12:00", String::as_str))?,
    };
    let scene = Arc::new(load_scene(Path::new(scene_path), &PanelCatalog::new()).map_err(|e| e.to_string())?.scene);
    let model = LightModel::precompute(scene.clone(), LightSettings::default())?;
    let sky = sky_at(&scene.site, &spec, &when).1.map_err(|e| e.to_string())?;
    let lighting = model.solve(&sky, None);
    let sensors: Vec<usize> = (0..scene.sensors.len()).filter(|&i| scene.sensors[i].name.starts_with(room.as_str())).collect();
    if sensors.is_empty() {
        return Err(format!("no sensor's name starts with '{room}'"));
    }
    let mean = sensors.iter().map(|&i| lighting.sensors[i].total).sum::<f64>() / sensors.len() as f64;
    println!("{} sensors of '{room}': mean {mean:.1} lx", sensors.len());
    // The room's surfaces: the sides its sensors see.
    let mut seen = vec![false; lighting.sides.len()];
    for &i in &sensors {
        for &(side, _) in &model.sensor_gather(i).form_factors {
            seen[side as usize] = true;
        }
    }
    // Flux (luminous W) gathered by the room's sides, from outside them.
    let (mut gathered, mut came_in) = (0.0, 0.0);
    let (mut into, mut from): (BTreeMap<u32, f64>, BTreeMap<u32, f64>) = Default::default();
    for side in (0..seen.len()).filter(|&s| seen[s]) {
        let area = f64::from(scene.patches.patches[side / 2].area);
        for &(source, share) in &model.side_gather(side).form_factors {
            let flux = f64::from(share) * luminous(model.side_exitance(&lighting, source as usize)) * area;
            gathered += flux;
            if !seen[source as usize] {
                came_in += flux;
                *into.entry(scene.patches.patches[side / 2].surface).or_default() += flux;
                *from.entry(scene.patches.patches[source as usize / 2].surface).or_default() += flux;
            }
        }
    }
    println!(
        "{} sides seen; they gather {gathered:.3} W (luminous) of interreflected light, {came_in:.3} W from sides outside them",
        seen.iter().filter(|&&s| s).count()
    );
    list(&scene, "reached", into, came_in);
    list(&scene, "came from", from, came_in);
    Ok(())
}

/// The ten surfaces carrying most of `flux` (by surface), with where they lie.
fn list(scene: &Scene, what: &str, flux: BTreeMap<u32, f64>, total: f64) {
    let mut flux: Vec<(u32, f64)> = flux.into_iter().collect();
    flux.sort_by(|a, b| b.1.total_cmp(&a.1));
    println!("light from outside the room {what}:");
    for (surface, f) in flux.into_iter().take(10) {
        let s = &scene.surfaces[surface as usize];
        let tris = &scene.triangles[s.triangles.start as usize..s.triangles.end as usize];
        let (lo, hi) = tris.iter().flat_map(|t| t.vertices).fold((glam::Vec3::MAX, glam::Vec3::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        println!(
            "  {:5.1}%  surface {surface} ({}, {:.3} m², {} patches) from {:.2?} to {:.2?}",
            100.0 * f / total.max(f64::MIN_POSITIVE),
            scene.materials[s.material as usize].name,
            s.area,
            s.patches.len(),
            lo.to_array(),
            hi.to_array()
        );
    }
}
