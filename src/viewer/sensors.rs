//! Sensors in the viewer: markers with their readings in the 3D view, a
//! selected sensor (click a marker or a table row), and the selected
//! sensor's illuminance over the current day (every half hour, each solve
//! warm-started from the previous one) and, when asked, over the year,
//! both computed in the background with the light engine.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use super::background::Background;
use super::camera::cursor_in_view;
use super::focus::PanelFocus;
use super::schedule::ViewerSystems;
pub use crate::day::{DAY_STEPS, YEAR_DAYS};
use crate::day::{day_series, year_map_dates};
use crate::ecs::{LightEngine, LightingState, Site, SkyChoice, SolarTime};
use crate::light::LightModel;
use crate::time::Date;

/// Sensors in the viewer: selection, markers, and the selected sensor's day
/// and year computed in the background.
pub struct SensorsPlugin;

impl Plugin for SensorsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SelectedSensor>()
            .init_resource::<DaySeries>()
            .init_resource::<YearMap>()
            .add_systems(Update, (pick_sensor, update_day_series, update_year_map).in_set(ViewerSystems::Sensors))
            .add_systems(bevy_egui::EguiPrimaryContextPass, draw_markers.in_set(ViewerSystems::Overlays));
    }
}

/// The sensor the panels and the plot follow.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct SelectedSensor(pub Option<usize>);

/// The selected sensor's total illuminance (lux) over the day, by half
/// hour from 00:15; keyed by sensor, date, sky, site and light model (a new
/// key restarts it).
#[derive(Resource, Default)]
pub struct DaySeries(pub Background<(usize, Date, String), Vec<f64>>);

/// The selected sensor's illuminance over the year: day × half hour (the
/// thesis' figure 1.4h), computed in the background when asked for.
#[derive(Resource, Default)]
pub struct YearMap {
    /// Keyed by sensor, year, sky, site and light model.
    pub map: Background<(usize, i32, String), Vec<Vec<f64>>>,
    /// Days done, for the progress bar.
    done: Arc<AtomicUsize>,
    /// Set by the panel's button.
    pub requested: bool,
}

impl YearMap {
    /// Share done while computing.
    pub fn progress(&self) -> Option<f32> {
        self.map.task.as_ref().map(|_| self.done.load(Ordering::Relaxed) as f32 / YEAR_DAYS as f32)
    }
}

/// What the day and year plots are computed from.
#[derive(SystemParam)]
pub struct PlotInputs<'w> {
    selected: Res<'w, SelectedSensor>,
    solar: Res<'w, SolarTime>,
    sky: Res<'w, SkyChoice>,
    site: Option<Res<'w, Site>>,
    engine: Option<Res<'w, LightEngine>>,
}

impl PlotInputs<'_> {
    /// The selected sensor, the site and the light model, once all are there.
    fn ready(&self) -> Option<(usize, crate::site::Site, Arc<LightModel>)> {
        Some((self.selected.0?, self.site.as_ref()?.0, self.engine.as_ref()?.model.clone()?))
    }

    /// What a sensor's light depends on besides the date: the sky, the site
    /// and the light model (edited materials make a new one).
    fn light_key(&self) -> String {
        let model = self.engine.as_ref().and_then(|e| e.model.as_ref()).map(Arc::as_ptr);
        format!("{:?} {:?} {model:?}", self.sky.0, self.site.as_ref().map(|s| s.0))
    }
}

/// Starts the year map when asked (for the selected sensor, the current
/// year and sky), and collects it.
pub fn update_year_map(inputs: PlotInputs, mut year: ResMut<YearMap>) {
    year.map.collect();
    let first = inputs.solar.0.date.year;
    let key = inputs.selected.0.map(|s| (s, first, inputs.light_key()));
    if year.map.key.is_some() && year.map.key != key && year.map.task.is_none() {
        // What is shown no longer fits the sensor, sky, site or light model:
        // it goes, and a new year waits for a new request.
        year.map = Background::default();
    }
    // A request waits for the sensor and the light engine's model.
    if !year.requested {
        return;
    }
    let Some((sensor, site, model)) = inputs.ready() else { return };
    year.requested = false;
    let spec = inputs.sky.0.clone();
    let done = Arc::new(AtomicUsize::new(0));
    year.done = done.clone();
    year.map.start(key, move || {
        year_map_dates(first)
            .map(|date| {
                let day = day_series(&model, sensor, &site, date, &spec);
                done.fetch_add(1, Ordering::Relaxed);
                day
            })
            .collect()
    });
}

