//! `heliodon info`: a summary of a scene (loading, and the rays that tell
//! which side of each window is outside; no light).

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

use crate::cli::CliError;
use crate::cli::args::load_for_command;
use crate::light::{LightModel, WindowGroups};
use crate::panel::PanelCatalog;
use crate::scene::{MaterialKind, Scene};

/// Prints the summary of the scene file at `path`, loaded through the
/// scene cache as the other commands load it.
pub fn run(path: &Path, panels: &PanelCatalog) -> Result<(), CliError> {
    let scene = Arc::new(load_for_command(path, panels, false).map_err(CliError::failure)?);
    print!("{}", info(&scene, &LightModel::unlit(scene.clone()).windows));
    Ok(())
}

/// Compass name of a direction (x east, y north, z up).
fn compass(direction: glam::Vec3) -> String {
    if direction.z.abs() > 0.985 {
        return if direction.z > 0.0 { "up".into() } else { "down".into() };
    }
    let azimuth = direction.x.atan2(direction.y).to_degrees().rem_euclid(360.0);
    const NAMES: [&str; 8] = ["N", "NE", "E", "SE", "S", "SW", "W", "NW"];
    let name = NAMES[((azimuth + 22.5) / 45.0) as usize % 8];
    let tilt = direction.z.asin().to_degrees();
    if tilt.abs() < 1.0 {
        format!("{name} (azimuth {azimuth:.0}°)")
    } else {
        format!("{name} (azimuth {azimuth:.0}°, tilted {tilt:+.0}°)")
    }
}

/// The `info` summary of a scene; windows face the way `windows` says
/// (outward: the side that sees the sky).
pub fn info(scene: &Scene, windows: &WindowGroups) -> String {
    let mut out = String::new();
    let site = &scene.site;
    let (lo, hi) = scene.bounds;
    let size = hi - lo;
    let _ = writeln!(out, "scene      {}  ({})", scene.name, scene.files.scene.display());
    let _ = writeln!(
        out,
        "model      {}  up {:?}, scale {} m/unit; {:.2} × {:.2} × {:.2} m (x east, y north, z up)",
        scene.files.obj.display(),
        scene.frame.up,
        scene.frame.scale,
        size.x,
        size.y,
        size.z
    );
    let _ = writeln!(
        out,
        "site       latitude {:.4}°, longitude {:.4}°, UTC{:+}, elevation {} m, ground reflectance {}",
        site.latitude, site.longitude, site.timezone, site.elevation, site.ground_reflectance
    );
    let _ = writeln!(out, "triangles  {}", scene.triangles.len());
    let _ = writeln!(out, "surfaces   {}", scene.surfaces.len());
    let _ = writeln!(
        out,
        "patches    {} (patch size {} m, {} render triangles)",
        scene.patches.patches.len(),
        scene.patch_size,
        scene.patches.triangles.len()
    );
    let _ = write!(out, "{}", patch_breakdown(scene));
    let _ = writeln!(out, "materials  {}", scene.materials.len());
    for kind in ["diffuse", "glass", "panel"] {
        let of_kind: Vec<String> = scene
            .materials
            .iter()
            .filter(|m| m.kind.label() == kind)
            .map(|m| match &m.kind {
                MaterialKind::Diffuse { reflectance } => {
                    let [r, g, b] = reflectance.0;
                    if r == g && g == b { format!("{} ρ={r}", m.name) } else { format!("{} ρ=[{r}, {g}, {b}]", m.name) }
                }
                MaterialKind::Glass { transmittance } => format!("{} τ={transmittance}", m.name),
                MaterialKind::Panel { panel, .. } => format!("{} ({panel})", m.name),
            })
            .collect();
        let _ = writeln!(
            out,
            "  {kind:<8} {}{}",
            of_kind.len(),
            if of_kind.is_empty() { String::new() } else { format!(": {}", of_kind.join(", ")) }
        );
    }
    let _ = writeln!(out, "windows    {}, {:.2} m² in all", scene.windows.len(), scene.window_area());
    for (i, window) in scene.windows.iter().enumerate() {
        let c = window.centroid;
        let _ = writeln!(
            out,
            "  #{i:<3} {:<14} {:6.2} m²  facing {}  centre ({:.2}, {:.2}, {:.2})",
            scene.material(window.material).name,
            window.area,
            if windows.groups[windows.group_of_window[i] as usize].enclosed {
                "nowhere (sees no sky from either side)".to_string()
            } else {
                compass(windows.outward[i].as_vec3())
            },
            c.x,
            c.y,
            c.z
        );
    }
    let points = scene.sensors.iter().filter(|s| s.size.is_none() && s.grid.is_none()).count();
    let areas = scene.sensors.iter().filter(|s| s.size.is_some()).count();
    let mut grids: Vec<(&str, usize)> = Vec::new();
    for grid in scene.sensors.iter().filter_map(|s| s.grid.as_deref()) {
        match grids.iter_mut().find(|(name, _)| *name == grid) {
            Some((_, count)) => *count += 1,
            None => grids.push((grid, 1)),
        }
    }
    let grid_text: Vec<String> = grids.iter().map(|(name, count)| format!("{name} {count}")).collect();
    let _ = writeln!(
        out,
        "sensors    {} ({points} point, {areas} area{})",
        scene.sensors.len(),
        if grid_text.is_empty() { String::new() } else { format!(", grids: {}", grid_text.join(", ")) }
    );
    if !scene.viewpoints.is_empty() {
        let names: Vec<&str> = scene.viewpoints.iter().map(|v| v.name.as_str()).collect();
        let _ = writeln!(out, "cameras    {}", names.join(", "));
    }
    out
}

