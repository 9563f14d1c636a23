//! heliodon's core: the science of daylighting, plain Rust without Bevy.
//!
//! From the bottom (see ARCHITECTURE.md):
//! - where and when: [`site`], [`time`], [`weather`] (EPW files);
//! - the sun and the skies: [`sun`] (NREL SPA), [`sky`] (gensky, gendaylit,
//!   CIE, sky patches);
//! - the model: [`scene`] (scene files, OBJ and MTL, surfaces, patches,
//!   sensors), kept on disk by [`scene_cache`];
//! - complex fenestration: [`panel`] (the API panel crates implement);
//! - the light engine: [`light`] (daylight coefficients, form factors,
//!   radiosity, direct sun and panel beams, the cache), [`day`] (a
//!   sensor's day and year) and [`annual`] (a year of EPW weather: DA,
//!   UDI, ASE, sDA);
//! - what the renderer's stencil pass draws: [`sun_pass`];
//! - the Radiance export: [`radiance`]; CSV and JSON that stay valid
//!   whatever the names: [`report`].
//!
//! The Bevy layer (the `heliodon` crate: ECS, renderer, viewer, CLI) is
//! built on this crate; panel crates need only this one ([`prelude`]).

#![warn(missing_docs)]

pub mod annual;
pub mod day;
mod lanes;
pub mod light;
pub mod panel;
mod parallel;
pub mod radiance;
pub mod report;
pub mod scene;
pub mod scene_cache;
pub mod site;
pub mod sky;
pub mod sun;
pub mod sun_pass;
pub mod sweep;
pub mod time;
pub mod weather;

/// The glam heliodon's geometry is in (the version Bevy uses).
pub use glam;
/// The TOML types panel parameters are read from.
pub use toml;

/// The bundled scenes, by folder name under `assets/scenes/`.
pub const BUNDLED_SCENES: [&str; 3] = ["test_room", "office", "living_room"];

/// Path of a bundled scene: under `./assets` when run from a checkout's root,
/// else under the workspace's own folder.
pub fn bundled_scene(name: &str) -> std::path::PathBuf {
    let relative = std::path::Path::new("assets/scenes").join(name).join("scene.toml");
    if relative.exists() { relative } else { std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(relative) }
}

/// The panel guide (docs/panels.md), compiled: its examples are doctests.
#[doc = include_str!("../../docs/panels.md")]
pub mod panel_guide {}

/// What a panel crate needs: the panel API and the vector type of its
/// directions.
pub mod prelude {
    pub use crate::panel::{
        Key, KeyKind, Lobe, MeasuredTransmission, PanelCatalog, PanelModel, PanelResponse, PanelType, ParameterError, Parameters,
        fresnel_reflectance, reflect, refract,
    };
    pub use glam::DVec3;
}
