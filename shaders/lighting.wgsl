// heliodon's surface material: the light engine's sky and interreflected
// light per patch, interpolated at the vertices of each surface (vertex
// colour, in cd/m²), scaled by the camera's exposure; Bevy's tone mapping
// follows. Direct sun is added per pixel by the sun pass (sun_pass.wgsl).
// In false-colour mode the vertex colour's red channel holds illuminance in
// lux and is mapped to a colour scale here, per pixel.

#import bevy_pbr::forward_io::VertexOutput
#import bevy_pbr::mesh_view_bindings::view

struct LightingMaterial {
    // Glass and panels: a display colour with coverage in alpha.
    tint: vec4<f32>,
    // 0: luminance (cd/m², exposed); 1: false colour of illuminance.
    mode: u32,
    // Illuminance at the top of the false-colour scale, lux.
    scale_max_lux: f32,
    // Fragments above this height (model z) are cut away from the eye.
    section: f32,
    // 1: a panel, drawn with its look (below).
    is_panel: u32,
    // A vertical section: fragments with dot(normal, p) > offset are cut
    // away (xy: the horizontal normal, w: the offset; a zero normal: none).
    vertical_section: vec4<f32>,
    panel: PanelLook,
}

// A panel's look under the sky: the sky and ground it passes into the room
// by the way the eye looks out through it (panel_sky, cd/m²), the
// diffusely transmitted sun's luminance (cd/m²), and per lobe the way its
// light travels into the room (xyz) with the cosine of its cone's half
// angle (w) and its luminance (x of lobe_luminance): the eye sees a lobe
// where it looks at the panel from within the cone, against the light.
struct PanelLook {
    // The panel's normal into the room: the side it looks like this from.
    inward: vec4<f32>,
    diffuse: f32,
    // 1: the sky it passes is drawn (panel_sky), 0: not in this mode.
    sky: f32,
    lobe_count: u32,
    lobes: array<vec4<f32>, 8>,
    lobe_luminance: array<vec4<f32>, 8>,
}

// Surfaces within this distance of a section are drawn in the cut colour:
// a line where the section cuts them, so the cut reads as one.
const CUT_LINE: f32 = 0.03;
const CUT_COLOUR: vec4<f32> = vec4(0.55, 0.08, 0.06, 1.0);
// The most a panel's light is drawn at, after exposure: the view's
// half-float target holds 65,504.
const MAX_DRAWN: f32 = 60000.0;

@group(#{MATERIAL_BIND_GROUP}) @binding(0) var<uniform> material: LightingMaterial;
@group(#{MATERIAL_BIND_GROUP}) @binding(1) var panel_sky: texture_cube<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(2) var panel_sky_sampler: sampler;

// The false-colour scale: logarithmic over three decades below the top,
// blue, cyan, green, yellow, red, white (heliodon::render::false_colour is
// the same scale on the CPU, for legends).
fn false_colour(lux: f32, top: f32) -> vec3<f32> {
    let t = clamp(log2(max(lux, 1e-6) / top) / log2(1000.0) + 1.0, 0.0, 1.0);
    let stops = array<vec3<f32>, 6>(
        vec3(0.02, 0.02, 0.35), vec3(0.0, 0.45, 0.9), vec3(0.05, 0.75, 0.25),
        vec3(0.95, 0.9, 0.1), vec3(0.9, 0.15, 0.05), vec3(1.0, 1.0, 1.0),
    );
    let x = t * 5.0;
    let i = min(u32(floor(x)), 4u);
    return mix(stops[i], stops[i + 1u], x - f32(i));
}

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
    let beyond = dot(material.vertical_section.xy, in.world_position.xy) - material.vertical_section.w;
    let has_vertical = dot(material.vertical_section.xy, material.vertical_section.xy) > 0.0;
    if in.world_position.z > material.section || (has_vertical && beyond > 0.0) {
        discard;
    }
    if in.world_position.z > material.section - CUT_LINE || (has_vertical && beyond > -CUT_LINE) {
        return CUT_COLOUR;
    }
#ifdef VERTEX_COLORS
    let value = in.color.rgb;
#else
    let value = vec3(0.0);
#endif
    if material.tint.a < 1.0 && material.is_panel == 1u {
        let to_eye = normalize(view.world_position - in.world_position.xyz);
        if material.mode == 0u && dot(to_eye, material.panel.inward.xyz) > 0.0 {
            // Seen from the room, a panel is the light it sends toward the
            // eye: the sky and ground it passes that way, its diffuse sun,
            // its lobes.
            var light = material.panel.diffuse + material.panel.sky * textureSampleLevel(panel_sky, panel_sky_sampler, -to_eye, 0.0).r;
            for (var k = 0u; k < material.panel.lobe_count; k++) {
                let lobe = material.panel.lobes[k];
                // A soft rim a thousandth of the cosine wide, against aliasing.
                light += material.panel.lobe_luminance[k].x * smoothstep(lobe.w - 1e-3, lobe.w, dot(to_eye, lobe.xyz));
            }
            // Kept within the half-float target (a lobe seen against its
            // light may be millions of cd/m²): the physical image saturates there.
            return vec4(vec3(min(light * view.exposure, MAX_DRAWN)), 1.0);
        }
        // From outside, or in false colour: the panel's display colour.
        return vec4(material.tint.rgb * material.tint.a, material.tint.a);
    }
    if material.tint.a < 1.0 {
        return material.tint;
    }
    if material.mode == 1u {
        return vec4(false_colour(value.r, material.scale_max_lux), 1.0);
    }
    return vec4(value * view.exposure, 1.0);
}
