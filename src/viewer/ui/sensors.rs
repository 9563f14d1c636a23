//! The sensors panel: the live table room by room, the selected sensor's day and year
//! (egui_plot: axes with units, hover values, legend, the year's colour
//! scale), and CSV export of the table and the day.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::egui::{self, Ui};
use egui_plot::{Heatmap, Legend, Line, Plot, PlotPoint, PlotPoints, Points, VLine};

use crate::day::{DAY_STEPS, YEAR_DAYS};
use crate::ecs::{ActiveScene, LightingState};
use crate::light::SensorReading;
use crate::report::csv_field;
use crate::time::LocalDateTime;
use crate::viewer::sensors::{DaySeries, SelectedSensor, YearMap};

/// What the sensors panel reads and writes.
#[derive(SystemParam)]
pub struct SensorPanel<'w> {
    lighting: Option<Res<'w, LightingState>>,
    selected: ResMut<'w, SelectedSensor>,
    series: Res<'w, DaySeries>,
    year: ResMut<'w, YearMap>,
    /// The open scene (the camera panel lists its viewpoints).
    pub active: Res<'w, ActiveScene>,
}

impl SensorPanel<'_> {
    /// Draws the panel at local time `now`; exports say where they went in `note`.
    pub fn show(&mut self, ui: &mut Ui, note: &mut Option<String>, now: LocalDateTime) {
        sensor_panel(ui, note, self, now);
    }
}

/// The live sensor table, the selected sensor's day, CSV export.
fn sensor_panel(ui: &mut Ui, note: &mut Option<String>, sensors: &mut SensorPanel, now: LocalDateTime) {
    ui.heading("Sensors (lux)");
    let Some(lighting) = sensors.lighting.as_ref().and_then(|l| l.lighting.as_ref()) else { return };
    let readings = &lighting.sensors;
    if let Some(selected) = sensors.selected.0.and_then(|i| readings.get(i)) {
        ui.label(format!("{}: {:.0} lx over {} (every half hour)", selected.name, selected.total, now.date));
        match &sensors.series.0.values {
            Some(values) => day_plot(ui, values, now.time.hours()),
            None => {
                ui.add(egui::Spinner::new());
            }
        }
        match (&sensors.year.map.values, sensors.year.progress()) {
            (_, Some(done)) => {
                ui.add(egui::ProgressBar::new(done).text("the year, every two weeks…"));
            }
            (Some(values), None) => year_map(ui, values, now.date.day_of_year(), now.time.hours()),
            (None, None) => {
                if ui.button("Compute the year (day × time)").clicked() {
                    sensors.year.requested = true;
                }
            }
        }
    } else {
        ui.label("Click a sensor (in the view or the table) for its day.");
    }
    ui.horizontal(|ui| {
        if ui.button("Export table (CSV)").clicked() {
            let mut csv = String::from("name,illuminance_lux,direct_sun_lux,direct_sky_lux,indirect_lux\n");
            for r in readings {
                csv.push_str(&format!("{},{:.1},{:.1},{:.1},{:.1}\n", csv_field(&r.name), r.total, r.direct_sun, r.direct_sky, r.indirect));
            }
            *note = Some(write_export("heliodon-sensors.csv", &csv));
        }
        if let (Some(values), Some(i)) = (&sensors.series.0.values, sensors.selected.0)
            && ui.button("Export day (CSV)").clicked()
        {
            let mut csv = String::from("time,illuminance_lux\n");
            for (k, v) in values.iter().enumerate() {
                let minutes = ((k as f64 + 0.5) * 24.0 * 60.0 / DAY_STEPS as f64).round() as i64;
                csv.push_str(&format!("{:02}:{:02},{v:.1}\n", minutes / 60, minutes % 60));
            }
            *note = Some(write_export(&format!("heliodon-day-{}.csv", readings[i].name.replace('/', "-")), &csv));
        }
    });
    // A grid's or a room's sensors (`<room>/<k>`) under one header with
    // their mean, least and most: a building's thousands of sensors read
    // room by room, and a closed room draws none of its rows. Sensors of
    // no room, one after another, make one table.
    let mut rows = 0..0;
    while rows.end < readings.len() {
        rows = rows.end..rows.end + 1;
        let room = room_of(&readings[rows.start]);
        while readings.get(rows.end).is_some_and(|r| room_of(r) == room) {
            rows.end += 1;
        }
        match room {
            Some(room) => {
                let totals = readings[rows.clone()].iter().map(|r| r.total);
                let mean = totals.clone().sum::<f64>() / rows.len() as f64;
                let (least, most) = totals.fold((f64::INFINITY, 0.0f64), |(lo, hi), t| (lo.min(t), hi.max(t)));
                let title = format!("{room}: {} sensors, mean {mean:.0} lx, {least:.0}–{most:.0}", rows.len());
                egui::CollapsingHeader::new(title)
                    .id_salt(("sensor room", rows.start))
                    .default_open(readings.len() <= ROWS_OPEN)
                    .show(ui, |ui| sensor_rows(ui, readings, rows.clone(), &mut sensors.selected.0));
            }
            None => sensor_rows(ui, readings, rows.clone(), &mut sensors.selected.0),
        }
    }
}

