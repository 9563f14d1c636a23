//! [`HeliodonRenderPlugin`]: the hybrid renderer of the thesis (sections
//! 3.3 and 3.5). Surfaces show the light engine's sky and interreflected
//! light per patch ([`surfaces`]); direct sun is drawn per pixel every frame
//! by stencil shadow volumes ([`sun_pass`]); Bevy's HDR target, exposure and
//! filmic tone mapping turn the physical values (cd/m²) into a picture.
//! Also the initial view of a scene and offscreen rendering ([`offscreen`]).

pub mod offscreen;
pub mod shadow_volume;
pub mod sun_pass;
pub mod surfaces;

use std::sync::Arc;

use bevy::camera::Exposure;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::render_resource::TextureUsages;
use bevy::camera::Hdr;
use bevy::render::view::Msaa;

use crate::ecs::{ActiveScene, HeliodonSystems, LightingState, SunSky};
use crate::light::side_of;
use crate::scene::{DEFAULT_FOV, MaterialKind, Scene, Viewpoint};
use sun_pass::{SunPassFrame, SunPassInput, SunPassPlugin, SunPassView, lit_vertices};
use surfaces::{SurfaceLightingPlugin, side_value};

pub struct HeliodonRenderPlugin;

/// What shows where there is no model: a pale sky.
pub const BACKGROUND: Color = Color::srgb(0.82, 0.86, 0.9);

impl Plugin for HeliodonRenderPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(ClearColor(BACKGROUND))
            .init_resource::<RenderSettings>()
            .add_plugins((SurfaceLightingPlugin, SunPassPlugin))
            .add_systems(Update, (update_sun_pass, auto_exposure).after(HeliodonSystems::Lighting));
    }
}

/// What the picture shows: the thesis' debugging views, which designers use too.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum RenderMode {
    /// Sun, sky and interreflected light.
    #[default]
    Full,
    /// Direct sun only (the stencil passes).
    Sun,
    /// Direct sky and ground light only.
    Sky,
    /// Interreflected light only.
    Indirect,
    /// Illuminance on surfaces (lux) as false colour.
    FalseColour,
}

impl RenderMode {
    /// The names `--mode` takes.
    pub const NAMES: [&str; 5] = ["full", "sun", "sky", "indirect", "falsecolor"];

    pub fn parse(name: &str) -> Option<Self> {
        let index = Self::NAMES.iter().position(|n| *n == name)?;
        Some([Self::Full, Self::Sun, Self::Sky, Self::Indirect, Self::FalseColour][index])
    }

    fn draws_sun(self) -> bool {
        matches!(self, Self::Full | Self::Sun)
    }
}

/// How the view turns light into a picture.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    pub mode: RenderMode,
    /// Exposure value (EV100); `None`: set from the scene's light as it lands.
    pub exposure: Option<f32>,
    /// Top of the false-colour scale, lux (the scale spans three decades).
    pub false_colour_max_lux: f32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self { mode: RenderMode::Full, exposure: None, false_colour_max_lux: 10_000.0 }
    }
}

/// A camera set up for the hybrid renderer: HDR target, no MSAA (the sun
/// pass shares the main depth), sampleable depth, filmic tone mapping.
pub fn hybrid_camera() -> impl Bundle {
    (
        Camera3d { depth_texture_usages: (TextureUsages::RENDER_ATTACHMENT | TextureUsages::TEXTURE_BINDING).into(), ..default() },
        Hdr,
        Msaa::Off,
        Tonemapping::AgX,
        Exposure::default(),
        SunPassView,
    )
}

/// A camera whose image holds physical values: luminance in cd/m² (its
/// exposure factor is 1 and it has no tone mapping); automatic exposure
/// leaves it alone.
#[derive(Component, Clone, Copy, Default)]
pub struct PhysicalUnits;

