//! The `heliodon` command line (see the contract in the README): argument
//! parsing with clap, one line per error, and the text of each subcommand.

use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::ecs::{AddPanels, panel_catalog};
use crate::panel::PanelCatalog;
use crate::render::offscreen::OffscreenRequest;
use crate::render::{RenderMode, RenderSettings};
use crate::scene::{self, DEFAULT_FOV, MaterialKind, Scene, Viewpoint};
use crate::light::{LightSettings, Lighting, cache};
use crate::site::Site;
use crate::sky::{Sky, SkyInputs, SkySpec, sky_at};
use crate::sun::{self, SolarPosition};
use crate::time::{Date, LocalDateTime, TimeOfDay};

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
    #[command(allow_negative_numbers = true)]
    View(ViewArgs),
    /// Print a summary of a scene: geometry, patches, materials, windows, sensors, site
    Info {
        /// Scene file (TOML)
        scene: PathBuf,
    },
    /// Illuminance at the scene's sensors (lux): total, direct sun, direct sky, indirect
    #[command(allow_negative_numbers = true)]
    Sensors(SensorsArgs),
    /// Write a Radiance model of the scene, sky and sensors, with a run.sh that computes the sensors in Radiance
    #[command(name = "export-radiance", allow_negative_numbers = true)]
    ExportRadiance(ExportArgs),
    /// Draw a view of the scene lit by the sun and sky to a PNG, headless (any GPU or a software Vulkan driver)
    #[command(allow_negative_numbers = true)]
    Render(RenderArgs),
    /// Sun position (NREL SPA) for a site and a local standard time, or the day's sunrise, noon and sunset
    #[command(allow_negative_numbers = true)]
    Sun(SunArgs),
}

#[derive(clap::Args, Debug)]
pub struct ViewArgs {
    /// Scene file (TOML); the bundled example when absent
    pub scene: Option<PathBuf>,
    /// Wait until the light has converged, save the window (with its panels) to FILE and exit
    #[arg(long, value_name = "FILE")]
    pub screenshot: Option<PathBuf>,
    /// Wait until the light has converged, save the 3D view's luminance to FILE (Radiance RGBE, W/sr/m² at 179 lm/W) and exit
    #[arg(long, value_name = "FILE")]
    pub hdr: Option<PathBuf>,
    /// Select the sensor NAME: its day is plotted (and, with --screenshot, waited for)
    #[arg(long, value_name = "NAME")]
    pub sensor: Option<String>,
    /// With --sensor: also compute its year map (day of year × time of day)
    #[arg(long, requires = "sensor")]
    pub year: bool,
    /// Local date, YYYY-MM-DD
    #[arg(long, value_parser = Date::parse)]
    pub date: Option<Date>,
    /// Local standard time, HH:MM
    #[arg(long, value_parser = TimeOfDay::parse)]
    pub time: Option<TimeOfDay>,
    #[command(flatten)]
    pub sky: SkyArgs,
}

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

#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub case: SceneCase,
    /// PNG file to write
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the physical image (radiance, W/sr/m² per channel; 179 lm/W) as a Radiance .hdr picture
    #[arg(long, value_name = "FILE")]
    pub hdr: Option<PathBuf>,
    /// A viewpoint from the scene's [[cameras]]
    #[arg(long, conflicts_with_all = ["eye", "target"])]
    pub camera: Option<String>,
    /// Eye position, model metres: X,Y,Z
    #[arg(long, value_parser = parse_point, requires = "target")]
    pub eye: Option<glam::Vec3>,
    /// Point looked at: X,Y,Z
    #[arg(long, value_parser = parse_point, requires = "eye")]
    pub target: Option<glam::Vec3>,
    /// Vertical field of view, degrees
    #[arg(long, value_name = "DEG", value_parser = in_range(1.0, 170.0))]
    pub fov: Option<f64>,
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub width: u32,
    #[arg(long, default_value_t = 800, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub height: u32,
    /// Exposure value (EV100); automatic from the scene's light when absent
    #[arg(long, value_name = "EV", value_parser = in_range(-10.0, 30.0))]
    pub exposure: Option<f64>,
    /// full, sun, sky, indirect or falsecolor
    #[arg(long, default_value = "full", value_parser = parse_mode)]
    pub mode: RenderMode,
}

