//! [`SurfaceLightingPlugin`]: the model's surfaces drawn with the light
//! engine's per-patch sky and interreflected light ([`LightingMaterial`],
//! shaders/lighting.wgsl). Each material gets one mesh holding both sides of
//! its surfaces (a wall lit on one side is dark on the other); vertex values
//! average the patches of one surface and side that meet there, so light is
//! smooth across patches and never bleeds over a crease. Under the patch
//! meshes lies the model's own (watertight) triangles, pushed back in depth
//! and shaded with each surface's mean: where patch clipping leaves
//! T-junctions between surfaces, a crack shows that instead of the sky.
//! Around the model lies the ground outside ([`GroundPlane`]), lit by the
//! sky here and by the sun in the sun pass, which draws the building's
//! shadow on it.

use std::collections::HashMap;
use std::f64::consts::PI;

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy::render::render_resource::{AsBindGroup, ShaderType};
use bevy::shader::ShaderRef;

use super::{HeliodonRenderSystems, RenderMode, RenderSettings};
use crate::ecs::{ActiveScene, LightingState, SceneSpawned, SunSky};
use crate::light::{Channels, LobeLook, PanelLook, side_of};
use crate::scene::{MaterialKind, Scene};
use crate::sky::LUMINOUS_EFFICACY;
use heliodon_core::sun_pass::GroundPlane;

pub struct SurfaceLightingPlugin;

impl Plugin for SurfaceLightingPlugin {
    fn build(&self, app: &mut App) {
        let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
        let _ =
            shaders.insert(LIGHTING_SHADER.id(), Shader::from_wgsl(include_str!("../../shaders/lighting.wgsl"), "shaders/lighting.wgsl"));
        app.add_plugins(MaterialPlugin::<LightingMaterial>::default()).add_systems(
            Update,
            (spawn_surface_meshes, update_surface_values, update_ground).chain().in_set(HeliodonRenderSystems::Surfaces),
        );
    }
}

const LIGHTING_SHADER: Handle<Shader> = bevy::asset::uuid_handle!("3c9a1e52-7d4b-4f60-9e2a-5b8c7d6e1f04");

/// Surfaces as the engine lights them; see shaders/lighting.wgsl.
#[derive(Asset, TypePath, AsBindGroup, Debug, Clone)]
#[uniform(0, LightingMaterialUniform)]
#[bind_group_data(LightingMaterialKey)]
pub struct LightingMaterial {
    /// Glass and panels: a display colour with coverage; opaque surfaces: alpha 1.
    pub tint: LinearRgba,
    pub mode: RenderMode,
    pub scale_max_lux: f32,
    /// Fragments above this height are not drawn ([`RenderSettings::section`]).
    pub section: f32,
    /// Fragments beyond this vertical plane (normal x, y, 0, offset) are not
    /// drawn ([`RenderSettings::vertical_section`]; a zero normal: none).
    pub vertical_section: Vec4,
    /// Drawn behind the patch meshes, filling their cracks.
    pub underlay: bool,
    /// A panel's look under the sun (none for other surfaces).
    pub panel: Option<PanelLookUniform>,
    /// The sky and ground a panel passes into the room, by the way the eye
    /// looks out through it (cd/m², a cubemap as wgpu samples them).
    #[texture(1, dimension = "cube")]
    #[sampler(2)]
    pub panel_sky: Option<Handle<Image>>,
}

/// The most lobes a panel is drawn with (the brightest when it has more).
const MAX_DRAWN_LOBES: usize = 8;

/// A panel's look for the shader ([`heliodon_core::light::PanelLook`]):
/// the side it is seen like this from, the diffuse sun's luminance,
/// whether the sky it passes is drawn (its cubemap, [`LightingMaterial::panel_sky`]),
/// and per lobe the way its light travels (xyz) with the cosine of its
/// cone's half angle (w), and its luminance.
#[derive(ShaderType, Debug, Clone, Copy, Default, PartialEq)]
pub struct PanelLookUniform {
    inward: Vec4,
    diffuse: f32,
    /// 1 where the mode draws the sky, else 0.
    sky: f32,
    lobe_count: u32,
    lobes: [Vec4; MAX_DRAWN_LOBES],
    lobe_luminance: [Vec4; MAX_DRAWN_LOBES],
}

