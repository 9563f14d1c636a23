//! The sun pass's render-world resources: pipelines (depth copy, volume
//! counting and toggling, lit surfaces), the uploaded frame and each view's
//! depth-stencil target.

use std::sync::Arc;

use bevy::core_pipeline::FullscreenShader;
use bevy::mesh::VertexBufferLayout;
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::render_resource::binding_types::{texture_depth_2d, uniform_buffer};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::texture::{CachedTexture, TextureCache};
use bevy::render::view::ViewUniform;

use super::{DEPTH_COPY_SHADER, SUN_PASS_SHADER, SunPassFrame, SunPassInput, SunPassSurfaces, SunPassView};

/// Depth bias of the opaque casters' caps, away from the camera (reverse Z:
/// negative), so the lit face of a caster, which is its volume's near cap,
/// counts as outside despite rounding.
pub(super) const CAP_DEPTH_BIAS: DepthBiasState = DepthBiasState { constant: -16, slope_scale: -2.0, clamp: 0.0 };
/// Stencil bits counting opaque volumes, and the bit a window's volume toggles.
pub(super) const COUNT_BITS: u32 = 0x7f;
pub(super) const WINDOW_BIT: u32 = 0x80;

/// Uniform of one light for `lit_fragment`.
#[derive(ShaderType, Clone, Copy)]
pub(super) struct SunLightUniform {
    pub(super) direction: Vec3,
    pub(super) irradiance: f32,
}

#[derive(Resource)]
pub(super) struct SunPassPipelines {
    pub(super) view_layout: BindGroupLayoutDescriptor,
    pub(super) light_layout: BindGroupLayoutDescriptor,
    pub(super) depth_layout: BindGroupLayoutDescriptor,
    pub(super) copy_depth: CachedRenderPipelineId,
    pub(super) count_caps: CachedRenderPipelineId,
    pub(super) count_volume: CachedRenderPipelineId,
    pub(super) toggle_volume: CachedRenderPipelineId,
    pub(super) lit: CachedRenderPipelineId,
}

/// The current frame on the GPU.
#[derive(Resource, Default)]
pub(super) struct SunPassBuffers {
    pub(super) generation: Option<u64>,
    pub(super) lit: Option<(Arc<SunPassSurfaces>, Buffer)>,
    pub(super) volumes: Option<Buffer>,
    /// Each light's share of the lit surfaces ([`SunPassFrame::lit_indices`]).
    pub(super) lit_indices: Option<Buffer>,
    pub(super) lights: DynamicUniformBuffer<SunLightUniform>,
    /// Dynamic offset of each light's uniform.
    pub(super) light_offsets: Vec<u32>,
    pub(super) frame: Option<Arc<SunPassFrame>>,
}

/// The sun pass's depth-stencil target of a view.
#[derive(Component)]
pub(super) struct SunStencilTarget(pub(super) CachedTexture);

pub(super) const STENCIL_FORMAT: TextureFormat = TextureFormat::Depth24PlusStencil8;

pub(super) fn init_pipelines(mut commands: Commands, pipeline_cache: Res<PipelineCache>, fullscreen: Res<FullscreenShader>) {
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
        let face = |depth_fail_op| StencilFaceState {
            compare: CompareFunction::Always,
            fail_op: StencilOperation::Keep,
            depth_fail_op,
            pass_op: StencilOperation::Keep,
        };
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
    let lit_face = StencilFaceState {
        compare: CompareFunction::Equal,
        fail_op: StencilOperation::Keep,
        depth_fail_op: StencilOperation::Keep,
        pass_op: StencilOperation::Keep,
    };
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
    commands.insert_resource(SunPassPipelines {
        view_layout,
        light_layout,
        depth_layout,
        copy_depth,
        count_caps,
        count_volume,
        toggle_volume,
        lit,
    });
}

pub(super) fn upload_frame(
    input: Res<SunPassInput>,
    mut buffers: ResMut<SunPassBuffers>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
) {
    let Some(frame) = input.0.clone() else {
        buffers.frame = None;
        return;
    };
    if buffers.generation == Some(frame.generation) {
        return;
    }
    // The buffers' bytes are the frame's own (no copy: the volumes of a
    // large model are tens of megabytes, uploaded again each sun move).
    let buffer = |label: &str, contents: &[u8], usage: BufferUsages| {
        (!contents.is_empty()).then(|| device.create_buffer_with_data(&BufferInitDescriptor { label: Some(label), contents, usage }))
    };
    let same_lit = buffers.lit.as_ref().is_some_and(|(surfaces, _)| Arc::ptr_eq(surfaces, &frame.surfaces));
    if !same_lit {
        buffers.lit = buffer("heliodon_sun_lit", bytemuck::cast_slice(&frame.surfaces.lit), BufferUsages::VERTEX)
            .map(|b| (frame.surfaces.clone(), b));
    }
    buffers.volumes = buffer("heliodon_sun_volumes", bytemuck::cast_slice(&frame.volumes), BufferUsages::VERTEX);
    buffers.lit_indices = buffer("heliodon_sun_lit_indices", bytemuck::cast_slice(&frame.lit_indices), BufferUsages::INDEX);
    buffers.lights.clear();
    let offsets: Vec<u32> =
        frame.lights().map(|l| buffers.lights.push(&SunLightUniform { direction: l.direction, irradiance: l.irradiance })).collect();
    buffers.light_offsets = offsets;
    buffers.lights.write_buffer(&device, &queue);
    buffers.generation = Some(frame.generation);
    buffers.frame = Some(frame);
}

pub(super) fn prepare_stencil_targets(
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
