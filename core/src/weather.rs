//! Weather files: EnergyPlus EPW, as the annual study reads them (see the
//! contract's "Annual climate-based daylight").
//!
//! - The header's `LOCATION` line gives the station's latitude, longitude,
//!   time zone and elevation (a check against the scene's site).
//! - Each data row is an hour *ending* at `hour` (1-24), local standard
//!   time; columns 14 and 15 (counting from 0) are the direct normal and
//!   diffuse horizontal irradiance, W/m².
//! - The calendar is 365 days: rows for 29 February are skipped, so a file
//!   holds exactly 8,760 hours, in order.
//! - Missing radiation (EPW's 9999) reads as 0 and is counted, so the caller
//!   can say how many daylight hours lack it.
//!
//! Every error is one line: the file, the line and the column.

use std::path::Path;

use crate::time::days_in_month;

/// Hours of a 365-day year.
pub const HOURS: usize = 8760;
/// EPW's code for missing radiation.
const MISSING: f64 = 9999.0;
/// Above this (W/m²) an irradiance is not the sun's: the solar constant with room.
const MAX_IRRADIANCE: f64 = 1400.0;

/// The weather station, from the `LOCATION` line.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// City, region and country as the file names them.
    pub name: String,
    /// Degrees, north positive.
    pub latitude: f64,
    /// Degrees, east positive.
    pub longitude: f64,
    /// Hours from UTC of local standard time.
    pub timezone: f64,
    /// Metres above sea level.
    pub elevation: f64,
}

/// One hour of the year.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeatherHour {
    /// 1-12.
    pub month: u32,
    /// 1-31.
    pub day: u32,
    /// 1-24: the hour ending at this time, local standard time.
    pub hour: u32,
    /// Direct normal irradiance, W/m² (0 where missing).
    pub direct_normal: f64,
    /// Diffuse horizontal irradiance, W/m² (0 where missing).
    pub diffuse_horizontal: f64,
    /// Whether the file gave no direct or no diffuse value for this hour.
    pub missing: bool,
}

/// A year of weather.
#[derive(Debug, Clone, PartialEq)]
pub struct Weather {
    /// Where it was recorded.
    pub station: Station,
    /// [`HOURS`] hours from 1 January 01:00 to 31 December 24:00.
    pub hours: Vec<WeatherHour>,
}

impl Station {
    /// Whether the station is more than 1° of latitude or longitude, or a
    /// time zone, from `site`: its weather is then not the site's (the
    /// contract's warning).
    pub fn is_far_from(&self, site: &crate::site::Site) -> bool {
        (self.latitude - site.latitude).abs() > 1.0
            || (self.longitude - site.longitude).abs() > 1.0
            || (self.timezone - site.timezone).abs() >= 1.0
    }
}

impl Weather {
    /// Reads an EPW file; errors name it.
    pub fn read(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Self::parse_epw(&text, path)
    }

    /// Reads an EPW file's text; `path` names it in errors.
    pub fn parse_epw(text: &str, path: &Path) -> Result<Self, String> {
        let at = |line: usize, what: String| format!("{}:{line}: {what}", path.display());
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim_end_matches('\r')));
        let (_, location) = lines.next().ok_or_else(|| format!("{}: empty file (an EPW starts with a LOCATION line)", path.display()))?;
        let station = station(location).map_err(|e| at(1, e))?;
        let mut hours = Vec::with_capacity(HOURS);
        let mut last_line = 1;
        for (line, row) in lines {
            last_line = line;
            let fields: Vec<&str> = row.split(',').collect();
            // Header lines (DESIGN CONDITIONS … DATA PERIODS) come before the first row of numbers.
            if hours.is_empty() && fields[0].trim().parse::<i32>().is_err() {
                continue;
            }
            if row.trim().is_empty() {
                continue;
            }
            let Some(hour) = weather_hour(&fields).map_err(|e| at(line, e))? else { continue };
            let expected = hours.len();
            if expected >= HOURS {
                return Err(at(line, format!("more than {HOURS} hours (a 365-day year; 29 February is skipped)")));
            }
            let (month, day, h) = calendar(expected);
            if (hour.month, hour.day, hour.hour) != (month, day, h) {
                return Err(at(
                    line,
                    format!("hour {} of {}-{:02} is out of order: {month}-{day:02} hour {h} expected", hour.hour, hour.month, hour.day),
                ));
            }
            hours.push(hour);
        }
        if hours.len() != HOURS {
            return Err(at(last_line, format!("the file looks truncated: {} of {HOURS} hours", hours.len())));
        }
        Ok(Self { station, hours })
    }

    /// Hours whose direct or diffuse radiation the file marks missing
    /// (9999); they read as 0.
    pub fn missing_hours(&self) -> usize {
        self.hours.iter().filter(|h| h.missing).count()
    }
}

