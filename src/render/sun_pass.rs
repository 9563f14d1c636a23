//! [`SunPassPlugin`]: direct sun per pixel with stencil shadow volumes, the
//! thesis' algorithm 1, as a render system in Bevy's `Core3d` schedule after
//! the opaque pass.
//!
//! Per frame and view, in one render pass on the view's HDR target:
//! 1. the main depth (no stencil in Bevy) is copied into the pass's own
//!    `Depth24PlusStencil8` target, stencil cleared;
//! 2. the volumes of every opaque surface are counted into the low 7 stencil
//!    bits (depth-fail: front faces decrement, back faces increment where the
//!    depth test fails, so a camera inside a volume is still right);
//! 3. for every light through a window (the sun through each pane facing it;
//!    later each panel lobe, as a fake sun): that window's volume toggles the
//!    top bit, the lit surfaces are drawn again where the stencil reads
//!    exactly "top bit set, no opaque volume" adding ρ/π · E · τ · cos θ,
//!    and the window's volume is drawn again to clear the bit;
//! 4. the windows' volumes are added to the count and the sun is added where
//!    nothing at all is in the way (the outside of the building).
//!
//! The main world prepares what to draw ([`SunPassFrame`]) when the scene,
//! the sun or the render mode change; the render world uploads it once per
//! change.

use std::ops::Range;
use std::sync::Arc;

use bevy::core_pipeline::schedule::Core3d;
use bevy::core_pipeline::{Core3dSystems, FullscreenShader};
use bevy::core_pipeline::core_3d::main_opaque_pass_3d;
use bevy::core_pipeline::core_3d::main_transparent_pass_3d;
use bevy::mesh::VertexBufferLayout;
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::extract_component::{ExtractComponent, ExtractComponentPlugin};
use bevy::render::extract_resource::{ExtractResource, ExtractResourcePlugin};
use bevy::render::render_resource::binding_types::{texture_depth_2d, uniform_buffer};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::texture::{CachedTexture, TextureCache};
use bevy::render::view::{ViewDepthTexture, ViewTarget, ViewUniform, ViewUniformOffset, ViewUniforms};
use bevy::render::{Render, RenderApp, RenderStartup, RenderSystems};

use super::shadow_volume::shadow_volume;
use crate::light::{Glass, LightModel};
use crate::scene::{MaterialKind, Scene, clip_convex};
use crate::sky::SunSource;

/// Depth bias of the opaque casters' caps, away from the camera (reverse Z:
/// negative), so the lit face of a caster, which is its volume's near cap,
/// counts as outside despite rounding.
const CAP_DEPTH_BIAS: DepthBiasState = DepthBiasState { constant: -16, slope_scale: -2.0, clamp: 0.0 };
/// Stencil bits counting opaque volumes, and the bit a window's volume toggles.
const COUNT_BITS: u32 = 0x7f;
const WINDOW_BIT: u32 = 0x80;

pub struct SunPassPlugin;

/// Marks the cameras that get the sun pass (they need `Hdr`, `Msaa::Off`
/// and a sampleable depth texture; [`super::hybrid_camera`] sets them up).
#[derive(Component, Clone, Copy, Default, ExtractComponent)]
pub struct SunPassView;

/// A light along a pass's direction and the aperture it comes through.
#[derive(Debug, Clone, PartialEq)]
pub struct SunLight {
    /// Unit vector toward the light (the sun, or a lobe's fake sun).
    pub direction: Vec3,
    /// Irradiance normal to `direction` after the window, W/m².
    pub irradiance: f32,
    /// The aperture's volume (range in [`SunPassFrame::volumes`]); `None`:
    /// light that meets no surface at all (the outside of the model), with
    /// every window's volume counted as blocking.
    pub aperture: Option<Range<u32>>,
}

/// Everything drawn for one light direction: the opaque casters' volume
/// along it, then its lights.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectionPass {
    pub opaque_caps: Range<u32>,
    pub opaque_sides: Range<u32>,
    /// Every window's volume along this direction (for the outside light).
    pub all_windows: Range<u32>,
    pub lights: Vec<SunLight>,
}

