//! The camera panel: presets (top, front, side, 3D), the scene's and the
//! saved viewpoints, walk mode. It only asks: the camera carries the
//! requests out ([`crate::viewer::camera::apply_camera_request`]).

use bevy_egui::egui::{self, Ui};

use crate::ecs::ActiveScene;
use crate::scene::Viewpoint;
use crate::viewer::camera::{CameraControl, CameraRequest};

/// Camera presets, the scene's and the user's viewpoints, walk mode.
pub fn camera_panel(ui: &mut Ui, control: &mut CameraControl, active: &ActiveScene) {
    ui.heading("Camera");
    ui.horizontal(|ui| {
        for (label, request) in [
            ("Top", CameraRequest::Top),
            ("Front", CameraRequest::Front),
            ("Side", CameraRequest::Side),
            ("3D", CameraRequest::Perspective),
        ] {
            if ui.button(label).clicked() {
                control.request = Some(request);
            }
        }
    });
    let views: Vec<Viewpoint> =
        active.scene.iter().flat_map(|s| s.viewpoints.iter().cloned()).chain(control.saved_views.iter().cloned()).collect();
    ui.horizontal(|ui| {
        egui::ComboBox::from_id_salt("viewpoints").selected_text("viewpoints").show_ui(ui, |ui| {
            for view in &views {
                if ui.selectable_label(false, &view.name).clicked() {
                    control.request = Some(CameraRequest::Viewpoint(view.clone()));
                }
            }
        });
        if ui.button("Save view").clicked() {
            control.request = Some(CameraRequest::Save);
        }
    });
    ui.checkbox(&mut control.walk, "walk (W A S D)");
}