fn parse_point(text: &str) -> Result<glam::Vec3, String> {
    let values: Vec<f32> = text.split(',').map(|v| v.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|_| format!("'{text}' is not X,Y,Z"))?;
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok(glam::Vec3::new(x, y, z)),
        _ => Err(format!("'{text}' is not three finite numbers X,Y,Z")),
    }
}

fn parse_mode(text: &str) -> Result<RenderMode, String> {
    RenderMode::parse(text).ok_or_else(|| format!("'{text}' is not one of {}", RenderMode::NAMES.join(", ")))
}

#[derive(clap::Args, Debug)]
pub struct SunArgs {
    /// Degrees, north positive
    #[arg(long, value_name = "DEG", value_parser = in_range(-90.0, 90.0))]
    pub latitude: f64,
    /// Degrees, east positive (Boston is -71.06)
    #[arg(long, value_name = "DEG", value_parser = in_range(-180.0, 180.0))]
    pub longitude: f64,
    /// Hours from UTC of local standard time (Boston is -5)
    #[arg(long, value_name = "HOURS", value_parser = in_range(-14.0, 14.0))]
    pub timezone: f64,
    /// Local date, YYYY-MM-DD
    #[arg(long, value_parser = Date::parse)]
    pub date: Date,
    /// Local standard time, HH:MM or HH:MM:SS (not needed with --day)
    #[arg(long, value_parser = TimeOfDay::parse, required_unless_present = "day")]
    pub time: Option<TimeOfDay>,
    /// List the day's sunrise, solar noon and sunset instead
    #[arg(long)]
    pub day: bool,
    /// Site elevation in metres
    #[arg(long, value_name = "M", default_value_t = Site::DEFAULT_ELEVATION, value_parser = in_range(-500.0, 9000.0))]
    pub elevation: f64,
    /// Mean air pressure in millibars (for refraction)
    #[arg(long, value_name = "MBAR", default_value_t = Site::DEFAULT_PRESSURE, value_parser = in_range(300.0, 1200.0))]
    pub pressure: f64,
    /// Mean air temperature in °C (for refraction)
    #[arg(long, value_name = "C", default_value_t = Site::DEFAULT_TEMPERATURE, value_parser = in_range(-90.0, 60.0))]
    pub temperature: f64,
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
}

#[derive(clap::Args, Debug)]
pub struct SensorsArgs {
    /// Scene file (TOML)
    pub scene: PathBuf,
    /// Local dates, YYYY-MM-DD, comma-separated for several
    #[arg(long, value_parser = Date::parse, value_delimiter = ',', required = true)]
    pub date: Vec<Date>,
    /// Local standard times, HH:MM, comma-separated for several
    #[arg(long, value_parser = TimeOfDay::parse, value_delimiter = ',', required = true)]
    pub time: Vec<TimeOfDay>,
    #[command(flatten)]
    pub sky: SkyArgs,
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Neither read nor write the precomputation cache
    #[arg(long)]
    pub no_cache: bool,
}

#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    #[command(flatten)]
    pub case: SceneCase,
    /// Folder to write scene.rad, sky.rad, sensors.pts, sensors.txt and run.sh into
    #[arg(long)]
    pub out: PathBuf,
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
fn in_range(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    move |text: &str| {
        let value: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number"))?;
        if !value.is_finite() || value < lo || value > hi {
            return Err(format!("{value} is outside {lo}..{hi}"));
        }
        Ok(value)
    }
}

