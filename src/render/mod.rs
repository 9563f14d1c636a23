//! [`HeliodonRenderPlugin`]: the hybrid renderer of the thesis (sections
//! 3.3 and 3.5). Surfaces show the light engine's sky and interreflected
//! light per patch ([`surfaces`]); direct sun is drawn per pixel every frame
//! by stencil shadow volumes ([`sun_pass`]); Bevy's HDR target, exposure and
//! filmic tone mapping turn the physical values (cd/m²) into a picture; the
//! sky model's luminance is drawn around the model ([`sky`]).
//! Also the initial view of a scene and offscreen rendering ([`offscreen`]).

pub mod legend;
pub mod offscreen;
pub mod reference;
pub mod sky;
pub mod sun_pass;
pub mod surfaces;

use std::sync::Arc;

use bevy::anti_alias::smaa::Smaa;
use bevy::camera::Exposure;
use bevy::camera::Hdr;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::render_resource::{PollType, TextureUsages};
use bevy::render::renderer::{RenderAdapterInfo, RenderDevice};
use bevy::render::view::Msaa;
use bevy::render::{Render, RenderApp, RenderSystems};

use crate::ecs::{ActiveScene, HeliodonSystems, LightEngine, LightingState, RayModel, SunSky};
use crate::light::{Channels, LightModel, side_of};
use crate::scene::{DEFAULT_FOV, MaterialKind, Scene, Viewpoint};
use sun_pass::{SunPassFrame, SunPassInput, SunPassPlugin, SunPassSurfaces, SunPassView};
use surfaces::{SurfaceLightingPlugin, side_value};

pub struct HeliodonRenderPlugin;

/// The renderer's main-world systems, in `Update` after the light engine
/// (`HeliodonSystems::Lighting`), in order:
/// 1. `Surfaces`: the patch meshes spawned and their vertex values set from
///    the light ([`surfaces`]);
/// 2. `SunPass`: what the stencil pass draws, rebuilt when the scene, the sun
///    or the mode change ([`sun_pass`]);
/// 3. `Exposure`: automatic exposure and the tone map of the mode.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HeliodonRenderSystems {
    Surfaces,
    SunPass,
    Exposure,
}

/// What shows where there is no model: a pale sky.
pub const BACKGROUND: Color = Color::srgb(0.82, 0.86, 0.9);

impl Plugin for HeliodonRenderPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(ClearColor(BACKGROUND))
            .init_resource::<RenderSettings>()
            .configure_sets(
                Update,
                (HeliodonRenderSystems::Surfaces, HeliodonRenderSystems::SunPass, HeliodonRenderSystems::Exposure)
                    .chain()
                    .after(HeliodonSystems::Lighting),
            )
            .add_plugins((SurfaceLightingPlugin, SunPassPlugin, sky::SkyBackgroundPlugin))
            .add_systems(Update, (update_sun_pass, surfaces::update_panel_looks).in_set(HeliodonRenderSystems::SunPass))
            .add_systems(Update, (auto_exposure, tone_mapping_for_mode).in_set(HeliodonRenderSystems::Exposure));
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            render_app.add_systems(Render, wait_for_software_rasterizer.before(RenderSystems::PrepareAssets));
        }
    }
}

/// On a software rasterizer (Mesa's lavapipe), each frame starts once the
/// last one is drawn. There nothing else bounds the frames in flight: while
/// the light settles, frames and the patch meshes' uploads queued faster
/// than the CPU drew them, and the viewer of AC20-Institute-Var-2 held
/// 2.3 GB of them. A GPU keeps its own pace.
fn wait_for_software_rasterizer(adapter: Res<RenderAdapterInfo>, device: Res<RenderDevice>) {
    if adapter.device_type == wgpu_types::DeviceType::Cpu {
        // A lost device fails the frame's own submissions with its message.
        let _ = device.poll(PollType::wait_indefinitely());
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

    pub(crate) fn draws_sun(self) -> bool {
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
    /// A horizontal section: what lies above this height (model z, metres)
    /// is hidden from the eye, so that one looks into the rooms from above.
    /// The light still comes from the whole model (the sun pass's volumes
    /// are every surface's).
    pub section: Option<f32>,
    /// A vertical section, hiding one side of a vertical plane as
    /// `section` hides what lies above.
    pub vertical_section: Option<VerticalSection>,
}

/// A vertical section plane: what lies beyond it, toward `azimuth`, is
/// hidden from the eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerticalSection {
    /// The way the hidden side lies, degrees clockwise from the model's
    /// north (+y).
    pub azimuth: f32,
    /// Where the plane stands along that way from the model's origin, m.
    pub offset: f32,
}

impl RenderSettings {
    /// Whether a section hides point `p` (model metres) from the eye.
    pub fn cuts_away(&self, p: crate::glam::DVec3) -> bool {
        let above = self.section.is_some_and(|z| p.z > f64::from(z));
        let beyond = self.vertical_section.is_some_and(|v| {
            let plane = v.plane().as_dvec4();
            plane.x * p.x + plane.y * p.y > plane.w
        });
        above || beyond
    }
}

impl VerticalSection {
    /// The section hiding what lies beyond `point` toward `azimuth`.
    pub fn through(point: Vec3, azimuth: f32) -> Self {
        Self { azimuth, offset: normal(azimuth).dot(point.truncate()) }
    }

    /// The plane's horizontal normal toward the hidden side, and its offset.
    pub fn plane(&self) -> Vec4 {
        normal(self.azimuth).extend(0.0).extend(self.offset)
    }
}

/// The horizontal unit vector toward `azimuth` (degrees clockwise from +y).
fn normal(azimuth: f32) -> Vec2 {
    let (sin, cos) = azimuth.to_radians().sin_cos();
    Vec2::new(sin, cos)
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self { mode: RenderMode::Full, exposure: None, false_colour_max_lux: 10_000.0, section: None, vertical_section: None }
    }
}