/// What the sun pass draws for the current scene, sun and mode.
pub struct SunPassFrame {
    /// Counts changes, so the render world uploads each frame only once.
    pub generation: u64,
    /// Lit surfaces as interleaved position, normal, albedo (9 floats per vertex).
    pub lit: Arc<Vec<f32>>,
    /// All shadow volumes, referred to by ranges.
    pub volumes: Vec<Vec4>,
    /// The sun's direction first, then each panel lobe's.
    pub passes: Vec<DirectionPass>,
}

/// The main world's hand-over to the render world; `None` draws nothing.
#[derive(Resource, Clone, Default, ExtractResource)]
pub struct SunPassInput(pub Option<Arc<SunPassFrame>>);

impl SunPassFrame {
    /// The passes for `scene` under `sun`, sharing `lit` (see
    /// [`lit_vertices`]); `model` knows the panel windows and their lobes.
    /// The sun's pass lights through glass (Radiance's transmittance at each
    /// aperture's angle) and the outside; each panel lobe is a fake sun with
    /// a pass of its own through its panel's windows (the thesis' 1 + 2·k·d
    /// passes). The real sun's shading of a panel from outside is not drawn
    /// for lobes yet (the engine's numbers include it).
    pub fn new(scene: &Scene, model: &LightModel, lit: Arc<Vec<f32>>, sun: &SunSource, generation: u64) -> Self {
        let surface_triangles = |surface: u32| {
            let range = scene.surfaces[surface as usize].triangles.clone();
            scene.triangles[range.start as usize..range.end as usize].iter().map(|t| t.vertices)
        };
        let opaque_casters: Vec<[Vec3; 3]> = scene
            .triangles
            .iter()
            .filter(|t| matches!(scene.materials[t.material as usize].kind, MaterialKind::Diffuse { .. }))
            .map(|t| t.vertices)
            .collect();
        // Apertures: glass windows of one material facing one way pass the
        // sun alike; panel windows go by the engine's panel groups.
        #[derive(PartialEq)]
        enum Key {
            Glass(u32, [i32; 3]),
            Panel(u32),
        }
        let mut apertures: Vec<(Key, Vec<[Vec3; 3]>, Vec3)> = Vec::new();
        for window in &scene.windows {
            let key = match model.panel_group_of_surface(window.surface) {
                Some(group) => Key::Panel(group),
                None => Key::Glass(window.material, window.normal.to_array().map(|c| (c * 1e4).round() as i32)),
            };
            match apertures.iter_mut().find(|a| a.0 == key) {
                Some(aperture) => aperture.1.extend(surface_triangles(window.surface)),
                None => apertures.push((key, surface_triangles(window.surface).collect(), window.normal)),
            }
        }
        let mut volumes: Vec<Vec4> = Vec::new();
        let add_volume = |casters: &[[Vec3; 3]], direction: Vec3, volumes: &mut Vec<Vec4>| {
            let volume = shadow_volume(casters, direction);
            let start = volumes.len() as u32;
            let caps = start..start + volume.caps.len() as u32;
            volumes.extend(volume.caps);
            volumes.extend(volume.sides);
            (caps.clone(), caps.end..volumes.len() as u32)
        };
        let direction_pass = |casters: &[[Vec3; 3]], direction: Vec3, volumes: &mut Vec<Vec4>| {
            let (opaque_caps, opaque_sides) = add_volume(casters, direction, volumes);
            DirectionPass { opaque_caps, opaque_sides, all_windows: 0..0, lights: Vec::new() }
        };
        let to_sun = sun.direction.as_vec3();
        let mut sun_pass = direction_pass(&opaque_casters, to_sun, &mut volumes);
        let windows_start = volumes.len() as u32;
        let mut aperture_volumes = Vec::new();
        for (_, panes, _) in &apertures {
            let (caps, sides) = add_volume(panes, to_sun, &mut volumes);
            aperture_volumes.push(caps.start..sides.end);
        }
        sun_pass.all_windows = windows_start..volumes.len() as u32;
        let beams = model.sun_beams(sun);
        let mut lobe_passes = Vec::new();
        for ((key, panes, normal), volume) in apertures.iter().zip(aperture_volumes) {
            match key {
                Key::Glass(material, _) => {
                    let cos = f64::from(normal.dot(to_sun));
                    let transmittance = match &scene.materials[*material as usize].kind {
                        MaterialKind::Glass { transmittance } => Glass::from_transmittance(f64::from(*transmittance)).at(cos).0,
                        _ => 1.0,
                    };
                    if cos.abs() > 1e-6 {
                        let irradiance = (sun.normal_irradiance() * transmittance) as f32;
                        sun_pass.lights.push(SunLight { direction: to_sun, irradiance, aperture: Some(volume) });
                    }
                }
                Key::Panel(group) => {
                    // What shades the panel from the real sun outside casts
                    // along each lobe too, from where it lies on the panel.
                    let shadows = shadows_on(panes, *normal, &opaque_casters, to_sun);
                    // A lobe's light starts at the panel: only what lies on
                    // the room side of it casts along the lobe.
                    let inside = normal * -to_sun.dot(*normal).signum();
                    let inner_casters = beside(&opaque_casters, panes[0][0], inside);
                    for beam in beams.iter().filter(|b| b.panel_group == Some(*group)) {
                        let direction = beam.to_light.as_vec3();
                        let mut pass = direction_pass(&inner_casters, direction, &mut volumes);
                        let (_, shadow_sides) = add_volume(&shadows, direction, &mut volumes);
                        pass.opaque_sides.end = shadow_sides.end;
                        let (caps, sides) = add_volume(panes, direction, &mut volumes);
                        pass.lights.push(SunLight { direction, irradiance: beam.normal_irradiance as f32, aperture: Some(caps.start..sides.end) });
                        lobe_passes.push(pass);
                    }
                }
            }
        }
        sun_pass.lights.push(SunLight { direction: to_sun, irradiance: sun.normal_irradiance() as f32, aperture: None });
        let mut passes = vec![sun_pass];
        passes.extend(lobe_passes);
        Self { generation, lit, volumes, passes }
    }

