//! The sun pass's main-world geometry: what the stencil shadow-volume pass
//! draws for one scene, sun and panel state ([`SunPassFrame`]), as plain
//! data for the renderer to upload. The algorithm (the thesis' algorithm 1)
//! and the GPU side are described in the renderer's `render::sun_pass`.
//!
//! - [`Casters`] (`shadow_volume.rs`): per-triangle volumes for a directional light,
//!   silhouette edges only where the casters are manifold;
//! - [`SunPassFrame::new`]: one [`DirectionPass`] per light direction (the
//!   sun, then every panel lobe as a fake sun), its opaque casters' volume
//!   and its lights through apertures (glass windows of one material facing
//!   one way, or a panel group's windows);
//! - [`lit_vertices`]: the diffuse surfaces the lit passes draw, and the
//!   ground outside ([`GroundPlane`]), where the building's shadow falls;
//! - [`LitRuns`]: per light through an aperture, only the runs of those
//!   triangles that its beam can reach (a room's surfaces behind its
//!   windows, not the whole building's), since every lit pass
//!   rasterizes what it draws however little of it the stencil passes.

mod shadow_volume;

use std::ops::Range;
use std::sync::Arc;

use glam::{Vec2, Vec3, Vec4};

pub use shadow_volume::{Casters, VolumeEnd};

use crate::light::{Glass, LightModel};
use crate::scene::{MaterialKind, Scene, clip_convex};
use crate::sky::SunSource;

/// A light along a pass's direction and the aperture it comes through.
#[derive(Debug, Clone, PartialEq)]
pub struct SunLight {
    /// Unit vector toward the light (the sun, or a lobe's fake sun).
    pub direction: Vec3,
    /// Irradiance normal to `direction` after the window, W/m².
    pub irradiance: f32,
    /// The aperture's volume (range in [`SunPassFrame::volumes`]); `None`:
    /// light that meets no surface at all (the outside of the model), with
    /// every window's volume counted as blocking.
    pub aperture: Option<Range<u32>>,
    /// The lit surfaces drawn for it: a range of [`SunPassFrame::lit_indices`]
    /// (those its beam through the aperture can reach; never empty: a beam
    /// that reaches no lit surface is no light of the frame), or `None`: all.
    pub lit: Option<Range<u32>>,
}

/// Everything drawn for one light direction: the opaque casters' volume
/// along it, then its lights.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectionPass {
    /// The opaque casters' near caps (range in [`SunPassFrame::volumes`]), drawn depth-biased.
    pub opaque_caps: Range<u32>,
    /// The opaque casters' side triangles (and the shadows exterior casters throw on a panel).
    pub opaque_sides: Range<u32>,
    /// Every window's volume along this direction (for the outside light).
    pub all_windows: Range<u32>,
    /// The lights along this direction, each through its aperture.
    pub lights: Vec<SunLight>,
}

/// What the sun pass draws for the current scene, sun and mode.
pub struct SunPassFrame {
    /// Counts changes, so the render world uploads each frame only once.
    pub generation: u64,
    /// The scene's surfaces as the sun pass sees them, whatever the sun.
    pub surfaces: Arc<SunPassSurfaces>,
    /// Vertex indices into the lit surfaces, the lights' [`SunLight::lit`] one after another.
    pub lit_indices: Vec<u32>,
    /// All shadow volumes, referred to by ranges.
    pub volumes: Vec<Vec4>,
    /// The sun's direction first, then each panel lobe's.
    pub passes: Vec<DirectionPass>,
}

