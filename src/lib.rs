//! heliodon: a digital heliodon for daylighting design.
//!
//! Layers, from the bottom (see ARCHITECTURE.md):
//! - science, plain Rust without Bevy types: [`site`], [`time`], [`scene`],
//!   [`sun`], [`sky`], [`light`], [`panel`] (the panel API);
//! - the ECS layer: [`ecs`] ([`HeliodonPlugins`], runs headless);
//! - drawing: [`render`]; the window and its input: [`viewer`];
//! - the command line: [`cli`]; Radiance export: [`radiance`].

pub mod cli;
pub mod ecs;
pub mod light;
pub mod panel;
pub mod radiance;
pub mod render;
pub mod scene;
pub mod site;
pub mod sky;
pub mod sun;
pub mod time;
pub mod viewer;

use std::path::{Path, PathBuf};

use bevy::asset::{AssetMetaCheck, AssetPlugin, UnapprovedPathMode};

pub use ecs::HeliodonPlugins;
/// The Bevy and glam heliodon is built on, for panel plugins (one version for all).
pub use bevy;
pub use glam;

/// The `AssetPlugin` heliodon apps need: scene files are opened by absolute
/// path wherever they are, and carry no `.meta` files.
pub fn asset_plugin() -> AssetPlugin {
    AssetPlugin {
        unapproved_path_mode: UnapprovedPathMode::Allow,
        meta_check: AssetMetaCheck::Never,
        ..Default::default()
    }
}

/// The bundled scenes, by folder name under `assets/scenes/`.
pub const BUNDLED_SCENES: [&str; 3] = ["test_room", "office", "living_room"];

/// The scene the viewer opens when given none.
pub const DEFAULT_SCENE: &str = "office";

/// Path of a bundled scene: under `./assets` when run from a checkout's root,
/// else under the crate's own folder.
pub fn bundled_scene(name: &str) -> PathBuf {
    let relative = Path::new("assets/scenes").join(name).join("scene.toml");
    if relative.exists() {
        relative
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
    }
}
