//! `heliodon sweep` and `heliodon sweep-merge`: one or two keys of a window
//! material over a grid, every combination read at the sensors (at an
//! instant, or DA300 and sDA over a year), in shards for batch systems.
//! The engine is [`crate::sweep`]; this is flags, tables and files.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::annual::{Occupancy, YearSkies};
use crate::cli::CliError;
use crate::cli::args::{
    Format, LightArgs, SkyArgs, load_for_command, precompute_for_command, progress_bar, sky_for, warn_about_coefficients,
};
use crate::cli::sweep_table::{Row, SDA_ROW, Table, best, key_value};
use crate::panel::PanelCatalog;
use crate::report::{csv_field, json_string};
use crate::sweep::{Axis, Grid, MAX_AXES, Target, Variation, parse_shard, sweep};
use crate::time::{Date, LocalDateTime, TimeOfDay};
use crate::weather::Weather;

/// The trailer a shard's CSV ends with: `sweep-merge` checks it.
const SHARD_MARK: &str = "# heliodon sweep shard ";

#[derive(clap::Args, Debug)]
#[command(group(clap::ArgGroup::new("sensors").required(true).args(["sensor", "all_sensors"])))]
pub struct SweepArgs {
    /// Scene file (TOML)
    pub scene: PathBuf,
    /// The window material whose keys vary (a panel or a glass)
    #[arg(long)]
    pub material: String,
    /// A key and its values: KEY=LO..HI:STEP (a list item as facet_angles[1]); once or twice
    #[arg(long = "vary", value_name = "KEY=LO..HI:STEP", value_parser = Axis::parse, required = true)]
    pub vary: Vec<Axis>,
    /// Read this sensor
    #[arg(long)]
    pub sensor: Option<String>,
    /// Read every sensor
    #[arg(long)]
    pub all_sensors: bool,
    /// Local date, YYYY-MM-DD (with --time: one instant)
    #[arg(long, value_parser = Date::parse, requires = "time", conflicts_with = "weather")]
    pub date: Option<Date>,
    /// Local standard time, HH:MM
    #[arg(long, value_parser = TimeOfDay::parse, requires = "date")]
    pub time: Option<TimeOfDay>,
    #[command(flatten)]
    pub sky: SkyArgs,
    /// A year of weather (EPW): each combination's DA300 at the sensors and the scene's sDA
    #[arg(long, value_name = "FILE.epw")]
    pub weather: Option<PathBuf>,
    /// Occupied hours, local standard time (with --weather)
    #[arg(long, value_name = "HH:MM-HH:MM", value_parser = Occupancy::parse, default_value = "08:00-18:00")]
    pub occupied: Occupancy,
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Draw the curve (one key) or heat map (two keys) to this PNG
    #[arg(long, value_name = "HEATMAP.png")]
    pub out: Option<PathBuf>,
    /// Compute only part K of N equal parts (K from 1), to join with sweep-merge
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<(usize, usize)>,
    #[command(flatten)]
    pub light: LightArgs,
}

#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The parts' CSV files (sweep --shard K/N --format csv)
    #[arg(required = true, value_name = "PART.csv")]
    pub parts: Vec<PathBuf>,
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
    /// Draw the curve (one key) or heat map (two keys) to this PNG
    #[arg(long, value_name = "HEATMAP.png")]
    pub out: Option<PathBuf>,
}