impl PanelLookUniform {
    /// `look` as `mode` draws it: the sun's parts in the full and sun
    /// modes, the sky's in the full and sky modes.
    fn new(look: &PanelLook, mode: RenderMode) -> Self {
        let sun = mode.draws_sun();
        let mut lobes: Vec<&LobeLook> = look.lobes.iter().filter(|_| sun).collect();
        lobes.sort_by(|a, b| (b.luminance * b.half_angle * b.half_angle).total_cmp(&(a.luminance * a.half_angle * a.half_angle)));
        let mut uniform = Self {
            inward: look.inward.as_vec3().extend(0.0),
            diffuse: if sun { look.diffuse as f32 } else { 0.0 },
            sky: f32::from(u8::from(matches!(mode, RenderMode::Full | RenderMode::Sky))),
            lobe_count: lobes.len().min(MAX_DRAWN_LOBES) as u32,
            ..Default::default()
        };
        for (k, lobe) in lobes.into_iter().take(MAX_DRAWN_LOBES).enumerate() {
            uniform.lobes[k] = lobe.travel.as_vec3().extend(lobe.half_angle.cos() as f32);
            uniform.lobe_luminance[k] = Vec4::new(lobe.luminance as f32, 0.0, 0.0, 0.0);
        }
        uniform
    }
}

impl LightingMaterial {
    /// A surface's material under the view's `settings`.
    fn new(settings: &RenderSettings, tint: LinearRgba, underlay: bool) -> Self {
        Self {
            tint,
            mode: settings.mode,
            scale_max_lux: settings.false_colour_max_lux,
            section: section_height(settings),
            vertical_section: vertical_plane(settings),
            underlay,
            panel: None,
            panel_sky: None,
        }
    }
}

/// What changes the pipeline: the underlay's depth bias.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct LightingMaterialKey {
    underlay: bool,
}

impl From<&LightingMaterial> for LightingMaterialKey {
    fn from(material: &LightingMaterial) -> Self {
        Self { underlay: material.underlay }
    }
}

#[derive(ShaderType, Clone, Copy)]
pub struct LightingMaterialUniform {
    tint: Vec4,
    mode: u32,
    scale_max_lux: f32,
    section: f32,
    /// 1: a panel, drawn with its look.
    is_panel: u32,
    vertical_section: Vec4,
    panel: PanelLookUniform,
}

impl bevy::render::render_resource::AsBindGroupShaderType<LightingMaterialUniform> for LightingMaterial {
    fn as_bind_group_shader_type(
        &self,
        _: &bevy::render::render_asset::RenderAssets<bevy::render::texture::GpuImage>,
    ) -> LightingMaterialUniform {
        LightingMaterialUniform {
            tint: self.tint.to_vec4(),
            mode: u32::from(self.mode == RenderMode::FalseColour),
            scale_max_lux: self.scale_max_lux,
            section: self.section,
            is_panel: u32::from(self.panel.is_some()),
            vertical_section: self.vertical_section,
            panel: self.panel.unwrap_or_default(),
        }
    }
}

impl Material for LightingMaterial {
    fn fragment_shader() -> ShaderRef {
        LIGHTING_SHADER.into()
    }

    fn alpha_mode(&self) -> AlphaMode {
        match self.tint.alpha < 1.0 {
            // A panel: its own light from the room, its display colour over
            // what shows through from outside (lighting.wgsl).
            true if self.panel.is_some() => AlphaMode::Premultiplied,
            true => AlphaMode::Blend,
            false => AlphaMode::Opaque,
        }
    }

    fn specialize(
        _: &bevy::pbr::MaterialPipeline,
        descriptor: &mut bevy::render::render_resource::RenderPipelineDescriptor,
        _: &bevy::mesh::MeshVertexBufferLayoutRef,
        key: bevy::pbr::MaterialPipelineKey<Self>,
    ) -> Result<(), bevy::render::render_resource::SpecializedMeshPipelineError> {
        // Reverse Z: a negative bias moves the underlay away from the camera.
        if key.bind_group_data.underlay
            && let Some(depth) = descriptor.depth_stencil.as_mut()
        {
            depth.bias.constant = -16;
            depth.bias.slope_scale = -2.0;
        }
        Ok(())
    }
}

/// Glass as a faint blue-grey (its alpha is its opacity, 1 − τ), panels
/// amber: readable at any exposure (a panel seen from the room is drawn as
/// its own light instead, [`update_panel_looks`]).
const GLASS_TINT: LinearRgba = LinearRgba::new(0.35, 0.45, 0.55, 0.18);
const PANEL_TINT: LinearRgba = LinearRgba::new(0.7, 0.5, 0.2, 0.3);