    /// The lights of all passes in order (one uniform each).
    pub fn lights(&self) -> impl Iterator<Item = &SunLight> {
        self.passes.iter().flat_map(|p| &p.lights)
    }

    /// Draw calls per frame: per pass the opaque caps and sides, per light
    /// through an aperture its volume twice and the lit surfaces, for the
    /// outside light the windows' volumes and the lit surfaces; plus the
    /// depth copy.
    pub fn draw_count(&self) -> usize {
        1 + self.passes.iter().map(|p| 2 + p.lights.iter().map(|l| if l.aperture.is_some() { 3 } else { 2 }).sum::<usize>()).sum::<usize>()
    }
}

/// The shadows `casters` throw on a window's `panes` (a plane with
/// `normal`) under the sun along `to_sun`: each caster between the window
/// and the sun, projected along the sun onto the window's plane and clipped
/// to each pane (panes are triangles, hence convex). As casters along a
/// lobe, they keep its light from the shaded part of the panel.
fn shadows_on(panes: &[[Vec3; 3]], normal: Vec3, casters: &[[Vec3; 3]], to_sun: Vec3) -> Vec<[Vec3; 3]> {
    let Some(origin) = panes.first().map(|p| p[0]) else { return Vec::new() };
    let toward = to_sun.dot(normal);
    if toward.abs() < 1e-6 {
        return Vec::new();
    }
    // The sun's side of the plane: `above` along `side`.
    let side = normal * toward.signum();
    let (lo, hi) = panes.iter().flatten().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let mut out = Vec::new();
    for in_front in beside(casters, origin, side) {
        // Along the sun onto the plane.
        let projected: Vec<Vec3> = in_front.iter().map(|&p| p - to_sun * ((p - origin).dot(normal) / toward)).collect();
        let (plo, phi) = projected.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        if plo.cmpgt(hi + 1e-4).any() || phi.cmplt(lo - 1e-4).any() {
            continue;
        }
        for pane in panes {
            // Inside a pane: on the inner side of each of its edges' planes.
            let pane_normal = (pane[1] - pane[0]).cross(pane[2] - pane[0]);
            let mut polygon = projected.clone();
            for k in 0..3 {
                let (a, b) = (pane[k], pane[(k + 1) % 3]);
                let inward = pane_normal.cross(b - a);
                polygon = clip_convex(&polygon, inward, a.dot(inward), true);
                if polygon.len() < 3 {
                    break;
                }
            }
            for k in 1..polygon.len().saturating_sub(1) {
                out.push([polygon[0], polygon[k], polygon[k + 1]]);
            }
        }
    }
    out
}

