//! Calendar dates and local standard times, parsed strictly: `2026-02-30`
//! and `24:01` are errors with a message saying why. Plain Rust.

use std::fmt;

/// A proleptic Gregorian calendar date.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Date {
    /// Astronomical year numbering: 0 is 1 BC, −1 is 2 BC.
    pub year: i32,
    /// 1 for January … 12 for December.
    pub month: u32,
    /// Day of the month, from 1.
    pub day: u32,
}

const MONTHS: [&str; 12] =
    ["January", "February", "March", "April", "May", "June", "July", "August", "September", "October", "November", "December"];

/// Whether `year` has a 29 February: every fourth year, but of the
/// centuries only those divisible by 400.
pub fn is_leap_year(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

/// Days in `month` (1-12) of `year`, leap years counted.
pub fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        _ if is_leap_year(year) => 29,
        _ => 28,
    }
}

impl Date {
    /// A date, checked: months 1-12, days within the month, years -2000..6000
    /// (the span the solar position algorithm covers).
    pub fn new(year: i32, month: u32, day: u32) -> Result<Self, String> {
        if !(-2000..=6000).contains(&year) {
            return Err(format!("year {year} is outside -2000..6000"));
        }
        if !(1..=12).contains(&month) {
            return Err(format!("month {month} is not 1-12"));
        }
        let days = days_in_month(year, month);
        if day < 1 || day > days {
            return Err(format!("{} {year} has {days} days, not {day}", MONTHS[month as usize - 1]));
        }
        Ok(Self { year, month, day })
    }

    /// Parses `YYYY-MM-DD`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || format!("'{text}' is not a date (expected YYYY-MM-DD)");
        let mut parts = text.trim().splitn(3, '-');
        let (Some(y), Some(m), Some(d)) = (parts.next(), parts.next(), parts.next()) else { return Err(bad()) };
        if y.len() != 4 || m.len() != 2 || d.len() != 2 {
            return Err(bad());
        }
        let number = |s: &str| s.parse::<u32>().map_err(|_| bad());
        Self::new(number(y)? as i32, number(m)?, number(d)?).map_err(|why| format!("'{text}' is not a date: {why}"))
    }

    /// Days since 1970-01-01 (negative before).
    pub fn days_since_epoch(self) -> i64 {
        // Howard Hinnant's days_from_civil.
        let y = i64::from(self.year) - i64::from(self.month <= 2);
        let era = y.div_euclid(400);
        let yoe = y - era * 400;
        let m = i64::from(self.month);
        let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(self.day) - 1;
        let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
        era * 146_097 + doe - 719_468
    }

    /// The date `days` after the epoch.
    pub fn from_days_since_epoch(days: i64) -> Self {
        let z = days + 719_468;
        let era = z.div_euclid(146_097);
        let doe = z - era * 146_097;
        let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
        let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
        let mp = (5 * doy + 2) / 153;
        let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
        let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
        let year = (yoe + era * 400 + i64::from(month <= 2)) as i32;
        Self { year, month, day }
    }

    /// 1 for 1 January.
    pub fn day_of_year(self) -> u32 {
        (self.days_since_epoch() - Date { year: self.year, month: 1, day: 1 }.days_since_epoch()) as u32 + 1
    }

    /// The date `n` days later (earlier when negative).
    pub fn add_days(self, n: i64) -> Self {
        Self::from_days_since_epoch(self.days_since_epoch() + n)
    }
}

impl fmt::Display for Date {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:04}-{:02}-{:02}", self.year, self.month, self.day)
    }
}

/// Time of day in seconds after midnight, 0 ..= 86400 (24:00 is the end of the day).
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct TimeOfDay(f64);

impl TimeOfDay {
    /// Seconds in a day: 24:00, the end of the day, is this many.
    pub const SECONDS_PER_DAY: f64 = 86_400.0;

    /// A time `seconds` after midnight; an error outside 0 ..= 86400.
    pub fn from_seconds(seconds: f64) -> Result<Self, String> {
        if !(0.0..=Self::SECONDS_PER_DAY).contains(&seconds) {
            return Err(format!("{seconds} s is outside 00:00-24:00"));
        }
        Ok(Self(seconds))
    }

    /// A time `hours` after midnight (13.5 is 13:30); an error outside 0 ..= 24.
    pub fn from_hours(hours: f64) -> Result<Self, String> {
        Self::from_seconds(hours * 3600.0).map_err(|_| format!("{hours} h is outside 00:00-24:00"))
    }

