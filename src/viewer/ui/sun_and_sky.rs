//! The sun and sky panel: date (day-of-year slider, exact date, equinoxes
//! and solstices), time (slider, exact HH:MM, play the day), site and north
//! with a sun-path diagram, sky type and its parameters, exposure, and the
//! note of the last clamped value.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy::window::RequestRedraw;
use bevy_egui::egui::{self, Ui};

use crate::ecs::{ActiveScene, Site, SkyChoice, SkyRejected, SolarTime, SunSky};
use crate::render::RenderSettings;
use crate::sky::{SkySpec, perez};
use crate::sun::solar_position;
use crate::time::{Date, LocalDateTime, TimeOfDay, days_in_month};
use crate::viewer::widgets::{bounded, clock_text, parse_clock, slider};

/// The day plays: hours of solar time per second, while playing.
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq)]
pub struct PlayDay(pub Option<f64>);

/// What the sun and sky panel reads and writes. Resources are written only
/// when a value changes: writing marks them changed, and a changed time or
/// sky starts a relight.
#[derive(SystemParam)]
pub struct SunAndSkyPanel<'w, 's> {
    solar: ResMut<'w, SolarTime>,
    sky: ResMut<'w, SkyChoice>,
    site: Option<ResMut<'w, Site>>,
    sun_sky: Option<Res<'w, SunSky>>,
    active: Res<'w, ActiveScene>,
    play: ResMut<'w, PlayDay>,
    /// Skies that could not be made (the light shown is the last sky's).
    rejected: MessageReader<'w, 's, SkyRejected>,
}

/// Moves the clock while the day plays (and asks for the next frame).
pub fn play_the_day(time: Res<Time>, play: Res<PlayDay>, mut solar: ResMut<SolarTime>, mut redraw: MessageWriter<RequestRedraw>) {
    let Some(speed) = play.0 else { return };
    redraw.write(RequestRedraw);
    let mut hours = solar.0.time.hours() + speed * f64::from(time.delta_secs());
    let mut date = solar.0.date;
    if hours >= 24.0 {
        hours -= 24.0;
        date = date.add_days(1);
    }
    if let Ok(time) = TimeOfDay::from_hours(hours) {
        solar.0 = LocalDateTime { date, time };
    }
}

/// The quick dates: equinoxes and solstices.
const QUICK_DATES: [(&str, u32, u32); 4] = [("Mar 21", 3, 21), ("Jun 21", 6, 21), ("Sep 23", 9, 23), ("Dec 21", 12, 21)];

impl SunAndSkyPanel<'_, '_> {
    /// The designer's live turn of north (degrees), for the windows panel's compass.
    pub fn north_turn(&self) -> f64 {
        self.site.as_ref().map_or(0.0, |s| s.north_turn)
    }

    /// The site, once a scene has one.
    pub fn site(&self) -> Option<crate::site::Site> {
        self.site.as_ref().map(|s| s.0)
    }

    /// The local date and time shown.
    pub fn now(&self) -> LocalDateTime {
        self.solar.0
    }

    /// Draws the panel; `settings` for the exposure, `note` for what was clamped.
    pub fn show(&mut self, ui: &mut Ui, settings: &mut ResMut<RenderSettings>, note: &mut Option<String>) {
        for rejected in self.rejected.read() {
            *note = Some(format!("{}; the light shown is the last sky's", rejected.message));
        }
        let scene = self.active.scene.clone();
        sun_and_sky_panel(
            ui,
            note,
            &mut self.play,
            &mut self.solar,
            &mut self.sky,
            settings,
            self.site.as_mut(),
            self.sun_sky.as_deref(),
            scene.as_deref(),
        );
    }
}