/// A mesh of one diffuse material with how its vertices take the light.
#[derive(Component, Default)]
pub struct SurfaceValues {
    reflectance: [f32; 3],
    /// Per mesh vertex, its node.
    vertex_node: Vec<u32>,
    /// Per node, the patch sides meeting there with their weights (areas).
    nodes: Vec<Vec<(u32, f32)>>,
}

fn spawn_surface_meshes(
    mut commands: Commands,
    mut spawned: MessageReader<SceneSpawned>,
    active: Res<ActiveScene>,
    settings: Res<RenderSettings>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<LightingMaterial>>,
) {
    let Some(SceneSpawned { root, .. }) = spawned.read().last() else { return };
    let Some(scene) = &active.scene else { return };
    let ground = GroundPlane::of(scene);
    commands.spawn((
        Mesh3d(meshes.add(ground_mesh(&ground))),
        MeshMaterial3d(materials.add(LightingMaterial::new(&settings, LinearRgba::BLACK, false))),
        Ground(ground),
        ChildOf(*root),
    ));
    for (index, material) in scene.materials.iter().enumerate() {
        let Some((mesh, values)) = material_mesh(scene, index as u32) else { continue };
        let tint = match &material.kind {
            MaterialKind::Diffuse { .. } => LinearRgba::BLACK,
            // What lies beyond shows through by the glass's transmittance.
            MaterialKind::Glass { transmittance } => LinearRgba { alpha: (1.0 - transmittance).clamp(0.02, 1.0), ..GLASS_TINT },
            MaterialKind::Panel { .. } => PANEL_TINT,
        };
        let lighting = |underlay| LightingMaterial::new(&settings, tint, underlay);
        let is_panel = matches!(material.kind, MaterialKind::Panel { .. });
        let surface = LightingMaterial { panel: is_panel.then(PanelLookUniform::default), ..lighting(false) };
        let mut entity = commands.spawn((Mesh3d(meshes.add(mesh)), MeshMaterial3d(materials.add(surface)), ChildOf(*root)));
        if is_panel {
            entity.insert(PanelSurface(index as u32));
        }
        if let MaterialKind::Diffuse { reflectance } = &material.kind {
            entity.insert(SurfaceValues { reflectance: reflectance.0, ..values });
            let (mesh, values) = underlay_mesh(scene, index as u32);
            commands.spawn((
                Mesh3d(meshes.add(mesh)),
                MeshMaterial3d(materials.add(lighting(true))),
                SurfaceValues { reflectance: reflectance.0, ..values },
                ChildOf(*root),
            ));
        }
    }
}

/// The mesh of a panel material (index into the scene's materials).
#[derive(Component)]
pub struct PanelSurface(u32);

/// Panels as they look under the current sky ([`crate::light::LightModel::panel_looks`]):
/// the sky and ground they pass, by the way the eye looks out through them;
/// their lobes bright where the eye looks against one; the diffusely
/// transmitted sun everywhere.
pub(super) fn update_panel_looks(
    ray_model: Option<Res<crate::ecs::RayModel>>,
    sun_sky: Option<Res<SunSky>>,
    settings: Res<RenderSettings>,
    panels: Query<(&PanelSurface, &MeshMaterial3d<LightingMaterial>)>,
    added: Query<(), Added<PanelSurface>>,
    mut materials: ResMut<Assets<LightingMaterial>>,
    mut images: ResMut<Assets<Image>>,
) {
    let changed = ray_model.as_ref().is_some_and(|r| r.is_changed()) || sun_sky.as_ref().is_some_and(|s| s.is_changed());
    if panels.is_empty() || (!changed && !settings.is_changed() && added.is_empty()) {
        return;
    }
    let (Some(model), Some(sun_sky)) = (&ray_model, &sun_sky) else { return };
    let looks = model.0.panel_looks(&sun_sky.sky);
    for (panel, material) in &panels {
        let Some(look) = looks.iter().find(|l| l.material == panel.0) else { continue };
        let sky = super::sky::bake_cubemap(PANEL_SKY_FACE, |outward| [model.0.panel_sky_luminance(look, outward) as f32; 3]);
        if let Some(mut material) = materials.get_mut(&material.0) {
            material.panel = Some(PanelLookUniform::new(look, settings.mode));
            match &material.panel_sky {
                Some(handle) => {
                    let _ = images.insert(handle.id(), sky);
                }
                None => material.panel_sky = Some(images.add(sky)),
            }
        }
    }
}

