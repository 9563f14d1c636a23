//! [`ScenePlugin`]: opens scene files ([`OpenScene`]), and once loaded
//! replaces the scene's entities: one per material, surface, window and
//! sensor, under one [`SceneRoot`], the [`Site`] resource and the scene's
//! ray-query model ([`RayModel`]). Materials are edited at run time
//! ([`EditMaterial`], [`GiveOwnMaterial`]).

use std::ops::{Deref, Range};
use std::path::PathBuf;
use std::sync::Arc;

use bevy::asset::AssetLoadFailedEvent;
use bevy::prelude::*;

use super::scene_asset::{SceneAsset, SceneLoader, SceneLoaderSettings, describe_load_failure, scene_asset_path};
use super::{HeliodonSystems, LightCacheDir, PanelRegistry};
use crate::light::LightModel;
use crate::scene::{self, Scene};

pub struct ScenePlugin;

impl Plugin for ScenePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<PanelRegistry>()
            .init_asset::<SceneAsset>()
            .init_asset_loader::<SceneLoader>()
            .init_resource::<ActiveScene>()
            .add_message::<OpenScene>()
            .add_message::<SceneSpawned>()
            .add_message::<SceneLoadFailed>()
            .add_message::<EditMaterial>()
            .add_message::<GiveOwnMaterial>()
            .add_message::<MaterialEditRejected>()
            .configure_sets(
                Update,
                (HeliodonSystems::LoadScene, HeliodonSystems::SpawnScene, HeliodonSystems::UpdateSunSky, HeliodonSystems::Lighting).chain(),
            )
            .add_systems(Update, request_scene.in_set(HeliodonSystems::LoadScene))
            .add_systems(
                Update,
                ((spawn_loaded_scene, report_failed_load, apply_material_edits), make_ray_model)
                    .chain()
                    .in_set(HeliodonSystems::SpawnScene),
            );
    }
}

/// The active scene's ray-query model (no light gathered,
/// [`LightModel::unlit`]): its patch and shadow tracers, panel windows and
/// their lobes, for the sun pass, the viewer's clicks and lobe arrows. Made
/// when a scene is spawned; the light engine's precomputation takes its
/// tracers rather than building them again (on the furnished floor of
/// offices, two BVHs of about 300,000 triangles each).
#[derive(Resource, Clone)]
pub struct RayModel(pub Arc<LightModel>);

impl RayModel {
    /// The model, where it is `scene`'s (the same `Arc`): a scene just
    /// replaced may still have its predecessor's for a frame.
    pub fn of(&self, scene: &Arc<Scene>) -> Option<&Arc<LightModel>> {
        Arc::ptr_eq(&self.0.scene, scene).then_some(&self.0)
    }
}

/// Makes the [`RayModel`] of a scene just spawned.
fn make_ray_model(mut commands: Commands, active: Res<ActiveScene>, ray_model: Option<Res<RayModel>>) {
    let Some(scene) = active.scene.as_ref().filter(|_| active.is_changed()) else { return };
    if ray_model.is_none_or(|m| m.of(scene).is_none()) {
        commands.insert_resource(RayModel(Arc::new(LightModel::unlit(scene.clone()))));
    }
}

/// Ask for a scene file to be opened (replacing the current scene).
#[derive(Message, Debug, Clone)]
pub struct OpenScene(pub PathBuf);

/// The scene's entities were (re)spawned.
#[derive(Message, Debug, Clone)]
pub struct SceneSpawned {
    pub root: Entity,
    /// The same scene again with edited materials (a view need not reset).
    pub edited: bool,
}

/// Change a material of the active scene: a diffuse one's reflectance, or a
/// window material between glass and a registered panel. The scene is
/// spawned again and its light recomputed.
#[derive(Message, Debug, Clone)]
pub struct EditMaterial {
    pub index: u32,
    pub kind: scene::MaterialKind,
}

/// Give some surfaces (a group of windows) a material of their own, a copy
/// of the one they share with others, so it can be edited alone
/// ([`Scene::give_own_material`]). The scene is spawned again.
#[derive(Message, Debug, Clone)]
pub struct GiveOwnMaterial {
    pub surfaces: Vec<u32>,
    pub name: String,
}

/// An edit that cannot apply (a diffuse material made a window, or the
/// reverse); one line.
#[derive(Message, Debug, Clone, PartialEq, Eq)]
pub struct MaterialEditRejected {
    pub message: String,
}

/// A requested scene could not be loaded; `message` is one line.
#[derive(Message, Debug, Clone)]
pub struct SceneLoadFailed {
    pub path: PathBuf,
    pub message: String,
}

/// The scene being shown, and the one being loaded.
#[derive(Resource, Default)]
pub struct ActiveScene {
    /// The scene shown, edits included, once there is one.
    pub scene: Option<Arc<Scene>>,
    /// The same scene as its file gives it (what the edits are made on).
    pub loaded: Option<Arc<Scene>>,
    pub root: Option<Entity>,
    /// The file it was opened from.
    pub path: Option<PathBuf>,
    pending: Option<(PathBuf, Handle<SceneAsset>)>,
}

impl ActiveScene {
    pub fn is_loading(&self) -> bool {
        self.pending.is_some()
    }
}

/// The site of the active scene.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct Site(pub crate::site::Site);

