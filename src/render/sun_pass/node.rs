//! The sun pass as a render system in `Core3d`, after the opaque pass: per
//! view, the depth copy, then per light direction one render pass over a
//! cleared stencil (see the module above for the steps).

use std::ops::Range;

use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::diagnostic::RecordDiagnostics;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, ViewQuery};
use bevy::render::view::{ViewDepthTexture, ViewTarget, ViewUniformOffset, ViewUniforms};

use super::SunPassView;
use super::resources::{SunPassBuffers, SunPassPipelines, SunStencilTarget, WINDOW_BIT};

pub(super) fn sun_pass(
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
    let (Some(copy_depth), Some(count_caps), Some(count_volume), Some(toggle_volume), Some(lit_pipeline)) = (
        get(pipelines.copy_depth),
        get(pipelines.count_caps),
        get(pipelines.count_volume),
        get(pipelines.toggle_volume),
        get(pipelines.lit),
    ) else {
        return;
    };
    let (Some(view_binding), Some(light_binding)) = (view_uniforms.uniforms.binding(), buffers.lights.binding()) else { return };
    let device = ctx.render_device().clone();
    let layout = |l: &BindGroupLayoutDescriptor| pipeline_cache.get_bind_group_layout(l);
    let view_group =
        device.create_bind_group("heliodon_sun_view", &layout(&pipelines.view_layout), &BindGroupEntries::single(view_binding));
    let light_group =
        device.create_bind_group("heliodon_sun_light", &layout(&pipelines.light_layout), &BindGroupEntries::single(light_binding));
    let depth_group =
        device.create_bind_group("heliodon_sun_depth", &layout(&pipelines.depth_layout), &BindGroupEntries::single(depth.view()));

    // GPU time per pass, of the opaque volumes and of each light (its
    // window's volume and its lit surfaces), where `RenderDiagnosticsPlugin`
    // records them (the render bench's `HELIODON_BENCH_GPU_TIMES`).
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    // A span's name, made only where spans are recorded.
    let name = |make: &dyn Fn() -> String| if diagnostics.is_some() { make() } else { String::new() };
    let lit_vertices = (frame.surfaces.lit.len() / 9) as u32;
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
        let pass_span = diagnostics.pass_span(&mut pass, name(&|| format!("heliodon_sun_pass {pass_index}")));
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
        // The lit surfaces for one light: those its beam may reach, or all.
        macro_rules! draw_lit {
            ($reference:expr, $share:expr) => {{
                pass.set_pipeline(lit_pipeline);
                pass.set_bind_group(0, &*view_group, &[view_offset.offset]);
                pass.set_bind_group(1, &*light_group, &[buffers.light_offsets[light_index]]);
                pass.set_stencil_reference($reference);
                pass.set_vertex_buffer(0, *lit.slice(..));
                match ($share, &buffers.lit_indices) {
                    (Some(range), Some(indices)) => {
                        pass.set_index_buffer(*indices.slice(..), IndexFormat::Uint32);
                        pass.draw_indexed(range.clone(), 0, 0..1);
                    }
                    (Some(_), None) => {}
                    (None, _) => pass.draw(0..lit_vertices, 0..1),
                }
            }};
        }
        let span = diagnostics.time_span(&mut pass, "opaque volumes");
        draw_volumes!(count_caps, direction.opaque_caps.clone());
        draw_volumes!(count_volume, direction.opaque_sides.clone());
        span.end(&mut pass);
        for light in &direction.lights {
            let span = diagnostics.time_span(&mut pass, name(&|| format!("light {light_index}")));
            match &light.aperture {
                Some(aperture) => {
                    draw_volumes!(toggle_volume, aperture.clone());
                    let lit_span = diagnostics.time_span(&mut pass, "lit");
                    draw_lit!(WINDOW_BIT, light.lit.as_ref());
                    lit_span.end(&mut pass);
                    draw_volumes!(toggle_volume, aperture.clone());
                }
                None => {
                    draw_volumes!(count_volume, direction.all_windows.clone());
                    let lit_span = diagnostics.time_span(&mut pass, "lit");
                    draw_lit!(0, light.lit.as_ref());
                    lit_span.end(&mut pass);
                }
            }
            span.end(&mut pass);
            light_index += 1;
        }
        pass_span.end(&mut pass);
    }
}
