//! A CAD-like camera: left-drag orbits about the point of the model under
//! the cursor where it pressed (that point stays put on the screen; a click
//! without a drag leaves the view alone), right- or middle-drag
//! pans, the wheel zooms toward the point under the cursor, `F` frames the
//! building (the scene's focus: its windows and sensors). In walk mode (a panel checkbox) W/A/S/D move the eye at its
//! height and left-drag looks around from it. z is up. The camera panel's
//! presets and viewpoints arrive as [`CameraControl`] requests.

use bevy::input::mouse::{AccumulatedMouseScroll, MouseScrollUnit};
use bevy::prelude::*;
use bevy::window::PrimaryWindow;

use super::focus::PanelFocus;
use super::schedule::ViewerSystems;
use crate::ecs::ActiveScene;
use crate::render::framing;
use crate::scene::Viewpoint;

/// The camera: navigation every frame, and the requests of the camera panel.
pub struct CameraPlugin;

impl Plugin for CameraPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<CameraControl>().add_systems(Update, (apply_camera_request, navigate).chain().in_set(ViewerSystems::Camera));
    }
}

/// What the camera panel asks of the camera, and the views kept this session.
#[derive(Resource, Debug, Clone, Default)]
pub struct CameraControl {
    /// A change asked for, applied by [`apply_camera_request`].
    pub request: Option<CameraRequest>,
    /// Views the user saved this session.
    pub saved_views: Vec<Viewpoint>,
    /// Walk mode: W/A/S/D move the eye at its height, dragging looks around.
    pub walk: bool,
}

/// The camera changes the panel offers.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraRequest {
    /// Straight down on the model.
    Top,
    /// From the south, level.
    Front,
    /// From the east, level.
    Side,
    /// From the south-west and above.
    Perspective,
    Viewpoint(Viewpoint),
    /// Keep the current view in the list.
    Save,
}

/// Orbit state; the transform is derived from it every frame.
#[derive(Component, Debug, Clone, Copy)]
pub struct CadCamera {
    pub focus: Vec3,
    /// Distance from the eye to the focus.
    pub distance: f32,
    /// Azimuth of the eye around the focus, radians counter-clockwise from +x.
    pub yaw: f32,
    /// Elevation of the eye above the focus, radians.
    pub pitch: f32,
}

/// Radians of orbit per pixel of drag.
const ORBIT_SPEED: f32 = 0.006;
/// Zoom factor per wheel line.
const ZOOM_STEP: f32 = 0.85;
const PIXELS_PER_LINE: f32 = 40.0;
const MAX_PITCH: f32 = 1.55;
/// Walking speed, metres per second.
const WALK_SPEED: f32 = 1.4;

impl CadCamera {
    pub fn looking(eye: Vec3, target: Vec3) -> Self {
        let offset = eye - target;
        let distance = offset.length().max(1e-3);
        Self { focus: target, distance, yaw: offset.y.atan2(offset.x), pitch: (offset.z / distance).clamp(-1.0, 1.0).asin() }
    }

    pub fn from_viewpoint(view: &Viewpoint) -> Self {
        Self::looking(view.eye, view.target)
    }

    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.focus + self.distance * Vec3::new(cp * cy, cp * sy, sp)
    }

    /// Turns the view by `yaw` and `pitch` (radians) about `pivot`, which
    /// keeps its place in the view (the focus, when `None`; the eye, to look
    /// around from it).
    pub fn orbit(&mut self, yaw: f32, pitch: f32, pivot: Option<Vec3>) {
        let before = self.transform().rotation;
        self.yaw += yaw;
        self.pitch = (self.pitch + pitch).clamp(-MAX_PITCH, MAX_PITCH);
        if let Some(pivot) = pivot {
            let turn = self.transform().rotation * before.inverse();
            self.focus = pivot + turn * (self.focus - pivot);
        }
    }

    pub fn transform(&self) -> Transform {
        Transform::from_translation(self.eye()).looking_at(self.focus, Vec3::Z)
    }
}