/// The parts of `casters` strictly on the `side` of the plane through
/// `origin` (as triangles).
fn beside(casters: &[[Vec3; 3]], origin: Vec3, side: Vec3) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for caster in casters {
        let polygon = clip_convex(&caster[..], side, origin.dot(side) + 1e-4, true);
        for k in 1..polygon.len().saturating_sub(1) {
            out.push([polygon[0], polygon[k], polygon[k + 1]]);
        }
    }
    out
}

/// The diffuse surfaces as the sun pass draws them: the very triangles of
/// the patch meshes the main pass drew, so their depths match exactly.
/// A face the model holds twice is drawn once (light is added, so a
/// duplicate would double it).
pub fn lit_vertices(scene: &Scene) -> Vec<f32> {
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for patch in &scene.patches.patches {
        let MaterialKind::Diffuse { reflectance } = &scene.materials[patch.material as usize].kind else { continue };
        for triangle in &scene.patches.triangles[patch.triangles.start as usize..patch.triangles.end as usize] {
            let mut key = triangle.map(|v| v.to_array().map(f32::to_bits));
            key.sort_unstable();
            if !seen.insert(key) {
                continue;
            }
            for v in triangle {
                out.extend(v.to_array());
                out.extend(patch.normal.to_array());
                out.extend(reflectance.0);
            }
        }
    }
    out
}

impl Plugin for SunPassPlugin {
    fn build(&self, app: &mut App) {
        let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
        let _ = shaders.insert(SUN_PASS_SHADER.id(), Shader::from_wgsl(include_str!("../../shaders/sun_pass.wgsl"), "shaders/sun_pass.wgsl"));
        let _ = shaders.insert(DEPTH_COPY_SHADER.id(), Shader::from_wgsl(include_str!("../../shaders/depth_copy.wgsl"), "shaders/depth_copy.wgsl"));
        app.init_resource::<SunPassInput>()
            .add_plugins((ExtractResourcePlugin::<SunPassInput>::default(), ExtractComponentPlugin::<SunPassView>::default()));
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else { return };
        render_app
            .init_resource::<SunPassBuffers>()
            .add_systems(RenderStartup, init_pipelines)
            .add_systems(Render, (upload_frame, prepare_stencil_targets).in_set(RenderSystems::PrepareResources))
            .add_systems(
                Core3d,
                sun_pass.after(main_opaque_pass_3d).before(main_transparent_pass_3d).in_set(Core3dSystems::MainPass),
            );
    }
}

const SUN_PASS_SHADER: Handle<Shader> = bevy::asset::uuid_handle!("6b1f2c3e-9a57-4d0e-8f3a-2c6d5e7f8a91");
const DEPTH_COPY_SHADER: Handle<Shader> = bevy::asset::uuid_handle!("0d4e5f6a-7b8c-4d9e-a0b1-c2d3e4f5a6b7");

/// Uniform of one light for `lit_fragment`.
#[derive(ShaderType, Clone, Copy)]
struct SunLightUniform {
    direction: Vec3,
    irradiance: f32,
}

#[derive(Resource)]
struct SunPassPipelines {
    view_layout: BindGroupLayoutDescriptor,
    light_layout: BindGroupLayoutDescriptor,
    depth_layout: BindGroupLayoutDescriptor,
    copy_depth: CachedRenderPipelineId,
    count_caps: CachedRenderPipelineId,
    count_volume: CachedRenderPipelineId,
    toggle_volume: CachedRenderPipelineId,
    lit: CachedRenderPipelineId,
}

/// The current frame on the GPU.
#[derive(Resource, Default)]
struct SunPassBuffers {
    generation: Option<u64>,
    lit: Option<(Arc<Vec<f32>>, Buffer)>,
    volumes: Option<Buffer>,
    lights: DynamicUniformBuffer<SunLightUniform>,
    /// Dynamic offset of each light's uniform.
    light_offsets: Vec<u32>,
    frame: Option<Arc<SunPassFrame>>,
}

/// The sun pass's depth-stencil target of a view.
#[derive(Component)]
struct SunStencilTarget(CachedTexture);

const STENCIL_FORMAT: TextureFormat = TextureFormat::Depth24PlusStencil8;