impl SunPassFrame {
    /// The passes for `scene` under `sun`, from its `surfaces` made once
    /// ([`SunPassSurfaces::new`]); `model` knows the panel windows and their lobes.
    /// The sun's pass lights through glass (Radiance's transmittance at each
    /// aperture's angle) and the outside; each panel lobe is a fake sun with
    /// a pass of its own through its panel's windows (the thesis' 1 + 2·k·d
    /// passes). What shades a panel from the real sun outside is projected
    /// onto the panel and casts along each of its lobes, as in the engine.
    pub fn new(scene: &Scene, model: &LightModel, surfaces: Arc<SunPassSurfaces>, sun: &SunSource, generation: u64) -> Self {
        let surface_triangles = |surface: u32| scene.surface_triangles(surface).iter().map(|t| t.vertices);
        let opaque_casters = surfaces.opaque.triangles();
        // Apertures: the window groups (one material facing one way, see
        // `light::windows`), glass passing the sun alike, panels by their lobes.
        enum Key {
            Glass(u32),
            Panel(u32),
        }
        let apertures: Vec<(Key, Casters, Vec3)> = model
            .windows
            .groups
            .iter()
            .map(|group| {
                let surfaces = group.windows.iter().map(|&w| scene.windows[w as usize].surface);
                let panes = Casters::new(surfaces.clone().flat_map(surface_triangles).collect());
                let first = surfaces.clone().next().expect("a group has a window");
                let key = match model.panel_group_of_surface(first) {
                    Some(panel_group) => Key::Panel(panel_group),
                    None => Key::Glass(group.material),
                };
                (key, panes, group.outward.as_vec3())
            })
            .collect();
        let mut volumes: Vec<Vec4> = Vec::new();
        // Volumes end a metre past the ground drawn outside (or above the model, for light going up).
        let ground = GroundPlane::of(scene).height;
        let end = |direction: Vec3| VolumeEnd::beyond(ground, scene.bounds.1.z, direction);
        let add_volume =
            |casters: &Casters, direction: Vec3, volumes: &mut Vec<Vec4>| casters.volume_into(direction, end(direction), volumes);
        let direction_pass = |(opaque_caps, opaque_sides): (Range<u32>, Range<u32>)| DirectionPass {
            opaque_caps,
            opaque_sides,
            all_windows: 0..0,
            lights: Vec::new(),
        };
        let runs = &surfaces.runs;
        let mut lit_indices = Vec::new();
        let to_sun = sun.direction.as_vec3();
        let mut sun_pass = direction_pass(add_volume(&surfaces.opaque, to_sun, &mut volumes));
        let windows_start = volumes.len() as u32;
        let mut aperture_volumes = Vec::new();
        for (_, panes, _) in &apertures {
            let (caps, sides) = add_volume(panes, to_sun, &mut volumes);
            aperture_volumes.push(caps.start..sides.end);
        }
        sun_pass.all_windows = windows_start..volumes.len() as u32;
        let beams = model.sun_beams(sun);
        let mut lobe_passes = Vec::new();
        for ((key, pane_casters, normal), volume) in apertures.iter().zip(aperture_volumes) {
            let panes = pane_casters.triangles();
            match key {
                Key::Glass(material) => {
                    let cos = f64::from(normal.dot(to_sun));
                    let transmittance = match &scene.materials[*material as usize].kind {
                        MaterialKind::Glass { transmittance } => Glass::from_transmittance(f64::from(*transmittance)).at(cos).0,
                        _ => 1.0,
                    };
                    if cos.abs() > 1e-6 {
                        let lit = runs.reached(panes, to_sun, &mut lit_indices);
                        if !lit.is_empty() {
                            let irradiance = (sun.normal_irradiance() * transmittance) as f32;
                            sun_pass.lights.push(SunLight { direction: to_sun, irradiance, aperture: Some(volume), lit: Some(lit) });
                        }
                    }
                }
                Key::Panel(group) => {
                    // What shades the panel from the real sun outside casts
                    // along each lobe too, from where it lies on the panel.
                    let shadows = Casters::new(shadows_on(panes, *normal, opaque_casters, to_sun));
                    // A lobe's light starts at the panel: only what lies on
                    // the room side of it casts along the lobe.
                    let inside = normal * -to_sun.dot(*normal).signum();
                    let inner_casters = Casters::new(beside(opaque_casters, panes[0][0], inside));
                    for beam in beams.iter().filter(|b| b.panel_group == Some(*group)) {
                        let direction = beam.to_light.as_vec3();
                        let lit = runs.reached(panes, direction, &mut lit_indices);
                        if lit.is_empty() {
                            continue;
                        }
                        let mut pass = direction_pass(add_volume(&inner_casters, direction, &mut volumes));
                        let (_, shadow_sides) = add_volume(&shadows, direction, &mut volumes);
                        pass.opaque_sides.end = shadow_sides.end;
                        let (caps, sides) = add_volume(pane_casters, direction, &mut volumes);
                        pass.lights.push(SunLight {
                            direction,
                            irradiance: beam.normal_irradiance as f32,
                            aperture: Some(caps.start..sides.end),
                            lit: Some(lit),
                        });
                        lobe_passes.push(pass);
                    }
                }
            }
        }
        sun_pass.lights.push(SunLight { direction: to_sun, irradiance: sun.normal_irradiance() as f32, aperture: None, lit: None });
        let mut passes = vec![sun_pass];
        passes.extend(lobe_passes);
        Self { generation, surfaces, lit_indices, volumes, passes }
    }