/// A camera a person looks through: the hybrid renderer's, its edges
/// smoothed by SMAA after tone mapping, so that the sun pass's stencil
/// stays exact (MSAA would need a multisampled stencil and depth for it).
pub fn picture_camera() -> impl Bundle {
    (hybrid_camera(), Smaa::default())
}

/// A camera set up for the hybrid renderer: HDR target, no MSAA (the sun
/// pass shares the main depth), sampleable depth, filmic tone mapping.
/// Without anti-aliasing: a physical-units image keeps each pixel's own
/// value.
pub fn hybrid_camera() -> impl Bundle {
    (
        Camera3d { depth_texture_usages: (TextureUsages::RENDER_ATTACHMENT | TextureUsages::TEXTURE_BINDING).into(), ..default() },
        Hdr,
        Msaa::Off,
        FILMIC,
        Exposure::default(),
        SunPassView,
    )
}

/// False colour is shown as computed; every other mode is tone-mapped.
fn tone_mapping_for_mode(settings: Res<RenderSettings>, mut cameras: Query<(Ref<SunPassView>, &mut Tonemapping), Without<PhysicalUnits>>) {
    let wanted = if settings.mode == RenderMode::FalseColour { Tonemapping::None } else { FILMIC };
    for (view, mut tonemapping) in &mut cameras {
        if (settings.is_changed() || view.is_added()) && *tonemapping != wanted {
            *tonemapping = wanted;
        }
    }
}

/// The filmic tone map of pictures.
const FILMIC: Tonemapping = Tonemapping::AgX;

/// The false-colour scale (shaders/lighting.wgsl draws the same): linear
/// RGB for an illuminance, logarithmic over the three decades below `top`.
pub fn false_colour(lux: f32, top: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 6] =
        [[0.02, 0.02, 0.35], [0.0, 0.45, 0.9], [0.05, 0.75, 0.25], [0.95, 0.9, 0.1], [0.9, 0.15, 0.05], [1.0, 1.0, 1.0]];
    let t = ((lux.max(1e-6) / top).log2() / 1000f32.log2() + 1.0).clamp(0.0, 1.0);
    let x = t * 5.0;
    let i = (x.floor() as usize).min(4);
    let f = x - i as f32;
    [0, 1, 2].map(|c| STOPS[i][c] * (1.0 - f) + STOPS[i + 1][c] * f)
}

/// Query filter for the cameras a person looks through (not the
/// physical-units ones beside them).
pub type PictureCamera = (With<SunPassView>, Without<PhysicalUnits>);

/// A camera whose image holds physical values: luminance in cd/m² (its
/// exposure factor is 1 and it has no tone mapping); automatic exposure
/// leaves it alone.
#[derive(Component, Clone, Copy, Default)]
pub struct PhysicalUnits;

/// The sun pass's surfaces of a scene (by address).
type PerScene = (usize, Arc<SunPassSurfaces>);

