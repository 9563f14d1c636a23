//! The ECS layer: heliodon's state as Bevy resources and entities, updated by
//! systems in named sets ([`HeliodonSystems`], in that order each frame). [`HeliodonPlugins`] is everything that simulates;
//! it runs headless (`MinimalPlugins` + `AssetPlugin`) as well as in the
//! viewer. Drawing lives in [`crate::render`], windows and input in
//! [`crate::viewer`].

mod lighting;
mod scene_asset;
mod scene_plugin;
mod sun_sky;

use bevy::app::PluginGroupBuilder;
use bevy::prelude::*;

pub use lighting::{
    LightCacheDir, LightEngine, LightSettings, LightWaker, LightingFailed, LightingPlugin, LightingState, LightingUpdated, RefineForDisplay,
};
pub use scene_asset::{PanelRegistry, RegisterPanel, SceneAsset, SceneLoader, describe_load_failure, scene_asset_path};
pub use scene_plugin::{
    ActiveScene, EditMaterial, GiveOwnMaterial, MaterialEditRejected, MaterialOf, OpenScene, RayModel, SceneLoadFailed, SceneMaterial,
    ScenePlugin, SceneRoot, SceneSensor, SceneSpawned, SceneSurface, SceneWindow, Site,
};
pub use sun_sky::{LightChanged, SkyChoice, SkyRejected, SkySubdivision, SolarTime, SunSky, SunSkyPlugin};

/// The simulation plugins, in dependency order.
pub struct HeliodonPlugins;

impl PluginGroup for HeliodonPlugins {
    fn build(self) -> PluginGroupBuilder {
        PluginGroupBuilder::start::<Self>().add(ScenePlugin).add(SunSkyPlugin).add(LightingPlugin)
    }
}

/// heliodon's systems, in the order they run each frame in `Update`.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HeliodonSystems {
    /// Start loading requested scene files.
    LoadScene,
    /// Replace the scene entities once a load has finished.
    SpawnScene,
    /// Recompute the sun and sky when the site, time or sky changed.
    UpdateSunSky,
    /// Precompute light transport for a new scene; start, and apply, relights.
    Lighting,
}
