//! The `heliodon` command line (see the contract in the README): argument
//! parsing with clap, one line per error, and the text of each subcommand.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::ecs::PanelRegistry;
use crate::scene::{self, MaterialKind, Scene};

#[derive(Parser, Debug)]
#[command(
    name = "heliodon",
    version,
    about = "Daylighting design: sun, sky and interreflected light on building models",
    args_conflicts_with_subcommands = true,
    allow_negative_numbers = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Scene file (TOML) to open in the viewer; the bundled example when absent
    pub scene: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Open the interactive viewer
    View {
        /// Scene file (TOML); the bundled example when absent
        scene: Option<PathBuf>,
    },
    /// Print a summary of a scene: geometry, patches, materials, windows, sensors, site
    Info {
        /// Scene file (TOML)
        scene: PathBuf,
    },
}

/// Parses the command line and runs it.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(error) => {
            use clap::error::ErrorKind;
            if matches!(
                error.kind(),
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                error.exit();
            }
            let rendered = error.render().to_string();
            let first = rendered.lines().next().unwrap_or("invalid arguments");
            eprintln!("{first} (see heliodon --help)");
            return ExitCode::from(2);
        }
    };
    match cli.command {
        None => crate::viewer::run(cli.scene.unwrap_or_else(|| crate::bundled_scene(crate::DEFAULT_SCENE))),
        Some(Command::View { scene }) => {
            crate::viewer::run(scene.unwrap_or_else(|| crate::bundled_scene(crate::DEFAULT_SCENE)))
        }
        Some(Command::Info { scene }) => match scene::load_scene(&scene, &PanelRegistry::default().names()) {
            Ok(loaded) => {
                for warning in &loaded.warnings {
                    eprintln!("warning: {warning}");
                }
                print!("{}", info(&loaded.scene));
                ExitCode::SUCCESS
            }
            Err(error) => {
                eprintln!("error: {error}");
                ExitCode::FAILURE
            }
        },
    }
}

/// Compass name of a horizontal direction (x east, y north).
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

/// The `info` summary of a scene.
pub fn info(scene: &Scene) -> String {
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
        scene.lighting.patch_size,
        scene.patches.triangles.len()
    );
    let _ = writeln!(out, "materials  {}", scene.materials.len());
    for kind in ["diffuse", "glass", "panel"] {
        let of_kind: Vec<String> = scene
            .materials
            .iter()
            .filter(|m| m.kind.label() == kind)
            .map(|m| match &m.kind {
                MaterialKind::Diffuse { reflectance } => {
                    let [r, g, b] = reflectance.0;
                    if r == g && g == b {
                        format!("{} ρ={r}", m.name)
                    } else {
                        format!("{} ρ=[{r}, {g}, {b}]", m.name)
                    }
                }
                MaterialKind::Glass { transmittance } => format!("{} τ={transmittance}", m.name),
                MaterialKind::Panel { panel, .. } => format!("{} ({panel})", m.name),
            })
            .collect();
        let _ = writeln!(out, "  {kind:<8} {}{}", of_kind.len(), if of_kind.is_empty() { String::new() } else { format!(": {}", of_kind.join(", ")) });
    }
    let _ = writeln!(out, "windows    {}, {:.2} m² in all", scene.windows.len(), scene.window_area());
    for (i, window) in scene.windows.iter().enumerate() {
        let c = window.centroid;
        let _ = writeln!(
            out,
            "  #{i:<3} {:<14} {:6.2} m²  facing {}  centre ({:.2}, {:.2}, {:.2})",
            scene.material(window.material).name,
            window.area,
            compass(window.normal),
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