/// Where the patches go: how many face up, down and sideways, and how
/// wide they are against `patch_size` (the side of a square of their
/// area), with the area each class covers: what to look at when a model
/// has more patches than expected.
fn patch_breakdown(scene: &Scene) -> String {
    const WIDTHS: [(&str, f32); 4] = [("finest", 1.0), ("to 2×", 2.0), ("to 4×", 4.0), ("wider", f32::INFINITY)];
    let mut by_width = [(0usize, 0f64); 4];
    let mut by_facing = [(0usize, 0f64); 3];
    for patch in &scene.patches.patches {
        let width = patch.area.sqrt() / scene.patch_size;
        // A finest cell cut by an edge is narrower; rounding lets a whole one count as finest.
        let class = WIDTHS.iter().position(|&(_, most)| width <= most * 1.001).unwrap_or(WIDTHS.len() - 1);
        let facing = if patch.normal.z > 0.7 {
            0
        } else if patch.normal.z < -0.7 {
            1
        } else {
            2
        };
        for (count, area) in [&mut by_width[class], &mut by_facing[facing]] {
            *count += 1;
            *area += f64::from(patch.area);
        }
    }
    let list = |names: &[&str], classes: &[(usize, f64)]| -> String {
        names.iter().zip(classes).map(|(name, (count, area))| format!("{name} {count} ({area:.0} m²)")).collect::<Vec<_>>().join(", ")
    };
    let widths: Vec<&str> = WIDTHS.iter().map(|(name, _)| *name).collect();
    format!(
        "  wide     {}\n  facing   {}\n  most     {}\n",
        list(&widths, &by_width),
        list(&["up", "down", "sideways"], &by_facing),
        most_cut_surfaces(scene, 3)
    )
}

/// The `count` surfaces cut into the most patches past what their area
/// needs (their area in finest cells), each with its area, material, facing
/// and centre (canonical frame): a stair's stringer cut at every tread and
/// riser, a partition a row of sensors stands beside, a façade's strips
/// between its windows; the first places to look when a model has more
/// patches than expected. A cluster's patch counts for its first surface
/// (it is listed there).
fn most_cut_surfaces(scene: &Scene, count: usize) -> String {
    let patches_of = |s: usize| scene.surfaces[s].patch_indices().len();
    let finest_cells = |s: usize| (scene.surfaces[s].area / (scene.patch_size * scene.patch_size)).ceil() as usize;
    let past_area = |s: usize| patches_of(s).saturating_sub(finest_cells(s));
    let mut order: Vec<usize> = (0..scene.surfaces.len()).filter(|&s| past_area(s) > 0).collect();
    order.sort_by(|&a, &b| past_area(b).cmp(&past_area(a)).then(a.cmp(&b)));
    let described: Vec<String> = order
        .iter()
        .take(count)
        .map(|&s| {
            let surface = &scene.surfaces[s];
            let centre = surface.centroid(&scene.triangles);
            format!(
                "{} patches on {:.2} m² ({} finest cells) of {} facing {} at ({:.2}, {:.2}, {:.2})",
                patches_of(s),
                surface.area,
                finest_cells(s),
                scene.material(surface.material).name,
                compass(surface.normal),
                centre.x,
                centre.y,
                centre.z
            )
        })
        .collect();
    if described.is_empty() { "none past their area".to_string() } else { described.join("; ") }
}
