//! The number widgets of every panel and the note they leave: a value typed
//! outside its range is clamped into it and [`Note`] says so (never a
//! panic, never a silent change). A leaf: it imports nothing of the viewer.

use std::fmt::Display;
use std::ops::RangeInclusive;

use bevy::prelude::*;
use bevy_egui::egui::emath::Numeric;
use bevy_egui::egui::{self, Ui};

/// The last clamped input, saved file or refused edit, shown under the sun
/// and sky until the next one.
#[derive(Resource, Debug, Clone, Default, PartialEq)]
pub struct Note(pub Option<String>);

/// Minutes as HH:MM (a sign in front when negative).
pub fn clock_text(minutes: i64) -> String {
    let sign = if minutes < 0 { "-" } else { "" };
    format!("{sign}{:02}:{:02}", minutes.abs() / 60, minutes.abs() % 60)
}

/// Minutes from HH:MM typed by hand; minutes past 59 or anything that is
/// not a clock time is refused (the field keeps its value).
pub fn parse_clock(text: &str) -> Option<i64> {
    let (h, m) = text.trim().split_once(':')?;
    let (h, m) = (h.trim(), m.trim().parse::<i64>().ok().filter(|m| (0..60).contains(m))?);
    let hours = h.trim_start_matches('-').parse::<i64>().ok()?;
    let minutes = hours * 60 + m;
    Some(if h.starts_with('-') { -minutes } else { minutes })
}

/// A number field: what is typed outside `range` is clamped into it, with a
/// note saying so (never a panic, never a silent change).
pub fn bounded<N: Numeric + Display>(
    ui: &mut Ui,
    value: &mut N,
    range: RangeInclusive<N>,
    speed: f64,
    prefix: &str,
    suffix: &str,
    note: &mut Option<String>,
) -> egui::Response {
    let response = ui.add(egui::DragValue::new(value).speed(speed).prefix(prefix).suffix(suffix));
    clamp_noted(value, range, prefix.trim_start(), suffix, note);
    response
}

/// A slider for browsing; a value typed into its box outside `range` is
/// clamped with a note, as in [`bounded`].
pub fn slider<N: Numeric + Display>(
    ui: &mut Ui,
    value: &mut N,
    range: RangeInclusive<N>,
    text: &str,
    note: &mut Option<String>,
) -> egui::Response {
    let response = ui.add(egui::Slider::new(value, range.clone()).text(text).clamping(egui::SliderClamping::Never));
    clamp_noted(value, range, &format!("{text} "), "", note);
    response
}

/// Clamps `value` into `range`; when it was outside, says so in `note`.
pub fn clamp_noted<N: Numeric + Display>(value: &mut N, range: RangeInclusive<N>, what: &str, suffix: &str, note: &mut Option<String>) {
    let (v, lo, hi) = (value.to_f64(), range.start().to_f64(), range.end().to_f64());
    if (lo..=hi).contains(&v) {
        return;
    }
    let clamped = if v.is_nan() || v < lo { *range.start() } else { *range.end() };
    *note = Some(format!("{what}{value}{suffix} is outside {}..{}: {clamped} is used", range.start(), range.end()));
    *value = clamped;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_values_out_of_range_are_clamped_with_a_note() {
        let ctx = egui::Context::default();
        let (mut latitude, mut ok, mut note) = (123.0, 42.0, None);
        let mut output = ctx.run_ui(egui::RawInput::default(), |ui| {
            bounded(ui, &mut ok, -90.0..=90.0, 0.1, "lat ", "", &mut note);
            assert!(note.is_none());
            bounded(ui, &mut latitude, -90.0..=90.0, 0.1, "lat ", "", &mut note);
        });
        // Nothing draws the frame here: its font textures are dropped on purpose.
        output.textures_delta.clear();
        assert_eq!((ok, latitude), (42.0, 90.0));
        assert_eq!(note.as_deref(), Some("lat 123 is outside -90..90: 90 is used"));
        // Whole numbers and the boxes of sliders likewise.
        let (mut month, mut ev, mut month_note, mut ev_note) = (13u32, 30.0f32, None, None);
        let mut output = ctx.run_ui(egui::RawInput::default(), |ui| {
            bounded(ui, &mut month, 1..=12, 0.05, "month ", "", &mut month_note);
            slider(ui, &mut ev, -5.0..=20.0, "EV", &mut ev_note);
        });
        output.textures_delta.clear();
        assert_eq!((month, ev), (12, 20.0));
        assert_eq!(month_note.as_deref(), Some("month 13 is outside 1..12: 12 is used"));
        assert_eq!(ev_note.as_deref(), Some("EV 30 is outside -5..20: 20 is used"));
        // Clock times typed by hand.
        assert_eq!(parse_clock("09:30"), Some(570));
        assert_eq!(parse_clock("25:30"), Some(1530));
        assert_eq!(parse_clock("-0:30"), Some(-30));
        assert_eq!((parse_clock("10:75"), parse_clock("noon")), (None, None));
        assert_eq!(clock_text(-30), "-00:30");
    }
}
