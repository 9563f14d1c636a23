//! The lobes of a panel window for the current sun, drawn as arrows (the
//! thesis' figure 3.2 in 3D): `L` selects the next panel window (and after
//! the last, none). The sun's arrow comes in yellow; each transmitted lobe
//! leaves into the room, its length and brightness its share.

use bevy::prelude::*;

use super::focus::PanelFocus;
use super::schedule::ViewerSystems;
use crate::ecs::{ActiveScene, RayModel, SunSky};

/// `L` and the lobe arrows.
pub struct LobesPlugin;

impl Plugin for LobesPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ShownLobes>().add_systems(Update, (select_panel_window, draw_lobes).chain().in_set(ViewerSystems::Overlays));
    }
}

/// The panel window whose lobes are shown ([`crate::scene::Scene::windows`] index).
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct ShownLobes(pub Option<usize>);

/// Length (m) of an arrow carrying all of the incoming light.
const ARROW_LENGTH: f32 = 1.5;

pub fn select_panel_window(
    keys: Res<ButtonInput<KeyCode>>,
    focus: Option<Res<PanelFocus>>,
    active: Res<ActiveScene>,
    ray_model: Option<Res<RayModel>>,
    mut shown: ResMut<ShownLobes>,
) {
    // An L typed into a panel field is for the field.
    if !keys.just_pressed(KeyCode::KeyL) || focus.is_some_and(|f| f.keyboard) {
        return;
    }
    let (Some(scene), Some(model)) = (&active.scene, ray_model) else { return };
    let panels: Vec<usize> =
        (0..scene.windows.len()).filter(|&w| model.0.panel_group_of_surface(scene.windows[w].surface).is_some()).collect();
    shown.0 = match shown.0.and_then(|w| panels.iter().position(|&p| p == w)) {
        Some(k) => panels.get(k + 1).copied(),
        None => panels.first().copied(),
    };
}

pub fn draw_lobes(
    mut gizmos: Gizmos,
    shown: Res<ShownLobes>,
    active: Res<ActiveScene>,
    ray_model: Option<Res<RayModel>>,
    sun_sky: Option<Res<SunSky>>,
) {
    let (Some(window), Some(scene), Some(model), Some(sun_sky)) = (shown.0, &active.scene, ray_model, sun_sky) else { return };
    let Some(window) = scene.windows.get(window) else { return };
    let Some(sun) = sun_sky.sky.sun_up() else { return };
    let Some(group) = model.0.panel_group_of_surface(window.surface) else { return };
    let centre = window.centroid;
    let to_sun = sun.direction.as_vec3();
    gizmos.arrow(centre + to_sun * ARROW_LENGTH, centre, Color::srgb(1.0, 0.85, 0.1));
    let normal = window.normal.as_dvec3();
    let on_window = sun.normal_irradiance() * sun.direction.dot(normal).abs();
    for beam in model.0.sun_beams(&sun).iter().filter(|b| b.panel_group == Some(group)) {
        // The lobe's share of the sun's flux on the window.
        let share = (beam.normal_irradiance * beam.to_light.dot(normal).abs() / on_window.max(1e-9)).min(1.0) as f32;
        let out = -beam.to_light.as_vec3();
        gizmos.arrow(centre, centre + out * ARROW_LENGTH * share.max(0.05), Color::srgb(0.2 + 0.8 * share, 0.5 + 0.5 * share, 1.0));
    }
}