/// Parses the command line and runs it.
/// Runs the command line; `add_panels` adds the panel plugins to every app
/// it makes, and the scene loader knows the panels they register.
pub fn main(add_panels: AddPanels) -> ExitCode {
    let panels = panel_catalog(add_panels);
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
            // clap's message on one line: what is wrong, without the usage and tips.
            let rendered = error.render().to_string();
            let message: Vec<&str> = rendered
                .lines()
                .take_while(|l| !l.starts_with("Usage:"))
                .map(str::trim)
                .filter(|l| !l.is_empty() && !l.starts_with("tip:") && !l.starts_with("For more information"))
                .collect();
            eprintln!("{} (see heliodon --help)", message.join(" "));
            return ExitCode::from(2);
        }
    };
    match cli.command {
        None => crate::viewer::run(cli.scene.unwrap_or_else(|| crate::bundled_scene(crate::DEFAULT_SCENE)), add_panels, None),
        Some(Command::View(args)) => match view_request(&args) {
            Ok(start) => crate::viewer::run(args.scene.clone().unwrap_or_else(|| crate::bundled_scene(crate::DEFAULT_SCENE)), add_panels, Some(start)),
            Err(error) => {
                eprintln!("error: {error}");
                ExitCode::from(2)
            }
        },
        Some(Command::Info { scene }) => match scene::load_scene(&scene, &panels) {
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
        Some(Command::Sensors(args)) => match sensors(&args, &panels) {
            Ok(text) => {
                print!("{text}");
                ExitCode::SUCCESS
            }
            Err(error) => {
                eprintln!("error: {error}");
                ExitCode::FAILURE
            }
        },
        Some(Command::ExportRadiance(args)) => match export_radiance(&args, &panels) {
            Ok(()) => ExitCode::SUCCESS,
            Err(error) => {
                eprintln!("error: {error}");
                ExitCode::FAILURE
            }
        },
        Some(Command::Render(args)) => match render(&args, &panels, add_panels) {
            Ok(()) => ExitCode::SUCCESS,
            Err(error) => {
                eprintln!("error: {error}");
                ExitCode::FAILURE
            }
        },
        Some(Command::Sun(args)) => {
            print!("{}", sun_report(&args));
            ExitCode::SUCCESS
        }
    }
}

/// A progress bar on standard error, when it is a terminal.
fn progress_bar(fraction: f64) {
    if std::io::stderr().is_terminal() {
        let filled = (fraction * 40.0).round() as usize;
        eprint!("\rprecomputing light [{}{}] {:3.0}%", "#".repeat(filled), " ".repeat(40 - filled.min(40)), 100.0 * fraction);
    }
}

/// Loads a scene for a command, printing its warnings.
fn load_for_command(path: &std::path::Path, panels: &PanelCatalog) -> Result<Scene, String> {
    let loaded = scene::load_scene(path, panels).map_err(|e| e.to_string())?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(loaded.scene)
}

/// The sun and sky of a scene's site at a local time.
fn sky_for(scene: &Scene, spec: &SkySpec, sky_name: &str, when: LocalDateTime) -> Result<(SolarPosition, Sky), String> {
    let (position, sky) = sky_at(&scene.site, spec, &when);
    let sky = sky.map_err(|e| format!("--sky {sky_name} on {} {}: {e}", when.date, when.time))?;
    Ok((position, sky))
}

/// The `export-radiance` command.
pub fn export_radiance(args: &ExportArgs, panels: &PanelCatalog) -> Result<(), String> {
    let (case, spec) = (&args.case, args.case.sky.spec()?);
    let scene = load_for_command(&case.scene, panels)?;
    let when = case.when();
    let (position, sky) = sky_for(&scene, &spec, &case.sky.sky, when)?;
    let label = format!(
        "{} {} {} sky, sun altitude {:.4}°, azimuth {:.4}° (SPA)",
        when.date, when.time, case.sky.sky, position.altitude, position.azimuth
    );
    crate::radiance::export(&scene, &sky, &label, &args.out)
}

/// How `view` starts: the time and sky given, and where to save a screenshot.
fn view_request(args: &ViewArgs) -> Result<crate::viewer::ViewStart, String> {
    let sky = if args.sky.sky != "clear" || args.sky.turbidity.is_some() { Some(args.sky.spec()?) } else { None };
    let default = crate::ecs::SolarTime::default().0;
    let when = (args.date.is_some() || args.time.is_some())
        .then(|| LocalDateTime { date: args.date.unwrap_or(default.date), time: args.time.unwrap_or(default.time) });
    Ok(crate::viewer::ViewStart { screenshot: args.screenshot.clone(), hdr: args.hdr.clone(), sensor: args.sensor.clone(), year: args.year, when, sky })
}

