//! [`SkyBackgroundPlugin`]: the sky model's luminance drawn around the model
//! and seen through its glass. The current sky ([`SunSky`]: gensky, Perez
//! or CIE, and below the horizon the ground glow, without the sun) is baked
//! on the CPU into a cubemap of [`FACE`]² texels a face whenever it changes,
//! in W/sr/m², and drawn as Bevy's `Skybox` at 179 lm/W: cd/m² like the
//! surfaces, under the same exposure and tone map, and in the
//! physical-units image as it is. The models are photometric; a sky with a
//! sun is drawn a light blue of the same luminance ([`CLEAR_BLUE`]), an
//! overcast one and the ground grey. Only the full and sky modes draw it;
//! the others show one part of the light on the surfaces, not the sky.

use bevy::asset::RenderAssetUsages;
use bevy::light::Skybox;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat, TextureViewDescriptor, TextureViewDimension};

use super::{HeliodonRenderSystems, RenderMode, RenderSettings, SunPassView};
use crate::ecs::SunSky;
use crate::glam::DVec3;
use crate::sky::{LUMINOUS_EFFICACY, Sky};

pub struct SkyBackgroundPlugin;

impl Plugin for SkyBackgroundPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(Update, (bake_sky, show_sky).chain().in_set(HeliodonRenderSystems::Surfaces));
    }
}

/// Texels along a cubemap face's side: the sky's luminance changes over
/// tens of degrees (the circumsolar ring over a few, 2.8° a texel here).
const FACE: usize = 32;

/// The colour of a sky with a sun, luminance 1 by Radiance's weights
/// (0.265, 0.670, 0.065).
pub const CLEAR_BLUE: [f32; 3] = [0.788, 1.029, 1.564];

/// The cubemap of the current sky, once there is one.
#[derive(Resource)]
struct SkyCubemap(Handle<Image>);

/// The direction through texel (`column`, `row`) of cubemap face `face`
/// (+x, −x, +y, −y, +z, −z; rows from the top), as wgpu samples cubemaps.
pub fn cube_direction(face: usize, column: usize, row: usize, side: usize) -> DVec3 {
    let s = 2.0 * (column as f64 + 0.5) / side as f64 - 1.0;
    let t = 2.0 * (row as f64 + 0.5) / side as f64 - 1.0;
    let d = match face {
        0 => DVec3::new(1.0, -t, -s),
        1 => DVec3::new(-1.0, -t, s),
        2 => DVec3::new(s, 1.0, t),
        3 => DVec3::new(s, -1.0, -t),
        4 => DVec3::new(s, -t, 1.0),
        _ => DVec3::new(-s, -t, -1.0),
    };
    d.normalize()
}

/// The sky's radiance (W/sr/m²) over a cubemap, as half floats.
fn cubemap(sky: &Sky) -> Image {
    let blue = sky.sun_up().is_some_and(|s| s.normal_irradiance() > 0.0);
    bake_cubemap(FACE, |d| {
        // Bevy's skybox samples the world direction with z negated (its
        // cubemaps are left-handed); the model's frame is its world.
        let direction = d * DVec3::new(1.0, 1.0, -1.0);
        let radiance = sky.radiance(direction) as f32;
        let colour = if blue && direction.z > 0.0 { CLEAR_BLUE } else { [1.0; 3] };
        colour.map(|c| c * radiance)
    })
}

/// A cubemap of `side`² texels a face holding `colour` of each texel's
/// direction (as wgpu samples cubemaps, [`cube_direction`]), as half floats.
pub(super) fn bake_cubemap(side: usize, colour: impl Fn(DVec3) -> [f32; 3]) -> Image {
    let mut data = Vec::with_capacity(6 * side * side * 8);
    for face in 0..6 {
        for row in 0..side {
            for column in 0..side {
                for value in colour(cube_direction(face, column, row, side)).into_iter().chain([1.0]) {
                    data.extend_from_slice(&half::f16::from_f32(value).to_le_bytes());
                }
            }
        }
    }
    let size = Extent3d { width: side as u32, height: side as u32, depth_or_array_layers: 6 };
    let mut image = Image::new(size, TextureDimension::D2, data, TextureFormat::Rgba16Float, RenderAssetUsages::RENDER_WORLD);
    image.texture_view_descriptor = Some(TextureViewDescriptor { dimension: Some(TextureViewDimension::Cube), ..default() });
    image
}

/// Bakes the sky again when it changes.
fn bake_sky(mut commands: Commands, sun_sky: Option<Res<SunSky>>, cubemap_of: Option<Res<SkyCubemap>>, mut images: ResMut<Assets<Image>>) {
    let Some(sun_sky) = sun_sky.filter(|s| s.is_changed()) else { return };
    let image = cubemap(&sun_sky.sky);
    match cubemap_of {
        Some(cubemap) => {
            let _ = images.insert(cubemap.0.id(), image);
        }
        None => commands.insert_resource(SkyCubemap(images.add(image))),
    }
}

/// Puts the sky behind every camera of the hybrid renderer in the modes
/// that show it, and takes it away in the others.
fn show_sky(
    mut commands: Commands,
    cubemap: Option<Res<SkyCubemap>>,
    settings: Res<RenderSettings>,
    cameras: Query<(Entity, Has<Skybox>), With<SunPassView>>,
) {
    let shown = matches!(settings.mode, RenderMode::Full | RenderMode::Sky);
    for (camera, has) in &cameras {
        match (&cubemap, shown) {
            (Some(cubemap), true) if !has || cubemap.is_changed() || settings.is_changed() => {
                commands.entity(camera).insert(Skybox {
                    image: Some(cubemap.0.clone()),
                    brightness: LUMINOUS_EFFICACY as f32,
                    rotation: Quat::IDENTITY,
                });
            }
            (_, false) if has => {
                commands.entity(camera).remove::<Skybox>();
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blue keeps the sky's luminance.
    #[test]
    fn clear_blue_has_unit_luminance() {
        let luminance = crate::light::luminous(CLEAR_BLUE.map(f64::from));
        assert!((luminance - 1.0).abs() < 1e-3, "{luminance}");
    }

    /// Each face's middle looks along its axis, and neighbouring faces meet
    /// edge to edge: the last column of +z's middle row is the first of +x's.
    #[test]
    fn cube_faces_follow_wgpu() {
        let axes = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
        for (face, axis) in axes.iter().enumerate() {
            assert!(cube_direction(face, 2, 2, 5).distance(*axis) < 1e-12, "face {face}");
        }
        // +z (top, looking up with −y at the top of the face): its right edge is +x.
        let right_of_up = cube_direction(4, 999, 500, 1000);
        let left_of_x = cube_direction(0, 0, 500, 1000);
        assert!(right_of_up.distance(left_of_x) < 0.01, "{right_of_up} vs {left_of_x}");
    }
}
