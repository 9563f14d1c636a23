//! The annual panel: open a weather file (EPW), say what it means at the
//! site (as `annual` warns), take the sky from it, run
//! the year in the background, read sDA and ASE, colour the sensors by a
//! metric with its legend, and save the table as CSV.

use bevy::prelude::*;
use bevy_egui::egui::{self, Ui};

use crate::viewer::annual::{AnnualStudy, Metric, metric_colour, weather_notes};

/// Draws the panel; what happened (a file opened, a CSV written) goes to `note`.
pub fn annual_panel(
    ui: &mut Ui,
    study: &mut AnnualStudy,
    site: Option<&crate::site::Site>,
    path_text: &mut String,
    note: &mut Option<String>,
) {
    ui.heading("Annual (EPW weather)");
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(path_text).hint_text("weather file .epw").desired_width(190.0));
        if ui.button("Open").clicked() {
            *note = Some(match study.open(std::path::Path::new(path_text.trim())) {
                Ok(()) => format!("opened {}", path_text.trim()),
                Err(e) => e,
            });
        }
    });
    let Some(weather) = study.weather.as_ref().map(|(_, weather)| weather.clone()) else {
        ui.label("Open an EPW file (or start with view --weather FILE) for the year's sky and the annual study.");
        return;
    };
    let station = &weather.station;
    ui.label(format!("{} ({:.2}°, {:.2}°, UTC{:+})", station.name, station.latitude, station.longitude, station.timezone));
    let warning = egui::Color32::from_rgb(255, 210, 40);
    if site.is_some_and(|site| station.is_far_from(site)) {
        ui.colored_label(warning, "far from the scene's site: its sun is the site's, its weather the station's");
    }
    if let Some(site) = site
        && study.notes.as_ref().is_none_or(|(at, _)| at != site)
    {
        study.notes = Some((*site, weather_notes(site, &weather)));
    }
    for note in study.notes.iter().flat_map(|(_, notes)| notes) {
        ui.colored_label(warning, note);
    }
    ui.checkbox(&mut study.weather_sky, "Sky from the weather file (this hour's Perez sky)");
    match study.progress() {
        Some(done) => {
            ui.add(egui::ProgressBar::new(done).text("the year, hour by hour…"));
        }
        None => {
            if ui.button("Run the year (08:00-18:00 occupied)").clicked() {
                study.requested = true;
            }
        }
    }
    if let Some(Err(e)) = &study.result.values {
        ui.colored_label(egui::Color32::LIGHT_RED, e);
    }
    let Some(year) = study.year() else { return };
    ui.label(format!("sDA300/50%  {:.1}% of point sensors", year.sda()));
    ui.label(format!("ASE1000/250 {:.1}% of point sensors", year.ase()));
    ui.label(format!("{} occupied hours", year.occupied_hours));
    if ui.button("Save the table (CSV)").clicked() {
        *note = Some(crate::viewer::ui::sensors::write_export("heliodon-annual.csv", &year.csv()));
    }
    let tops = Metric::ALL.map(|m| m.top(year));
    let mut colour_by = study.colour_by;
    ui.label("Colour the sensors by");
    ui.horizontal_wrapped(|ui| {
        ui.selectable_value(&mut colour_by, None, "nothing");
        for metric in Metric::ALL {
            ui.selectable_value(&mut colour_by, Some(metric), metric.label());
        }
    });
    if let Some(metric) = colour_by {
        let k = Metric::ALL.iter().position(|m| *m == metric).expect("a metric");
        legend(ui, tops[k], metric.label());
    }
    study.colour_by = colour_by;
}

/// The metric's colour scale from 0 to `top`, labelled in its unit.
fn legend(ui: &mut Ui, top: f64, label: &str) {
    let (response, painter) = ui.allocate_painter(egui::vec2(ui.available_width().min(260.0), 34.0), egui::Sense::hover());
    let rect = response.rect;
    let steps = 48;
    for k in 0..steps {
        let [r, g, b] = metric_colour(k as f64 / (steps - 1) as f64);
        let x0 = rect.left() + rect.width() * k as f32 / steps as f32;
        let cell = egui::Rect::from_min_size(egui::pos2(x0, rect.top()), egui::vec2(rect.width() / steps as f32 + 1.0, 16.0));
        painter.rect_filled(cell, 0.0, egui::Color32::from(egui::Rgba::from_rgb(r, g, b)));
    }
    for k in 0..=4 {
        let x = rect.left() + rect.width() * k as f32 / 4.0;
        let align = match k {
            0 => egui::Align2::LEFT_BOTTOM,
            4 => egui::Align2::RIGHT_BOTTOM,
            _ => egui::Align2::CENTER_BOTTOM,
        };
        painter.text(
            egui::pos2(x, rect.bottom()),
            align,
            format!("{:.0}", top * k as f64 / 4.0),
            egui::FontId::proportional(11.0),
            ui.visuals().text_color(),
        );
    }
    ui.label(label);
}

/// The annual panel's system parameter: the study and the path being typed.
#[derive(bevy::ecs::system::SystemParam)]
pub struct AnnualPanel<'w, 's> {
    study: ResMut<'w, AnnualStudy>,
    path_text: Local<'s, String>,
}

impl AnnualPanel<'_, '_> {
    /// Draws the panel for the scene's `site`.
    pub fn show(&mut self, ui: &mut Ui, note: &mut Option<String>, site: Option<crate::site::Site>) {
        if self.path_text.is_empty()
            && let Some((path, _)) = &self.study.weather
        {
            *self.path_text = path.display().to_string();
        }
        annual_panel(ui, &mut self.study, site.as_ref(), &mut self.path_text, note);
    }

    /// The EPW hour the sky comes from, for the sun-and-sky panel.
    pub fn sky_hour(&self) -> Option<&str> {
        self.study.hour.as_deref()
    }
}