/// Rebuilds what the sun pass draws when the scene, sun or mode change.
fn update_sun_pass(
    active: Res<ActiveScene>,
    sun_sky: Option<Res<SunSky>>,
    settings: Res<RenderSettings>,
    mut input: ResMut<SunPassInput>,
    mut lit: Local<Option<(usize, Arc<Vec<f32>>)>>,
    mut generation: Local<u64>,
) {
    let scene_changed = active.is_changed();
    if !scene_changed && !settings.is_changed() && !sun_sky.as_ref().is_some_and(|s| s.is_changed()) {
        return;
    }
    let (Some(scene), Some(sun_sky)) = (&active.scene, sun_sky) else {
        input.0 = None;
        return;
    };
    let sun = sun_sky.sky.sun.filter(|s| s.direction.z > 0.0);
    let Some(sun) = sun.filter(|_| settings.mode.draws_sun()) else {
        input.0 = None;
        return;
    };
    let scene_id = Arc::as_ptr(scene) as usize;
    let vertices = match &*lit {
        Some((id, vertices)) if *id == scene_id => vertices.clone(),
        _ => {
            let vertices = Arc::new(lit_vertices(scene));
            *lit = Some((scene_id, vertices.clone()));
            vertices
        }
    };
    *generation += 1;
    let frame = SunPassFrame::new(scene, vertices, sun.direction.as_vec3(), sun.normal_irradiance() as f32, *generation);
    input.0 = Some(Arc::new(frame));
}

/// With automatic exposure, meters the scene's light as it lands, as a
/// reflected-light meter would (EV100 = log2(L · 100 / 12.5)): L is the
/// log-average luminance of all lit surfaces, sun included, or with direct
/// sun alone, that of a mid-grey surface facing the sun.
fn auto_exposure(
    state: Option<Res<LightingState>>,
    sun_sky: Option<Res<SunSky>>,
    settings: Res<RenderSettings>,
    active: Res<ActiveScene>,
    mut cameras: Query<&mut Exposure, (With<SunPassView>, Without<PhysicalUnits>)>,
    added: Query<(), Added<SunPassView>>,
) {
    let light_changed = state.as_ref().is_some_and(|s| s.is_changed()) || sun_sky.as_ref().is_some_and(|s| s.is_changed());
    if !light_changed && !settings.is_changed() && added.is_empty() {
        return;
    }
    let metered = match (&active.scene, state.as_ref().and_then(|s| s.lighting.as_ref())) {
        _ if settings.mode == RenderMode::Sun => sun_sky
            .as_ref()
            .and_then(|s| s.sky.sun)
            .filter(|sun| sun.direction.z > 0.0)
            .map(|sun| MID_GREY / std::f64::consts::PI * sun.normal_irradiance() * crate::sky::LUMINOUS_EFFICACY),
        (Some(scene), Some(lighting)) => log_average_luminance(scene, &lighting.sides),
        _ => None,
    };
    let Some(ev100) = settings.exposure.or(metered.map(|luminance| (luminance * 100.0 / 12.5).log2() as f32)) else { return };
    for mut exposure in &mut cameras {
        exposure.ev100 = ev100;
    }
}

/// Reflectance of the surface the direct-sun view is metered on.
const MID_GREY: f64 = 0.18;

/// Area-weighted log-average luminance (cd/m²) of the diffuse patch sides
/// that receive any light.
fn log_average_luminance(scene: &Scene, sides: &[crate::light::Channels]) -> Option<f64> {
    let (mut sum, mut area) = (0.0, 0.0);
    for (p, patch) in scene.patches.patches.iter().enumerate() {
        let MaterialKind::Diffuse { reflectance } = &scene.materials[patch.material as usize].kind else { continue };
        for back in [false, true] {
            let channels = sides.get(side_of(p as u32, back) as usize)?;
            let with_sun = crate::light::Channels { sky: channels.sky + channels.sun, ..*channels };
            let [r, g, b] = side_value(&with_sun, reflectance.0, RenderMode::Full);
            let luminance = f64::from(0.265 * r + 0.670 * g + 0.065 * b);
            if luminance > 1e-3 {
                sum += f64::from(patch.area) * luminance.ln();
                area += f64::from(patch.area);
            }
        }
    }
    (area > 0.0).then(|| (sum / area).exp())
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