#[allow(clippy::too_many_arguments)]
pub fn navigate(
    mouse: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    scroll: Res<AccumulatedMouseScroll>,
    window: Single<&Window, With<PrimaryWindow>>,
    active: Res<ActiveScene>,
    focus: Option<Res<PanelFocus>>,
    control: Option<Res<CameraControl>>,
    ray_model: Option<Res<crate::ecs::RayModel>>,
    time: Res<Time>,
    mut cameras: Query<(&mut CadCamera, &mut Transform, &Camera, &GlobalTransform, &Projection)>,
    mut drag_in_view: Local<bool>,
    mut pivot: Local<Option<Vec3>>,
    mut last_cursor: Local<Option<Vec2>>,
) {
    // Drags follow the cursor across the window (raw mouse motion is not
    // there on every system: remote desktops, Xvfb).
    let moved = window.cursor_position().zip(*last_cursor).map_or(Vec2::ZERO, |(now, before)| now - before);
    *last_cursor = window.cursor_position();
    let over_panels = focus.as_ref().zip(window.cursor_position()).is_some_and(|(focus, cursor)| focus.over_panels(cursor));
    let walking = control.as_ref().is_some_and(|c| c.walk);
    // Keys typed into a panel field are for the field.
    let keys_for_camera = !focus.as_ref().is_some_and(|f| f.keyboard);
    let buttons = [MouseButton::Left, MouseButton::Right, MouseButton::Middle];
    for (mut cad, mut transform, camera, global, projection) in &mut cameras {
        let fov = match projection {
            Projection::Perspective(p) => p.fov,
            _ => std::f32::consts::FRAC_PI_3,
        };
        // The pointer belongs to the view only inside its viewport and off
        // the panels; a drag belongs to where it started. (The panels' flag
        // is a frame old, so a press that lands with a jump of the pointer
        // is told apart by the viewport alone.)
        let cursor = cursor_in_view(&window, camera).filter(|_| !over_panels);
        if mouse.any_just_pressed(buttons) {
            *drag_in_view = cursor.is_some();
        } else if !mouse.any_pressed(buttons) {
            *drag_in_view = false;
        }
        let delta = if *drag_in_view { moved } else { Vec2::ZERO };
        let cursor_ray = cursor.and_then(|cursor| camera.viewport_to_world(global, cursor).ok());
        if over_panels && !*drag_in_view {
            // Keys typed into a panel are not for the camera either.
            *transform = cad.transform();
            continue;
        }
        if mouse.just_pressed(MouseButton::Left) {
            // The point of the model under the cursor (none off the model:
            // then the orbit is about the focus).
            *pivot = cursor_ray.zip(ray_model.as_ref()).and_then(|(ray, model)| {
                let (_, distance) = model.0.trace(ray.origin.as_dvec3(), ray.direction.as_vec3().as_dvec3())?;
                Some(ray.origin + ray.direction * distance as f32)
            });
        }
        if mouse.pressed(MouseButton::Left) && delta != Vec2::ZERO {
            // Walking looks around from the eye; otherwise orbit the pivot.
            let pivot = if walking { Some(cad.eye()) } else { *pivot };
            cad.orbit(-delta.x * ORBIT_SPEED, delta.y * ORBIT_SPEED, pivot);
        }
        if walking {
            let (sin, cos) = cad.yaw.sin_cos();
            let forward = -Vec3::new(cos, sin, 0.0);
            let right = forward.cross(Vec3::Z);
            let mut step = Vec3::ZERO;
            for (key, direction) in [(KeyCode::KeyW, forward), (KeyCode::KeyS, -forward), (KeyCode::KeyD, right), (KeyCode::KeyA, -right)] {
                if keys_for_camera && keys.pressed(key) {
                    step += direction;
                }
            }
            cad.focus += step.normalize_or_zero() * WALK_SPEED * time.delta_secs();
        }
        if (mouse.pressed(MouseButton::Right) || mouse.pressed(MouseButton::Middle)) && delta != Vec2::ZERO {
            // One pixel moves the focus by what a pixel spans at the focus distance.
            let per_pixel = 2.0 * cad.distance * (fov / 2.0).tan() / window.height().max(1.0);
            let right = transform.right().as_vec3();
            let up = transform.up().as_vec3();
            cad.focus += (-delta.x * right + delta.y * up) * per_pixel;
        }
        let lines = match scroll.unit {
            MouseScrollUnit::Line => scroll.delta.y,
            MouseScrollUnit::Pixel => scroll.delta.y / PIXELS_PER_LINE,
        };
        if lines != 0.0 && cursor.is_some() {
            let factor = ZOOM_STEP.powf(lines);
            // Scale the eye and the focus about the point under the cursor on
            // the plane through the focus facing the camera.
            let anchor = cursor_ray
                .and_then(|ray| {
                    let normal = global.forward().as_vec3();
                    let t = ray.intersect_plane(cad.focus, InfinitePlane3d::new(normal))?;
                    Some(ray.get_point(t))
                })
                .unwrap_or(cad.focus);
            cad.focus = anchor + (cad.focus - anchor) * factor;
            cad.distance *= factor;
        }
        if keys_for_camera
            && keys.just_pressed(KeyCode::KeyF)
            && let Some(scene) = &active.scene
        {
            let (centre, distance) = framing(scene.focus, fov.to_degrees());
            cad.focus = centre;
            cad.distance = distance;
        }
        *transform = cad.transform();
    }
}

