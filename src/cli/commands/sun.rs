//! `heliodon sun`: the sun's position (NREL SPA), or the day's sunrise,
//! solar noon and sunset.

use std::fmt::Write as _;

use crate::cli::args::{Format, in_range};
use crate::site::Site;
use crate::sun::{self, SolarPosition};
use crate::time::{Date, LocalDateTime, TimeOfDay};

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

/// Prints the report.
pub fn run(args: &SunArgs) {
    print!("{}", sun_report(args));
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
                let _ = writeln!(
                    out,
                    "{} at latitude {}°, longitude {}°, UTC{:+} (local standard time)",
                    args.date, args.latitude, args.longitude, args.timezone
                );
                for (name, time) in events {
                    match (time, position(time)) {
                        (Some(t), Some(p)) => {
                            let _ = writeln!(out, "{name:<8} {t}  altitude {:7.3}°  azimuth {:7.3}°", p.altitude, p.azimuth);
                        }
                        _ => {
                            let why =
                                if day.up_at_noon { "the sun does not set (polar day)" } else { "the sun does not rise (polar night)" };
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
            let _ = writeln!(
                out,
                "{} {} at latitude {}°, longitude {}°, UTC{:+} (local standard time)",
                args.date, time, args.latitude, args.longitude, args.timezone
            );
            let _ = writeln!(
                out,
                "altitude   {:9.4}°  apparent (refraction included){}",
                p.altitude,
                if p.is_up() { "" } else { ", below the horizon" }
            );
            let _ = writeln!(out, "azimuth    {:9.4}°  clockwise from true north", p.azimuth);
            let _ = writeln!(out, "ΔT         {:9.2} s", p.delta_t);
        }
    }
    out
}