/// Texels along a side of a panel's sky cubemap: the sky transfer is kept
/// per sky bin (Reinhart MF:n), a few degrees and more each.
const PANEL_SKY_FACE: usize = 16;

/// The ground outside, as drawn ([`GroundPlane`]).
#[derive(Component)]
pub struct Ground(GroundPlane);

/// The ground's square, facing up, with the same corners the sun pass
/// lights (so their depths match).
fn ground_mesh(ground: &GroundPlane) -> Mesh {
    let [a, b, c, d] = ground.corners();
    let mut builder = MeshBuilder::default();
    builder.triangle([a, b, c], Vec3::Z, [0; 3]);
    builder.triangle([a, c, d], Vec3::Z, [0; 3]);
    builder.build().0
}

/// The ground's sky light (cd/m²: ρ/π of the sky's horizontal irradiance,
/// as a surface open to the whole sky gets it) in the modes that draw the
/// sky; in sun mode the sun pass alone lights it. The indirect and
/// false-colour views are about the model's surfaces: no ground.
fn update_ground(
    sun_sky: Option<Res<SunSky>>,
    settings: Res<RenderSettings>,
    mut grounds: Query<(&Ground, &Mesh3d, &mut Visibility)>,
    added: Query<(), Added<Ground>>,
    mut meshes: ResMut<Assets<Mesh>>,
) {
    if !sun_sky.as_ref().is_some_and(|s| s.is_changed()) && !settings.is_changed() && added.is_empty() {
        return;
    }
    for (ground, mesh, mut visibility) in &mut grounds {
        let shown = matches!(settings.mode, RenderMode::Full | RenderMode::Sky | RenderMode::Sun);
        *visibility = if shown { Visibility::Inherited } else { Visibility::Hidden };
        let sky = sun_sky.as_ref().filter(|_| settings.mode != RenderMode::Sun).map_or(0.0, |s| s.sky.diffuse_horizontal);
        let luminance = (f64::from(ground.0.reflectance) / PI * sky * LUMINOUS_EFFICACY) as f32;
        if let Some(mut mesh) = meshes.get_mut(&mesh.0) {
            let vertices = mesh.count_vertices();
            mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, vec![[luminance, luminance, luminance, 1.0]; vertices]);
        }
    }
}

/// Both sides of the model's triangles of a diffuse `material`, each
/// surface side one node holding all its patches.
fn underlay_mesh(scene: &Scene, material: u32) -> (Mesh, SurfaceValues) {
    let mut builder = MeshBuilder::default();
    for surface in scene.surfaces.iter().filter(|s| s.material == material) {
        for back in [false, true] {
            let sides: Vec<(u32, f32)> =
                (surface.patches.clone()).map(|p| (side_of(p, back), scene.patches.patches[p as usize].area)).collect();
            let node = builder.values.nodes.len() as u32;
            builder.values.nodes.push(sides);
            let normal = if back { -surface.normal } else { surface.normal };
            for triangle in &scene.triangles[surface.triangle_indices()] {
                let [a, b, c] = triangle.vertices;
                builder.triangle(if back { [a, c, b] } else { [a, b, c] }, normal, [node; 3]);
            }
        }
    }
    builder.build()
}

/// Vertices with their nodes, and the indexed mesh they make: a vertex is
/// shared by the triangles that meet there with the same node, so a
/// surface side's patches hold each corner once, not once per triangle
/// (the furnished floor of offices: 3.67 → 1.17 million vertices, in the
/// app's mesh, its GPU copy and the upload's staging; on a software driver
/// all three are process memory).
#[derive(Default)]
struct MeshBuilder {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u32>,
    vertex_of: HashMap<(u32, [u32; 3]), u32>,
    values: SurfaceValues,
}

impl MeshBuilder {
    fn triangle(&mut self, vertices: [Vec3; 3], normal: Vec3, nodes: [u32; 3]) {
        for (v, node) in vertices.into_iter().zip(nodes) {
            let count = self.positions.len() as u32;
            let vertex = *self.vertex_of.entry((node, v.to_array().map(f32::to_bits))).or_insert(count);
            if vertex == count {
                self.values.vertex_node.push(node);
                self.positions.push(v.to_array());
                self.normals.push(normal.to_array());
            }
            self.indices.push(vertex);
        }
    }