/// The `render` command.
pub fn render(args: &RenderArgs, panels: &PanelCatalog, add_panels: AddPanels) -> Result<(), String> {
    let (case, sky) = (&args.case, args.case.sky.spec()?);
    let scene = load_for_command(&case.scene, panels)?;
    let mut view = match &args.camera {
        Some(name) => Some(scene.viewpoints.iter().find(|v| &v.name == name).cloned().ok_or_else(|| {
            let known: Vec<&str> = scene.viewpoints.iter().map(|v| v.name.as_str()).collect();
            format!("--camera {name}: {} has no such camera (it has: {})", case.scene.display(), if known.is_empty() { "none".into() } else { known.join(", ") })
        })?),
        None => args.eye.zip(args.target).map(|(eye, target)| Viewpoint { name: "command line".into(), eye, target, fov: DEFAULT_FOV }),
    };
    if view.as_ref().is_some_and(|v| (v.eye - v.target).length() < 1e-6) {
        return Err("--eye and --target are the same point".into());
    }
    if let Some(fov) = args.fov {
        let base = view.unwrap_or_else(|| crate::render::initial_view(&scene));
        view = Some(Viewpoint { fov: fov as f32, ..base });
    }
    let image = crate::render::offscreen::render(OffscreenRequest {
        scene: case.scene.clone(),
        view,
        width: args.width,
        height: args.height,
        when: Some(case.when()),
        sky: Some(sky),
        settings: RenderSettings { mode: args.mode, exposure: args.exposure.map(|e| e as f32), ..Default::default() },
        add_panels,
    })?;
    image.save_png(&args.out)?;
    match &args.hdr {
        Some(path) => image.save_hdr(path),
        None => Ok(()),
    }
}

/// The `sensors` command: one precomputation, then every date × time.
pub fn sensors(args: &SensorsArgs, panels: &PanelCatalog) -> Result<String, String> {
    let spec = args.sky.spec()?;
    let scene = std::sync::Arc::new(load_for_command(&args.scene, panels)?);
    let cache_dir = if args.no_cache { None } else { cache::default_dir() };
    let (model, _) = cache::precompute_cached(scene.clone(), LightSettings::default(), cache_dir.as_deref(), &progress_bar)?;
    if std::io::stderr().is_terminal() {
        eprint!("\r{:60}\r", "");
    }
    for i in model.sensors_inside_solids() {
        eprintln!(
            "warning: {}: sensor '{}' seems to be inside a solid (every direction meets a back face); it reads what reaches it there",
            args.scene.display(),
            scene.sensors[i].name
        );
    }
    let cases: Vec<LocalDateTime> =
        args.date.iter().flat_map(|&date| args.time.iter().map(move |&time| LocalDateTime { date, time })).collect();
    let several = cases.len() > 1;
    let mut out = String::new();
    let mut previous: Option<Lighting> = None;
    if args.format == Format::Csv {
        let _ = writeln!(out, "{}name,illuminance_lux,direct_sun_lux,direct_sky_lux,indirect_lux", if several { "date,time," } else { "" });
    }
    let mut json = Vec::new();
    for when in cases {
        let (position, sky) = sky_for(&scene, &spec, &args.sky.sky, when)?;
        let lighting = model.solve(&sky, previous.as_ref());
        match args.format {
            Format::Csv => {
                for r in &lighting.sensors {
                    let prefix = if several { format!("{},{},", when.date, when.time) } else { String::new() };
                    let _ = writeln!(out, "{prefix}{},{:.1},{:.1},{:.1},{:.1}", r.name, r.total, r.direct_sun, r.direct_sky, r.indirect);
                }
            }
            Format::Json => {
                let rows: Vec<String> = lighting
                    .sensors
                    .iter()
                    .map(|r| {
                        format!(
                            "{{\"name\": {:?}, \"illuminance_lux\": {:.1}, \"direct_sun_lux\": {:.1}, \"direct_sky_lux\": {:.1}, \"indirect_lux\": {:.1}}}",
                            r.name, r.total, r.direct_sun, r.direct_sky, r.indirect
                        )
                    })
                    .collect();
                json.push(format!(
                    "{{\"date\": \"{}\", \"time\": \"{}\", \"sun_altitude_deg\": {:.4}, \"sun_azimuth_deg\": {:.4}, \"sky\": \"{}\", \"sensors\": [{}]}}",
                    when.date, when.time, position.altitude, position.azimuth, args.sky.sky, rows.join(", ")
                ));
            }
            Format::Table => {
                let _ = writeln!(
                    out,
                    "{} {}  sun altitude {:.2}°, azimuth {:.2}°  sky {}",
                    when.date, when.time, position.altitude, position.azimuth, args.sky.sky
                );
                let _ = writeln!(out, "{:<20} {:>10} {:>10} {:>10} {:>10}", "sensor", "total lx", "sun lx", "sky lx", "indirect lx");
                for r in &lighting.sensors {
                    let _ = writeln!(out, "{:<20} {:>10.1} {:>10.1} {:>10.1} {:>10.1}", r.name, r.total, r.direct_sun, r.direct_sky, r.indirect);
                }
            }
        }
        previous = Some(lighting);
    }
    if args.format == Format::Json {
        let _ = writeln!(out, "{}", if several { format!("[{}]", json.join(", ")) } else { json.concat() });
    }
    Ok(out)
}