/// Sensor markers: a small cross and, over it, its total lux; in false
/// colour (the plan view) a disc in the colour of its lux as well, so a
/// grid reads as the surfaces around it do.
pub fn draw_markers(
    mut gizmos: Gizmos,
    active: Res<crate::ecs::ActiveScene>,
    selected: Res<SelectedSensor>,
    settings: Res<crate::render::RenderSettings>,
    mut contexts: bevy_egui::EguiContexts,
    lighting: Option<Res<LightingState>>,
    camera: Query<(&Camera, &GlobalTransform), crate::render::PictureCamera>,
) -> Result {
    let Some(scene) = &active.scene else { return Ok(()) };
    let Ok((camera, transform)) = camera.single() else { return Ok(()) };
    let ctx = contexts.ctx_mut()?.clone();
    let readings = lighting.as_ref().and_then(|l| l.lighting.as_ref()).map(|l| &l.sensors);
    for (i, sensor) in scene.sensors.iter().enumerate() {
        let chosen = selected.0 == Some(i);
        let mut colour = if chosen { Color::srgb(1.0, 0.3, 0.2) } else { Color::srgb(0.2, 0.8, 1.0) };
        let size = if chosen { 0.12 } else { 0.06 };
        let p = sensor.position;
        if let (crate::render::RenderMode::FalseColour, Some(reading)) = (settings.mode, readings.and_then(|r| r.get(i))) {
            let [r, g, b] = crate::render::false_colour(reading.total as f32, settings.false_colour_max_lux);
            let disc = Isometry3d::new(p, Quat::from_rotation_arc(Vec3::Z, sensor.normal.normalize_or(Vec3::Z)));
            gizmos.circle(disc, 2.0 * size, Color::srgb(r, g, b));
            colour = if chosen { colour } else { Color::srgb(r, g, b) };
        }
        gizmos.line(p - Vec3::X * size, p + Vec3::X * size, colour);
        gizmos.line(p - Vec3::Y * size, p + Vec3::Y * size, colour);
        gizmos.line(p, p + sensor.normal * size * 2.0, colour);
        let (Some(reading), Ok(screen)) = (readings.and_then(|r| r.get(i)), camera.world_to_viewport(transform, p)) else { continue };
        // Labels for the chosen sensor and, to keep the view readable, for a few.
        if chosen || scene.sensors.len() <= 12 {
            // Viewport conversions give window coordinates, as egui places areas.
            bevy_egui::egui::Area::new(bevy_egui::egui::Id::new(("sensor", i)))
                .fixed_pos(bevy_egui::egui::pos2(screen.x + 6.0, screen.y - 18.0))
                .interactable(false)
                .show(&ctx, |ui| {
                    ui.label(
                        bevy_egui::egui::RichText::new(format!("{} {:.0} lx", sensor.name, reading.total))
                            .small()
                            .background_color(bevy_egui::egui::Color32::from_black_alpha(160)),
                    );
                });
        }
    }
    Ok(())
}

/// A click (without dragging) near a marker selects it.
pub fn pick_sensor(
    mouse: Res<ButtonInput<MouseButton>>,
    window: Single<&Window, bevy::ecs::query::With<bevy::window::PrimaryWindow>>,
    active: Res<crate::ecs::ActiveScene>,
    focus: Res<PanelFocus>,
    camera: Query<(&Camera, &GlobalTransform), crate::render::PictureCamera>,
    mut pressed_at: Local<Option<Vec2>>,
    mut selected: ResMut<SelectedSensor>,
) {
    let (Some(scene), Ok((camera, transform))) = (&active.scene, camera.single()) else { return };
    // A click in the view, off the panels, that does not move.
    let cursor = window.cursor_position().filter(|c| !focus.over_panels(*c)).and_then(|_| cursor_in_view(&window, camera));
    if mouse.just_pressed(MouseButton::Left) {
        *pressed_at = cursor;
    }
    if !mouse.just_released(MouseButton::Left) {
        return;
    }
    let (Some(start), Some(cursor)) = (pressed_at.take(), cursor) else { return };
    if start.distance(cursor) > 4.0 {
        return;
    }
    let nearest = scene
        .sensors
        .iter()
        .enumerate()
        .filter_map(|(i, s)| camera.world_to_viewport(transform, s.position).ok().map(|p| (i, p.distance(cursor))))
        .filter(|(_, d)| *d < 14.0)
        .min_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((i, _)) = nearest {
        selected.0 = Some(i);
    }
}

/// Starts the selected sensor's day series when the sensor, date, sky,
/// site or light model change, and collects it when done.
pub fn update_day_series(inputs: PlotInputs, mut series: ResMut<DaySeries>) {
    series.0.collect();
    let Some((sensor, site, model)) = inputs.ready() else { return };
    let date = inputs.solar.0.date;
    let key = (sensor, date, inputs.light_key());
    if series.0.key.as_ref() == Some(&key) {
        return;
    }
    let spec = inputs.sky.0.clone();
    series.0.start(Some(key), move || day_series(&model, sensor, &site, date, &spec));
}
