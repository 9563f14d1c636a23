//! [`DesignerUiPlugin`]: the designer's panels (bevy_egui). Left: the sun
//! and sky (date, time, play, site and north with a sun-path diagram, sky
//! type and parameters, exposure), then the windows and materials
//! ([`super::materials`]). Right: the camera (presets, viewpoints, walk
//! mode), the view (modes, the light's progress, saving the image) and the
//! sensors (live table, the selected one's day and year, CSV export). The 3D
//! view fills the space between them: the camera's viewport follows the
//! panels, and the pointer over a panel belongs to the panel.

use bevy::camera::visibility::RenderLayers;
use bevy::diagnostic::{DiagnosticsStore, FrameTimeDiagnosticsPlugin};
use bevy::camera::{CameraOutputMode, Viewport};
use bevy::prelude::*;
use bevy::render::render_resource::BlendState;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, LayerId, Ui, UiBuilder};
use bevy_egui::{EguiContexts, EguiGlobalSettings, EguiPlugin, EguiPrimaryContextPass, PrimaryEguiContext};

use bevy::ecs::system::SystemParam;
use bevy_egui::egui::emath::Numeric;
use std::fmt::Display;
use std::ops::RangeInclusive;
use std::path::PathBuf;

use super::camera::CadCamera;
use super::sensors::{DAY_STEPS, DaySeries, SelectedSensor, YEAR_DAYS, YearMap};
use super::capture::{SaveResults, SaveView};
use super::materials::{MaterialEdits, MaterialPanel, material_panel};
use crate::ecs::{ActiveScene, LightEngine, LightingState, Site, SkyChoice, SolarTime, SunSky};
use crate::scene::Viewpoint;
use crate::render::{RenderMode, RenderSettings};
use crate::sky::perez;
use crate::sky::SkySpec;
use crate::sun::solar_position;
use crate::time::{Date, LocalDateTime, TimeOfDay, days_in_month};

pub struct DesignerUiPlugin;

impl Plugin for DesignerUiPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<FrameTimeDiagnosticsPlugin>() {
            app.add_plugins(FrameTimeDiagnosticsPlugin::default());
        }
        app.add_plugins(EguiPlugin::default())
            .init_resource::<UiState>()
            .init_resource::<SelectedSensor>()
            .init_resource::<DaySeries>()
            .init_resource::<YearMap>()
            .add_systems(Startup, spawn_ui_camera)
            .add_systems(EguiPrimaryContextPass, (panels, super::sensors::draw_markers).chain())
            .add_systems(
                Update,
                (
                    play_the_day,
                    apply_camera_request,
                    save_image,
                    note_saves.run_if(resource_changed::<SaveResults>),
                    super::sensors::pick_sensor,
                    super::sensors::update_day_series,
                    super::sensors::update_year_map,
                ),
            );
    }
}

/// What the panels keep between frames, and what they ask of the app.
#[derive(Resource, Debug, Clone, Default)]
pub struct UiState {
    /// The day plays: hours of solar time per second.
    pub playing: Option<f64>,
    /// Whether the pointer is over a panel (the camera then ignores it), as
    /// egui saw it at `pointer_checked_at`; see [`UiState::over_panels`].
    pub pointer_over_panels: bool,
    pub pointer_checked_at: Option<Vec2>,
    /// A panel field has the keyboard (keys typed are not for the camera).
    pub keyboard_for_panels: bool,
    /// Last clamped input or saved file, shown until the next one.
    pub note: Option<String>,
    /// Views the user saved this session.
    pub saved_views: Vec<Viewpoint>,
    /// Walk mode: W/A/S/D move the eye at its height, dragging looks around.
    pub walk: bool,
    /// A camera change asked for by the panel, applied by [`apply_camera_request`].
    pub camera_request: Option<CameraRequest>,
    /// Save the window as a PNG, or the view's luminance as an HDR (in the
    /// working folder).
    pub save_image: Option<ImageFormat>,
    /// What the materials panel is editing.
    pub materials: MaterialEdits,
}

impl UiState {
    /// Whether the pointer at `cursor` is over a panel. egui's answer is a
    /// frame old: it counts only where the pointer has not moved since (a
    /// pointer that jumped into the view and clicked in one frame is in the
    /// view; the side panels are outside the view's viewport anyway).
    pub fn over_panels(&self, cursor: Vec2) -> bool {
        self.pointer_over_panels && self.pointer_checked_at.is_some_and(|p| p.distance(cursor) < 0.5)
    }
}