/// Runs the sweep and prints it.
pub fn run(args: &SweepArgs, panels: &PanelCatalog) -> Result<(), CliError> {
    if args.vary.len() > MAX_AXES {
        return Err(CliError::usage(format!("--vary: {} keys given; a sweep varies one or two", args.vary.len())));
    }
    if args.weather.is_none() && args.date.is_none() {
        return Err(CliError::usage("a sweep needs an instant (--date and --time) or a year (--weather FILE.epw)"));
    }
    let scene = std::sync::Arc::new(load_for_command(&args.scene, panels, args.light.no_cache)?);
    let grid = Grid { axes: args.vary.clone() };
    let variation = Variation::new(&scene, &args.material, &grid, panels)?;
    let sensors: Vec<usize> = match &args.sensor {
        Some(name) => vec![scene.sensors.iter().position(|s| &s.name == name).ok_or_else(|| {
            let names: Vec<&str> = scene.sensors.iter().take(8).map(|s| s.name.as_str()).collect();
            format!(
                "--sensor {name}: the scene has no such sensor (its sensors: {}{})",
                names.join(", "),
                if scene.sensors.len() > 8 { ", …" } else { "" }
            )
        })?],
        None if scene.sensors.is_empty() => return Err(CliError::failure(format!("{}: the scene has no sensors", args.scene.display()))),
        None => (0..scene.sensors.len()).collect(),
    };
    let weather = match &args.weather {
        Some(path) => {
            let weather = Weather::read(path)?;
            super::annual::warn_about_weather(path, &weather, &scene.site);
            super::annual::warn_about_skipped_hours(path, YearSkies::new(&scene.site, &weather).skipped(&weather).as_ref());
            Some(weather)
        }
        None => None,
    };
    if weather.is_some() && !scene.shades.is_empty() {
        eprintln!("warning: {}: the sweep reads the year with the [[shades]] up, as `annual --no-shades` does", args.scene.display());
    }
    let sky = match (args.date, args.time) {
        (Some(date), Some(time)) => Some(sky_for(&scene, &args.sky.spec()?, &args.sky.sky, LocalDateTime { date, time })?.1),
        _ => None,
    };
    let target = match (&weather, &sky) {
        (Some(weather), _) => Target::Year(weather, args.occupied),
        (None, Some(sky)) => Target::Instant(sky),
        (None, None) => unreachable!("checked above"),
    };
    let range = match args.shard {
        Some((k, n)) => grid.shard(k, n),
        None => 0..grid.len(),
    };
    let mut model = precompute_for_command(scene.clone(), args.light.settings(), args.light.no_cache)?;
    warn_about_coefficients(&args.scene, &model);
    let progress = progress_bar("sweeping");
    let outcomes = sweep(&mut model, &variation, &grid, range, &sensors, target, &|_, done| progress.set_position((done * 1000.0) as u64));
    progress.finish_and_clear();

    let names: Vec<String> = sensors.iter().map(|&s| scene.sensors[s].name.clone()).collect();
    let mut rows = Vec::new();
    for outcome in &outcomes {
        let row = |sensor: &str, value: Result<f64, String>| Row { values: outcome.values.clone(), sensor: sensor.to_string(), value };
        match &outcome.result {
            Ok((values, sda)) => {
                rows.extend(names.iter().zip(values).map(|(name, v)| row(name, Ok(*v))));
                rows.extend(sda.map(|v| row(SDA_ROW, Ok(v))));
            }
            Err(e) => {
                rows.extend(names.iter().map(|name| row(name, Err(e.clone()))));
                if weather.is_some() {
                    rows.push(row(SDA_ROW, Err(e.clone())));
                }
            }
        }
    }
    let table =
        Table { keys: grid.axes.iter().map(|a| a.key.clone()).collect(), unit: if weather.is_some() { "%" } else { "lux" }.into(), rows };
    let mut text = report(&table, args.format);
    if let (Some((k, n)), Format::Csv) = (args.shard, args.format) {
        let _ = writeln!(text, "{SHARD_MARK}{k}/{n} of {}", signature(args));
    }
    print!("{text}");
    if let Some(path) = &args.out {
        crate::cli::plot::write_sweep_picture(&table, path)?;
    }
    Ok(())
}

