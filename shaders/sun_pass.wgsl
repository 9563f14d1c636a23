// Direct sun by stencil shadow volumes (thesis algorithm 1): `volume` draws
// the extruded volumes into the stencil only (points at infinity have w = 0);
// `lit_*` redraws the lit surfaces where the stencil says the light arrives,
// adding ρ/π · E · cos θ as luminance (cd/m²) scaled by the exposure.

#import bevy_render::view::View

@group(0) @binding(0) var<uniform> view: View;

struct SunLight {
    // Unit vector toward the light (the sun, or a panel lobe's fake sun).
    direction: vec3<f32>,
    // Irradiance normal to the direction after the window, W/m².
    irradiance: f32,
}

@group(1) @binding(0) var<uniform> light: SunLight;

const PI: f32 = 3.141592653589793;
// Luminous efficacy Radiance uses for W to lm.
const EFFICACY: f32 = 179.0;

@vertex
fn volume(@location(0) position: vec4<f32>) -> @builtin(position) vec4<f32> {
    return view.clip_from_world * position;
}

// Volumes write no colour; the pass's colour target is declared but masked.
@fragment
fn volume_fragment() {}

struct LitVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) albedo: vec3<f32>,
}

@vertex
fn lit_vertex(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) albedo: vec3<f32>) -> LitVertex {
    var out: LitVertex;
    out.clip = view.clip_from_world * vec4(position, 1.0);
    out.normal = normal;
    out.albedo = albedo;
    return out;
}

@fragment
fn lit_fragment(in: LitVertex, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Surfaces reflect on both sides: the side facing the camera counts.
    let normal = select(-in.normal, in.normal, front);
    let cos_theta = max(dot(normalize(normal), light.direction), 0.0);
    let luminance = in.albedo / PI * light.irradiance * cos_theta * EFFICACY;
    return vec4(luminance * view.exposure, 0.0);
}
