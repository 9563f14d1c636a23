//! Scene files as a Bevy asset: [`SceneAsset`] and its [`AssetLoader`], which
//! runs the pure loader of [`crate::scene`] over Bevy's asset readers.

use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};

use bevy::asset::io::{AssetReaderError, Reader};
use bevy::asset::{AssetLoadError, AssetLoader, AssetPath, LoadContext};
use bevy::prelude::*;

use crate::panel::{PanelCatalog, PanelType};
use crate::scene::{self, Scene, SceneError, SceneReader, SceneWarning};
use crate::scene_cache;

/// A loaded scene file with its warnings.
#[derive(Asset, TypePath, Debug, Clone)]
pub struct SceneAsset {
    pub scene: Arc<Scene>,
    pub warnings: Vec<SceneWarning>,
}

/// The panel types plugins have registered: what the scene loader, the
/// engine, the renderer and the UI know by name. Shared with the scene
/// loader, so a panel registered at any time before a load is known to it.
#[derive(Resource, Clone, Default)]
pub struct PanelRegistry {
    catalog: Arc<RwLock<PanelCatalog>>,
}

impl PanelRegistry {
    pub fn register(&self, panel: impl PanelType + 'static) {
        self.catalog.write().expect("panel registry lock").register(Arc::new(panel));
    }

    /// Registers every panel type of `catalog`.
    pub fn register_all(&self, catalog: &PanelCatalog) {
        self.catalog.write().expect("panel registry lock").extend(catalog);
    }

    /// A snapshot of the registered panel types.
    pub fn catalog(&self) -> PanelCatalog {
        self.catalog.read().expect("panel registry lock").clone()
    }
}

/// Registering panel types in an app, one line each:
/// `app.register_panel(MyPanel)`, or a whole catalog with
/// `app.register_panels(&catalog)`. The panel's crate needs no Bevy.
pub trait RegisterPanel {
    fn register_panel(&mut self, panel: impl PanelType + 'static) -> &mut Self;
    fn register_panels(&mut self, catalog: &PanelCatalog) -> &mut Self;
}

impl RegisterPanel for App {
    fn register_panel(&mut self, panel: impl PanelType + 'static) -> &mut Self {
        self.world_mut().get_resource_or_init::<PanelRegistry>().register(panel);
        self
    }

    fn register_panels(&mut self, catalog: &PanelCatalog) -> &mut Self {
        self.world_mut().get_resource_or_init::<PanelRegistry>().register_all(catalog);
        self
    }
}

/// Loads `.toml` scene files, reading their OBJ and MTL through the same
/// asset source.
#[derive(TypePath)]
pub struct SceneLoader {
    panels: PanelRegistry,
}

impl FromWorld for SceneLoader {
    fn from_world(world: &mut World) -> Self {
        Self { panels: world.get_resource_or_init::<PanelRegistry>().clone() }
    }
}

/// How [`SceneLoader`] reads a scene: the folder where it keeps what the
/// load makes of the model's files (the scene cache, beside the light
/// cache: [`crate::scene_cache`]); `None`, the default, keeps nothing.
/// The scene plugin hands it the [`super::LightCacheDir`] of the moment.
#[derive(Debug, Default, Clone, serde::Serialize, serde::Deserialize)]
pub struct SceneLoaderSettings {
    /// The cache folder.
    pub cache_dir: Option<PathBuf>,
}

impl AssetLoader for SceneLoader {
    type Asset = SceneAsset;
    type Settings = SceneLoaderSettings;
    type Error = SceneError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        settings: &SceneLoaderSettings,
        load_context: &mut LoadContext<'_>,
    ) -> Result<SceneAsset, SceneError> {
        let scene_path = load_context.path().path().to_path_buf();
        let mut scene_bytes = Vec::new();
        reader
            .read_to_end(&mut scene_bytes)
            .await
            .map_err(|e| SceneError::new(scene::Location::file(&scene_path), format!("cannot read scene file: {e}")))?;
        let mut files = AssetFiles { context: load_context, first: Some((scene_path.clone(), scene_bytes)) };
        let (loaded, _) =
            scene_cache::load_scene_cached_with(&scene_path, &self.panels.catalog(), &mut files, settings.cache_dir.as_deref()).await?;
        for warning in &loaded.warnings {
            warn!("{warning}");
        }
        Ok(SceneAsset { scene: Arc::new(loaded.scene), warnings: loaded.warnings })
    }

    fn extensions(&self) -> &[&str] {
        &["toml"]
    }
}

/// The scene's files through the loader's context; the scene file itself was
/// already read by Bevy.
struct AssetFiles<'a, 'b> {
    context: &'a mut LoadContext<'b>,
    first: Option<(PathBuf, Vec<u8>)>,
}

impl SceneReader for AssetFiles<'_, '_> {
    async fn read(&mut self, path: &Path) -> io::Result<Vec<u8>> {
        if let Some((first, _)) = &self.first
            && first == path
        {
            return Ok(self.first.take().expect("checked above").1);
        }
        let asset_path = AssetPath::from_path_buf(path.to_path_buf()).with_source(self.context.path().source().clone_owned());
        self.context.read_asset_bytes(asset_path).await.map_err(|error| match error {
            bevy::asset::ReadAssetBytesError::AssetReaderError(AssetReaderError::NotFound(_)) => {
                io::Error::new(io::ErrorKind::NotFound, "not found")
            }
            other => io::Error::other(other.to_string()),
        })
    }
}

/// One line for a failed scene load: the loader's own message when it has
/// one, else Bevy's.
pub fn describe_load_failure(error: &AssetLoadError) -> String {
    match error {
        AssetLoadError::AssetLoaderError(failure) => match failure.error().downcast_ref::<SceneError>() {
            Some(scene_error) => scene_error.to_string(),
            None => failure.error().to_string(),
        },
        AssetLoadError::AssetReaderError(AssetReaderError::NotFound(path)) => {
            format!("{}: cannot read scene file: not found", path.display())
        }
        other => other.to_string(),
    }
    .replace('\n', " ")
}

/// The asset path of a scene file on disk: absolute, so that any file can be
/// opened (the app's `AssetPlugin` must allow unapproved paths, see
/// [`crate::asset_plugin`]).
pub fn scene_asset_path(path: &Path) -> AssetPath<'static> {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    AssetPath::from_path_buf(absolute)
}
