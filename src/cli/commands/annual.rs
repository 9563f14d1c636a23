//! `heliodon annual`: a year of EPW weather on the scene's sensors (DA300,
//! UDI, ASE hours, sDA, ASE), from one (cached) precomputation.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::annual::{
    AnnualOptions, AnnualResult, HourlyReadings, Occupancy, ShadedModel, annual, missing_in_daylight_note, skipped_hours_note,
};
use crate::cli::CliError;
use crate::cli::args::{Format, LightArgs, load_for_command, precompute_for_command, progress_bar, warn_about_coefficients};
use crate::light::cache;
use crate::panel::PanelCatalog;
use crate::report::{csv_field, json_string};
use crate::site::Site;
use crate::weather::Weather;

#[derive(clap::Args, Debug)]
pub struct AnnualArgs {
    /// Scene file (TOML)
    pub scene: PathBuf,
    /// Weather file (EnergyPlus EPW)
    #[arg(long, value_name = "FILE.epw")]
    pub weather: PathBuf,
    /// Occupied hours, local standard time
    #[arg(long, value_name = "HH:MM-HH:MM", value_parser = Occupancy::parse, default_value = "08:00-18:00")]
    pub occupied: Occupancy,
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Also write every sensor's total lux for every hour (8,760 rows) to this CSV file
    #[arg(long, value_name = "FILE.csv")]
    pub hourly: Option<PathBuf>,
    /// Ignore the scene's [[shades]]: every hour with the windows as modelled
    #[arg(long)]
    pub no_shades: bool,
    #[command(flatten)]
    pub light: LightArgs,
}

/// Runs the year and prints the per-sensor metrics.
pub fn run(args: &AnnualArgs, panels: &PanelCatalog) -> Result<(), CliError> {
    let scene = std::sync::Arc::new(load_for_command(&args.scene, panels, args.light.no_cache)?);
    if scene.sensors.is_empty() {
        return Err(CliError::failure(format!(
            "{}: the scene has no sensors; an annual study reads sensors ([[sensors]] or [[sensor_grids]])",
            args.scene.display()
        )));
    }
    let weather = Weather::read(&args.weather)?;
    let site = &scene.site;
    warn_about_weather(&args.weather, &weather, site);

    let settings = args.light.settings();
    let model = precompute_for_command(scene.clone(), settings, args.light.no_cache)?;
    warn_about_coefficients(&args.scene, &model);
    let shaded = |down: &[usize]| precompute_for_command(std::sync::Arc::new(scene.with_shades_down(down)), settings, args.light.no_cache);
    let shades: Option<ShadedModel> = (!scene.shades.is_empty() && !args.no_shades).then_some(&shaded);
    // The year's sun at the site: traced once, then from the cache for every
    // weather file (unless its table would not fit in memory: then hour by hour).
    let cache_dir = if args.light.no_cache { None } else { cache::default_dir() };
    let hourly_csv = args.hourly.as_deref().map(|path| HourlyCsv::create(path, &scene, &weather)).transpose()?;
    let write_hour = |k: usize, values: &[f32]| hourly_csv.as_ref().map_or(Ok(()), |csv| csv.row(k, values));
    let progress = progress_bar("the year's sun, then a year of hours");
    let options = AnnualOptions {
        occupancy: args.occupied,
        shades,
        hourly: hourly_csv.is_some().then_some(&write_hour as HourlyReadings),
        sun_cache: cache_dir.as_deref(),
        ..Default::default()
    };
    let result = annual(&model, site, &weather, &options, &|done| progress.set_position((done * 1000.0) as u64));
    progress.finish_and_clear();
    let result = match (result, hourly_csv) {
        (Ok(result), Some(csv)) => csv.finish().map(|_| result),
        (Err(why), Some(csv)) => {
            csv.discard();
            Err(why)
        }
        (result, None) => result,
    }?;
    warn_about_skipped_hours(&args.weather, result.skipped.as_ref());
    print!("{}", report(&result, args.format, &args.weather));
    Ok(())
}

/// What a study at `site` should know of the weather file at `path`: a
/// station far from the site, missing values in daylight.
pub(crate) fn warn_about_weather(path: &Path, weather: &Weather, site: &Site) {
    let station = &weather.station;
    if station.is_far_from(site) {
        eprintln!(
            "warning: {}: the weather of {} ({:.2}°, {:.2}°, UTC{:+}) is far from the scene's site ({:.2}°, {:.2}°, UTC{:+}); the site's sun is used",
            path.display(),
            station.name,
            station.latitude,
            station.longitude,
            station.timezone,
            site.latitude,
            site.longitude,
            site.timezone
        );
    }
    if let Some(note) = missing_in_daylight_note(site, weather) {
        eprintln!("warning: {}: {note}", path.display());
    }
}

