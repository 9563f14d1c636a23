//! The view panel: the render mode (with the false-colour scale), a
//! horizontal section and the plan view, the light's progress, the frame
//! time, and saving the view.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::egui::{self, Ui};

use crate::ecs::{LightEngine, LightingState};
use crate::render::{RenderMode, RenderSettings, VerticalSection};
use crate::viewer::camera::{CadCamera, CameraControl, CameraRequest};
use crate::viewer::capture::{ImageFormat, SaveRequest};
use crate::viewer::redraw::DrawnFrameTimes;
use crate::viewer::widgets::bounded;

/// What the view panel reads and writes (the render settings come from the
/// caller: the sun and sky panel sets their exposure).
#[derive(SystemParam)]
pub struct ViewPanel<'w, 's> {
    lighting: Option<Res<'w, LightingState>>,
    engine: Option<Res<'w, LightEngine>>,
    frame_times: Res<'w, DrawnFrameTimes>,
    save: ResMut<'w, SaveRequest>,
    eyes: Query<'w, 's, &'static GlobalTransform, With<CadCamera>>,
}

impl ViewPanel<'_, '_> {
    /// Draws the panel; the plan view asks `camera` to look down.
    pub fn show(&mut self, ui: &mut Ui, settings: &mut ResMut<RenderSettings>, camera: &mut CameraControl, note: &mut Option<String>) {
        // Frame time while drawing, and the worst of the recent history (ms).
        let frame_time = self.frame_times.mean_and_worst();
        view_panel(ui, note, &mut self.save, settings, self.lighting.as_deref(), self.engine.as_deref(), frame_time);
        // Where a section cuts by default: under the ceiling of the camera's storey.
        let eye = self.eyes.iter().next().map(GlobalTransform::translation);
        let model = self.engine.as_ref().and_then(|e| e.model.clone());
        let storey = || model.as_ref()?.storey_section(eye?);
        section_row(ui, settings, camera, storey, note);
        // A vertical one by default through the middle of what the scene is
        // about (its windows and sensors), hiding the half toward the camera.
        let across = || {
            let (lo, hi) = model.as_ref()?.scene.focus;
            let middle = (lo + hi) / 2.0;
            let toward = (eye? - middle).truncate();
            let azimuth = toward.x.atan2(toward.y).to_degrees().rem_euclid(360.0);
            Some(VerticalSection::through(middle, azimuth))
        };
        vertical_section_row(ui, settings, across, note);
    }
}

/// The vertical section: on, the way its hidden side lies and where it stands.
fn vertical_section_row(
    ui: &mut Ui,
    settings: &mut ResMut<RenderSettings>,
    across: impl Fn() -> Option<VerticalSection>,
    note: &mut Option<String>,
) {
    ui.horizontal(|ui| {
        let mut on = settings.vertical_section.is_some();
        if ui.checkbox(&mut on, "vertical section").on_hover_text("hide what lies beyond a vertical plane").changed() {
            settings.vertical_section = on.then(|| across().unwrap_or(VerticalSection { azimuth: 180.0, offset: 0.0 }));
        }
        if let Some(section) = settings.vertical_section {
            let mut edited = section;
            bounded(ui, &mut edited.azimuth, 0.0..=360.0, 1.0, "toward ", "°", note);
            bounded(ui, &mut edited.offset, -10_000.0..=10_000.0, 0.05, "at ", " m", note);
            if edited != section {
                settings.vertical_section = Some(edited);
            }
        }
    });
}

