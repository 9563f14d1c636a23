//! A CPU reference for the direct-sun image: each pixel's ray finds its
//! surface in the light engine's BVH (or the ground drawn under the model,
//! `GroundPlane`), then shadow rays from there go toward
//! the sun through glass (Radiance's transmittance) and along each panel
//! lobe through its panel's windows ([`LightModel::sun_irradiance`]). The
//! renderer's `sun` mode is checked against it, pixel by pixel.

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;

use super::RenderMode;
use super::offscreen::{self, OffscreenRequest};
use crate::light::LightModel;
use crate::scene::{MaterialKind, Viewpoint, load_scene};
use crate::sky::{LUMINOUS_EFFICACY, sky_at};

/// Pixel centres' rays of a perspective camera as Bevy draws it (vertical
/// field of view, the model's z up), row by row from the top.
pub fn camera_rays(view: &Viewpoint, width: u32, height: u32) -> Vec<DVec3> {
    let forward = (view.target - view.eye).normalize().as_dvec3();
    let right = forward.cross(DVec3::Z).normalize();
    let up = right.cross(forward);
    let tan = (f64::from(view.fov).to_radians() / 2.0).tan();
    let aspect = f64::from(width) / f64::from(height);
    (0..height)
        .flat_map(|j| (0..width).map(move |i| (i, j)))
        .map(|(i, j)| {
            let x = (2.0 * (f64::from(i) + 0.5) / f64::from(width) - 1.0) * tan * aspect;
            let y = (1.0 - 2.0 * (f64::from(j) + 0.5) / f64::from(height)) * tan;
            (forward + right * x + up * y).normalize()
        })
        .collect()
}

/// How a rendered direct-sun image agrees with the reference.
#[derive(Debug, Clone)]
pub struct SunComparison {
    /// Pixels whose ray meets a diffuse surface or the ground.
    pub compared: usize,
    /// Share of them that agree on lit (above 1 cd/m²) or unlit.
    pub agreement: f64,
    /// Pixels lit in both.
    pub lit: usize,
    /// Share of those within 2% of the reference.
    pub within: f64,
    /// The largest relative difference among them.
    pub worst: f64,
}

impl std::fmt::Display for SunComparison {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} pixels, lit/unlit agree {:.2}%, {} lit, {:.2}% within 2% (worst {:.1}%)",
            self.compared,
            100.0 * self.agreement,
            self.lit,
            100.0 * self.within,
            100.0 * self.worst
        )
    }
}

/// Renders `request` in `sun` mode and compares it with the reference. The
/// picture goes to `picture` and a map of disagreements beside it
/// (`.diff.png`: red where only the reference is lit, green where only the
/// picture is).
pub fn compare_direct_sun(request: &OffscreenRequest, picture: &Path) -> Result<SunComparison, String> {
    let request = OffscreenRequest { settings: super::RenderSettings { mode: RenderMode::Sun, ..request.settings }, ..request.clone() };
    let scene = Arc::new(load_scene(&request.scene, &request.panels).map_err(|e| e.to_string())?.scene);
    let model = LightModel::unlit(scene.clone());
    let when = request.when.ok_or("the comparison needs a time")?;
    let spec = request.sky.clone().ok_or("the comparison needs a sky")?;
    let sky = sky_at(&scene.site, &spec, &when).1.map_err(|e| e.to_string())?;
    let sun = sky.sun_up().ok_or("the sun is down")?;
    let view = request.view.clone().unwrap_or_else(|| super::initial_view(&scene, Some(&model)));
    let image = offscreen::render(request.clone())?;
    image.save_png(picture)?;
    let (width, height) = (request.width, request.height);
    let (mut compared, mut agree, mut lit, mut within) = (0usize, 0usize, 0usize, 0usize);
    let mut worst: f64 = 0.0;
    let mut disagreement = image::RgbImage::new(width, height);
    let eye = view.eye.as_dvec3();
    let beams = model.sun_beams(&sun);
    let ground = heliodon_core::sun_pass::GroundPlane::of(&scene);
    for (k, (ray, pixel)) in camera_rays(&view, width, height).into_iter().zip(&image.physical).enumerate() {
        // The model, or where the ray passes it, the ground drawn under it.
        let (point, normal, reflectance) = match model.trace(eye, ray) {
            Some((patch, distance)) => {
                let patch = &scene.patches.patches[patch as usize];
                let MaterialKind::Diffuse { reflectance } = &scene.materials[patch.material as usize].kind else { continue };
                let normal = patch.normal.as_dvec3() * if patch.normal.as_dvec3().dot(ray) > 0.0 { -1.0 } else { 1.0 };
                (eye + ray * distance, normal, reflectance.0[1])
            }
            None => match ground.hit(eye, ray) {
                Some(point) => (point, DVec3::Z, ground.reflectance),
                None => continue,
            },
        };
        let irradiance = model.beams_irradiance(point, normal, &beams);
        let expected = f64::from(reflectance) / std::f64::consts::PI * irradiance * LUMINOUS_EFFICACY;
        let got = f64::from(pixel[1]);
        compared += 1;
        let (reference_lit, picture_lit) = (expected > 1.0, got > 1.0);
        agree += usize::from(reference_lit == picture_lit);
        let shade = match (reference_lit, picture_lit) {
            (a, b) if a == b => [40 + 80 * u8::from(a); 3],
            (true, _) => [255, 0, 0],
            _ => [0, 255, 0],
        };
        disagreement.put_pixel(k as u32 % width, k as u32 / width, image::Rgb(shade));
        if reference_lit && picture_lit {
            lit += 1;
            let error = (got / expected - 1.0).abs();
            within += usize::from(error <= 0.02);
            worst = worst.max(error);
        }
    }
    disagreement.save(picture.with_extension("diff.png")).map_err(|e| format!("{}: {e}", picture.display()))?;
    Ok(SunComparison { compared, agreement: agree as f64 / compared.max(1) as f64, lit, within: within as f64 / lit.max(1) as f64, worst })
}
