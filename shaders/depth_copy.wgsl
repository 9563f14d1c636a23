// Copies the main pass's depth (Depth32Float, no stencil) into the sun
// pass's own depth-stencil target: depth formats cannot be copied between.

#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput

@group(0) @binding(0) var main_depth: texture_depth_2d;

@fragment
fn copy_depth(in: FullscreenVertexOutput) -> @builtin(frag_depth) f32 {
    return textureLoad(main_depth, vec2<i32>(floor(in.position.xy)), 0);
}