/// Month, day and hour (1-24) of hour `index` of a 365-day year.
pub fn calendar(index: usize) -> (u32, u32, u32) {
    let (mut day_of_year, hour) = (index / 24, (index % 24) as u32 + 1);
    for month in 1..=12 {
        let days = if month == 2 { 28 } else { days_in_month(2025, month) } as usize;
        if day_of_year < days {
            return (month, day_of_year as u32 + 1, hour);
        }
        day_of_year -= days;
    }
    (12, 31, hour)
}

fn station(line: &str) -> Result<Station, String> {
    let fields: Vec<&str> = line.split(',').map(str::trim).collect();
    if fields.first() != Some(&"LOCATION") {
        return Err("an EPW starts with a LOCATION line".into());
    }
    if fields.len() < 10 {
        return Err(format!(
            "LOCATION has {} fields, 10 expected (city, region, country, source, WMO, latitude, longitude, time zone, elevation)",
            fields.len()
        ));
    }
    let number = |k: usize, what: &str, range: (f64, f64)| {
        let value: f64 = fields[k].parse().map_err(|_| format!("column {k} ({what}): '{}' is not a number", fields[k]))?;
        if !value.is_finite() || value < range.0 || value > range.1 {
            return Err(format!("column {k} ({what}): {value} is outside {}..{}", range.0, range.1));
        }
        Ok(value)
    };
    Ok(Station {
        name: [fields[1], fields[2], fields[3]].iter().filter(|f| !f.is_empty()).copied().collect::<Vec<_>>().join(", "),
        latitude: number(6, "latitude", (-90.0, 90.0))?,
        longitude: number(7, "longitude", (-180.0, 180.0))?,
        timezone: number(8, "time zone", (-14.0, 14.0))?,
        elevation: number(9, "elevation", (-1000.0, 9000.0))?,
    })
}