/// The room of a grid's or room's sensor (`<room>/<k>`).
fn room_of(reading: &SensorReading) -> Option<&str> {
    reading.name.split_once('/').map(|(room, _)| room)
}

/// A scene with more sensors than this shows its rooms' headers closed.
const ROWS_OPEN: usize = 100;

/// The table's rows `rows` of `readings`: name (click to select), total,
/// sun, sky and indirect lux.
fn sensor_rows(ui: &mut Ui, readings: &[SensorReading], rows: std::ops::Range<usize>, selected: &mut Option<usize>) {
    egui::Grid::new(("sensors", rows.start)).striped(true).num_columns(5).show(ui, |ui| {
        for title in ["sensor", "total", "sun", "sky", "indirect"] {
            ui.strong(title);
        }
        ui.end_row();
        for (i, r) in readings.iter().enumerate().take(rows.end).skip(rows.start) {
            if ui.selectable_label(*selected == Some(i), &r.name).clicked() {
                *selected = Some(i);
            }
            for value in [r.total, r.direct_sun, r.direct_sky, r.indirect] {
                ui.monospace(format!("{value:8.0}"));
            }
            ui.end_row();
        }
    });
}

/// Illuminance over the day, every half hour, with the current time marked
/// (hover for values).
fn day_plot(ui: &mut Ui, values: &[f64], now: f64) {
    let points: Vec<[f64; 2]> = values.iter().enumerate().map(|(k, &v)| [(k as f64 + 0.5) * 24.0 / values.len() as f64, v]).collect();
    Plot::new("day_plot")
        .height(140.0)
        .x_axis_label("local standard time (h)")
        .y_axis_label("illuminance (lx)")
        .include_x(0.0)
        .include_x(24.0)
        .include_y(0.0)
        .allow_scroll(false)
        .legend(Legend::default())
        .show(ui, |plot| {
            plot.line(Line::new("total", PlotPoints::from(points)).color(egui::Color32::from_rgb(120, 200, 255)));
            plot.vline(VLine::new("now", now).color(egui::Color32::from_rgb(255, 210, 40)));
        });
}

/// The year as a heat map: day of the year across (every two weeks), local
/// time up (every half hour), each cell in false colour to the year's peak,
/// with the colour scale beside it and now marked (hover for values).
fn year_map(ui: &mut Ui, values: &[Vec<f64>], day: u32, now: f64) {
    let peak = values.iter().flatten().copied().fold(10.0f64, f64::max);
    // Rows are times of day (bottom up), columns days.
    let cells: Vec<f64> = (0..DAY_STEPS).flat_map(|t| values.iter().map(move |d| d.get(t).copied().unwrap_or(0.0))).collect();
    let colour = move |lux: f64| {
        let [r, g, b] = if lux > 0.0 { crate::render::false_colour(lux as f32, peak as f32) } else { [0.05; 3] };
        egui::Color32::from(egui::Rgba::from_rgb(r, g, b))
    };
    let map = Heatmap::new(cells, YEAR_DAYS)
        .at(PlotPoint::new(1.0, 0.0))
        .tile_size(14.0, 24.0 / DAY_STEPS as f32)
        .custom_mapping(Box::new(colour))
        .show_labels(false)
        .name("illuminance (lx)");
    Plot::new("year_map").height(150.0).x_axis_label("day of year").y_axis_label("local standard time (h)").allow_scroll(false).show(
        ui,
        |plot| {
            plot.heatmap(map);
            plot.points(Points::new("now", vec![[f64::from(day), now]]).radius(4.0).color(egui::Color32::WHITE));
        },
    );
    crate::viewer::ui::view::false_colour_legend(ui, peak as f32);
}

/// Writes an export into the working folder; what to tell the user.
pub(super) fn write_export(name: &str, text: &str) -> String {
    match std::fs::write(name, text) {
        Ok(()) => format!("wrote {}", std::env::current_dir().map(|d| d.join(name).display().to_string()).unwrap_or(name.into())),
        Err(e) => format!("cannot write {name}: {e}"),
    }
}