#[allow(clippy::too_many_arguments)]
fn sun_and_sky_panel(
    ui: &mut Ui,
    note: &mut Option<String>,
    play: &mut PlayDay,
    solar: &mut ResMut<SolarTime>,
    sky: &mut ResMut<SkyChoice>,
    settings: &mut ResMut<RenderSettings>,
    site: Option<&mut ResMut<Site>>,
    sun_sky: Option<&SunSky>,
    scene: Option<&crate::scene::Scene>,
) {
    ui.heading("Sun and sky");
    let LocalDateTime { mut date, time } = solar.0;
    // Day of the year as a slider for browsing, the date as spinners for exact input.
    let days = if days_in_month(date.year, 2) == 29 { 366 } else { 365 };
    let mut day = date.day_of_year();
    ui.label(format!("Date: {date}"));
    if slider(ui, &mut day, 1..=days, "day of year", note).changed() {
        date = Date::new(date.year, 1, 1).expect("1 January").add_days(i64::from(day) - 1);
    }
    ui.horizontal(|ui| {
        let mut year = date.year;
        let mut month = date.month;
        let mut day = date.day;
        let y = bounded(ui, &mut year, 1900..=2100, 0.1, "year ", "", note).changed();
        let m = bounded(ui, &mut month, 1..=12, 0.05, "month ", "", note).changed();
        let d = bounded(ui, &mut day, 1..=31, 0.05, "day ", "", note).changed();
        if y || m || d {
            let last = days_in_month(year, month);
            if day > last {
                *note = Some(format!("day {day} clamped to {last}: {year}-{month:02} has {last} days"));
                day = last;
            }
            if let Ok(new) = Date::new(year, month, day) {
                date = new;
            }
        }
    });
    ui.horizontal(|ui| {
        for (label, month, day) in QUICK_DATES {
            if ui.button(label).clicked() {
                date = Date::new(date.year, month, day).expect("quick date");
            }
        }
    });
    let mut minutes = (time.hours() * 60.0).round() as i64;
    let clock = |m: f64, _: std::ops::RangeInclusive<usize>| clock_text(m as i64);
    ui.add(egui::Slider::new(&mut minutes, 0..=1439).text("time").custom_formatter(clock).clamping(egui::SliderClamping::Never));
    ui.horizontal(|ui| {
        ui.label("exact");
        ui.add(egui::DragValue::new(&mut minutes).custom_formatter(clock).custom_parser(|text| parse_clock(text).map(|m| m as f64)));
        let label = if play.0.is_some() { "Pause" } else { "Play the day" };
        if ui.button(label).clicked() {
            play.0 = if play.0.is_some() { None } else { Some(0.5) };
        }
    });
    if !(0..=1439).contains(&minutes) {
        let clamped = minutes.clamp(0, 1439);
        *note = Some(format!("time {} is outside 00:00..23:59: {} is used", clock_text(minutes), clock_text(clamped)));
        minutes = clamped;
    }
    let time = TimeOfDay::from_hours(minutes as f64 / 60.0).unwrap_or(time);
    let new = LocalDateTime { date, time };
    if new != solar.0 {
        solar.0 = new;
    }
    if let Some(sun_sky) = sun_sky {
        ui.label(format!("Sun: altitude {:.1}°, azimuth {:.1}°", sun_sky.sun.altitude, sun_sky.sun.azimuth));
        if let Some(refused) = &sun_sky.sky.refused {
            ui.colored_label(egui::Color32::from_rgb(230, 160, 60), refused.as_str());
        }
    }
    ui.separator();
    if let Some(site) = site {
        ui.label("Site");
        let mut s = site.0;
        ui.horizontal(|ui| {
            bounded(ui, &mut s.latitude, -90.0..=90.0, 0.1, "lat ", "", note);
            bounded(ui, &mut s.longitude, -180.0..=180.0, 0.1, "lon ", "", note);
        });
        // North as the designer sees it: from the model's own default north,
        // the scene file's turn included.
        let from_file = scene.map_or(0.0, |scene| scene.frame.north_angle());
        ui.horizontal(|ui| {
            bounded(ui, &mut s.timezone, -14.0..=14.0, 0.25, "UTC ", "", note);
            let mut north = from_file + s.north_turn;
            bounded(ui, &mut north, -360.0..=360.0, 0.5, "north ", "°", note)
                .on_hover_text("true north, clockwise from the model's north axis");
            if north != from_file + s.north_turn {
                s.north_turn = north - from_file;
            }
        });
        if s != site.0 {
            site.0 = s;
        }
        sun_path(ui, &site.0, solar.0);
    }
    ui.separator();
    sky_controls(ui, sky, note);
    ui.separator();
    let mut auto = settings.exposure.is_none();
    let mut ev = settings.exposure.unwrap_or(10.0);
    ui.horizontal(|ui| {
        ui.checkbox(&mut auto, "auto exposure");
        ui.add_enabled_ui(!auto, |ui| slider(ui, &mut ev, -5.0..=20.0, "EV", note));
    });
    let exposure = if auto { None } else { Some(ev) };
    if exposure != settings.exposure {
        settings.exposure = exposure;
    }
    if let Some(note) = note {
        ui.colored_label(egui::Color32::from_rgb(230, 160, 60), note.as_str());
    }
}

