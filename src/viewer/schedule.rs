//! The viewer's system sets ([`ViewerSystems`]), apart from the plugins
//! that fill them so that every module can name them without importing the
//! viewer's root.

use bevy::prelude::*;

/// The viewer's systems, in order. In `Update`, after the scene is spawned:
/// 1. `Camera`: the camera panel's requests, then navigation;
/// 2. `Sensors`: picking, and the selected sensor's day and year tasks;
/// 3. `Overlays`: lobe arrows (after the sun and sky are updated).
///
/// In bevy_egui's `EguiPrimaryContextPass`: `Panels` (the egui panels and
/// the 3D view's viewport), then `Overlays` (sensor markers and labels).
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ViewerSystems {
    Camera,
    Sensors,
    Panels,
    Overlays,
}
