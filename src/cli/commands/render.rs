//! `heliodon render`: a picture with the hybrid renderer, headless.

use std::path::PathBuf;

use crate::cli::CliError;
use crate::cli::args::{SceneCase, in_range, load_for_command, parse_point};
use crate::panel::PanelCatalog;
use crate::render::offscreen::OffscreenRequest;
use crate::render::{RenderMode, RenderSettings, VerticalSection};
use crate::scene::{DEFAULT_FOV, Viewpoint};

#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub case: SceneCase,
    /// PNG file to write
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the physical image (radiance, W/sr/m² per channel; 179 lm/W) as a Radiance .hdr picture
    #[arg(long, value_name = "FILE")]
    pub hdr: Option<PathBuf>,
    /// A viewpoint from the scene's [[cameras]]
    #[arg(long, conflicts_with_all = ["eye", "target"])]
    pub camera: Option<String>,
    /// Eye position, model metres: X,Y,Z
    #[arg(long, value_parser = parse_point, requires = "target")]
    pub eye: Option<glam::Vec3>,
    /// Point looked at: X,Y,Z
    #[arg(long, value_parser = parse_point, requires = "eye")]
    pub target: Option<glam::Vec3>,
    /// Vertical field of view, degrees
    #[arg(long, value_name = "DEG", value_parser = in_range(1.0, 170.0))]
    pub fov: Option<f64>,
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub width: u32,
    #[arg(long, default_value_t = 800, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub height: u32,
    /// Exposure value (EV100); automatic from the scene's light when absent
    #[arg(long, value_name = "EV", value_parser = in_range(-10.0, 30.0))]
    pub exposure: Option<f64>,
    /// full, sun, sky, indirect or falsecolor
    #[arg(long, default_value = "full", value_parser = parse_mode)]
    pub mode: RenderMode,
    /// A horizontal section: hide what lies above this height (model metres) to look into the rooms; the light still comes from the whole model
    #[arg(long, value_name = "Z", value_parser = in_range(-1e5, 1e5))]
    pub section: Option<f64>,
    /// A vertical section: hide what lies beyond a vertical plane, toward DEG (clockwise from north), M metres from the model's origin that way
    #[arg(long, value_name = "DEG,M", value_parser = parse_vertical_section)]
    pub vertical_section: Option<VerticalSection>,
    /// N times the light engine's rays per patch (hemisphere and aimed at windows): a smoother indirect light for a final picture, or a converged reference to measure the default's noise against; the precomputation takes about N times longer. Pictures already take more rays than sensors do: 8 times up to 6,250 patches, fewer on larger models (as the viewer's light once smoothed)
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub quality: u32,
}

fn parse_vertical_section(text: &str) -> Result<VerticalSection, String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [azimuth, offset] = parts[..] else { return Err(format!("'{text}' is not DEG,M")) };
    Ok(VerticalSection { azimuth: in_range(-360.0, 360.0)(azimuth)? as f32, offset: in_range(-1e5, 1e5)(offset)? as f32 })
}

fn parse_mode(text: &str) -> Result<RenderMode, String> {
    RenderMode::parse(text).ok_or_else(|| format!("'{text}' is not one of {}", RenderMode::NAMES.join(", ")))
}

/// Renders the view and writes the PNG (and the HDR).
pub fn run(args: &RenderArgs, panels: &PanelCatalog) -> Result<(), CliError> {
    let (case, sky) = (&args.case, args.case.sky.spec()?);
    let scene = load_for_command(&case.scene, panels, false)?;
    let view = match &args.camera {
        Some(name) => Some(scene.viewpoints.iter().find(|v| &v.name == name).cloned().ok_or_else(|| {
            let known: Vec<&str> = scene.viewpoints.iter().map(|v| v.name.as_str()).collect();
            format!(
                "--camera {name}: {} has no such camera (it has: {})",
                case.scene.display(),
                if known.is_empty() { "none".into() } else { known.join(", ") }
            )
        })?),
        None => args.eye.zip(args.target).map(|(eye, target)| Viewpoint { name: "command line".into(), eye, target, fov: DEFAULT_FOV }),
    };
    if view.as_ref().is_some_and(|v| (v.eye - v.target).length() < 1e-6) {
        return Err(CliError::failure("--eye and --target are the same point"));
    }
    let image = crate::render::offscreen::render(OffscreenRequest {
        scene: case.scene.clone(),
        view,
        fov: args.fov.map(|fov| fov as f32),
        width: args.width,
        height: args.height,
        when: Some(case.when()),
        sky: Some(sky),
        settings: RenderSettings {
            mode: args.mode,
            exposure: args.exposure.map(|e| e as f32),
            section: args.section.map(|z| z as f32),
            vertical_section: args.vertical_section,
            ..Default::default()
        },
        // The light as the viewer shows it once smoothed.
        light: crate::light::LightSettings::default().with_more_patch_rays(args.quality as usize).for_display(scene.patches.patches.len()),
        panels: panels.clone(),
    })?;
    image.save_png(&args.out)?;
    if let Some(path) = &args.hdr {
        image.save_hdr(path)?;
    }
    Ok(())
}
