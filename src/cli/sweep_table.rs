//! A sweep's table: its rows (one per combination and sensor), how a
//! combination scores and which is best. The sweep command prints, merges
//! and reads it back; the plot draws it.

/// The row of the scene's sDA300/50% in a sweep against a year.
pub const SDA_ROW: &str = "sDA300/50%";

/// A sweep's rows: one per combination and sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The varied keys.
    pub keys: Vec<String>,
    /// What the values are: `lux` or `%`.
    pub unit: String,
    pub rows: Vec<Row>,
}

/// One combination at one sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub values: Vec<f64>,
    pub sensor: String,
    /// The value, or why the combination does not build.
    pub value: Result<f64, String>,
}

/// A key value as the tables print it.
pub fn key_value(v: f64) -> String {
    format!("{v}")
}

/// Each combination's score: one sensor's value (lux, or its DA300 over a
/// year); for several, the scene's sDA over a year, else their mean;
/// `None` when it does not build.
pub fn scores(table: &Table) -> Vec<(Vec<f64>, Option<f64>)> {
    let mut out: Vec<(Vec<f64>, Option<f64>)> = Vec::new();
    for rows in table.rows.chunk_by(|a, b| a.values == b.values) {
        let sensors: Vec<f64> = rows.iter().filter(|r| r.sensor != SDA_ROW).filter_map(|r| r.value.clone().ok()).collect();
        let sda = rows.iter().find(|r| r.sensor == SDA_ROW).and_then(|r| r.value.clone().ok());
        let built = rows.iter().all(|r| r.value.is_ok()) && !sensors.is_empty();
        // One sensor is judged by itself, over a year too (its DA300); several by the sDA.
        let score = match (sensors.len(), sda) {
            (1, _) | (_, None) => sensors.iter().sum::<f64>() / sensors.len() as f64,
            (_, Some(sda)) => sda,
        };
        out.push((rows[0].values.clone(), built.then_some(score)));
    }
    out
}

/// The best combination (the largest score, see [`scores`]) and its score.
pub fn best(table: &Table) -> Option<(Vec<f64>, f64)> {
    scores(table)
        .into_iter()
        .filter_map(|(values, score)| Some((values, score?)))
        .fold(None, |best: Option<(Vec<f64>, f64)>, c| if best.as_ref().is_none_or(|b| c.1 > b.1) { Some(c) } else { best })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Over a year one sensor is judged by its DA300, several by the sDA.
    #[test]
    fn a_year_is_judged_at_the_one_sensor_asked_or_by_the_sda() {
        let row = |x: f64, sensor: &str, value: f64| Row { values: vec![x], sensor: sensor.into(), value: Ok(value) };
        let one = |rows: Vec<Row>| Table { keys: vec!["a".into()], unit: "%".into(), rows };
        // The sensor is best at a = 1, the scene's sDA at a = 2.
        let at_one_sensor = one(vec![row(1.0, "back", 60.0), row(1.0, SDA_ROW, 40.0), row(2.0, "back", 50.0), row(2.0, SDA_ROW, 45.0)]);
        assert_eq!(best(&at_one_sensor), Some((vec![1.0], 60.0)));
        let at_two = one(vec![
            row(1.0, "back", 60.0),
            row(1.0, "desk", 90.0),
            row(1.0, SDA_ROW, 40.0),
            row(2.0, "back", 50.0),
            row(2.0, "desk", 90.0),
            row(2.0, SDA_ROW, 45.0),
        ]);
        assert_eq!(best(&at_two), Some((vec![2.0], 45.0)));
    }
}