/// The files the view can be saved as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Hdr,
}

impl ImageFormat {
    fn extension(self) -> &'static str {
        match self {
            ImageFormat::Png => "png",
            ImageFormat::Hdr => "hdr",
        }
    }
}

/// The camera changes the panel offers.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraRequest {
    /// Straight down on the model.
    Top,
    /// From the south, level.
    Front,
    /// From the east, level.
    Side,
    /// From the south-west and above.
    Perspective,
    Viewpoint(Viewpoint),
    /// Keep the current view in the list.
    Save,
}

/// The panels are drawn by a camera of their own over the whole window.
fn spawn_ui_camera(mut commands: Commands, mut settings: ResMut<EguiGlobalSettings>) {
    settings.auto_create_primary_context = false;
    commands.spawn((
        PrimaryEguiContext,
        Camera2d,
        RenderLayers::none(),
        Camera {
            order: 10,
            output_mode: CameraOutputMode::Write { blend_state: Some(BlendState::ALPHA_BLENDING), clear_color: ClearColorConfig::None },
            clear_color: ClearColorConfig::Custom(Color::NONE),
            ..default()
        },
    ));
}

fn play_the_day(time: Res<Time>, ui: Res<UiState>, mut solar: ResMut<SolarTime>) {
    let Some(speed) = ui.playing else { return };
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

/// What the sensors part of the panel reads and writes.
#[derive(SystemParam)]
pub struct SensorPanel<'w> {
    lighting: Option<Res<'w, LightingState>>,
    engine: Option<Res<'w, LightEngine>>,
    selected: ResMut<'w, SelectedSensor>,
    series: Res<'w, DaySeries>,
    year: ResMut<'w, YearMap>,
    active: Res<'w, ActiveScene>,
}

#[allow(clippy::too_many_arguments)]
fn panels(
    mut contexts: EguiContexts,
    mut ui_state: ResMut<UiState>,
    mut solar: ResMut<SolarTime>,
    mut sky: ResMut<SkyChoice>,
    mut settings: ResMut<RenderSettings>,
    site: Option<ResMut<Site>>,
    sun_sky: Option<Res<SunSky>>,
    mut sensors: SensorPanel,
    mut materials: MaterialPanel,
    window: Single<&Window, With<PrimaryWindow>>,
    mut cameras: Query<&mut Camera, crate::render::PictureCamera>,
    diagnostics: Res<DiagnosticsStore>,
) -> Result {
    // Frame time, smoothed and the worst of the recent history (ms).
    let frame_time = diagnostics.get(&FrameTimeDiagnosticsPlugin::FRAME_TIME).and_then(|d| Some((d.smoothed()?, d.values().copied().fold(0.0, f64::max))));
    let ctx = contexts.ctx_mut()?.clone();
    let mut root = Ui::new(ctx.clone(), "viewport".into(), UiBuilder::new().layer_id(LayerId::background()).max_rect(ctx.viewport_rect()));
    let left = egui::Panel::left("sun_and_sky")
        .default_size(270.0)
        .show(&mut root, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                let north_turn = site.as_ref().map_or(0.0, |s| s.north_turn);
                sun_and_sky_panel(ui, &mut ui_state, &mut solar, &mut sky, &mut settings, site, sun_sky.as_deref(), sensors.active.scene.as_deref());
                ui.separator();
                if let Some(scene) = &sensors.active.scene {
                    let UiState { materials: edits, note, .. } = &mut *ui_state;
                    material_panel(ui, edits, note, scene, north_turn, &mut materials);
                }
            });
        })
        .response
        .rect
        .width();
    let right = egui::Panel::right("view_and_sensors")
        .default_size(330.0)
        .show(&mut root, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                camera_panel(ui, &mut ui_state, &sensors.active);
                ui.separator();
                view_panel(ui, &mut ui_state, &mut settings, sensors.lighting.as_deref(), sensors.engine.as_deref(), frame_time);
                ui.separator();
                sensor_panel(ui, &mut ui_state, &mut sensors, &solar);
            });
        })
        .response
        .rect
        .width();
    ui_state.pointer_over_panels = ctx.is_pointer_over_egui();
    ui_state.pointer_checked_at = window.cursor_position();
    ui_state.keyboard_for_panels = ctx.egui_wants_keyboard_input();
    // The 3D view: what the panels leave.
    let scale = window.scale_factor();
    let (left, right) = ((left * scale) as u32, (right * scale) as u32);
    let width = window.physical_width().saturating_sub(left + right).max(1);
    let viewport = Viewport { physical_position: UVec2::new(left, 0), physical_size: UVec2::new(width, window.physical_height().max(1)), ..default() };
    for mut camera in &mut cameras {
        let same = camera.viewport.as_ref().is_some_and(|v| v.physical_position == viewport.physical_position && v.physical_size == viewport.physical_size);
        if !same {
            camera.viewport = Some(viewport.clone());
        }
    }
    Ok(())
}