/// What makes two shards parts of one sweep: everything but the shard.
fn signature(args: &SweepArgs) -> String {
    let target = match (&args.weather, args.date, args.time) {
        (Some(w), ..) => format!("weather {} occupied {}-{}", w.display(), args.occupied.start, args.occupied.end),
        (None, Some(d), Some(t)) => format!(
            "{d} {t} sky {} {:?} {:?} {:?} {:?} {:?}",
            args.sky.sky, args.sky.dni, args.sky.dhi, args.sky.direct_lux, args.sky.diffuse_lux, args.sky.turbidity
        ),
        _ => String::new(),
    };
    let vary: Vec<String> = args.vary.iter().map(|a| format!("{}={:?}", a.key, a.values)).collect();
    let sensors = args.sensor.clone().unwrap_or_else(|| "all".into());
    format!("scene {} material {} vary {} sensors {sensors} {target}", args.scene.display(), args.material, vary.join(" "))
}

/// Joins shards' CSVs into the unsharded sweep's output.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let mut parts: Vec<(usize, usize, String, &Path, String)> = Vec::new();
    for path in &args.parts {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let body: Vec<&str> = text.lines().collect();
        let mark = body.last().and_then(|l| l.strip_prefix(SHARD_MARK)).ok_or_else(|| {
            format!(
                "{}: not a sweep part (its last line is not '{SHARD_MARK}K/N of …': run sweep --shard K/N --format csv)",
                path.display()
            )
        })?;
        let (shard, signature) =
            mark.split_once(" of ").ok_or_else(|| format!("{}:{}: a damaged shard line", path.display(), body.len()))?;
        let (k, n) = parse_shard(shard).map_err(|e| format!("{}:{}: {e}", path.display(), body.len()))?;
        parts.push((k, n, signature.to_string(), path, body[..body.len() - 1].join("\n")));
    }
    let (n, signature, first) = (parts[0].1, parts[0].2.clone(), parts[0].3);
    for (k, m, other, path, _) in &parts {
        if *other != signature || *m != n {
            return Err(CliError::failure(format!(
                "{}: part {k}/{m} is of another sweep than {} ({other} / {signature})",
                path.display(),
                first.display()
            )));
        }
    }
    parts.sort_by_key(|p| p.0);
    for k in 1..=n {
        match parts.iter().filter(|p| p.0 == k).count() {
            0 => return Err(CliError::failure(format!("part {k}/{n} is missing"))),
            1 => {}
            _ => return Err(CliError::failure(format!("part {k}/{n} is given more than once"))),
        }
    }
    let mut header = None;
    let mut csv = String::new();
    for (k, _, _, path, body) in &parts {
        let mut lines = body.lines();
        let head = lines.next().unwrap_or_default();
        match &header {
            None => {
                header = Some(head.to_string());
                csv.push_str(head);
                csv.push('\n');
            }
            Some(h) if h != head => {
                return Err(CliError::failure(format!("{}: part {k}'s header '{head}' differs from '{h}'", path.display())));
            }
            _ => {}
        }
        lines.for_each(|l| {
            csv.push_str(l);
            csv.push('\n');
        });
    }
    let table = parse_csv(&csv, signature.contains(" weather "))?;
    print!("{}", if args.format == Format::Csv { csv } else { report(&table, args.format) });
    if let Some(path) = &args.out {
        crate::cli::plot::write_sweep_picture(&table, path)?;
    }
    Ok(())
}

/// A sweep's CSV read back.
fn parse_csv(csv: &str, year: bool) -> Result<Table, String> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let keys: Vec<String> = header[..header.len().saturating_sub(2)].iter().map(|k| k.to_string()).collect();
    let rows = lines
        .enumerate()
        .map(|(i, line)| {
            let fields = split_csv(line);
            let bad = || format!("line {}: '{line}' is not a sweep row", i + 2);
            if fields.len() != keys.len() + 2 {
                return Err(bad());
            }
            let values = fields[..keys.len()].iter().map(|v| v.parse::<f64>().map_err(|_| bad())).collect::<Result<_, _>>()?;
            let value = match fields[keys.len() + 1].strip_prefix("error: ") {
                Some(e) => Err(e.to_string()),
                None => Ok(fields[keys.len() + 1].parse::<f64>().map_err(|_| bad())?),
            };
            Ok(Row { values, sensor: fields[keys.len()].clone(), value })
        })
        .collect::<Result<_, String>>()?;
    Ok(Table { keys, unit: if year { "%" } else { "lux" }.into(), rows })
}