/// Rebuilds what the sun pass draws when the scene, its ray-query model
/// ([`RayModel`], made when the scene spawns), the sun or the mode change.
fn update_sun_pass(
    active: Res<ActiveScene>,
    ray_model: Option<Res<RayModel>>,
    sun_sky: Option<Res<SunSky>>,
    settings: Res<RenderSettings>,
    mut input: ResMut<SunPassInput>,
    mut per_scene: Local<Option<PerScene>>,
    mut generation: Local<u64>,
) {
    let changed = active.is_changed() || ray_model.as_ref().is_some_and(|m| m.is_changed());
    if !changed && !settings.is_changed() && !sun_sky.as_ref().is_some_and(|s| s.is_changed()) {
        return;
    }
    let Some(scene) = &active.scene else {
        input.0 = None;
        return;
    };
    // Panel windows and their lobes come from the scene's own ray-query
    // model; until it is there, nothing is drawn.
    let Some(model) = ray_model.as_ref().and_then(|m| m.of(scene)).cloned() else {
        input.0 = None;
        return;
    };
    // The sun pass's surfaces are made once per scene.
    let scene_id = Arc::as_ptr(scene) as usize;
    let surfaces = match &*per_scene {
        Some((id, surfaces)) if *id == scene_id => surfaces.clone(),
        _ => {
            let made = Arc::new(SunPassSurfaces::new(scene));
            *per_scene = Some((scene_id, made.clone()));
            made
        }
    };
    let Some(sun_sky) = sun_sky else {
        input.0 = None;
        return;
    };
    let sun = sun_sky.sky.sun_up();
    let Some(sun) = sun.filter(|_| settings.mode.draws_sun()) else {
        input.0 = None;
        return;
    };
    *generation += 1;
    let frame = SunPassFrame::new(scene, &model, surfaces, &sun, *generation);
    input.0 = Some(Arc::new(frame));
}

/// With automatic exposure, meters what each camera sees as a
/// photographer would: the log-average luminance L of the surfaces in view
/// (sun included, weighted by the solid angle they fill) is mapped to
/// middle grey, 0.18 (EV100 = log2(1.2 · L / 0.18) in Bevy's terms). With
/// direct sun alone, L is that of a mid-grey surface facing the sun.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn auto_exposure(
    state: Option<Res<LightingState>>,
    engine: Option<Res<LightEngine>>,
    sun_sky: Option<Res<SunSky>>,
    settings: Res<RenderSettings>,
    active: Res<ActiveScene>,
    mut cameras: Query<(Ref<GlobalTransform>, &Projection, &mut Exposure), (With<SunPassView>, Without<PhysicalUnits>)>,
) {
    let light_changed = state.as_ref().is_some_and(|s| s.is_changed()) || sun_sky.as_ref().is_some_and(|s| s.is_changed());
    for (transform, projection, mut exposure) in &mut cameras {
        if !light_changed && !settings.is_changed() && !transform.is_changed() {
            continue;
        }
        let metered = if settings.mode == RenderMode::Sun {
            sun_sky
                .as_ref()
                .and_then(|s| s.sky.sun_up())
                .map(|sun| MIDDLE_GREY / std::f64::consts::PI * sun.normal_irradiance() * crate::sky::LUMINOUS_EFFICACY)
        } else {
            match (&active.scene, state.as_ref().and_then(|s| s.lighting.as_ref()), engine.as_ref().and_then(|e| e.model.as_ref())) {
                (Some(scene), Some(lighting), Some(model)) => {
                    metered_luminance(scene, model, &lighting.sides, &transform, projection, &|p| settings.cuts_away(p))
                }
                _ => None,
            }
        };
        if let Some(ev100) = settings.exposure.or(metered.map(|luminance| (1.2 * luminance / MIDDLE_GREY).log2() as f32)) {
            exposure.ev100 = ev100;
        }
    }
}

/// Reflectance that automatic exposure shows as middle grey.
const MIDDLE_GREY: f64 = 0.18;
/// Patches metered at most per exposure update (evenly spread).
const METERED_PATCHES: usize = 4096;