    /// Lit triangles rasterized per frame, all lights together.
    pub fn lit_triangles_drawn(&self) -> usize {
        let all = self.surfaces.lit_triangles();
        self.lights().map(|l| l.lit.as_ref().map_or(all, |range| range.len() / 3)).sum()
    }

    /// The lights of all passes in order (one uniform each).
    pub fn lights(&self) -> impl Iterator<Item = &SunLight> {
        self.passes.iter().flat_map(|p| &p.lights)
    }

    /// Draw calls per frame: per pass the opaque caps and sides, per light
    /// through an aperture its volume twice and the lit surfaces, for the
    /// outside light the windows' volumes and the lit surfaces; plus the
    /// depth copy.
    pub fn draw_count(&self) -> usize {
        1 + self.passes.iter().map(|p| 2 + p.lights.iter().map(|l| if l.aperture.is_some() { 3 } else { 2 }).sum::<usize>()).sum::<usize>()
    }
}

/// What the sun pass needs of a scene whatever the sun, made once per
/// scene: the lit surfaces ([`lit_vertices`]) and their runs, and the
/// opaque casters with their shared edges.
pub struct SunPassSurfaces {
    /// Lit surfaces as interleaved position, normal, albedo (9 floats per vertex).
    pub lit: Vec<f32>,
    runs: LitRuns,
    opaque: Casters,
}

impl SunPassSurfaces {
    /// `scene`'s surfaces for the sun pass (a quarter of a second for
    /// 100,000 triangles, against milliseconds per sun move after it).
    pub fn new(scene: &Scene) -> Self {
        let lit = lit_vertices(scene);
        let (opaque, vertices): (Vec<_>, Vec<_>) = scene
            .triangles
            .iter()
            .filter(|t| matches!(scene.materials[t.material as usize].kind, MaterialKind::Diffuse { .. }))
            .map(|t| (t.vertices, t.file_vertices))
            .unzip();
        Self { runs: LitRuns::new(&lit), lit, opaque: Casters::of_model(opaque, &vertices) }
    }

    /// How many lit triangles there are (9 floats per vertex).
    pub fn lit_triangles(&self) -> usize {
        self.lit.len() / 27
    }
}

/// The lit triangles in runs of [`LitRuns::RUN`] as [`lit_vertices`] lists
/// them (a patch's triangles, then its neighbour's on the same surface: runs
/// lie close together), each with its bounding box.
struct LitRuns {
    /// Centre and half size of each run's box.
    boxes: Vec<(Vec3, Vec3)>,
    triangles: u32,
}

impl LitRuns {
    const RUN: u32 = 16;