/// Splits one CSV line (fields quoted as [`csv_field`] quotes them).
fn split_csv(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut field)),
            c => field.push(c),
        }
    }
    fields.push(field);
    fields
}

fn report(table: &Table, format: Format) -> String {
    let mut out = String::new();
    let value = |v: &Result<f64, String>| match v {
        Ok(v) => format!("{v:.1}"),
        Err(e) => format!("error: {e}"),
    };
    match format {
        Format::Csv => {
            let _ = writeln!(out, "{},sensor,value", table.keys.iter().map(|k| csv_field(k)).collect::<Vec<_>>().join(","));
            for row in &table.rows {
                let keys: Vec<String> = row.values.iter().map(|&v| key_value(v)).collect();
                let _ = writeln!(out, "{},{},{}", keys.join(","), csv_field(&row.sensor), csv_field(&value(&row.value)));
            }
        }
        Format::Json => {
            let rows: Vec<String> = table
                .rows
                .iter()
                .map(|row| {
                    let keys: Vec<String> =
                        table.keys.iter().zip(&row.values).map(|(k, v)| format!("{}: {}", json_string(k), key_value(*v))).collect();
                    let value = match &row.value {
                        Ok(v) => format!("\"value\": {v:.1}"),
                        Err(e) => format!("\"error\": {}", json_string(e)),
                    };
                    format!("{{{}, \"sensor\": {}, {value}}}", keys.join(", "), json_string(&row.sensor))
                })
                .collect();
            let best = best(table).map_or("null".to_string(), |(values, score)| {
                let keys: Vec<String> =
                    table.keys.iter().zip(&values).map(|(k, v)| format!("{}: {}", json_string(k), key_value(*v))).collect();
                format!("{{{}, \"score\": {score:.1}}}", keys.join(", "))
            });
            let keys: Vec<String> = table.keys.iter().map(|k| json_string(k)).collect();
            let _ = writeln!(
                out,
                "{{\"keys\": [{}], \"unit\": {}, \"best\": {best}, \"rows\": [{}]}}",
                keys.join(", "),
                json_string(&table.unit),
                rows.join(", ")
            );
        }
        Format::Table => {
            if let Some((values, score)) = best(table) {
                let keys: Vec<String> = table.keys.iter().zip(&values).map(|(k, v)| format!("{k} = {}", key_value(*v))).collect();
                let sensors: std::collections::BTreeSet<&str> = table.rows.iter().map(|r| r.sensor.as_str()).collect();
                let what = match sensors.len() {
                    _ if sensors.contains(SDA_ROW) => "sDA300/50%".to_string(),
                    1 => format!("at {}", table.rows[0].sensor),
                    _ => "mean over the sensors".to_string(),
                };
                let _ = writeln!(out, "best: {} ({what} {score:.1} {})", keys.join(", "), table.unit);
            }
            let widths: Vec<usize> = table.keys.iter().map(|k| k.len().max(8)).collect();
            let head: Vec<String> = table.keys.iter().zip(&widths).map(|(k, w)| format!("{k:>w$}")).collect();
            let _ = writeln!(out, "{} {:<20} {:>10}", head.join(" "), "sensor", table.unit);
            for row in &table.rows {
                let keys: Vec<String> = row.values.iter().zip(&widths).map(|(v, w)| format!("{:>w$}", key_value(*v))).collect();
                let _ = writeln!(out, "{} {:<20} {:>10}", keys.join(" "), row.sensor, value(&row.value));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_split_back() {
        assert_eq!(split_csv("1,2.5,desk,\"error: a, b \"\"c\"\"\""), vec!["1", "2.5", "desk", "error: a, b \"c\""]);
    }
}