fn init_pipelines(mut commands: Commands, pipeline_cache: Res<PipelineCache>, fullscreen: Res<FullscreenShader>) {
    let view_layout = BindGroupLayoutDescriptor::new(
        "heliodon_sun_view",
        &BindGroupLayoutEntries::single(ShaderStages::VERTEX_FRAGMENT, uniform_buffer::<ViewUniform>(true)),
    );
    let light_layout = BindGroupLayoutDescriptor::new(
        "heliodon_sun_light",
        &BindGroupLayoutEntries::single(ShaderStages::FRAGMENT, uniform_buffer::<SunLightUniform>(true)),
    );
    let depth_layout =
        BindGroupLayoutDescriptor::new("heliodon_sun_depth", &BindGroupLayoutEntries::single(ShaderStages::FRAGMENT, texture_depth_2d()));
    // Every pipeline declares the HDR colour target, so all run in one pass.
    let colour = |blend: Option<BlendState>, write_mask: ColorWrites| {
        vec![Some(ColorTargetState { format: TextureFormat::Rgba16Float, blend, write_mask })]
    };
    let stencil = |face: StencilFaceState, read_mask: u32, write_mask: u32| StencilState { front: face, back: face, read_mask, write_mask };
    let depth_stencil = |depth_write: bool, compare: CompareFunction, stencil: StencilState| DepthStencilState {
        format: STENCIL_FORMAT,
        depth_write_enabled: Some(depth_write),
        depth_compare: Some(compare),
        stencil,
        bias: DepthBiasState::default(),
    };
    let no_culling = PrimitiveState { cull_mode: None, ..default() };
    let copy_depth = pipeline_cache.queue_render_pipeline(RenderPipelineDescriptor {
        label: Some("heliodon_sun_copy_depth".into()),
        layout: vec![depth_layout.clone()],
        vertex: fullscreen.to_vertex_state(),
        fragment: Some(FragmentState {
            shader: DEPTH_COPY_SHADER,
            entry_point: Some("copy_depth".into()),
            targets: colour(None, ColorWrites::empty()),
            ..default()
        }),
        depth_stencil: Some(depth_stencil(true, CompareFunction::Always, StencilState::default())),
        primitive: no_culling,
        ..default()
    });
    let volume_vertex = VertexState {
        shader: SUN_PASS_SHADER,
        entry_point: Some("volume".into()),
        buffers: vec![VertexBufferLayout::from_vertex_formats(VertexStepMode::Vertex, [VertexFormat::Float32x4])],
        ..default()
    };
    // Volumes touch only the stencil; the depth test (reverse Z: nearer is
    // greater) fails where the volume's face lies behind the scene.
    let volume_pipeline = |label: &'static str, front: StencilOperation, back: StencilOperation, write_mask: u32, bias: DepthBiasState| {
        let face = |depth_fail_op| StencilFaceState { compare: CompareFunction::Always, fail_op: StencilOperation::Keep, depth_fail_op, pass_op: StencilOperation::Keep };
        pipeline_cache.queue_render_pipeline(RenderPipelineDescriptor {
            label: Some(label.into()),
            layout: vec![view_layout.clone()],
            vertex: volume_vertex.clone(),
            fragment: Some(FragmentState {
                shader: SUN_PASS_SHADER,
                entry_point: Some("volume_fragment".into()),
                targets: colour(None, ColorWrites::empty()),
                ..default()
            }),
            depth_stencil: Some(DepthStencilState {
                stencil: StencilState { front: face(front), back: face(back), read_mask: 0xff, write_mask },
                bias,
                ..depth_stencil(false, CompareFunction::Greater, StencilState::default())
            }),
            primitive: no_culling,
            ..default()
        })
    };
    let (decrement, increment, invert) = (StencilOperation::DecrementWrap, StencilOperation::IncrementWrap, StencilOperation::Invert);
    let count_caps = volume_pipeline("heliodon_sun_count_caps", decrement, increment, COUNT_BITS, CAP_DEPTH_BIAS);
    let count_volume = volume_pipeline("heliodon_sun_count_volume", decrement, increment, COUNT_BITS, DepthBiasState::default());
    let toggle_volume = volume_pipeline("heliodon_sun_toggle_volume", invert, invert, WINDOW_BIT, DepthBiasState::default());
    let lit_face = StencilFaceState { compare: CompareFunction::Equal, fail_op: StencilOperation::Keep, depth_fail_op: StencilOperation::Keep, pass_op: StencilOperation::Keep };
    let additive = BlendComponent { src_factor: BlendFactor::One, dst_factor: BlendFactor::One, operation: BlendOperation::Add };
    let lit = pipeline_cache.queue_render_pipeline(RenderPipelineDescriptor {
        label: Some("heliodon_sun_lit".into()),
        layout: vec![view_layout.clone(), light_layout.clone()],
        vertex: VertexState {
            shader: SUN_PASS_SHADER,
            entry_point: Some("lit_vertex".into()),
            buffers: vec![VertexBufferLayout::from_vertex_formats(
                VertexStepMode::Vertex,
                [VertexFormat::Float32x3, VertexFormat::Float32x3, VertexFormat::Float32x3],
            )],
            ..default()
        },
        fragment: Some(FragmentState {
            shader: SUN_PASS_SHADER,
            entry_point: Some("lit_fragment".into()),
            targets: colour(Some(BlendState { color: additive, alpha: additive }), ColorWrites::ALL),
            ..default()
        }),
        depth_stencil: Some(depth_stencil(false, CompareFunction::GreaterEqual, stencil(lit_face, 0xff, 0))),
        primitive: no_culling,
        ..default()
    });
    commands.insert_resource(SunPassPipelines { view_layout, light_layout, depth_layout, copy_depth, count_caps, count_volume, toggle_volume, lit });
}

