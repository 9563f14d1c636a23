//! Who the pointer and the keyboard belong to: the panels or the 3D view.
//! The panels write [`PanelFocus`] each frame; the camera, sensor picking
//! and the lobe keys read it. A leaf: it imports nothing of the viewer.

use bevy::prelude::*;

/// Where the panels have the pointer and the keyboard.
#[derive(Resource, Debug, Clone, Default)]
pub struct PanelFocus {
    /// Whether the pointer is over a panel (the camera then ignores it), as
    /// egui saw it at `pointer_checked_at`; see [`PanelFocus::over_panels`].
    pub pointer_over_panels: bool,
    pub pointer_checked_at: Option<Vec2>,
    /// A panel field has the keyboard (keys typed are not for the camera).
    pub keyboard: bool,
}

impl PanelFocus {
    /// Whether the pointer at `cursor` is over a panel. egui's answer is a
    /// frame old: it counts only where the pointer has not moved since (a
    /// pointer that jumped into the view and clicked in one frame is in the
    /// view; the side panels are outside the view's viewport anyway).
    pub fn over_panels(&self, cursor: Vec2) -> bool {
        self.pointer_over_panels && self.pointer_checked_at.is_some_and(|p| p.distance(cursor) < 0.5)
    }
}