    /// Parses `HH:MM` or `HH:MM:SS` (seconds may have a fraction).
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || format!("'{text}' is not a time (expected HH:MM or HH:MM:SS)");
        let parts: Vec<&str> = text.trim().split(':').collect();
        if !(2..=3).contains(&parts.len()) || parts[0].is_empty() || parts[1].len() != 2 {
            return Err(bad());
        }
        let hours: u32 = parts[0].parse().map_err(|_| bad())?;
        let minutes: u32 = parts[1].parse().map_err(|_| bad())?;
        let seconds: f64 = match parts.get(2) {
            Some(s) if s.len() >= 2 && s.chars().all(|c| c.is_ascii_digit() || c == '.') => s.parse().map_err(|_| bad())?,
            Some(_) => return Err(bad()),
            None => 0.0,
        };
        if minutes >= 60 || seconds >= 60.0 {
            return Err(format!("'{text}' is not a time: minutes and seconds run 0-59"));
        }
        // Checked before any arithmetic: a huge hour count must not wrap into the day.
        if hours > 24 {
            return Err(format!("'{text}' is outside 00:00-24:00"));
        }
        let total = f64::from(hours * 3600 + minutes * 60) + seconds;
        if total > Self::SECONDS_PER_DAY {
            return Err(format!("'{text}' is outside 00:00-24:00"));
        }
        Ok(Self(total))
    }

    /// Seconds after midnight.
    pub fn seconds(self) -> f64 {
        self.0
    }

    /// Hours after midnight, with the fraction (13.5 for 13:30).
    pub fn hours(self) -> f64 {
        self.0 / 3600.0
    }
}

impl fmt::Display for TimeOfDay {
    /// `HH:MM:SS`, rounded to the second.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.0.round() as u64;
        write!(f, "{:02}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60)
    }
}

/// A date and a local standard time (no daylight saving) at a site.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalDateTime {
    /// The local calendar date.
    pub date: Date,
    /// Local standard time of day (the site's `timezone`, no daylight saving).
    pub time: TimeOfDay,
}

impl LocalDateTime {
    /// Julian day (UT) for a site `timezone` hours from UTC.
    pub fn julian_day(&self, timezone: f64) -> f64 {
        let seconds = self.time.seconds() - timezone * 3600.0;
        self.date.days_since_epoch() as f64 + seconds / TimeOfDay::SECONDS_PER_DAY + 2_440_587.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_are_checked() {
        assert!(Date::parse("2026-02-30").unwrap_err().contains("February 2026 has 28 days"));
        assert!(Date::parse("2024-02-29").is_ok());
        assert!(Date::parse("2100-02-29").is_err());
        assert!(Date::parse("2026-13-01").unwrap_err().contains("month 13"));
        assert!(Date::parse("21-03-2026").is_err());
        assert!(Date::parse("2026-3-21").is_err());
    }

    #[test]
    fn days_round_trip_and_count_from_1970() {
        assert_eq!(Date::new(1970, 1, 1).unwrap().days_since_epoch(), 0);
        assert_eq!(Date::new(2000, 1, 1).unwrap().days_since_epoch(), 10_957);
        for days in [-800_000, -1, 0, 59, 10_957, 20_000, 1_500_000] {
            assert_eq!(Date::from_days_since_epoch(days).days_since_epoch(), days);
        }
        assert_eq!(Date::new(2024, 12, 31).unwrap().day_of_year(), 366);
        assert_eq!(Date::new(2026, 3, 21).unwrap().day_of_year(), 80);
    }

    #[test]
    fn times_are_checked() {
        assert_eq!(TimeOfDay::parse("13:30").unwrap().seconds(), 48_600.0);
        assert_eq!(TimeOfDay::parse("12:30:30").unwrap().seconds(), 45_030.0);
        assert_eq!(TimeOfDay::parse("24:00").unwrap().hours(), 24.0);
        assert!(TimeOfDay::parse("24:01").is_err());
        assert!(TimeOfDay::parse("25:00").is_err());
        // An hour count whose seconds overflow 32 bits does not wrap into the day.
        assert!(TimeOfDay::parse("4294967:00").unwrap_err().contains("outside 00:00-24:00"));
        assert!(TimeOfDay::parse("1193047:00").is_err());
        assert!(TimeOfDay::parse("12:60").is_err());
        assert!(TimeOfDay::parse("12").is_err());
        assert!(TimeOfDay::parse("-1:00").is_err());
        assert_eq!(TimeOfDay::parse("07:05:09").unwrap().to_string(), "07:05:09");
    }

    #[test]
    fn julian_day_of_the_spa_reference_instant() {
        // 2003-10-17 12:30:30 at UTC-7 (Reda & Andreas 2004).
        let t = LocalDateTime { date: Date::new(2003, 10, 17).unwrap(), time: TimeOfDay::parse("12:30:30").unwrap() };
        assert!((t.julian_day(-7.0) - 2_452_930.312_847).abs() < 1e-6);
    }
}