impl Deref for Site {
    type Target = crate::site::Site;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

/// The entity all of a scene's entities hang under; despawning it removes the scene.
#[derive(Component, Debug)]
pub struct SceneRoot;

#[derive(Component, Debug, Clone)]
pub struct SceneMaterial {
    /// Index into [`Scene::materials`].
    pub index: u32,
    pub material: scene::Material,
}

/// A surface and the lighting patches it is cut into.
#[derive(Component, Debug, Clone)]
pub struct SceneSurface {
    /// Index into [`Scene::surfaces`].
    pub index: u32,
    pub patches: Range<u32>,
    pub area: f32,
    pub normal: Vec3,
}

/// The material entity of a surface or window.
#[derive(Component, Debug, Clone, Copy)]
pub struct MaterialOf(pub Entity);

/// An aperture (glass or panel).
#[derive(Component, Debug, Clone)]
pub struct SceneWindow {
    /// Index into [`Scene::windows`].
    pub index: u32,
    pub window: scene::Window,
}

#[derive(Component, Debug, Clone)]
pub struct SceneSensor(pub scene::Sensor);

/// Starts loading the scene last asked for, through the scene cache in the
/// light cache's folder (where there is one).
fn request_scene(
    mut requests: MessageReader<OpenScene>,
    asset_server: Res<AssetServer>,
    cache_dir: Option<Res<LightCacheDir>>,
    mut active: ResMut<ActiveScene>,
) {
    if let Some(OpenScene(path)) = requests.read().last() {
        let cache_dir = cache_dir.and_then(|dir| dir.0.clone());
        let handle = asset_server
            .load_builder()
            .with_settings(move |settings: &mut SceneLoaderSettings| settings.cache_dir.clone_from(&cache_dir))
            .load(scene_asset_path(path));
        active.pending = Some((path.clone(), handle));
    }
}

fn spawn_loaded_scene(
    mut commands: Commands,
    mut active: ResMut<ActiveScene>,
    assets: Res<Assets<SceneAsset>>,
    asset_server: Res<AssetServer>,
    mut spawned: MessageWriter<SceneSpawned>,
) {
    let Some((_, handle)) = &active.pending else { return };
    if !asset_server.is_loaded_with_dependencies(handle.id()) {
        return;
    }
    let Some(asset) = assets.get(handle) else { return };
    let scene = asset.scene.clone();
    if let Some(old) = active.root.take() {
        commands.entity(old).despawn();
    }
    let root = spawn_scene(&mut commands, &scene);
    commands.insert_resource(Site(scene.site));
    active.path = active.pending.take().map(|(path, _)| path);
    active.loaded = Some(scene.clone());
    active.scene = Some(scene);
    active.root = Some(root);
    spawned.write(SceneSpawned { root, edited: false });
}

/// Applies material edits: the scene with the new materials replaces the
/// active one (same geometry, surfaces and windows).
fn apply_material_edits(
    mut commands: Commands,
    mut edits: MessageReader<EditMaterial>,
    mut splits: MessageReader<GiveOwnMaterial>,
    mut active: ResMut<ActiveScene>,
    mut spawned: MessageWriter<SceneSpawned>,
    mut rejected: MessageWriter<MaterialEditRejected>,
) {
    let edits: Vec<EditMaterial> = edits.read().cloned().collect();
    let splits: Vec<GiveOwnMaterial> = splits.read().cloned().collect();
    if edits.is_empty() && splits.is_empty() {
        return;
    }
    let Some(current) = active.scene.clone() else { return };
    let mut scene = (*current).clone();
    for split in splits {
        if scene.give_own_material(&split.surfaces, split.name.clone()).is_none() {
            rejected.write(MaterialEditRejected { message: format!("'{}': the surfaces given do not share one material", split.name) });
        }
    }
    for edit in edits {
        let Some(material) = scene.materials.get_mut(edit.index as usize) else { continue };
        if material.kind.transmits() != edit.kind.transmits() {
            rejected.write(MaterialEditRejected {
                message: format!("material '{}' is a {}; it cannot become a {}", material.name, material.kind.label(), edit.kind.label()),
            });
            continue;
        }
        material.kind = edit.kind;
    }
    if let Some(old) = active.root.take() {
        commands.entity(old).despawn();
    }
    let root = spawn_scene(&mut commands, &scene);
    active.scene = Some(Arc::new(scene));
    active.root = Some(root);
    spawned.write(SceneSpawned { root, edited: true });
}

fn report_failed_load(
    mut failures: MessageReader<AssetLoadFailedEvent<SceneAsset>>,
    mut active: ResMut<ActiveScene>,
    mut failed: MessageWriter<SceneLoadFailed>,
) {
    for failure in failures.read() {
        let Some((path, handle)) = &active.pending else { continue };
        if handle.id() != failure.id {
            continue;
        }
        let message = describe_load_failure(&failure.error);
        failed.write(SceneLoadFailed { path: path.clone(), message });
        active.pending = None;
    }
}

fn spawn_scene(commands: &mut Commands, scene: &Scene) -> Entity {
    let root = commands.spawn((SceneRoot, Name::new(scene.name.clone()), Transform::default(), Visibility::default())).id();
    let materials: Vec<Entity> = scene
        .materials
        .iter()
        .enumerate()
        .map(|(index, material)| {
            commands
                .spawn((SceneMaterial { index: index as u32, material: material.clone() }, Name::new(material.name.clone()), ChildOf(root)))
                .id()
        })
        .collect();
    for (index, surface) in scene.surfaces.iter().enumerate() {
        commands.spawn((
            SceneSurface { index: index as u32, patches: surface.patches.clone(), area: surface.area, normal: surface.normal },
            MaterialOf(materials[surface.material as usize]),
            ChildOf(root),
        ));
    }
    for (index, window) in scene.windows.iter().enumerate() {
        commands.spawn((
            SceneWindow { index: index as u32, window: window.clone() },
            MaterialOf(materials[window.material as usize]),
            ChildOf(root),
        ));
    }
    for sensor in &scene.sensors {
        commands.spawn((SceneSensor(sensor.clone()), Name::new(sensor.name.clone()), ChildOf(root)));
    }
    root
}
