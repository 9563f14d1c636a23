//! A sensor's light over a day and over a year (the thesis' figure 1.4h):
//! solves at every half hour, each warm-started from the one before.

use std::sync::Arc;

use crate::light::LightModel;
use crate::site::Site;
use crate::sky::{SkySpec, sky_at};
use crate::time::{Date, LocalDateTime, TimeOfDay};

/// Half-hour steps of a day series.
pub const DAY_STEPS: usize = 48;

/// Days of a year map: every two weeks from 1 January.
pub const YEAR_DAYS: usize = 26;

/// A sensor's total lux every half hour of a day, from 00:15. Hours whose
/// sky cannot be made (the sun too low for a sky that needs it) read 0.
pub fn day_series(model: &Arc<LightModel>, sensor: usize, site: &Site, date: Date, spec: &SkySpec) -> Vec<f64> {
    let mut previous = None;
    (0..DAY_STEPS)
        .map(|k| {
            let time = TimeOfDay::from_hours((k as f64 + 0.5) * 24.0 / DAY_STEPS as f64).expect("a time of day");
            let Ok(sky) = sky_at(site, spec, &LocalDateTime { date, time }).1 else { return 0.0 };
            let lighting = model.solve(&sky, previous.as_ref());
            let value = lighting.sensors.get(sensor).map_or(0.0, |r| r.total);
            previous = Some(lighting);
            value
        })
        .collect()
}

/// The dates of a year map of `year`: [`YEAR_DAYS`] days, two weeks apart.
pub fn year_map_dates(year: i32) -> impl Iterator<Item = Date> {
    (0..YEAR_DAYS).map(move |k| Date::new(year, 1, 1).expect("1 January").add_days(14 * k as i64))
}