    fn new(lit: &[f32]) -> Self {
        let triangles = (lit.len() / 27) as u32;
        let vertex = |i: usize| Vec3::from_slice(&lit[9 * i..9 * i + 3]);
        let boxes = (0..triangles.div_ceil(Self::RUN))
            .map(|run| {
                let vertices = 3 * (run * Self::RUN) as usize..3 * ((run + 1) * Self::RUN).min(triangles) as usize;
                let (lo, hi) = vertices.map(vertex).fold((Vec3::MAX, Vec3::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
                ((lo + hi) * 0.5, (hi - lo) * 0.5)
            })
            .collect();
        Self { boxes, triangles }
    }

    /// Appends to `indices` the vertices of the runs that light along
    /// `to_light` through `panes` may reach, and returns their range there.
    /// A run is kept where its box, seen along the light, overlaps a pane's
    /// outline and is not wholly on the light's side of the pane's plane:
    /// conservative, as the stencil still decides per pixel.
    fn reached(&self, panes: &[[Vec3; 3]], to_light: Vec3, indices: &mut Vec<u32>) -> Range<u32> {
        /// Keeps what lies this close to a pane's plane on the light's side (m).
        const PLANE_TOLERANCE: f32 = 0.01;
        let (across_u, across_v) = to_light.any_orthonormal_pair();
        let across = |p: Vec3| Vec2::new(p.dot(across_u), p.dot(across_v));
        // Each pane as the light sees it: its outline across the beam, and
        // its plane with the normal toward the light.
        let beams: Vec<_> = panes
            .iter()
            .filter_map(|pane| {
                let normal = (pane[1] - pane[0]).cross(pane[2] - pane[0]).normalize_or_zero();
                let toward = normal.dot(to_light);
                (toward.abs() > 1e-6).then(|| {
                    let normal = normal * toward.signum();
                    let (lo, hi) = pane.iter().map(|&p| across(p)).fold((Vec2::MAX, Vec2::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
                    (lo, hi, normal, normal.dot(pane[0]))
                })
            })
            .collect();
        let (all_lo, all_hi) = beams.iter().fold((Vec2::MAX, Vec2::MIN), |(lo, hi), b| (lo.min(b.0), hi.max(b.1)));
        let start = indices.len() as u32;
        let radius_across = |half: Vec3| Vec2::new(half.dot(across_u.abs()), half.dot(across_v.abs()));
        for (run, &(centre, half)) in self.boxes.iter().enumerate() {
            let (middle, radius) = (across(centre), radius_across(half));
            let overlaps = |lo: Vec2, hi: Vec2| (middle - radius).cmple(hi).all() && (middle + radius).cmpge(lo).all();
            let reached = overlaps(all_lo, all_hi)
                && beams.iter().any(|&(lo, hi, normal, offset)| {
                    overlaps(lo, hi) && centre.dot(normal) - half.dot(normal.abs()) - offset <= PLANE_TOLERANCE
                });
            if reached {
                let run = run as u32;
                indices.extend(3 * run * Self::RUN..3 * ((run + 1) * Self::RUN).min(self.triangles));
            }
        }
        start..indices.len() as u32
    }
}

/// The shadows `casters` throw on a window's `panes` (a plane with
/// `normal`) under the sun along `to_sun`: each caster between the window
/// and the sun, projected along the sun onto the window's plane and clipped
/// to each pane (panes are triangles, hence convex). As casters along a
/// lobe, they keep its light from the shaded part of the panel.
fn shadows_on(panes: &[[Vec3; 3]], normal: Vec3, casters: &[[Vec3; 3]], to_sun: Vec3) -> Vec<[Vec3; 3]> {
    let Some(origin) = panes.first().map(|p| p[0]) else { return Vec::new() };
    let toward = to_sun.dot(normal);
    if toward.abs() < 1e-6 {
        return Vec::new();
    }
    // The sun's side of the plane: `above` along `side`.
    let side = normal * toward.signum();
    let (lo, hi) = panes.iter().flatten().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let mut out = Vec::new();
    for in_front in beside(casters, origin, side) {
        // Along the sun onto the plane.
        let projected: Vec<Vec3> = in_front.iter().map(|&p| p - to_sun * ((p - origin).dot(normal) / toward)).collect();
        let (plo, phi) = projected.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        if plo.cmpgt(hi + 1e-4).any() || phi.cmplt(lo - 1e-4).any() {
            continue;
        }
        for pane in panes {
            // Inside a pane: on the inner side of each of its edges' planes.
            let pane_normal = (pane[1] - pane[0]).cross(pane[2] - pane[0]);
            let mut polygon = projected.clone();
            for k in 0..3 {
                let (a, b) = (pane[k], pane[(k + 1) % 3]);
                let inward = pane_normal.cross(b - a);
                polygon = clip_convex(&polygon, inward, a.dot(inward), true);
                if polygon.len() < 3 {
                    break;
                }
            }
            for k in 1..polygon.len().saturating_sub(1) {
                out.push([polygon[0], polygon[k], polygon[k + 1]]);
            }
        }
    }
    out
}

/// The parts of `casters` strictly on the `side` of the plane through
/// `origin` (as triangles).
fn beside(casters: &[[Vec3; 3]], origin: Vec3, side: Vec3) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for caster in casters {
        let polygon = clip_convex(&caster[..], side, origin.dot(side) + 1e-4, true);
        for k in 1..polygon.len().saturating_sub(1) {
            out.push([polygon[0], polygon[k], polygon[k + 1]]);
        }
    }
    out
}

/// The ground outside as the renderer draws it: a horizontal square of the
/// site's ground reflectance just under the model's lowest point, far wider
/// than the model, so the building's sun shadow falls on it. The light
/// engine does not see it (its ground is the sky model's glow below the
/// horizon, of the same luminance where the sun reaches); a model with a
/// ground of its own covers it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundPlane {
    /// Its height (model z).
    pub height: f32,
    /// Its middle, under the middle of the model.
    pub centre: Vec2,
    /// Half its side.
    pub half_size: f32,
    /// The site's ground reflectance.
    pub reflectance: f32,
}

/// How far under the model's lowest point the drawn ground lies (m): a
/// model's own ground polygon there hides it without z-fighting.
const GROUND_BELOW: f32 = 0.01;

impl GroundPlane {
    /// The ground drawn around `scene`: reaching 20 model widths and at least
    /// a kilometre out.
    pub fn of(scene: &Scene) -> Self {
        let (lo, hi) = scene.bounds;
        let width = (hi - lo).truncate().length();
        Self {
            height: lo.z - GROUND_BELOW,
            centre: ((lo + hi) * 0.5).truncate(),
            half_size: (20.0 * width).max(1000.0),
            reflectance: scene.site.ground_reflectance as f32,
        }
    }

    /// Its corners, anticlockwise seen from above (facing up).
    pub fn corners(&self) -> [Vec3; 4] {
        let (c, r) = (self.centre, self.half_size);
        [[-r, -r], [r, -r], [r, r], [-r, r]].map(|[x, y]| Vec3::new(c.x + x, c.y + y, self.height))
    }

    /// Where a ray from `origin` along `direction` meets it from above.
    pub fn hit(&self, origin: glam::DVec3, direction: glam::DVec3) -> Option<glam::DVec3> {
        let t = (f64::from(self.height) - origin.z) / direction.z;
        let point = origin + direction * t;
        let inside = (point.truncate() - self.centre.as_dvec2()).abs().max_element() <= f64::from(self.half_size);
        (origin.z > f64::from(self.height) && t > 0.0 && inside).then_some(point)
    }
}

/// The diffuse surfaces as the sun pass draws them: the very triangles of
/// the patch meshes the main pass drew, so their depths match exactly,
/// then the ground outside ([`GroundPlane`]). A face the model holds twice
/// is drawn once (light is added, so a duplicate would double it).
pub fn lit_vertices(scene: &Scene) -> Vec<f32> {
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for patch in &scene.patches.patches {
        let MaterialKind::Diffuse { reflectance } = &scene.materials[patch.material as usize].kind else { continue };
        for triangle in &scene.patches.triangles[patch.triangle_indices()] {
            let mut key = triangle.map(|v| v.to_array().map(f32::to_bits));
            key.sort_unstable();
            if !seen.insert(key) {
                continue;
            }
            for v in triangle {
                out.extend(v.to_array());
                out.extend(patch.normal.to_array());
                out.extend(reflectance.0);
            }
        }
    }
    let ground = GroundPlane::of(scene);
    let [a, b, c, d] = ground.corners();
    for v in [a, b, c, a, c, d] {
        out.extend(v.to_array());
        out.extend([0.0, 0.0, 1.0]);
        out.extend([ground.reflectance; 3]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lit vertices of 16 copies of each triangle (one run each), normal
    /// and albedo left at zero.
    fn runs_of(triangles: &[[Vec3; 3]]) -> Vec<f32> {
        let mut lit = Vec::new();
        for triangle in triangles {
            for _ in 0..LitRuns::RUN {
                for v in triangle {
                    lit.extend(v.to_array());
                    lit.extend([0.0; 6]);
                }
            }
        }
        lit
    }

    /// A 1 m window in the plane y = 0 under a sun 45° high toward −y: its
    /// beam falls on the floor at z = −0.5 about a metre in, not three
    /// metres in, nor beside the window, nor on what lies outside in line
    /// with it (on the sun's side of its plane).
    #[test]
    fn a_light_draws_only_what_its_beam_through_the_window_can_reach() {
        let v = Vec3::new;
        let pane = [[v(0., 0., 0.), v(1., 0., 0.), v(1., 0., 1.)], [v(0., 0., 0.), v(1., 0., 1.), v(0., 0., 1.)]];
        let floor = |y: f32| [v(0.2, y, -0.5), v(0.8, y, -0.5), v(0.5, y + 0.4, -0.5)];
        let in_the_beam = floor(0.8);
        let too_deep = floor(3.0);
        let beside_it = [v(4.0, 0.8, -0.5), v(4.6, 0.8, -0.5), v(4.3, 1.2, -0.5)];
        let outside = [v(0.2, -1.5, 2.0), v(0.8, -1.5, 2.0), v(0.5, -1.1, 2.0)];
        let runs = LitRuns::new(&runs_of(&[too_deep, in_the_beam, beside_it, outside]));
        let to_sun = v(0.0, -1.0, 1.0).normalize();
        let mut indices = Vec::new();
        let range = runs.reached(&pane, to_sun, &mut indices);
        assert_eq!(range, 0..3 * LitRuns::RUN);
        assert_eq!(indices, (3 * LitRuns::RUN..6 * LitRuns::RUN).collect::<Vec<_>>());
        // From straight ahead the beam goes level: the floor a metre in is
        // below the sill, what lies outside above the lintel.
        let range = runs.reached(&pane, v(0.0, -1.0, 0.0), &mut indices);
        assert!(range.is_empty());
    }
}