// Resources are passed as `ResMut` and written only when a value changes:
// writing marks them changed, and a changed time or sky starts a relight.
#[allow(clippy::too_many_arguments)]
fn sun_and_sky_panel(
    ui: &mut Ui,
    state: &mut UiState,
    solar: &mut ResMut<SolarTime>,
    sky: &mut ResMut<SkyChoice>,
    settings: &mut ResMut<RenderSettings>,
    site: Option<ResMut<Site>>,
    sun_sky: Option<&SunSky>,
    scene: Option<&crate::scene::Scene>,
) {
    ui.heading("Sun and sky");
    let LocalDateTime { mut date, time } = solar.0;
    // Day of the year as a slider for browsing, the date as spinners for exact input.
    let days = if days_in_month(date.year, 2) == 29 { 366 } else { 365 };
    let mut day = date.day_of_year();
    ui.label(format!("Date: {date}"));
    if slider(ui, &mut day, 1..=days, "day of year", &mut state.note).changed() {
        date = Date::new(date.year, 1, 1).expect("1 January").add_days(i64::from(day) - 1);
    }
    ui.horizontal(|ui| {
        let mut year = date.year;
        let mut month = date.month;
        let mut day = date.day;
        let y = bounded(ui, &mut year, 1900..=2100, 0.1, "year ", "", &mut state.note).changed();
        let m = bounded(ui, &mut month, 1..=12, 0.05, "month ", "", &mut state.note).changed();
        let d = bounded(ui, &mut day, 1..=31, 0.05, "day ", "", &mut state.note).changed();
        if y || m || d {
            let last = days_in_month(year, month);
            if day > last {
                state.note = Some(format!("day {day} clamped to {last}: {year}-{month:02} has {last} days"));
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
        let label = if state.playing.is_some() { "Pause" } else { "Play the day" };
        if ui.button(label).clicked() {
            state.playing = if state.playing.is_some() { None } else { Some(0.5) };
        }
    });
    if !(0..=1439).contains(&minutes) {
        let clamped = minutes.clamp(0, 1439);
        state.note = Some(format!("time {} is outside 00:00..23:59: {} is used", clock_text(minutes), clock_text(clamped)));
        minutes = clamped;
    }
    let time = TimeOfDay::from_hours(minutes as f64 / 60.0).unwrap_or(time);
    let new = LocalDateTime { date, time };
    if new != solar.0 {
        solar.0 = new;
    }
    if let Some(sun_sky) = sun_sky {
        ui.label(format!("Sun: altitude {:.1}°, azimuth {:.1}°", sun_sky.sun.altitude, sun_sky.sun.azimuth));
    }
    ui.separator();
    if let Some(mut site) = site {
        ui.label("Site");
        let mut s = site.0;
        ui.horizontal(|ui| {
            bounded(ui, &mut s.latitude, -90.0..=90.0, 0.1, "lat ", "", &mut state.note);
            bounded(ui, &mut s.longitude, -180.0..=180.0, 0.1, "lon ", "", &mut state.note);
        });
        // North as the designer sees it: from the model's own default north,
        // the scene file's turn included.
        let from_file = scene.map_or(0.0, |scene| scene.frame.north_angle());
        ui.horizontal(|ui| {
            bounded(ui, &mut s.timezone, -14.0..=14.0, 0.25, "UTC ", "", &mut state.note);
            let mut north = from_file + s.north_turn;
            bounded(ui, &mut north, -360.0..=360.0, 0.5, "north ", "°", &mut state.note).on_hover_text("true north, clockwise from the model's north axis");
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
    sky_controls(ui, sky, &mut state.note);
    ui.separator();
    let mut auto = settings.exposure.is_none();
    let mut ev = settings.exposure.unwrap_or(10.0);
    ui.horizontal(|ui| {
        ui.checkbox(&mut auto, "auto exposure");
        ui.add_enabled_ui(!auto, |ui| slider(ui, &mut ev, -5.0..=20.0, "EV", &mut state.note));
    });
    let exposure = if auto { None } else { Some(ev) };
    if exposure != settings.exposure {
        settings.exposure = exposure;
    }
    if let Some(note) = &state.note {
        ui.colored_label(egui::Color32::from_rgb(230, 160, 60), note);
    }
}

/// Minutes as HH:MM (a sign in front when negative).
fn clock_text(minutes: i64) -> String {
    let sign = if minutes < 0 { "-" } else { "" };
    format!("{sign}{:02}:{:02}", minutes.abs() / 60, minutes.abs() % 60)
}

/// Minutes from HH:MM typed by hand; minutes past 59 or anything that is
/// not a clock time is refused (the field keeps its value).
fn parse_clock(text: &str) -> Option<i64> {
    let (h, m) = text.trim().split_once(':')?;
    let (h, m) = (h.trim(), m.trim().parse::<i64>().ok().filter(|m| (0..60).contains(m))?);
    let hours = h.trim_start_matches('-').parse::<i64>().ok()?;
    let minutes = hours * 60 + m;
    Some(if h.starts_with('-') { -minutes } else { minutes })
}

/// A number field: what is typed outside `range` is clamped into it, with a
/// note saying so (never a panic, never a silent change).
pub(super) fn bounded<N: Numeric + Display>(ui: &mut Ui, value: &mut N, range: RangeInclusive<N>, speed: f64, prefix: &str, suffix: &str, note: &mut Option<String>) -> egui::Response {
    let response = ui.add(egui::DragValue::new(value).speed(speed).prefix(prefix).suffix(suffix));
    clamp_noted(value, range, prefix.trim_start(), suffix, note);
    response
}

/// A slider for browsing; a value typed into its box outside `range` is
/// clamped with a note, as in [`bounded`].
fn slider<N: Numeric + Display>(ui: &mut Ui, value: &mut N, range: RangeInclusive<N>, text: &str, note: &mut Option<String>) -> egui::Response {
    let response = ui.add(egui::Slider::new(value, range.clone()).text(text).clamping(egui::SliderClamping::Never));
    clamp_noted(value, range, &format!("{text} "), "", note);
    response
}

/// Clamps `value` into `range`; when it was outside, says so in `note`.
pub(super) fn clamp_noted<N: Numeric + Display>(value: &mut N, range: RangeInclusive<N>, what: &str, suffix: &str, note: &mut Option<String>) {
    let (v, lo, hi) = (value.to_f64(), range.start().to_f64(), range.end().to_f64());
    if (lo..=hi).contains(&v) {
        return;
    }
    let clamped = if v.is_nan() || v < lo { *range.start() } else { *range.end() };
    *note = Some(format!("{what}{value}{suffix} is outside {}..{}: {clamped} is used", range.start(), range.end()));
    *value = clamped;
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
        painter.text(to_screen(azimuth, 0.0) + egui::vec2(0.0, -2.0), egui::Align2::CENTER_BOTTOM, label, egui::FontId::proportional(10.0), egui::Color32::GRAY);
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
            bounded(ui, diffuse_horizontal, 1.0..=600.0, 1.0, "DHI ", " W/m²", note);
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

fn view_panel(ui: &mut Ui, state: &mut UiState, settings: &mut ResMut<RenderSettings>, lighting: Option<&LightingState>, engine: Option<&LightEngine>, frame_time: Option<(f64, f64)>) {
    ui.heading("View");
    let labels = [(RenderMode::Full, "full"), (RenderMode::Sun, "direct sun"), (RenderMode::Sky, "direct sky"), (RenderMode::Indirect, "indirect"), (RenderMode::FalseColour, "false colour (lux)")];
    let mut mode = settings.mode;
    egui::ComboBox::from_label("mode").selected_text(labels.iter().find(|l| l.0 == mode).map_or("", |l| l.1)).show_ui(ui, |ui| {
        for (value, label) in labels {
            ui.selectable_value(&mut mode, value, label);
        }
    });
    if mode != settings.mode {
        settings.mode = mode;
    }
    if settings.mode == RenderMode::FalseColour {
        let mut top = settings.false_colour_max_lux;
        bounded(ui, &mut top, 10.0..=200_000.0, 10.0, "scale top ", " lx", &mut state.note);
        if top != settings.false_colour_max_lux {
            settings.false_colour_max_lux = top;
        }
        false_colour_legend(ui, settings.false_colour_max_lux);
    }
    let progress = match (engine, lighting) {
        (Some(e), _) if e.is_precomputing() => "precomputing the light…".to_string(),
        (_, Some(l)) if l.lighting.is_some() => {
            let (iterations, residual) = l.lighting.as_ref().map_or((0, f64::INFINITY), |x| (x.iterations, x.residual));
            if l.converged {
                format!("light converged ({iterations} iterations, residual {residual:.1e})")
            } else {
                format!("light settling… iteration {iterations}, residual {residual:.1e}")
            }
        }
        _ => "waiting for the light".to_string(),
    };
    ui.label(progress);
    if let Some((smoothed, worst)) = frame_time {
        ui.label(format!("frame {smoothed:.0} ms ({:.0} fps), worst recent {worst:.0} ms", 1000.0 / smoothed.max(1e-3)));
    }
    ui.horizontal(|ui| {
        if ui.button("Save image (PNG)").clicked() {
            state.save_image = Some(ImageFormat::Png);
        }
        // False colour is a legend's colours, not light: no luminance to save.
        let luminance = settings.mode != RenderMode::FalseColour;
        let hdr = ui.add_enabled(luminance, egui::Button::new("Save luminance (HDR)"));
        if hdr.on_hover_text("the 3D view in cd/m² (of the light the mode shows), as a Radiance picture").on_disabled_hover_text("false colour has no luminance to save").clicked() {
            state.save_image = Some(ImageFormat::Hdr);
        }
    });
}

/// Camera presets, the scene's and the user's viewpoints, walk mode.
fn camera_panel(ui: &mut Ui, state: &mut UiState, active: &ActiveScene) {
    ui.heading("Camera");
    ui.horizontal(|ui| {
        for (label, request) in [("Top", CameraRequest::Top), ("Front", CameraRequest::Front), ("Side", CameraRequest::Side), ("3D", CameraRequest::Perspective)] {
            if ui.button(label).clicked() {
                state.camera_request = Some(request);
            }
        }
    });
    let views: Vec<Viewpoint> = active.scene.iter().flat_map(|s| s.viewpoints.iter().cloned()).chain(state.saved_views.iter().cloned()).collect();
    ui.horizontal(|ui| {
        egui::ComboBox::from_id_salt("viewpoints").selected_text("viewpoints").show_ui(ui, |ui| {
            for view in &views {
                if ui.selectable_label(false, &view.name).clicked() {
                    state.camera_request = Some(CameraRequest::Viewpoint(view.clone()));
                }
            }
        });
        if ui.button("Save view").clicked() {
            state.camera_request = Some(CameraRequest::Save);
        }
    });
    ui.checkbox(&mut state.walk, "walk (W A S D)");
}

/// The live sensor table, the selected sensor's day, CSV export.
fn sensor_panel(ui: &mut Ui, state: &mut UiState, sensors: &mut SensorPanel, solar: &SolarTime) {
    ui.heading("Sensors (lux)");
    let Some(lighting) = sensors.lighting.as_ref().and_then(|l| l.lighting.as_ref()) else { return };
    let readings = &lighting.sensors;
    if let Some(selected) = sensors.selected.0.and_then(|i| readings.get(i)) {
        ui.label(format!("{}: {:.0} lx over {} (every half hour)", selected.name, selected.total, solar.0.date));
        match &sensors.series.0.values {
            Some(values) => day_plot(ui, values, solar.0.time.hours()),
            None => {
                ui.add(egui::Spinner::new());
            }
        }
        match (&sensors.year.map.values, sensors.year.progress()) {
            (_, Some(done)) => {
                ui.add(egui::ProgressBar::new(done).text("the year, every two weeks…"));
            }
            (Some(values), None) => year_map(ui, values, solar.0.date.day_of_year(), solar.0.time.hours()),
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
                csv.push_str(&format!("{},{:.1},{:.1},{:.1},{:.1}\n", r.name, r.total, r.direct_sun, r.direct_sky, r.indirect));
            }
            state.note = Some(write_export("heliodon-sensors.csv", &csv));
        }
        if let (Some(values), Some(i)) = (&sensors.series.0.values, sensors.selected.0)
            && ui.button("Export day (CSV)").clicked()
        {
            let mut csv = String::from("time,illuminance_lux\n");
            for (k, v) in values.iter().enumerate() {
                let minutes = ((k as f64 + 0.5) * 24.0 * 60.0 / DAY_STEPS as f64).round() as i64;
                csv.push_str(&format!("{:02}:{:02},{v:.1}\n", minutes / 60, minutes % 60));
            }
            state.note = Some(write_export(&format!("heliodon-day-{}.csv", readings[i].name.replace('/', "-")), &csv));
        }
    });
    egui::Grid::new("sensors").striped(true).num_columns(5).show(ui, |ui| {
        for title in ["sensor", "total", "sun", "sky", "indirect"] {
            ui.strong(title);
        }
        ui.end_row();
        for (i, r) in readings.iter().enumerate() {
            if ui.selectable_label(sensors.selected.0 == Some(i), &r.name).clicked() {
                sensors.selected.0 = Some(i);
            }
            for value in [r.total, r.direct_sun, r.direct_sky, r.indirect] {
                ui.monospace(format!("{value:8.0}"));
            }
            ui.end_row();
        }
    });
}

/// The year as a heat map: days of the year across, time of day up, each
/// cell in false colour (top of the scale: the year's peak), now marked.
fn year_map(ui: &mut Ui, values: &[Vec<f64>], day: u32, now: f64) {
    let (response, painter) = ui.allocate_painter(egui::vec2(ui.available_width().min(300.0), 130.0), egui::Sense::hover());
    let rect = response.rect;
    let peak = values.iter().flatten().copied().fold(10.0f64, f64::max) as f32;
    let (w, h) = (rect.width() / YEAR_DAYS as f32, rect.height() / DAY_STEPS as f32);
    for (d, day_values) in values.iter().enumerate() {
        for (t, &lux) in day_values.iter().enumerate() {
            let [r, g, b] = if lux > 0.0 { crate::render::false_colour(lux as f32, peak) } else { [0.05; 3] };
            let cell = egui::Rect::from_min_size(egui::pos2(rect.left() + d as f32 * w, rect.bottom() - (t + 1) as f32 * h), egui::vec2(w + 0.5, h + 0.5));
            painter.rect_filled(cell, 0.0, egui::Color32::from(egui::Rgba::from_rgb(r, g, b)));
        }
    }
    let now_point = egui::pos2(rect.left() + (day as f32 / 366.0) * rect.width(), rect.bottom() - (now / 24.0) as f32 * rect.height());
    painter.circle_stroke(now_point, 4.0, egui::Stroke::new(1.5, egui::Color32::WHITE));
    painter.text(rect.left_top() + egui::vec2(4.0, 2.0), egui::Align2::LEFT_TOP, format!("peak {peak:.0} lx"), egui::FontId::proportional(10.0), egui::Color32::WHITE);
}

/// Writes an export into the working folder; what to tell the user.
fn write_export(name: &str, text: &str) -> String {
    match std::fs::write(name, text) {
        Ok(()) => format!("wrote {}", std::env::current_dir().map(|d| d.join(name).display().to_string()).unwrap_or(name.into())),
        Err(e) => format!("cannot write {name}: {e}"),
    }
}

/// Illuminance over the day (log scale, 10 lx to the day's peak), with the
/// current time marked.
fn day_plot(ui: &mut Ui, values: &[f64], now: f64) {
    let (response, painter) = ui.allocate_painter(egui::vec2(ui.available_width().min(300.0), 120.0), egui::Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 4.0, egui::Color32::from_gray(28));
    let peak = values.iter().copied().fold(10.0f64, f64::max);
    let y = |lux: f64| rect.bottom() - ((lux.max(10.0) / 10.0).log10() / (peak / 10.0).log10().max(1e-6)) as f32 * (rect.height() - 14.0);
    let x = |hours: f64| rect.left() + (hours / 24.0) as f32 * rect.width();
    let points: Vec<egui::Pos2> = values.iter().enumerate().map(|(k, &v)| egui::pos2(x((k as f64 + 0.5) * 24.0 / values.len() as f64), y(v))).collect();
    painter.add(egui::Shape::line(points, egui::Stroke::new(1.5, egui::Color32::from_rgb(120, 200, 255))));
    painter.line_segment([egui::pos2(x(now), rect.top()), egui::pos2(x(now), rect.bottom())], egui::Stroke::new(1.0, egui::Color32::from_rgb(255, 210, 40)));
    painter.text(rect.left_top() + egui::vec2(4.0, 2.0), egui::Align2::LEFT_TOP, format!("{peak:.0} lx"), egui::FontId::proportional(10.0), egui::Color32::LIGHT_GRAY);
    for hours in [6.0, 12.0, 18.0] {
        painter.text(egui::pos2(x(hours), rect.bottom()), egui::Align2::CENTER_BOTTOM, format!("{hours:.0}h"), egui::FontId::proportional(10.0), egui::Color32::GRAY);
    }
}

/// Applies the camera panel's request.
pub fn apply_camera_request(mut state: ResMut<UiState>, active: Res<ActiveScene>, mut cameras: Query<&mut CadCamera>) {
    let Some(request) = state.camera_request.take() else { return };
    let Some(scene) = &active.scene else { return };
    let (centre, distance) = crate::render::framing(scene.bounds, crate::scene::DEFAULT_FOV);
    for mut camera in &mut cameras {
        let (yaw, pitch) = match &request {
            CameraRequest::Top => (-std::f32::consts::FRAC_PI_2, 1.5),
            CameraRequest::Front => (-std::f32::consts::FRAC_PI_2, 0.0),
            CameraRequest::Side => (0.0, 0.0),
            CameraRequest::Perspective => (-2.2, 0.6),
            CameraRequest::Viewpoint(view) => {
                *camera = CadCamera::from_viewpoint(view);
                continue;
            }
            CameraRequest::Save => {
                let name = format!("saved {}", state.saved_views.len() + 1);
                let eye = camera.eye();
                state.saved_views.push(Viewpoint { name, eye, target: camera.focus, fov: crate::scene::DEFAULT_FOV });
                continue;
            }
        };
        *camera = CadCamera { focus: centre, distance, yaw, pitch };
    }
}

/// Saves the view when asked, into the working folder, named by the time
/// (and a number, when that name is taken: nothing is overwritten).
fn save_image(mut state: ResMut<UiState>, mut saves: MessageWriter<SaveView>) {
    let Some(format) = state.save_image.take() else { return };
    let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let name = (1..)
        .map(|k| PathBuf::from(if k == 1 { format!("heliodon-view-{stamp}.{}", format.extension()) } else { format!("heliodon-view-{stamp}-{k}.{}", format.extension()) }))
        .find(|path| !path.exists())
        .expect("a free name");
    state.note = Some(format!("saving {}", name.display()));
    saves.write(match format {
        ImageFormat::Png => SaveView::Png(name),
        ImageFormat::Hdr => SaveView::Hdr(name),
    });
}

/// The outcome of the last save, as the note.
fn note_saves(results: Res<SaveResults>, mut state: ResMut<UiState>) {
    if let Some(last) = results.0.last() {
        state.note = Some(match last {
            Ok(path) => format!("wrote {}", std::env::current_dir().map(|d| d.join(path)).unwrap_or(path.clone()).display()),
            Err(message) => message.clone(),
        });
    }
}

/// The false-colour scale as a bar with its decades.
fn false_colour_legend(ui: &mut Ui, top: f32) {
    let (response, painter) = ui.allocate_painter(egui::vec2(ui.available_width().min(260.0), 34.0), egui::Sense::hover());
    let rect = response.rect;
    let steps = 64;
    for k in 0..steps {
        let t = k as f32 / (steps - 1) as f32;
        let lux = top * 1000f32.powf(t - 1.0);
        let [r, g, b] = crate::render::false_colour(lux, top);
        let colour = egui::Color32::from(egui::Rgba::from_rgb(r, g, b));
        let x0 = rect.left() + rect.width() * k as f32 / steps as f32;
        painter.rect_filled(egui::Rect::from_min_size(egui::pos2(x0, rect.top()), egui::vec2(rect.width() / steps as f32 + 1.0, 16.0)), 0.0, colour);
    }
    for decade in 0..4 {
        let lux = top / 10f32.powi(3 - decade);
        let x = rect.left() + rect.width() * decade as f32 / 3.0;
        painter.text(egui::pos2(x, rect.bottom()), egui::Align2::CENTER_BOTTOM, format!("{lux:.0}"), egui::FontId::proportional(10.0), egui::Color32::LIGHT_GRAY);
    }
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