/// Lit hours of the weather file at `path` that had no sky
/// ([`crate::annual::YearSkies::skipped`]).
pub(crate) fn warn_about_skipped_hours(path: &Path, skipped: Option<&(usize, String)>) {
    if let Some(skipped) = skipped {
        eprintln!("warning: {}: {}", path.display(), skipped_hours_note(skipped));
    }
}

/// `--hourly`'s file, written an hour at a time as the year is read: a
/// header of the sensors' names, then each hour's `month,day,hour` and
/// every sensor's total lux.
struct HourlyCsv<'w> {
    path: PathBuf,
    /// Behind a lock only because the year's callback must be `Sync`: it
    /// is called from one thread, in order.
    out: Mutex<BufWriter<File>>,
    weather: &'w Weather,
}

impl<'w> HourlyCsv<'w> {
    /// Creates the file and writes its header.
    fn create(path: &Path, scene: &crate::scene::Scene, weather: &'w Weather) -> Result<Self, String> {
        let mut header = String::from("month,day,hour");
        for sensor in &scene.sensors {
            header.push(',');
            header.push_str(&csv_field(&sensor.name));
        }
        header.push('\n');
        let csv = Self {
            path: path.to_path_buf(),
            out: Mutex::new(BufWriter::new(File::create(path).map_err(|e| Self::why(path, e))?)),
            weather,
        };
        csv.write(header.as_bytes())?;
        Ok(csv)
    }

    /// Hour `k`'s row.
    fn row(&self, k: usize, values: &[f32]) -> Result<(), String> {
        let hour = &self.weather.hours[k];
        let mut line = format!("{},{},{}", hour.month, hour.day, hour.hour);
        for value in values {
            let _ = write!(line, ",{value:.1}");
        }
        line.push('\n');
        self.write(line.as_bytes())
    }

    fn write(&self, bytes: &[u8]) -> Result<(), String> {
        self.out.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).write_all(bytes).map_err(|e| Self::why(&self.path, e))
    }

    /// Writes out what is left.
    fn finish(self) -> Result<(), String> {
        self.out.into_inner().unwrap_or_else(|poisoned| poisoned.into_inner()).flush().map_err(|e| Self::why(&self.path, e))
    }

    /// Removes the unfinished file of a year that failed.
    fn discard(self) {
        let path = self.path.clone();
        drop(self);
        let _ = std::fs::remove_file(path);
    }

    fn why(path: &Path, e: std::io::Error) -> String {
        format!("--hourly {}: {e}", path.display())
    }
}

fn report(result: &AnnualResult, format: Format, weather_path: &std::path::Path) -> String {
    let mut out = String::new();
    match format {
        Format::Csv => out.push_str(&result.csv()),
        Format::Json => {
            let rows: Vec<String> = result
                .sensors
                .iter()
                .map(|s| {
                    format!(
                        "{{\"name\": {}, \"da300\": {:.1}, \"udi_low\": {:.1}, \"udi\": {:.1}, \"udi_high\": {:.1}, \"ase_hours\": {}}}",
                        json_string(&s.name),
                        s.da300,
                        s.udi_low,
                        s.udi,
                        s.udi_high,
                        s.ase_hours
                    )
                })
                .collect();
            let _ = writeln!(
                out,
                "{{\"weather\": {}, \"occupied_hours\": {}, \"shaded_hours\": {}, \"sda300_50\": {:.1}, \"ase1000_250\": {:.1}, \"sensors\": [{}]}}",
                json_string(&weather_path.display().to_string()),
                result.occupied_hours,
                result.shaded_hours,
                result.sda(),
                result.ase(),
                rows.join(", ")
            );
        }
        Format::Table => {
            let _ = writeln!(out, "{}: {} occupied hours", weather_path.display(), result.occupied_hours);
            if result.shaded_hours > 0 {
                let _ = writeln!(out, "shades down in {} of them (IES LM-83)", result.shaded_hours);
            }
            match result.sensors.iter().filter(|s| s.point).count() {
                0 => out.push_str("sDA300/50%, ASE1000/250: none (they count point sensors; this scene has area sensors only)\n"),
                points => {
                    let _ = writeln!(out, "sDA300/50%  {:.1}% of {points} point sensors", result.sda());
                    let _ = writeln!(out, "ASE1000/250 {:.1}% of {points} point sensors", result.ase());
                }
            }
            let _ = writeln!(out, "{:<20} {:>7} {:>8} {:>7} {:>9} {:>9}", "sensor", "DA300 %", "UDI<100", "UDI %", "UDI>3000", "ASE h");
            for s in &result.sensors {
                let _ = writeln!(
                    out,
                    "{:<20} {:>7.1} {:>8.1} {:>7.1} {:>9.1} {:>9}",
                    s.name, s.da300, s.udi_low, s.udi, s.udi_high, s.ase_hours
                );
            }
        }
    }
    out
}