/// One data row; `None` for 29 February (the calendar has 365 days).
fn weather_hour(fields: &[&str]) -> Result<Option<WeatherHour>, String> {
    if fields.len() < 16 {
        return Err(format!("{} columns; a data row has at least 16 (the irradiances are columns 14 and 15)", fields.len()));
    }
    let whole = |k: usize, what: &str, range: (u32, u32)| {
        let value: u32 =
            fields[k].trim().parse().map_err(|_| format!("column {k} ({what}): '{}' is not a whole number", fields[k].trim()))?;
        if value < range.0 || value > range.1 {
            return Err(format!("column {k} ({what}): {value} is outside {}..{}", range.0, range.1));
        }
        Ok(value)
    };
    let month = whole(1, "month", (1, 12))?;
    let day = whole(2, "day", (1, 31))?;
    let hour = whole(3, "hour", (1, 24))?;
    if month == 2 && day == 29 {
        return Ok(None);
    }
    let days = if month == 2 { 28 } else { days_in_month(2025, month) };
    if day > days {
        return Err(format!("column 2 (day): {month}-{day:02} does not exist"));
    }
    let irradiance = |k: usize, what: &str| -> Result<Option<f64>, String> {
        let value: f64 = fields[k].trim().parse().map_err(|_| format!("column {k} ({what}): '{}' is not a number", fields[k].trim()))?;
        if value >= MISSING {
            return Ok(None);
        }
        if !value.is_finite() || !(0.0..=MAX_IRRADIANCE).contains(&value) {
            return Err(format!("column {k} ({what}): {value} W/m² is outside 0..{MAX_IRRADIANCE} (9999 marks a missing value)"));
        }
        Ok(Some(value))
    };
    let direct = irradiance(14, "direct normal irradiance")?;
    let diffuse = irradiance(15, "diffuse horizontal irradiance")?;
    Ok(Some(WeatherHour {
        month,
        day,
        hour,
        direct_normal: direct.unwrap_or(0.0),
        diffuse_horizontal: diffuse.unwrap_or(0.0),
        missing: direct.is_none() || diffuse.is_none(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic EPW: `rows` data rows of the year (29 February included when `leap`).
    pub(crate) fn epw(rows: usize, leap: bool) -> String {
        let mut text = String::from(
            "LOCATION,Testville,ST,USA,TMY3,123456,42.36,-71.06,-5.0,10.0\nDESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\nCOMMENTS 1,x\nCOMMENTS 2,y\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n",
        );
        for index in 0..HOURS {
            let (month, day, hour) = calendar(index);
            if leap && month == 3 && day == 1 && hour == 1 {
                for h in 1..=24 {
                    text.push_str(&format!("2024,2,29,{h},0,?,1,1,1,1,0,0,0,0,500,100\n"));
                }
            }
            if index == rows {
                break;
            }
            let (dni, dhi) = if (7..=17).contains(&hour) { (600, 120) } else { (0, 0) };
            text.push_str(&format!("2024,{month},{day},{hour},0,?,1,1,1,1,0,0,0,0,{dni},{dhi},0,0,0\n"));
        }
        text
    }

    #[test]
    fn a_year_reads_with_its_calendar_and_station() {
        let weather = Weather::parse_epw(&epw(HOURS, true), Path::new("w.epw")).unwrap();
        assert_eq!(weather.hours.len(), HOURS);
        assert_eq!((weather.station.latitude, weather.station.longitude, weather.station.timezone), (42.36, -71.06, -5.0));
        assert_eq!(weather.station.name, "Testville, ST, USA");
        let noon = weather.hours[24 * 59 + 11]; // 1 March 12:00, 29 February skipped
        assert_eq!((noon.month, noon.day, noon.hour, noon.direct_normal, noon.diffuse_horizontal), (3, 1, 12, 600.0, 120.0));
        assert_eq!(calendar(HOURS - 1), (12, 31, 24));
        // A byte-order mark and Windows line ends read the same.
        let windows = format!("\u{feff}{}", epw(HOURS, false).replace('\n', "\r\n"));
        assert_eq!(Weather::parse_epw(&windows, Path::new("w.epw")).unwrap().hours, weather.hours);
    }

    #[test]
    fn missing_radiation_reads_as_zero_and_is_counted() {
        let text = epw(HOURS, false).replacen(",600,120,", ",9999,120,", 3);
        let weather = Weather::parse_epw(&text, Path::new("w.epw")).unwrap();
        assert_eq!(weather.missing_hours(), 3);
        assert!(weather.hours.iter().filter(|h| h.missing).all(|h| h.direct_normal == 0.0));
    }

    #[test]
    fn malformed_files_are_one_line_naming_line_and_column() {
        let path = Path::new("w.epw");
        let err = |text: &str| Weather::parse_epw(text, path).unwrap_err();
        let e = err(&epw(5000, false));
        assert!(e.starts_with("w.epw:5008: ") && e.contains("truncated: 5000 of 8760"), "{e}");
        let e = err(&epw(HOURS, false).replacen(",600,120,", ",abc,120,", 1));
        assert!(e.contains("column 14 (direct normal irradiance): 'abc' is not a number"), "{e}");
        let e = err(&epw(HOURS, false).replacen(",600,120,", ",600,-5,", 1));
        assert!(e.contains("column 15 (diffuse horizontal irradiance): -5 W/m²"), "{e}");
        let e = err(&epw(HOURS, false).replacen("2024,1,1,2,", "2024,1,1,3,", 1));
        assert!(e.starts_with("w.epw:10: ") && e.contains("out of order"), "{e}");
        let e = err(&epw(HOURS, false).replacen("2024,1,1,1,0,?,1,1,1,1,0,0,0,0,0,0,0,0,0", "2024,1,1,1", 1));
        assert!(e.starts_with("w.epw:9: ") && e.contains("4 columns"), "{e}");
        let e =
            err(&epw(HOURS, false).replace("LOCATION,Testville,ST,USA,TMY3,123456,42.36", "LOCATION,Testville,ST,USA,TMY3,123456,142.36"));
        assert!(e.starts_with("w.epw:1: column 6 (latitude)"), "{e}");
        assert!(err("").contains("empty file"));
        assert!(err("hello\n").contains("LOCATION"));
        for e in [err(&epw(100, false)), err("x")] {
            assert!(!e.contains('\n'), "{e}");
        }
    }
}