    fn build(self) -> (Mesh, SurfaceValues) {
        let colours = vec![[0.0f32; 4]; self.positions.len()];
        let mesh = Mesh::new(PrimitiveTopology::TriangleList, RenderAssetUsages::default())
            .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, self.positions)
            .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, self.normals)
            .with_inserted_attribute(Mesh::ATTRIBUTE_COLOR, colours)
            .with_inserted_indices(Indices::U32(self.indices));
        (mesh, self.values)
    }
}

/// Two surfaces whose normals meet at a corner within this angle's cosine
/// (30°) are one curved sheet there: a hill or a round column tessellated
/// into facets, whose corners show the mean of the facets that meet.
const SMOOTH_CREASE_COS: f32 = 0.866;

/// Both sides of every patch of `material` (the back side wound the other
/// way), with vertex nodes shared within one surface and side; a node also
/// averages the other surfaces' sides meeting at its corner within
/// [`SMOOTH_CREASE_COS`] ([`smooth_shallow_creases`]).
fn material_mesh(scene: &Scene, material: u32) -> Option<(Mesh, SurfaceValues)> {
    let mut builder = MeshBuilder::default();
    let mut node_of: HashMap<(u32, bool, [i64; 3]), u32> = HashMap::new();
    let mut node_normals: Vec<Vec3> = Vec::new();
    for (p, patch) in scene.patches.patches.iter().enumerate().filter(|(_, p)| p.material == material) {
        let triangles = &scene.patches.triangles[patch.triangle_indices()];
        for back in [false, true] {
            let side = side_of(p as u32, back);
            let normal = if back { -patch.normal } else { patch.normal };
            for triangle in triangles {
                let t = if back { [triangle[0], triangle[2], triangle[1]] } else { *triangle };
                let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                let nodes = t.map(|v| {
                    let nodes = &mut builder.values.nodes;
                    let key = (patch.surface, back, v.to_array().map(|c| (f64::from(c) * 1e4).round() as i64));
                    let node = *node_of.entry(key).or_insert(nodes.len() as u32);
                    if node as usize == nodes.len() {
                        nodes.push(Vec::new());
                        node_normals.push(normal);
                    }
                    nodes[node as usize].push((side, area));
                    node
                });
                builder.triangle(t, normal, nodes);
            }
        }
    }
    let mut corners: Vec<([i64; 3], u32)> = node_of.into_iter().map(|((_, _, corner), node)| (corner, node)).collect();
    corners.sort_unstable();
    smooth_shallow_creases(&mut builder.values.nodes, &corners, &node_normals);
    (!builder.positions.is_empty()).then(|| builder.build())
}

/// Adds to each node the patch sides of the other nodes at its corner
/// (`corners`: (corner, node), sorted) whose normal is within
/// [`SMOOTH_CREASE_COS`] of its own: the facets of a curved sheet (a
/// terrain, a cylinder, whose clutter also falls into clusters by the main
/// direction of their normals) then shade smoothly into each other, where
/// each facet alone showed its own patch's light as a blotch. Walls
/// meeting a floor, a roof's two slopes, a surface's two sides stay apart.
fn smooth_shallow_creases(nodes: &mut [Vec<(u32, f32)>], corners: &[([i64; 3], u32)], normals: &[Vec3]) {
    let smooth = |a: u32, b: u32| a != b && normals[a as usize].dot(normals[b as usize]) >= SMOOTH_CREASE_COS;
    for meeting in corners.chunk_by(|a, b| a.0 == b.0) {
        // Most corners are creases alone (a box's): nothing to copy there.
        if !meeting.iter().any(|&(_, a)| meeting.iter().any(|&(_, b)| smooth(a, b))) {
            continue;
        }
        let own: Vec<Vec<(u32, f32)>> = meeting.iter().map(|&(_, node)| nodes[node as usize].clone()).collect();
        for &(_, node) in meeting {
            for (&(_, other), sides) in meeting.iter().zip(&own) {
                if smooth(node, other) {
                    nodes[node as usize].extend_from_slice(sides);
                }
            }
        }
    }
}

/// What a patch side shows in a mode: luminance (cd/m², RGB) or, for false
/// colour, illuminance (lux) in the first channel.
pub fn side_value(channels: &Channels, reflectance: [f32; 3], mode: RenderMode) -> [f32; 3] {
    let luminance = |irradiance: [f64; 3]| [0, 1, 2].map(|c| (f64::from(reflectance[c]) / PI * irradiance[c] * LUMINOUS_EFFICACY) as f32);
    match mode {
        // The sun pass draws the sun's beams; panels' diffuse sunlight is drawn here.
        RenderMode::Full => luminance(channels.indirect.map(|i| i + channels.sky + channels.sun_diffuse)),
        RenderMode::Sun => [0.0; 3],
        RenderMode::Sky => luminance([channels.sky; 3]),
        RenderMode::Indirect => luminance(channels.indirect),
        RenderMode::FalseColour => [((channels.sun + channels.sky + channels.indirect_luminous()) * LUMINOUS_EFFICACY) as f32, 0.0, 0.0],
    }
}

