//! heliodon: a digital heliodon for daylighting design.
//!
//! Layers, from the bottom (see ARCHITECTURE.md):
//! - the science, plain Rust without Bevy: the `heliodon-core` crate,
//!   re-exported here ([`site`], [`time`], [`scene`], [`sun`], [`sky`],
//!   [`light`], [`day`], [`panel`] (the panel API), [`sun_pass`] (what the
//!   stencil pass draws), [`radiance`]);
//! - the ECS layer: [`ecs`] ([`HeliodonPlugins`], runs headless);
//! - drawing: [`render`]; the window and its input: [`viewer`];
//! - the command line: [`cli`].

pub mod cli;
pub mod ecs;
pub mod render;
pub mod viewer;

pub use heliodon_core::{
    BUNDLED_SCENES, annual, bundled_scene, day, light, panel, radiance, report, scene, scene_cache, site, sky, sun, sun_pass, sweep, time,
    weather,
};

use bevy::asset::{AssetMetaCheck, AssetPlugin, UnapprovedPathMode};

/// The Bevy and glam heliodon is built on (one version for all).
pub use bevy;
pub use ecs::HeliodonPlugins;
pub use glam;
/// The core crate itself, for what its modules do not name.
pub use heliodon_core;

/// The `AssetPlugin` heliodon apps need: scene files are opened by absolute
/// path wherever they are, and carry no `.meta` files.
pub fn asset_plugin() -> AssetPlugin {
    AssetPlugin { unapproved_path_mode: UnapprovedPathMode::Allow, meta_check: AssetMetaCheck::Never, ..Default::default() }
}

/// The scene the viewer opens when given none.
pub const DEFAULT_SCENE: &str = "office";
