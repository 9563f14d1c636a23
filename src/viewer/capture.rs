//! Saving the view ([`SaveView`]): the window as a PNG (panels included),
//! and the 3D view's physical values as a Radiance HDR picture. For the
//! HDR, a physical-units camera with the view's own placement, projection
//! and viewport draws into a float image the size of the window for a few
//! frames; the image is read back, cropped to the viewport, written, and
//! the camera removed. Same camera, same viewport: the same pixels as the
//! window shows, in cd/m² instead of tone-mapped colour. The view panel's
//! buttons ask through [`SaveRequest`]; the outcome becomes the [`Note`].

use std::path::PathBuf;

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::PrimaryWindow;

use super::widgets::Note;
use crate::render::offscreen::{float_pixels, save_hdr, unit_exposure};
use crate::render::{PhysicalUnits, PictureCamera, hybrid_camera};

/// Frames the HDR camera draws before it is read: its pipelines and the
/// sun pass's per-view data are ready only a frame or two after it appears.
const HDR_FRAMES: u32 = 5;

/// Adds [`SaveView`] and the systems that carry it out, and the view
/// panel's [`SaveRequest`] (a file named by the time in the working folder).
pub struct CapturePlugin;

impl Plugin for CapturePlugin {
    fn build(&self, app: &mut App) {
        app.add_message::<SaveView>()
            .init_resource::<SaveResults>()
            .init_resource::<SaveRequest>()
            .add_systems(Update, (save_requested, note_saves.run_if(resource_changed::<SaveResults>)))
            .add_systems(PostUpdate, (start_saves, read_hdr_captures));
    }
}

/// A save the view panel asked for.
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SaveRequest(pub Option<ImageFormat>);

/// The files the view can be saved as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Hdr,
}

impl ImageFormat {
    pub fn extension(self) -> &'static str {
        match self {
            ImageFormat::Png => "png",
            ImageFormat::Hdr => "hdr",
        }
    }
}

/// Saves the view when asked, into the working folder, named by the time
/// (and a number, when that name is taken: nothing is overwritten).
fn save_requested(mut request: ResMut<SaveRequest>, mut note: ResMut<Note>, mut saves: MessageWriter<SaveView>) {
    let Some(format) = request.0.take() else { return };
    let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let name = (1..)
        .map(|k| {
            PathBuf::from(if k == 1 {
                format!("heliodon-view-{stamp}.{}", format.extension())
            } else {
                format!("heliodon-view-{stamp}-{k}.{}", format.extension())
            })
        })
        .find(|path| !path.exists())
        .expect("a free name");
    note.0 = Some(format!("saving {}", name.display()));
    saves.write(match format {
        ImageFormat::Png => SaveView::Png(name),
        ImageFormat::Hdr => SaveView::Hdr(name),
    });
}

/// The outcome of the last save, as the note.
fn note_saves(results: Res<SaveResults>, mut note: ResMut<Note>) {
    if let Some(last) = results.0.last() {
        note.0 = Some(match last {
            Ok(path) => format!("wrote {}", std::env::current_dir().map(|d| d.join(path)).unwrap_or(path.clone()).display()),
            Err(message) => message.clone(),
        });
    }
}

/// Save what the view shows.
#[derive(Message, Debug, Clone, PartialEq)]
pub enum SaveView {
    /// The window, panels included.
    Png(PathBuf),
    /// The 3D view's luminance (Radiance RGBE, W/sr/m² at 179 lm/W).
    Hdr(PathBuf),
}

/// Every save's outcome, in the order they finish: the file written, or one
/// line saying why not.
#[derive(Resource, Debug, Clone, Default)]
pub struct SaveResults(pub Vec<Result<PathBuf, String>>);

/// A physical-units camera drawing the view for an HDR file.
#[derive(Component)]
struct HdrCapture {
    path: PathBuf,
    frames_left: u32,
}

fn start_saves(
    mut requests: MessageReader<SaveView>,
    mut commands: Commands,
    mut images: ResMut<Assets<Image>>,
    mut results: ResMut<SaveResults>,
    window: Single<&Window, With<PrimaryWindow>>,
    view: Query<(&Camera, &Transform, &Projection), PictureCamera>,
) {
    for request in requests.read() {
        match request.clone() {
            SaveView::Png(path) => {
                commands.spawn(Screenshot::primary_window()).observe(
                    move |captured: On<ScreenshotCaptured>, mut results: ResMut<SaveResults>| {
                        let saved = captured
                            .image
                            .clone()
                            .try_into_dynamic()
                            .map_err(|e| e.to_string())
                            .and_then(|image| image.to_rgb8().save(&path).map_err(|e| e.to_string()));
                        results
                            .0
                            .push(saved.map(|()| path.clone()).map_err(|e| format!("{}: cannot save the picture: {e}", path.display())));
                    },
                );
            }
            SaveView::Hdr(path) => {
                let Ok((camera, transform, projection)) = view.single() else {
                    results.0.push(Err(format!("{}: no 3D view to save", path.display())));
                    continue;
                };
                let target = images.add(Image::new_target_texture(
                    window.physical_width().max(1),
                    window.physical_height().max(1),
                    TextureFormat::Rgba32Float,
                    None,
                ));
                commands
                    .spawn((
                        hybrid_camera(),
                        Camera { order: -1, viewport: camera.viewport.clone(), ..default() },
                        PhysicalUnits,
                        RenderTarget::Image(target.into()),
                        *transform,
                        projection.clone(),
                        HdrCapture { path, frames_left: HDR_FRAMES },
                    ))
                    .insert((Tonemapping::None, unit_exposure()));
            }
        }
    }
}

fn read_hdr_captures(mut commands: Commands, mut captures: Query<(Entity, &mut HdrCapture, &RenderTarget, &Camera)>) {
    for (entity, mut capture, target, camera) in &mut captures {
        if capture.frames_left == 0 {
            // Read back already; the camera goes when the picture is written.
            continue;
        }
        capture.frames_left -= 1;
        if capture.frames_left > 0 {
            continue;
        }
        let RenderTarget::Image(image) = target else { continue };
        let crop = camera.viewport.as_ref().map(|v| URect::from_corners(v.physical_position, v.physical_position + v.physical_size));
        let path = capture.path.clone();
        // The camera stays until its image is read: removing it in the frame
        // the read-back is asked for loses the image's contents.
        commands.spawn(Screenshot::image(image.handle.clone())).observe(
            move |captured: On<ScreenshotCaptured>, mut results: ResMut<SaveResults>, mut commands: Commands| {
                commands.entity(entity).despawn();
                let (width, height) = (captured.image.width(), captured.image.height());
                let pixels = float_pixels(&captured.image);
                let crop = crop.unwrap_or(URect::new(0, 0, width, height));
                let crop = URect::from_corners(crop.min.min(UVec2::new(width, height)), crop.max.min(UVec2::new(width, height)));
                let cropped: Vec<[f32; 3]> = (crop.min.y..crop.max.y)
                    .flat_map(|y| (crop.min.x..crop.max.x).map(move |x| (y * width + x) as usize))
                    .filter_map(|i| pixels.get(i).copied())
                    .collect();
                results.0.push(save_hdr(&path, crop.width(), crop.height(), &cropped).map(|()| path.clone()));
            },
        );
    }
}