fn upload_frame(input: Res<SunPassInput>, mut buffers: ResMut<SunPassBuffers>, device: Res<RenderDevice>, queue: Res<RenderQueue>) {
    let Some(frame) = input.0.clone() else {
        buffers.frame = None;
        return;
    };
    if buffers.generation == Some(frame.generation) {
        return;
    }
    let bytes = |floats: &[f32]| floats.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
    let vertex_buffer = |label: &str, contents: &[u8]| {
        (!contents.is_empty())
            .then(|| device.create_buffer_with_data(&BufferInitDescriptor { label: Some(label), contents, usage: BufferUsages::VERTEX }))
    };
    let same_lit = buffers.lit.as_ref().is_some_and(|(data, _)| Arc::ptr_eq(data, &frame.lit));
    if !same_lit {
        buffers.lit = vertex_buffer("heliodon_sun_lit", &bytes(&frame.lit)).map(|b| (frame.lit.clone(), b));
    }
    let volume_floats: Vec<f32> = frame.volumes.iter().flat_map(|v| v.to_array()).collect();
    buffers.volumes = vertex_buffer("heliodon_sun_volumes", &bytes(&volume_floats));
    buffers.lights.clear();
    let offsets: Vec<u32> = frame
        .lights()
        .map(|l| buffers.lights.push(&SunLightUniform { direction: l.direction, irradiance: l.irradiance }))
        .collect();
    buffers.light_offsets = offsets;
    buffers.lights.write_buffer(&device, &queue);
    buffers.generation = Some(frame.generation);
    buffers.frame = Some(frame);
}