/// The height above which surfaces are not drawn (none: out of reach).
fn section_height(settings: &RenderSettings) -> f32 {
    settings.section.unwrap_or(f32::MAX)
}

/// The vertical section's plane (none: a zero normal, nothing is beyond it).
fn vertical_plane(settings: &RenderSettings) -> Vec4 {
    settings.vertical_section.map_or(Vec4::ZERO, |v| v.plane())
}

fn update_surface_values(
    state: Option<Res<LightingState>>,
    settings: Res<RenderSettings>,
    surfaces: Query<(&Mesh3d, &MeshMaterial3d<LightingMaterial>, Option<&SurfaceValues>)>,
    added: Query<(), Added<SurfaceValues>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<LightingMaterial>>,
) {
    if !state.as_ref().is_some_and(|s| s.is_changed()) && !settings.is_changed() && added.is_empty() {
        return;
    }
    for (mesh, material, values) in &surfaces {
        if settings.is_changed()
            && let Some(mut material) = materials.get_mut(&material.0)
        {
            material.mode = settings.mode;
            material.scale_max_lux = settings.false_colour_max_lux;
            material.section = section_height(&settings);
            material.vertical_section = vertical_plane(&settings);
        }
        let (Some(values), Some(lighting)) = (values, state.as_ref().and_then(|s| s.lighting.as_ref())) else { continue };
        let node_values: Vec<[f32; 3]> = values
            .nodes
            .iter()
            .map(|sides| {
                let total: f32 = sides.iter().map(|s| s.1).sum();
                let mut sum = [0.0f32; 3];
                for &(side, weight) in sides {
                    let value = side_value(&lighting.sides[side as usize], values.reflectance, settings.mode);
                    (0..3).for_each(|c| sum[c] += weight * value[c]);
                }
                sum.map(|s| s / total.max(f32::MIN_POSITIVE))
            })
            .collect();
        let colours: Vec<[f32; 4]> = values
            .vertex_node
            .iter()
            .map(|&n| {
                let [r, g, b] = node_values[n as usize];
                [r, g, b, 1.0]
            })
            .collect();
        if let Some(mut mesh) = meshes.get_mut(&mesh.0) {
            mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, colours);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Facets of a curved sheet share their light at a corner; a wall on a
    /// floor, or a surface's other side, does not.
    #[test]
    fn corners_average_facets_meeting_at_a_shallow_crease_only() {
        let tilted = |degrees: f32| Vec3::new(degrees.to_radians().sin(), 0.0, degrees.to_radians().cos());
        // Node: a facet, the next facet of a hill 20° on, a wall (90°), the first facet's back,
        // and the first facet again at another corner.
        let normals = [Vec3::Z, tilted(20.0), Vec3::X, -Vec3::Z, Vec3::Z];
        let mut nodes: Vec<Vec<(u32, f32)>> = vec![vec![(0, 1.0)], vec![(2, 0.5)], vec![(4, 2.0)], vec![(1, 1.0)], vec![(0, 1.0)]];
        let corner = [0, 0, 0];
        let mut corners = vec![(corner, 0), (corner, 1), (corner, 2), (corner, 3), ([1, 0, 0], 4)];
        corners.sort_unstable();
        smooth_shallow_creases(&mut nodes, &corners, &normals);
        assert_eq!(nodes[0], vec![(0, 1.0), (2, 0.5)]);
        assert_eq!(nodes[1], vec![(2, 0.5), (0, 1.0)]);
        assert_eq!(nodes[2], vec![(4, 2.0)]);
        assert_eq!(nodes[3], vec![(1, 1.0)]);
        assert_eq!(nodes[4], vec![(0, 1.0)]);
        // Past the crease angle, facets keep their own light.
        let mut apart: Vec<Vec<(u32, f32)>> = vec![vec![(0, 1.0)], vec![(2, 1.0)]];
        smooth_shallow_creases(&mut apart, &[(corner, 0), (corner, 1)], &[Vec3::Z, tilted(35.0)]);
        assert_eq!(apart, vec![vec![(0, 1.0)], vec![(2, 1.0)]]);
    }
}
