//! [`HeliodonRenderPlugin`]: draws the active scene. For now plain shading
//! (each material's reflectance under a fixed key light and ambient light);
//! the hybrid sun/sky/indirect renderer replaces it. Also builds the initial
//! view of a scene, and renders offscreen ([`offscreen`]).

pub mod offscreen;

use bevy::asset::RenderAssetUsages;
use bevy::mesh::PrimitiveTopology;
use bevy::prelude::*;

use crate::ecs::{ActiveScene, HeliodonSystems, SceneSpawned};
use crate::scene::{DEFAULT_FOV, MaterialKind, Scene, Viewpoint};

pub struct HeliodonRenderPlugin;

/// What shows where there is no model: a pale sky.
pub const BACKGROUND: Color = Color::srgb(0.82, 0.86, 0.9);

impl Plugin for HeliodonRenderPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(GlobalAmbientLight { color: Color::WHITE, brightness: 400.0, ..default() })
            .insert_resource(ClearColor(BACKGROUND))
            .add_systems(Startup, spawn_key_light)
            .add_systems(Update, spawn_scene_meshes.after(HeliodonSystems::SpawnScene));
    }
}

fn spawn_key_light(mut commands: Commands) {
    // From the south-west, high: every orientation gets a different shade.
    commands.spawn((
        DirectionalLight { illuminance: 4000.0, shadow_maps_enabled: false, ..default() },
        Transform::from_xyz(-1.0, -2.0, 3.0).looking_at(Vec3::ZERO, Vec3::Z),
    ));
}

/// One mesh per material, made of the patch mesh's render triangles, under
/// the scene root so it goes with the scene.
fn spawn_scene_meshes(
    mut commands: Commands,
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let Some(SceneSpawned { root }) = spawned.read().last() else { return };
    let Some(scene) = &active.scene else { return };
    for (index, material) in scene.materials.iter().enumerate() {
        let Some(mesh) = material_mesh(scene, index as u32) else { continue };
        commands.spawn((
            Mesh3d(meshes.add(mesh)),
            MeshMaterial3d(materials.add(plain_material(&material.kind))),
            ChildOf(*root),
        ));
    }
}

fn material_mesh(scene: &Scene, material: u32) -> Option<Mesh> {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for patch in scene.patches.patches.iter().filter(|p| p.material == material) {
        for triangle in &scene.patches.triangles[patch.triangles.start as usize..patch.triangles.end as usize] {
            positions.extend(triangle.map(|v| v.to_array()));
            normals.extend([patch.normal.to_array(); 3]);
        }
    }
    if positions.is_empty() {
        return None;
    }
    Some(
        Mesh::new(PrimitiveTopology::TriangleList, RenderAssetUsages::default())
            .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
            .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals),
    )
}

/// Faces are single-sided in the model but reflect on both sides, as in Radiance.
fn plain_material(kind: &MaterialKind) -> StandardMaterial {
    let two_sided = StandardMaterial {
        double_sided: true,
        cull_mode: None,
        perceptual_roughness: 0.95,
        reflectance: 0.0,
        ..default()
    };
    match kind {
        MaterialKind::Diffuse { reflectance } => {
            let [r, g, b] = reflectance.0;
            StandardMaterial { base_color: Color::linear_rgb(r, g, b), ..two_sided }
        }
        MaterialKind::Glass { .. } => StandardMaterial {
            base_color: Color::linear_rgba(0.55, 0.75, 0.9, 0.25),
            alpha_mode: AlphaMode::Blend,
            ..two_sided
        },
        MaterialKind::Panel { .. } => StandardMaterial {
            base_color: Color::linear_rgba(0.9, 0.75, 0.4, 0.4),
            alpha_mode: AlphaMode::Blend,
            ..two_sided
        },
    }
}

/// The view a scene opens on: its first `[[cameras]]` entry, else the whole
/// model seen from the south-west and above.
pub fn initial_view(scene: &Scene) -> Viewpoint {
    if let Some(first) = scene.viewpoints.first() {
        return first.clone();
    }
    let fov = DEFAULT_FOV;
    let (target, distance) = framing(scene.bounds, fov);
    Viewpoint {
        name: "overview".into(),
        eye: target + Vec3::new(-0.55, -0.75, 0.55).normalize() * distance,
        target,
        fov,
    }
}

/// Centre of the bounds and the distance at which a camera with this vertical
/// field of view sees all of them.
pub fn framing((lo, hi): (Vec3, Vec3), fov_degrees: f32) -> (Vec3, f32) {
    let centre = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(0.1);
    (centre, 1.1 * radius / (fov_degrees.to_radians() / 2.0).sin())
}