/// Applies the camera panel's request.
pub fn apply_camera_request(mut control: ResMut<CameraControl>, active: Res<ActiveScene>, mut cameras: Query<&mut CadCamera>) {
    let Some(request) = control.request.take() else { return };
    let Some(scene) = &active.scene else { return };
    let (centre, distance) = framing(scene.focus, crate::scene::DEFAULT_FOV);
    for mut camera in &mut cameras {
        let (yaw, pitch) = match &request {
            CameraRequest::Top => (-std::f32::consts::FRAC_PI_2, 1.5),
            CameraRequest::Front => (-std::f32::consts::FRAC_PI_2, 0.0),
            CameraRequest::Side => (0.0, 0.0),
            CameraRequest::Perspective => (-2.2, 0.6),
            CameraRequest::Viewpoint(view) => {
                *camera = CadCamera::from_viewpoint(view);
                continue;
            }
            CameraRequest::Save => {
                let name = format!("saved {}", control.saved_views.len() + 1);
                let eye = camera.eye();
                control.saved_views.push(Viewpoint { name, eye, target: camera.focus, fov: crate::scene::DEFAULT_FOV });
                continue;
            }
        };
        *camera = CadCamera { focus: centre, distance, yaw, pitch };
    }
}

/// The cursor, when it is inside `camera`'s viewport (the panels shift and
/// narrow it). Window coordinates, as Bevy's viewport conversions take and
/// give them.
pub fn cursor_in_view(window: &Window, camera: &Camera) -> Option<Vec2> {
    let cursor = window.cursor_position()?;
    camera.logical_viewport_rect().filter(|rect| rect.contains(cursor)).map(|_| cursor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn looking_round_trips_the_eye() {
        let eye = Vec3::new(-3.0, -4.0, 2.5);
        let target = Vec3::new(1.0, 2.0, 0.5);
        let cad = CadCamera::looking(eye, target);
        assert!((cad.eye() - eye).length() < 1e-4);
    }

    #[test]
    fn orbiting_keeps_the_pivot_in_place_in_the_view() {
        let in_view = |cad: &CadCamera, p: Vec3| cad.transform().compute_affine().inverse().transform_point3(p);
        let mut cad = CadCamera::looking(Vec3::new(-3.0, -4.0, 2.5), Vec3::new(1.0, 2.0, 0.5));
        let pivot = Vec3::new(2.0, 1.0, 0.0);
        let before = in_view(&cad, pivot);
        cad.orbit(0.3, -0.2, Some(pivot));
        assert!((in_view(&cad, pivot) - before).length() < 1e-4, "{} vs {before}", in_view(&cad, pivot));
        // Looking around from the eye keeps the eye.
        let eye = cad.eye();
        cad.orbit(-0.5, 0.1, Some(eye));
        assert!((cad.eye() - eye).length() < 1e-4);
        // About the focus: the focus stays.
        let focus = cad.focus;
        cad.orbit(0.4, 0.0, None);
        assert_eq!(cad.focus, focus);
    }
}