/// The horizontal section (on, and its height) and the plan view: looking
/// down on the section with the light in false colour, as daylighting
/// reports show it.
fn section_row(
    ui: &mut Ui,
    settings: &mut ResMut<RenderSettings>,
    camera: &mut CameraControl,
    storey: impl Fn() -> Option<f32>,
    note: &mut Option<String>,
) {
    ui.horizontal(|ui| {
        let mut on = settings.section.is_some();
        if ui
            .checkbox(&mut on, "section at")
            .on_hover_text("hide what lies above this height to look into the rooms; the light still comes from the whole model")
            .changed()
        {
            settings.section = on.then(|| storey().unwrap_or(2.5));
        }
        if let Some(height) = settings.section {
            let mut value = height;
            bounded(ui, &mut value, -1000.0..=10_000.0, 0.05, "", " m", note);
            if value != height {
                settings.section = Some(value);
            }
        }
        if ui.button("Plan").on_hover_text("look down on the section, the light in false colour (lux)").clicked() {
            settings.section = settings.section.or_else(&storey).or(Some(2.5));
            settings.mode = RenderMode::FalseColour;
            camera.request = Some(CameraRequest::Top);
        }
    });
}

fn view_panel(
    ui: &mut Ui,
    note: &mut Option<String>,
    save: &mut SaveRequest,
    settings: &mut ResMut<RenderSettings>,
    lighting: Option<&LightingState>,
    engine: Option<&LightEngine>,
    frame_time: Option<(f64, f64)>,
) {
    ui.heading("View");
    let labels = [
        (RenderMode::Full, "full"),
        (RenderMode::Sun, "direct sun"),
        (RenderMode::Sky, "direct sky"),
        (RenderMode::Indirect, "indirect"),
        (RenderMode::FalseColour, "false colour (lux)"),
    ];
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
        bounded(ui, &mut top, 10.0..=200_000.0, 10.0, "scale top ", " lx", note);
        if top != settings.false_colour_max_lux {
            settings.false_colour_max_lux = top;
        }
        false_colour_legend(ui, settings.false_colour_max_lux);
    }
    let progress = match (engine, lighting) {
        (Some(e), _) if e.is_precomputing() && e.model.is_none() => "precomputing the light…".to_string(),
        (_, Some(l)) if l.lighting.is_some() => {
            let (iterations, residual) = l.lighting.as_ref().map_or((0, f64::INFINITY), |x| (x.iterations, x.residual));
            if engine.is_some_and(LightEngine::is_smoothing) {
                "light shown; smoothing it with more rays…".to_string()
            } else if l.converged {
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
            save.0 = Some(ImageFormat::Png);
        }
        // False colour is a legend's colours, not light: no luminance to save.
        let luminance = settings.mode != RenderMode::FalseColour;
        let hdr = ui.add_enabled(luminance, egui::Button::new("Save luminance (HDR)"));
        if hdr
            .on_hover_text("the 3D view in cd/m² (of the light the mode shows), as a Radiance picture")
            .on_disabled_hover_text("false colour has no luminance to save")
            .clicked()
        {
            save.0 = Some(ImageFormat::Hdr);
        }
    });
}

/// The false-colour scale as a bar with its decades.
pub fn false_colour_legend(ui: &mut Ui, top: f32) {
    let (response, painter) = ui.allocate_painter(egui::vec2(ui.available_width().min(260.0), 34.0), egui::Sense::hover());
    let rect = response.rect;
    let steps = 64;
    for k in 0..steps {
        let t = k as f32 / (steps - 1) as f32;
        let lux = top * 1000f32.powf(t - 1.0);
        let [r, g, b] = crate::render::false_colour(lux, top);
        let colour = egui::Color32::from(egui::Rgba::from_rgb(r, g, b));
        let x0 = rect.left() + rect.width() * k as f32 / steps as f32;
        painter.rect_filled(
            egui::Rect::from_min_size(egui::pos2(x0, rect.top()), egui::vec2(rect.width() / steps as f32 + 1.0, 16.0)),
            0.0,
            colour,
        );
    }
    for decade in 0..4 {
        let lux = top / 10f32.powi(3 - decade);
        let x = rect.left() + rect.width() * decade as f32 / 3.0;
        painter.text(
            egui::pos2(x, rect.bottom()),
            egui::Align2::CENTER_BOTTOM,
            format!("{lux:.0}"),
            egui::FontId::proportional(10.0),
            egui::Color32::LIGHT_GRAY,
        );
    }
}