/// Log-average luminance (cd/m²) of the diffuse patch sides a camera sees
/// (facing it, inside its view cone, not hidden; not `cut` away by a
/// section, and seen past what is), weighted by solid angle.
fn metered_luminance(
    scene: &Scene,
    model: &LightModel,
    sides: &[Channels],
    camera: &GlobalTransform,
    projection: &Projection,
    cut: &dyn Fn(crate::glam::DVec3) -> bool,
) -> Option<f64> {
    let eye = camera.translation().as_dvec3();
    let forward = camera.forward().as_vec3().as_dvec3();
    let Projection::Perspective(perspective) = projection else { return None };
    let half_diagonal = ((perspective.fov / 2.0).tan() * (1.0 + perspective.aspect_ratio.powi(2)).sqrt()).atan();
    let cos_cone = f64::from(half_diagonal.cos());
    let patches = &scene.patches.patches;
    let step = patches.len().div_ceil(METERED_PATCHES).max(1);
    let (mut sum, mut weight) = (0.0, 0.0);
    for p in (0..patches.len()).step_by(step) {
        let patch = &patches[p];
        let MaterialKind::Diffuse { reflectance } = &scene.materials[patch.material as usize].kind else { continue };
        let to_patch = patch.centroid.as_dvec3() - eye;
        let distance = to_patch.length();
        let direction = to_patch / distance;
        let back = direction.dot(patch.normal.as_dvec3()) > 0.0;
        let cos_view = direction.dot(patch.normal.as_dvec3()).abs();
        if direction.dot(forward) < cos_cone || cos_view < 1e-3 || cut(patch.centroid.as_dvec3()) {
            continue;
        }
        if hidden(model, eye, direction, distance, p, cut) {
            continue;
        }
        let channels = sides.get(side_of(p as u32, back) as usize)?;
        let with_sun = Channels { sky: channels.sky + channels.sun, sun_diffuse: 0.0, ..*channels };
        let [r, g, b] = side_value(&with_sun, reflectance.0, RenderMode::Full);
        let luminance = f64::from(0.265 * r + 0.670 * g + 0.065 * b);
        if luminance > 1e-3 {
            let solid_angle = f64::from(patch.area) * cos_view / (distance * distance);
            sum += solid_angle * luminance.ln();
            weight += solid_angle;
        }
    }
    (weight > 0.0).then(|| (sum / weight).exp())
}

/// Whether something not `cut` away lies between `eye` and patch `patch`,
/// `distance` away along `direction` (what a section hides is passed
/// through).
fn hidden(
    model: &LightModel,
    eye: crate::glam::DVec3,
    direction: crate::glam::DVec3,
    distance: f64,
    patch: usize,
    cut: &dyn Fn(crate::glam::DVec3) -> bool,
) -> bool {
    let mut travelled = 0.0;
    while let Some((hit, t)) = model.trace(eye + direction * travelled, direction) {
        let t = travelled + t;
        if hit as usize == patch || t >= distance - 1e-3 {
            return false;
        }
        if !cut(eye + direction * t) {
            return true;
        }
        travelled = t + 1e-4;
    }
    false
}

/// The view a scene opens on: its first `[[cameras]]` entry, else a view
/// from inside the room behind its largest windows looking out through them,
/// or with no window from the sensors' room toward its opening (`model`
/// traces where the room's walls and floor are), else the [`overview`].
pub fn initial_view(scene: &Scene, model: Option<&LightModel>) -> Viewpoint {
    if let Some(first) = scene.viewpoints.first() {
        return first.clone();
    }
    model.and_then(LightModel::interior_view).unwrap_or_else(|| overview(scene))
}

/// What the scene is about (its windows and sensors, [`Scene::focus`]) seen
/// from the south-west and above: the building, not its site's ground.
pub fn overview(scene: &Scene) -> Viewpoint {
    let fov = DEFAULT_FOV;
    let (target, distance) = framing(scene.focus, fov);
    Viewpoint { name: "overview".into(), eye: target + Vec3::new(-0.55, -0.75, 0.55).normalize() * distance, target, fov }
}

/// Centre of the bounds and the distance at which a camera with this vertical
/// field of view sees all of them.
pub fn framing((lo, hi): (Vec3, Vec3), fov_degrees: f32) -> (Vec3, f32) {
    let centre = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(0.1);
    (centre, 1.1 * radius / (fov_degrees.to_radians() / 2.0).sin())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glam::DVec3;

    /// A section hides what lies above it; a vertical one what lies beyond
    /// its plane toward its azimuth (south here: y under 4 m).
    #[test]
    fn sections_cut_away_above_and_beyond() {
        let settings = RenderSettings {
            section: Some(2.9),
            vertical_section: Some(VerticalSection { azimuth: 180.0, offset: -4.0 }),
            ..Default::default()
        };
        assert!(!settings.cuts_away(DVec3::new(1.0, 5.0, 1.0)));
        assert!(settings.cuts_away(DVec3::new(1.0, 5.0, 3.0)));
        assert!(settings.cuts_away(DVec3::new(1.0, 3.0, 1.0)));
        assert!(!RenderSettings::default().cuts_away(DVec3::new(1.0, 3.0, 100.0)));
        // East: x over 2 m hidden.
        let east = RenderSettings { vertical_section: Some(VerticalSection { azimuth: 90.0, offset: 2.0 }), ..Default::default() };
        assert!(east.cuts_away(DVec3::new(2.5, 0.0, 0.0)) && !east.cuts_away(DVec3::new(1.5, 0.0, 0.0)));
        let through = VerticalSection::through(Vec3::new(2.0, 5.0, 1.0), 90.0);
        assert!((through.offset - 2.0).abs() < 1e-6, "{through:?}");
    }
}
