//! Flags and helpers shared by several commands: a scene at a date, time
//! and sky ([`SceneCase`], [`SkyArgs`]), output formats, number parsers,
//! loading a scene with its warnings, and the precomputation's progress bar.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::light::{LightModel, LightSettings, cache};
use crate::panel::PanelCatalog;
use crate::scene::Scene;
use crate::scene_cache;
use crate::sky::{Sky, SkyInputs, SkySpec, sky_at};
use crate::sun::SolarPosition;
use crate::time::{Date, LocalDateTime, TimeOfDay};

/// A scene at one date, time and sky: what `render` and `export-radiance` take.
#[derive(clap::Args, Debug)]
pub struct SceneCase {
    /// Scene file (TOML)
    pub scene: PathBuf,
    /// Local date, YYYY-MM-DD
    #[arg(long, value_parser = Date::parse)]
    pub date: Date,
    /// Local standard time, HH:MM
    #[arg(long, value_parser = TimeOfDay::parse)]
    pub time: TimeOfDay,
    #[command(flatten)]
    pub sky: SkyArgs,
}

impl SceneCase {
    pub fn when(&self) -> LocalDateTime {
        LocalDateTime { date: self.date, time: self.time }
    }
}

/// The flags of the commands that precompute a scene's light: its cache
/// and which sample of its rays.
#[derive(clap::Args, Debug, Clone)]
pub struct LightArgs {
    /// Neither read nor write the precomputation cache
    #[arg(long)]
    pub no_cache: bool,
    /// Which Monte Carlo sample of the rays to draw (0, the default, or any
    /// other): the readings' spread over a few seeds is their noise
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

impl LightArgs {
    /// The light settings these flags ask for.
    pub fn settings(&self) -> LightSettings {
        LightSettings { seed: self.seed, ..Default::default() }
    }
}

/// The sky flags shared by the commands that light a scene.
#[derive(clap::Args, Debug, Clone)]
pub struct SkyArgs {
    /// clear, turbid, intermediate, overcast, uniform, perez or cie:1 … cie:15
    #[arg(long, default_value = "clear")]
    pub sky: String,
    /// Direct normal irradiance, W/m² (perez)
    #[arg(long, value_name = "W")]
    pub dni: Option<f64>,
    /// Diffuse horizontal irradiance, W/m² (perez)
    #[arg(long, value_name = "W")]
    pub dhi: Option<f64>,
    /// Direct normal illuminance, lux (perez, cie:N)
    #[arg(long, value_name = "LUX")]
    pub direct_lux: Option<f64>,
    /// Diffuse horizontal illuminance, lux (perez, cie:N)
    #[arg(long, value_name = "LUX")]
    pub diffuse_lux: Option<f64>,
    /// Turbidity of the clear and intermediate skies (default 2.45; turbid is 5)
    #[arg(long)]
    pub turbidity: Option<f64>,
}

impl SkyArgs {
    pub fn spec(&self) -> Result<SkySpec, String> {
        let inputs = SkyInputs {
            direct_normal: self.dni,
            diffuse_horizontal: self.dhi,
            direct_illuminance: self.direct_lux,
            diffuse_illuminance: self.diffuse_lux,
            turbidity: self.turbidity,
        };
        SkySpec::parse(&self.sky, &inputs).map_err(|e| format!("--sky {}: {e}", self.sky))
    }
}

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Table,
    Csv,
    Json,
}

/// A clap parser for a finite number within [lo, hi].
pub fn in_range(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    move |text: &str| {
        let value: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number"))?;
        if !value.is_finite() || value < lo || value > hi {
            return Err(format!("{value} is outside {lo}..{hi}"));
        }
        Ok(value)
    }
}

pub fn parse_point(text: &str) -> Result<glam::Vec3, String> {
    let values: Vec<f32> =
        text.split(',').map(|v| v.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|_| format!("'{text}' is not X,Y,Z"))?;
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok(glam::Vec3::new(x, y, z)),
        _ => Err(format!("'{text}' is not three finite numbers X,Y,Z")),
    }
}

/// Memory past which the sensor coefficients of a year or a sweep are
/// worth a warning before they are solved.
const LARGE_COEFFICIENTS: usize = 2 << 30;

/// Warns (one line) when the sensor coefficients a year or a sweep solves
/// take more than [`LARGE_COEFFICIENTS`]: they are dense, a number per
/// sensor and radiance slot (sky bin, straight or through glass or a
/// panel), and tens of thousands of sensors take gigabytes, which is
/// better said before than found out.
pub fn warn_about_coefficients(scene_path: &Path, model: &LightModel) {
    let bytes = model.coefficient_bytes();
    if bytes > LARGE_COEFFICIENTS {
        eprintln!(
            "warning: {}: the coefficients of {} sensors take about {:.1} GB of memory (a number per sensor and sky bin): the sensors of fewer rooms take less",
            scene_path.display(),
            model.scene.sensors.len(),
            bytes as f64 / 1e9
        );
    }
}

/// The scene's light model with `settings`, from the cache unless
/// `no_cache`, with the precomputation's progress bar on standard error.
pub fn precompute_for_command(scene: Arc<Scene>, settings: LightSettings, no_cache: bool) -> Result<LightModel, String> {
    let cache_dir = if no_cache { None } else { cache::default_dir() };
    let progress = progress_bar("precomputing light");
    let (model, _) =
        cache::precompute_cached(scene, settings, cache_dir.as_deref(), &|done| progress.set_position((done * 1000.0) as u64))?;
    progress.finish_and_clear();
    Ok(model)
}

/// A progress bar from 0 to 1000 on standard error (indicatif hides it when
/// standard error is not a terminal); `finish_and_clear` it when done.
pub fn progress_bar(label: &str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
    let template = format!("{label} [{{bar:40}}] {{percent:>3}}%");
    bar.set_style(ProgressStyle::with_template(&template).expect("a valid template").progress_chars("#> "));
    bar
}

/// Loads a scene for a command, printing its warnings; through the scene
/// cache unless `no_cache`.
pub fn load_for_command(path: &Path, panels: &PanelCatalog, no_cache: bool) -> Result<Scene, String> {
    let cache_dir = if no_cache { None } else { cache::default_dir() };
    let (loaded, _) = scene_cache::load_scene_cached(path, panels, cache_dir.as_deref()).map_err(|e| e.to_string())?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(loaded.scene)
}

/// The sun and sky of a scene's site at a local time.
pub fn sky_for(scene: &Scene, spec: &SkySpec, sky_name: &str, when: LocalDateTime) -> Result<(SolarPosition, Sky), String> {
    let (position, sky) = sky_at(&scene.site, spec, &when);
    let sky = sky.map_err(|e| format!("--sky {sky_name} on {} {}: {e}", when.date, when.time))?;
    if let Some(why) = &sky.refused {
        eprintln!("warning: --sky {sky_name} on {} {}: {why}", when.date, when.time);
    }
    Ok((position, sky))
}
