//! `heliodon view`: the interactive viewer, or with `--screenshot`/`--hdr`
//! a batch run that saves the window (see `viewer::batch`).

use std::path::PathBuf;
use std::process::ExitCode;

use crate::cli::CliError;
use crate::cli::args::SkyArgs;
use crate::panel::PanelCatalog;
use crate::time::{Date, LocalDateTime, TimeOfDay};

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
    /// A weather file (EPW): the sky of the shown hour comes from it, and the annual panel can run the year
    #[arg(long, value_name = "FILE.epw")]
    pub weather: Option<PathBuf>,
    /// With --weather: run the year at once, colour the sensors by DA300 (and, with --screenshot, wait for it and print sDA and ASE)
    #[arg(long, requires = "weather")]
    pub annual: bool,
    /// Open on the plan view: a section just under the ceiling of the storey in view, looked down on, the light in false colour (lux)
    #[arg(long)]
    pub plan: bool,
}

/// Opens the viewer on `scene` (the bundled office when none).
pub fn run(scene: Option<PathBuf>, args: Option<&ViewArgs>, panels: &PanelCatalog) -> Result<ExitCode, CliError> {
    let start = args.map(view_request).transpose().map_err(CliError::usage)?;
    Ok(crate::viewer::run(scene.unwrap_or_else(|| crate::bundled_scene(crate::DEFAULT_SCENE)), panels, start))
}

/// How `view` starts: the time and sky given, and where to save a screenshot.
fn view_request(args: &ViewArgs) -> Result<crate::viewer::ViewStart, String> {
    let sky = if args.sky.sky != "clear" || args.sky.turbidity.is_some() { Some(args.sky.spec()?) } else { None };
    let default = crate::ecs::SolarTime::default().0;
    let when = (args.date.is_some() || args.time.is_some())
        .then(|| LocalDateTime { date: args.date.unwrap_or(default.date), time: args.time.unwrap_or(default.time) });
    Ok(crate::viewer::ViewStart {
        screenshot: args.screenshot.clone(),
        hdr: args.hdr.clone(),
        sensor: args.sensor.clone(),
        year: args.year,
        when,
        sky,
        weather: args.weather.clone(),
        annual: args.annual,
        plan: args.plan,
    })
}