fn prepare_stencil_targets(
    mut commands: Commands,
    mut texture_cache: ResMut<TextureCache>,
    device: Res<RenderDevice>,
    views: Query<(Entity, &ExtractedCamera), With<SunPassView>>,
) {
    for (entity, camera) in &views {
        let Some(size) = camera.physical_target_size else { continue };
        let texture = texture_cache.get(
            &device,
            TextureDescriptor {
                label: Some("heliodon_sun_stencil"),
                size: Extent3d { width: size.x, height: size.y, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: TextureDimension::D2,
                format: STENCIL_FORMAT,
                usage: TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            },
        );
        commands.entity(entity).insert(SunStencilTarget(texture));
    }
}

fn sun_pass(
    view: ViewQuery<(&ViewTarget, &ViewDepthTexture, &SunStencilTarget, &ViewUniformOffset, &ExtractedCamera), With<SunPassView>>,
    pipelines: Option<Res<SunPassPipelines>>,
    pipeline_cache: Res<PipelineCache>,
    buffers: Res<SunPassBuffers>,
    view_uniforms: Res<ViewUniforms>,
    mut ctx: RenderContext,
) {
    let (target, depth, stencil, view_offset, camera) = view.into_inner();
    let (Some(pipelines), Some(frame), Some(volumes), Some((_, lit))) = (pipelines, &buffers.frame, &buffers.volumes, &buffers.lit) else {
        return;
    };
    let get = |id| pipeline_cache.get_render_pipeline(id);
    let (Some(copy_depth), Some(count_caps), Some(count_volume), Some(toggle_volume), Some(lit_pipeline)) =
        (get(pipelines.copy_depth), get(pipelines.count_caps), get(pipelines.count_volume), get(pipelines.toggle_volume), get(pipelines.lit))
    else {
        return;
    };
    let (Some(view_binding), Some(light_binding)) = (view_uniforms.uniforms.binding(), buffers.lights.binding()) else { return };
    let device = ctx.render_device().clone();
    let layout = |l: &BindGroupLayoutDescriptor| pipeline_cache.get_bind_group_layout(l);
    let view_group = device.create_bind_group("heliodon_sun_view", &layout(&pipelines.view_layout), &BindGroupEntries::single(view_binding));
    let light_group = device.create_bind_group("heliodon_sun_light", &layout(&pipelines.light_layout), &BindGroupEntries::single(light_binding));
    let depth_group = device.create_bind_group("heliodon_sun_depth", &layout(&pipelines.depth_layout), &BindGroupEntries::single(depth.view()));

    let lit_vertices = (frame.lit.len() / 9) as u32;
    let mut light_index = 0;
    for (pass_index, direction) in frame.passes.iter().enumerate() {
        // The first pass copies the main depth in; later ones keep that
        // depth and start from a clear stencil.
        let first = pass_index == 0;
        let mut pass = ctx.command_encoder().begin_render_pass(&RenderPassDescriptor {
            label: Some("heliodon_sun_pass"),
            color_attachments: &[Some(target.get_color_attachment())],
            depth_stencil_attachment: Some(RenderPassDepthStencilAttachment {
                view: &stencil.0.default_view,
                depth_ops: Some(Operations { load: if first { LoadOp::Clear(0.0) } else { LoadOp::Load }, store: StoreOp::Store }),
                stencil_ops: Some(Operations { load: LoadOp::Clear(0), store: StoreOp::Store }),
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some(viewport) = camera.viewport.as_ref() {
            let (position, size) = (viewport.physical_position.as_vec2(), viewport.physical_size.as_vec2());
            pass.set_viewport(position.x, position.y, size.x, size.y, viewport.depth.start, viewport.depth.end);
        }
        if first {
            pass.set_pipeline(copy_depth);
            pass.set_bind_group(0, &*depth_group, &[]);
            pass.draw(0..3, 0..1);
        }
        // Local macros rather than closures: wgpu's pass type is not re-exported by Bevy.
        macro_rules! draw_volumes {
            ($pipeline:expr, $range:expr) => {{
                let range: Range<u32> = $range;
                if !range.is_empty() {
                    pass.set_pipeline($pipeline);
                    pass.set_bind_group(0, &*view_group, &[view_offset.offset]);
                    pass.set_vertex_buffer(0, *volumes.slice(..));
                    pass.draw(range, 0..1);
                }
            }};
        }
        macro_rules! draw_lit {
            ($reference:expr) => {{
                pass.set_pipeline(lit_pipeline);
                pass.set_bind_group(0, &*view_group, &[view_offset.offset]);
                pass.set_bind_group(1, &*light_group, &[buffers.light_offsets[light_index]]);
                pass.set_stencil_reference($reference);
                pass.set_vertex_buffer(0, *lit.slice(..));
                pass.draw(0..lit_vertices, 0..1);
            }};
        }
        draw_volumes!(count_caps, direction.opaque_caps.clone());
        draw_volumes!(count_volume, direction.opaque_sides.clone());
        for light in &direction.lights {
            match &light.aperture {
                Some(aperture) => {
                    draw_volumes!(toggle_volume, aperture.clone());
                    draw_lit!(WINDOW_BIT);
                    draw_volumes!(toggle_volume, aperture.clone());
                }
                None => {
                    draw_volumes!(count_volume, direction.all_windows.clone());
                    draw_lit!(0);
                }
            }
            light_index += 1;
        }
    }
}