/// The `sun` command's output.
pub fn sun_report(args: &SunArgs) -> String {
    let site = Site {
        elevation: args.elevation,
        pressure: args.pressure,
        temperature: args.temperature,
        ..Site::new(args.latitude, args.longitude, args.timezone)
    };
    let at = |time: TimeOfDay| sun::solar_position(&site, &LocalDateTime { date: args.date, time });
    let mut out = String::new();
    if args.day {
        let day = sun::sun_day(&site, args.date);
        let events = [("sunrise", day.sunrise), ("noon", Some(day.noon)), ("sunset", day.sunset)];
        let position = |time: Option<TimeOfDay>| time.map(at);
        match args.format {
            Format::Csv => {
                let _ = writeln!(out, "event,time,altitude_deg,azimuth_deg");
                for (name, time) in events {
                    match position(time) {
                        Some(p) => {
                            let _ = writeln!(out, "{name},{},{:.6},{:.6}", time.expect("has a time"), p.altitude, p.azimuth);
                        }
                        None => {
                            let _ = writeln!(out, "{name},,,");
                        }
                    }
                }
            }
            Format::Json => {
                let field = |time: Option<TimeOfDay>| time.map_or("null".to_string(), |t| format!("\"{t}\""));
                let _ = writeln!(
                    out,
                    "{{\"date\": \"{}\", \"sunrise\": {}, \"noon\": {}, \"sunset\": {}, \"noon_altitude_deg\": {:.6}, \"sun_up_at_noon\": {}}}",
                    args.date,
                    field(day.sunrise),
                    field(Some(day.noon)),
                    field(day.sunset),
                    day.noon_altitude,
                    day.up_at_noon
                );
            }
            Format::Table => {
                let _ = writeln!(out, "{} at latitude {}°, longitude {}°, UTC{:+} (local standard time)", args.date, args.latitude, args.longitude, args.timezone);
                for (name, time) in events {
                    match (time, position(time)) {
                        (Some(t), Some(p)) => {
                            let _ = writeln!(out, "{name:<8} {t}  altitude {:7.3}°  azimuth {:7.3}°", p.altitude, p.azimuth);
                        }
                        _ => {
                            let why = if day.up_at_noon { "the sun does not set (polar day)" } else { "the sun does not rise (polar night)" };
                            let _ = writeln!(out, "{name:<8} none: {why}");
                        }
                    }
                }
            }
        }
        return out;
    }
    let time = args.time.expect("clap requires --time without --day");
    let p: SolarPosition = at(time);
    match args.format {
        Format::Csv => {
            let _ = writeln!(out, "altitude_deg,azimuth_deg\n{:.6},{:.6}", p.altitude, p.azimuth);
        }
        Format::Json => {
            let _ = writeln!(out, "{{\"altitude_deg\": {:.6}, \"azimuth_deg\": {:.6}}}", p.altitude, p.azimuth);
        }
        Format::Table => {
            let _ = writeln!(out, "{} {} at latitude {}°, longitude {}°, UTC{:+} (local standard time)", args.date, time, args.latitude, args.longitude, args.timezone);
            let _ = writeln!(out, "altitude   {:9.4}°  apparent (refraction included){}", p.altitude, if p.is_up() { "" } else { ", below the horizon" });
            let _ = writeln!(out, "azimuth    {:9.4}°  clockwise from true north", p.azimuth);
            let _ = writeln!(out, "ΔT         {:9.2} s", p.delta_t);
        }
    }
    out
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