/// A map-free sun-path diagram: today's arc (altitude against azimuth, the
/// horizon at the bottom) and the sun now.
fn sun_path(ui: &mut Ui, site: &crate::site::Site, now: LocalDateTime) {
    let (response, painter) = ui.allocate_painter(egui::vec2(ui.available_width().min(250.0), 110.0), egui::Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 4.0, egui::Color32::from_gray(28));
    let to_screen = |azimuth: f64, altitude: f64| {
        egui::pos2(rect.left() + (azimuth / 360.0) as f32 * rect.width(), rect.bottom() - (altitude.max(0.0) / 90.0) as f32 * rect.height())
    };
    for (label, azimuth) in [("E", 90.0), ("S", 180.0), ("W", 270.0)] {
        painter.text(
            to_screen(azimuth, 0.0) + egui::vec2(0.0, -2.0),
            egui::Align2::CENTER_BOTTOM,
            label,
            egui::FontId::proportional(10.0),
            egui::Color32::GRAY,
        );
    }
    let arc: Vec<egui::Pos2> = (0..=96)
        .filter_map(|k| {
            let time = TimeOfDay::from_hours(f64::from(k) / 4.0).ok()?;
            let p = solar_position(site, &LocalDateTime { date: now.date, time });
            (p.altitude > 0.0).then(|| to_screen(p.azimuth, p.altitude))
        })
        .collect();
    painter.add(egui::Shape::line(arc, egui::Stroke::new(1.5, egui::Color32::from_rgb(200, 170, 60))));
    let sun = solar_position(site, &now);
    if sun.altitude > 0.0 {
        painter.circle_filled(to_screen(sun.azimuth, sun.altitude), 5.0, egui::Color32::from_rgb(255, 210, 40));
    }
}

/// The sky type and its parameters.
fn sky_controls(ui: &mut Ui, sky: &mut ResMut<SkyChoice>, note: &mut Option<String>) {
    let names = ["clear", "turbid", "intermediate", "overcast", "uniform", "perez", "cie"];
    let current = match &sky.0 {
        SkySpec::Clear { turbidity } if *turbidity > 4.0 => "turbid",
        SkySpec::Clear { .. } => "clear",
        SkySpec::Intermediate { .. } => "intermediate",
        SkySpec::Overcast => "overcast",
        SkySpec::Uniform => "uniform",
        SkySpec::Perez(_) => "perez",
        SkySpec::Cie { .. } => "cie",
    };
    let mut chosen = current;
    egui::ComboBox::from_label("sky").selected_text(current).show_ui(ui, |ui| {
        for name in names {
            ui.selectable_value(&mut chosen, name, name);
        }
    });
    let mut spec = sky.0.clone();
    if chosen != current {
        spec = match chosen {
            "clear" => SkySpec::Clear { turbidity: crate::sky::DEFAULT_TURBIDITY },
            "turbid" => SkySpec::Clear { turbidity: 5.0 },
            "intermediate" => SkySpec::Intermediate { turbidity: crate::sky::DEFAULT_TURBIDITY },
            "overcast" => SkySpec::Overcast,
            "uniform" => SkySpec::Uniform,
            "perez" => SkySpec::Perez(perez::Input::Irradiance { direct_normal: 600.0, diffuse_horizontal: 120.0 }),
            _ => SkySpec::Cie { standard_type: 12, diffuse_illuminance: 15_000.0, direct_illuminance: 60_000.0 },
        };
    }
    match &mut spec {
        SkySpec::Clear { turbidity } | SkySpec::Intermediate { turbidity } => {
            slider(ui, turbidity, 1.0..=10.0, "turbidity", note);
        }
        SkySpec::Perez(perez::Input::Irradiance { direct_normal, diffuse_horizontal }) => {
            bounded(ui, direct_normal, 0.0..=1100.0, 1.0, "DNI ", " W/m²", note);
            // 0 with DNI 0 is a dark hour (a weather file's night): a sky, not a value to clamp.
            bounded(ui, diffuse_horizontal, 0.0..=600.0, 1.0, "DHI ", " W/m²", note);
        }
        SkySpec::Cie { standard_type, diffuse_illuminance, direct_illuminance } => {
            slider(ui, standard_type, 1..=15, "CIE type", note);
            bounded(ui, diffuse_illuminance, 100.0..=60_000.0, 50.0, "diffuse ", " lx", note);
            bounded(ui, direct_illuminance, 0.0..=120_000.0, 100.0, "direct ", " lx", note);
        }
        _ => {}
    }
    if spec != sky.0 {
        sky.0 = spec;
    }
}
