//! `heliodon sensors`: lux at every sensor for dates × times, sharing one
//! (cached) precomputation.

use std::fmt::Write as _;
use std::path::PathBuf;

use crate::cli::CliError;
use crate::cli::args::{Format, LightArgs, SkyArgs, load_for_command, precompute_for_command, sky_for};
use crate::light::{Lighting, without_daylight};
use crate::panel::PanelCatalog;
use crate::report::{csv_field, json_string};
use crate::time::{Date, LocalDateTime, TimeOfDay};

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
    #[command(flatten)]
    pub light: LightArgs,
}

/// Prints the readings.
pub fn run(args: &SensorsArgs, panels: &PanelCatalog) -> Result<(), CliError> {
    print!("{}", sensors(args, panels)?);
    Ok(())
}

/// The first five names and how many more: one warning line, however many sensors it is about.
fn first_few(names: &[&str]) -> String {
    let named = names.iter().take(5).copied().collect::<Vec<_>>().join(", ");
    if names.len() > 5 { format!("{named} and {} more", names.len() - 5) } else { named }
}

/// The `sensors` command: one precomputation, then every date × time.
pub fn sensors(args: &SensorsArgs, panels: &PanelCatalog) -> Result<String, String> {
    let spec = args.sky.spec()?;
    let scene = std::sync::Arc::new(load_for_command(&args.scene, panels, args.light.no_cache)?);
    let model = precompute_for_command(scene.clone(), args.light.settings(), args.light.no_cache)?;
    // Sensors in the open: outside every room, or a model without one.
    const OUTSIDE: f64 = 0.3;
    let outside: Vec<&str> =
        model.open_sky_shares().iter().zip(&scene.sensors).filter(|(share, _)| **share > OUTSIDE).map(|(_, s)| s.name.as_str()).collect();
    if !outside.is_empty() {
        let named = first_few(&outside);
        let what = if outside.len() == scene.sensors.len() {
            "every sensor sees the open sky directly: the model has no enclosed room around them"
        } else {
            "sensors outside every room (they see the open sky directly)"
        };
        eprintln!("warning: {}: {what}: {named}; they read the light where they are", args.scene.display());
    }
    let over_nothing: Vec<&str> = model.sensors_over_nothing().into_iter().map(|i| scene.sensors[i].name.as_str()).collect();
    if !over_nothing.is_empty() {
        eprintln!(
            "warning: {}: nothing under {} sensors (rays down from them meet no surface: the model has no floor there): {}; they read the ground's light through it",
            args.scene.display(),
            over_nothing.len(),
            first_few(&over_nothing)
        );
    }
    let inside: Vec<&str> = model.sensors_inside_solids().into_iter().map(|i| scene.sensors[i].name.as_str()).collect();
    if !inside.is_empty() {
        let (who, reads) = if inside.len() == 1 {
            ("a sensor seems to be", "it reads what reaches it")
        } else {
            ("sensors seem to be", "they read what reaches them")
        };
        eprintln!(
            "warning: {}: {who} inside a solid (every direction meets a back face): {}; {reads} there",
            args.scene.display(),
            first_few(&inside)
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
    // Per sensor: whether every case with daylight left it without any.
    let mut dark: Option<Vec<bool>> = None;
    for when in cases {
        let (position, sky) = sky_for(&scene, &spec, &args.sky.sky, when)?;
        let lighting = model.solve(&sky, previous.as_ref());
        if let Some(here) = without_daylight(&lighting.sensors, &sky) {
            dark = Some(match dark {
                Some(before) => before.iter().zip(&here).map(|(a, b)| *a && *b).collect(),
                None => here,
            });
        }
        match args.format {
            Format::Csv => {
                for r in &lighting.sensors {
                    let prefix = if several { format!("{},{},", when.date, when.time) } else { String::new() };
                    let _ = writeln!(
                        out,
                        "{prefix}{},{:.1},{:.1},{:.1},{:.1}",
                        csv_field(&r.name),
                        r.total,
                        r.direct_sun,
                        r.direct_sky,
                        r.indirect
                    );
                }
            }
            Format::Json => {
                let rows: Vec<String> = lighting
                    .sensors
                    .iter()
                    .map(|r| {
                        format!(
                            "{{\"name\": {}, \"illuminance_lux\": {:.1}, \"direct_sun_lux\": {:.1}, \"direct_sky_lux\": {:.1}, \"indirect_lux\": {:.1}}}",
                            json_string(&r.name), r.total, r.direct_sun, r.direct_sky, r.indirect
                        )
                    })
                    .collect();
                json.push(format!(
                    "{{\"date\": \"{}\", \"time\": \"{}\", \"sun_altitude_deg\": {:.4}, \"sun_azimuth_deg\": {:.4}, \"sky\": {}, \"sensors\": [{}]}}",
                    when.date, when.time, position.altitude, position.azimuth, json_string(&args.sky.sky), rows.join(", ")
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
                    let _ = writeln!(
                        out,
                        "{:<20} {:>10.1} {:>10.1} {:>10.1} {:>10.1}",
                        r.name, r.total, r.direct_sun, r.direct_sky, r.indirect
                    );
                }
            }
        }
        previous = Some(lighting);
    }
    if args.format == Format::Json {
        let _ = writeln!(out, "{}", if several { format!("[{}]", json.join(", ")) } else { json.concat() });
    }
    let dark: Vec<&str> =
        dark.unwrap_or_default().iter().zip(&scene.sensors).filter(|(dark, _)| **dark).map(|(_, s)| s.name.as_str()).collect();
    if !dark.is_empty() {
        let who = if dark.len() == 1 { "a sensor reads".to_string() } else { format!("{} sensors read", dark.len()) };
        eprintln!(
            "warning: {}: {who} almost no daylight (under 0.001% of the sky's horizontal illuminance, as in a room no window or opening lights): {}",
            args.scene.display(),
            first_few(&dark)
        );
    }
    Ok(out)
}
