//! [`DesignerUiPlugin`]: the designer's panels (bevy_egui), one file per
//! panel. Left: the sun and sky ([`sun_and_sky`]: date, time, play, site
//! and north with a sun-path diagram, sky type and parameters, exposure),
//! then the windows and materials ([`materials`]) and the sweep of a window
//! material's keys ([`sweep`]). Top: the File menu ([`file`]). Right: the camera
//! ([`camera`]: presets, viewpoints, walk mode), the view ([`view`]: modes,
//! the light's progress, saving the image) and the sensors ([`sensors`]:
//! live table, the selected one's day and year, CSV export) and the annual
//! study ([`annual`]: a weather file, its sky, the year, sensors coloured by
//! DA300, UDI or ASE, CSV). The 3D view
//! fills the space between them: the camera's viewport follows the panels,
//! and the pointer over a panel belongs to the panel ([`PanelFocus`]).
//!
//! Panels only read state and write requests or resources; the systems
//! that act on them live with what they act on (camera, capture, sensors).

pub mod annual;
pub mod camera;
pub mod file;
pub mod materials;
pub mod sensors;
pub mod sun_and_sky;
pub mod sweep;
pub mod view;

use bevy::camera::visibility::RenderLayers;
use bevy::camera::{CameraOutputMode, Viewport};
use bevy::prelude::*;
use bevy::render::render_resource::BlendState;
use bevy::window::PrimaryWindow;
use bevy_egui::egui::{self, LayerId, Ui, UiBuilder};
use bevy_egui::{EguiContexts, EguiGlobalSettings, EguiPlugin, EguiPrimaryContextPass, PrimaryEguiContext};

use super::camera::CameraControl;
use super::focus::PanelFocus;
use super::widgets::Note;
use crate::render::{PictureCamera, RenderSettings};
use crate::viewer::schedule::ViewerSystems;
use annual::AnnualPanel;
use file::{FileMenu, FilePrompt};
use materials::{MaterialEdits, MaterialPanel};
use sensors::SensorPanel;
use sun_and_sky::{PlayDay, SunAndSkyPanel};
use sweep::SweepPanel;
use view::ViewPanel;

pub struct DesignerUiPlugin;

impl Plugin for DesignerUiPlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins(EguiPlugin::default())
            .init_resource::<PlayDay>()
            .init_resource::<MaterialEdits>()
            .init_resource::<FilePrompt>()
            .add_systems(Startup, spawn_ui_camera)
            .add_systems(EguiPrimaryContextPass, panels.in_set(ViewerSystems::Panels))
            .add_systems(Update, sun_and_sky::play_the_day);
    }
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

/// Draws the panels, notes where the pointer and keyboard are, and gives
/// the 3D view what the panels leave.
#[allow(clippy::too_many_arguments)]
fn panels(
    mut contexts: EguiContexts,
    mut focus: ResMut<PanelFocus>,
    mut note: ResMut<Note>,
    mut settings: ResMut<RenderSettings>,
    mut camera_control: ResMut<CameraControl>,
    mut sun_and_sky: SunAndSkyPanel,
    mut materials: MaterialPanel,
    mut view: ViewPanel,
    mut sensors: SensorPanel,
    mut annual: AnnualPanel,
    mut sweep: SweepPanel,
    mut file_menu: FileMenu,
    window: Single<&Window, With<PrimaryWindow>>,
    mut cameras: Query<&mut Camera, PictureCamera>,
) -> Result {
    let ctx = contexts.ctx_mut()?.clone();
    let mut root = Ui::new(ctx.clone(), "viewport".into(), UiBuilder::new().layer_id(LayerId::background()).max_rect(ctx.viewport_rect()));
    let top = egui::Panel::top("menu").show(&mut root, |ui| file_menu.show(ui)).response.rect.height();
    let left = egui::Panel::left("sun_and_sky")
        .default_size(270.0)
        .show(&mut root, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                sun_and_sky.show(ui, &mut settings, &mut note.0);
                if let Some(hour) = annual.sky_hour() {
                    ui.label(egui::RichText::new(hour).color(egui::Color32::from_rgb(255, 210, 40)));
                }
                ui.separator();
                materials.show(ui, &mut note.0, sun_and_sky.north_turn());
                ui.separator();
                sweep.show(ui);
            });
        })
        .response
        .rect
        .width();
    let right = egui::Panel::right("view_and_sensors")
        .default_size(330.0)
        .show(&mut root, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                camera::camera_panel(ui, &mut camera_control, &sensors.active);
                ui.separator();
                view.show(ui, &mut settings, &mut camera_control, &mut note.0);
                ui.separator();
                annual.show(ui, &mut note.0, sun_and_sky.site());
                ui.separator();
                sensors.show(ui, &mut note.0, sun_and_sky.now());
            });
        })
        .response
        .rect
        .width();
    focus.pointer_over_panels = ctx.is_pointer_over_egui();
    focus.pointer_checked_at = window.cursor_position();
    focus.keyboard = ctx.egui_wants_keyboard_input();
    // The 3D view: what the panels leave.
    let scale = window.scale_factor();
    let (left, right, top) = ((left * scale) as u32, (right * scale) as u32, (top * scale) as u32);
    let width = window.physical_width().saturating_sub(left + right).max(1);
    let height = window.physical_height().saturating_sub(top).max(1);
    let viewport = Viewport { physical_position: UVec2::new(left, top), physical_size: UVec2::new(width, height), ..default() };
    for mut camera in &mut cameras {
        let same = camera
            .viewport
            .as_ref()
            .is_some_and(|v| v.physical_position == viewport.physical_position && v.physical_size == viewport.physical_size);
        if !same {
            camera.viewport = Some(viewport.clone());
        }
    }
    Ok(())
}
