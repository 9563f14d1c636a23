//! Window groups: the one rule by which windows are grouped everywhere —
//! the light engine's panel groups, the sun pass's apertures, the viewer's
//! windows panel and `info`. A group is the windows of one material whose
//! **outward** normals agree (and that all see sky, or all none). A window's outward side is the side from
//! which more sky is seen (ray-tested), not the side its polygon's normal
//! happens to point to: exported models wind their faces either way.

use glam::DVec3;

use super::bvh::Tracer;
use super::sampling::{Rng, cosine_directions, stratified_area_points, with_cumulative_areas};
use crate::scene::{Scene, Window};

/// Rays per hemisphere that decide which side of a window is outside.
const SIDE_RAYS: usize = 64;

/// Outward normals closer than this (1 − cos, about 0.003°) face one way.
const SAME_FACING: f64 = 1e-9;

/// Windows of one material that face one way.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowGroup {
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Unit normal toward the outside (the side that sees the sky).
    pub outward: DVec3,
    /// No test ray from either side of its windows reached the sky
    /// (interior glazing, or glass shut inside other surfaces, as a door
    /// leaf's box around its panes): `outward` is then a guess.
    pub enclosed: bool,
    /// Indices into [`Scene::windows`].
    pub windows: Vec<u32>,
}

/// Every window's outward normal and group.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WindowGroups {
    /// In the order their first window appears in [`Scene::windows`].
    pub groups: Vec<WindowGroup>,
    /// Per window of [`Scene::windows`]: its group.
    pub group_of_window: Vec<u32>,
    /// Per window: its outward unit normal.
    pub outward: Vec<DVec3>,
}

impl WindowGroups {
    /// Groups `scene`'s windows, testing each window's sides with `tracer`.
    pub(super) fn new(scene: &Scene, tracer: &Tracer) -> Self {
        let mut out = Self::default();
        for (index, window) in scene.windows.iter().enumerate() {
            let (outward, enclosed) = outward_normal(scene, tracer, window);
            let same =
                |g: &WindowGroup| g.material == window.material && g.enclosed == enclosed && g.outward.dot(outward) > 1.0 - SAME_FACING;
            let group = match out.groups.iter().position(same) {
                Some(group) => group,
                None => {
                    out.groups.push(WindowGroup { material: window.material, outward, enclosed, windows: Vec::new() });
                    out.groups.len() - 1
                }
            };
            out.groups[group].windows.push(index as u32);
            out.group_of_window.push(group as u32);
            out.outward.push(outward);
        }
        out
    }
}

/// The normal of `window` turned toward the outside: the side from which
/// more of the sky is seen (on a tie, against the polygon's normal); and
/// whether neither side sees any. The rays leave from points spread over
/// the pane, not its centre alone: a window of four lights has its
/// glazing bars crossing there.
fn outward_normal(scene: &Scene, tracer: &Tracer, window: &Window) -> (DVec3, bool) {
    let normal = window.normal.as_dvec3();
    let triangles = with_cumulative_areas(scene.surface_triangles(window.surface).iter().map(|t| t.vertices));
    let mut rng = Rng::new(5, u64::from(window.surface));
    let open = |side: DVec3, rng: &mut Rng| {
        let points: Vec<DVec3> = stratified_area_points(&triangles, SIDE_RAYS, rng).collect();
        let directions = cosine_directions(side, SIDE_RAYS, rng);
        points.into_iter().zip(directions).filter(|&(p, d)| tracer.closest(p + side * 1e-3, d, 1e-6).is_none()).count()
    };
    let along = open(normal, &mut rng);
    let against = open(-normal, &mut rng);
    (if along > against { normal } else { -normal }, along + against == 0)
}

/// An automatic view looks through the windows with a sensor within this
/// distance (m, across) of one of them, where there are such: the
/// sensors' room.
const VIEW_SENSOR_REACH: f32 = 5.0;
/// ... and this far (m) above or below its middle: the same storey.
const VIEW_SENSOR_STOREY: f32 = 2.0;
/// Surfaces this close (m) behind a window are its frame or sill, not the
/// room's far wall, for an automatic view.
const FRAME_DEPTH: f32 = 0.5;
/// Eye height above the floor for an automatic view, m.
const EYE_HEIGHT: f32 = 1.5;
/// Horizontal ways tried for where a windowless room opens, for the
/// automatic view.
const OPENING_WAYS: usize = 32;
/// Windows of a group closer than this (m, centre to centre) light one
/// room, for the automatic view.
const WINDOW_CLUSTER: f32 = 2.5;

/// The windows `windows` (indices into [`Scene::windows`]) in clusters:
/// chains of windows whose centres lie within [`WINDOW_CLUSTER`].
fn window_clusters(scene: &Scene, windows: &[u32]) -> Vec<Vec<u32>> {
    let mut clusters: Vec<Vec<u32>> = Vec::new();
    for &w in windows {
        let near = |c: &Vec<u32>| {
            c.iter().any(|&o| scene.windows[o as usize].centroid.distance(scene.windows[w as usize].centroid) < WINDOW_CLUSTER)
        };
        let mut joined: Vec<u32> = vec![w];
        clusters.retain(|c| {
            if near(c) {
                joined.extend(c);
                false
            } else {
                true
            }
        });
        clusters.push(joined);
    }
    clusters
}

impl super::LightModel {
    /// A view from inside the room behind the largest cluster of vertical
    /// windows (windows of one group within [`WINDOW_CLUSTER`] of each
    /// other: a group spans a whole façade, its middle may be a partition),
    /// of those that light a sensor where some do, looking out through
    /// them: the eye at eye height in the back corner (toward the far wall,
    /// then toward a side wall), looking a metre above the floor at the
    /// window nearest the sensors where the cluster lights them all (a
    /// study of one room), else nearest the cluster's middle, so the
    /// floor's sun patches and the windows are both in view. Where
    /// something stands between that corner and the windows (a stair, a
    /// column), the other back corner, then places nearer the windows, are
    /// tried for a clear sight. Without vertical windows that see the sky,
    /// the view from the sensors' room toward where it opens
    /// ([`Self::view_toward_the_opening`]); `None` without either.
    pub fn interior_view(&self) -> Option<crate::scene::Viewpoint> {
        let scene = &self.scene;
        let centroids = |cluster: &[u32]| cluster.iter().map(|&w| scene.windows[w as usize].centroid).collect::<Vec<_>>();
        let area = |cluster: &[u32]| cluster.iter().map(|&w| scene.windows[w as usize].area).sum::<f32>();
        // Whether a window of `windows` lights `sensor`: near it, on its storey.
        let lit_by = |windows: &[glam::Vec3], sensor: glam::Vec3| {
            windows.iter().any(|&w| (w - sensor).truncate().length() <= VIEW_SENSOR_REACH && (w.z - sensor.z).abs() <= VIEW_SENSOR_STOREY)
        };
        let sensors: Vec<glam::Vec3> = scene.sensors.iter().map(|s| s.position).collect();
        // The room with sensors first: that is what the scene is about.
        let cluster = self
            .windows
            .groups
            .iter()
            .filter(|g| g.outward.z.abs() < 0.7 && !g.enclosed)
            .flat_map(|g| window_clusters(scene, &g.windows).into_iter().map(move |c| (g, c)))
            .map(|(g, c)| {
                let windows = centroids(&c);
                ((sensors.iter().any(|&s| lit_by(&windows, s)), area(&c)), g, c)
            })
            .max_by(|(a, ..), (b, ..)| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)))
            .map(|(_, g, c)| (g, c));
        let Some((group, cluster)) = cluster else { return self.view_toward_the_opening() };
        let middle = cluster.iter().map(|&w| scene.windows[w as usize].centroid * scene.windows[w as usize].area).sum::<glam::Vec3>()
            / area(&cluster);
        // The window nearest the sensors where these windows light them all
        // (a study of one room), else nearest the cluster's middle: a long
        // band of windows has a partition or a floor slab behind its
        // middle, not a room.
        let nearest = |to: glam::Vec3| move |a: &glam::Vec3, b: &glam::Vec3| a.distance(to).total_cmp(&b.distance(to));
        let windows = centroids(&cluster);
        let one_room = !sensors.is_empty() && sensors.iter().all(|&s| lit_by(&windows, s));
        let sensor = sensors.iter().copied().filter(|_| one_room).min_by(nearest(middle));
        let centre = windows.iter().copied().min_by(nearest(sensor.unwrap_or(middle)))?;
        let inward = -glam::Vec3::new(group.outward.x as f32, group.outward.y as f32, 0.0).normalize();
        let across = inward.cross(glam::Vec3::Z);
        // The room's depth, past the window's own frame and sill.
        let mut depth = 0.05;
        while depth < FRAME_DEPTH {
            depth += 1e-3 + self.reach(centre + inward * depth, inward, 5.0);
        }
        // The eye `back` of the room's depth in from the windows, toward the
        // side wall along `side`; and the target it looks at.
        let place = |back: f32, side: glam::Vec3| {
            let mut eye = centre + inward * (back * depth);
            if side != glam::Vec3::ZERO {
                eye += side * (0.6 * self.reach(eye, side, 2.0));
            }
            let floor = eye.z - self.reach(eye, glam::Vec3::NEG_Z, EYE_HEIGHT);
            eye.z = floor + EYE_HEIGHT;
            (eye, glam::Vec3::new(centre.x, centre.y, floor + 1.0))
        };
        // Nothing (a stair, a column, a wardrobe) between the eye and the windows.
        let sees_windows = |(eye, target): &(glam::Vec3, glam::Vec3)| {
            self.reach(*eye, (*target - *eye).normalize_or_zero(), f32::INFINITY) >= 0.9 * eye.distance(*target)
        };
        // The back corner, then the other back corner, then nearer the windows.
        let places = [(0.85, across), (0.85, -across), (0.6, across), (0.6, -across), (0.4, glam::Vec3::ZERO)];
        let first = place(places[0].0, places[0].1);
        let (eye, target) = if sees_windows(&first) {
            first
        } else {
            places[1..].iter().map(|&(back, side)| place(back, side)).find(sees_windows).unwrap_or(first)
        };
        Some(crate::scene::Viewpoint { name: "inside".into(), eye, target, fov: crate::scene::DEFAULT_FOV })
    }

    /// A view from inside the sensors' room where no window lights it (a
    /// model exported without its glass, a room open to the outside): from
    /// the sensors' middle at eye height, toward the middle of the widest
    /// run of horizontal ways that leave the model (through the opening),
    /// else the way that reaches farthest; the eye steps back toward the
    /// wall behind, so the floor and the opening are both in view. `None`
    /// without sensors, or where every way leaves (sensors outdoors).
    fn view_toward_the_opening(&self) -> Option<crate::scene::Viewpoint> {
        let sensors = &self.scene.sensors;
        if sensors.is_empty() {
            return None;
        }
        let middle = sensors.iter().map(|s| s.position).sum::<glam::Vec3>() / sensors.len() as f32;
        let floor = middle.z - self.reach(middle, glam::Vec3::NEG_Z, 0.0);
        let from = glam::Vec3::new(middle.x, middle.y, floor + EYE_HEIGHT);
        let ways: Vec<(glam::Vec3, f32)> = (0..OPENING_WAYS)
            .map(|k| {
                let (sin, cos) = (k as f32 * std::f32::consts::TAU / OPENING_WAYS as f32).sin_cos();
                let way = glam::Vec3::new(cos, sin, 0.0);
                (way, self.reach(from, way, f32::INFINITY))
            })
            .collect();
        let leaves = |k: usize| ways[k % OPENING_WAYS].1.is_infinite();
        // Each run of ways that leave, from its first way: its length and middle.
        let runs = (0..OPENING_WAYS).filter(|&k| leaves(k) && !leaves(k + OPENING_WAYS - 1)).map(|first| {
            let length = (0..OPENING_WAYS).take_while(|&j| leaves(first + j)).count();
            (length, (first + length / 2) % OPENING_WAYS)
        });
        let best = match runs.max_by_key(|&(length, _)| length) {
            Some((_, middle)) => middle,
            None if leaves(0) => return None,
            None => (0..OPENING_WAYS).max_by(|&a, &b| ways[a].1.total_cmp(&ways[b].1))?,
        };
        let (way, ahead) = ways[best];
        let eye = from - way * (0.8 * self.reach(from, -way, 2.0));
        let target = from + way * ahead.min(3.0) + glam::Vec3::Z * (1.0 - EYE_HEIGHT);
        Some(crate::scene::Viewpoint { name: "inside".into(), eye, target, fov: crate::scene::DEFAULT_FOV })
    }

    /// How far a ray goes from `from` along `direction` before a surface
    /// (`fallback` if none): what the automatic views measure rooms by.
    fn reach(&self, from: glam::Vec3, direction: glam::Vec3, fallback: f32) -> f32 {
        self.trace(from.as_dvec3(), direction.as_dvec3()).map_or(fallback, |(_, d)| d as f32)
    }

    /// The height of a plan's horizontal section for a camera at `eye`:
    /// just under the ceiling of the storey the eye is in (the first
    /// surface straight above it), else, from outside, of the storey of the
    /// automatic interior view ([`Self::interior_view`]), else of the
    /// model's lowest point under its middle. `None` with no ceiling found.
    pub fn storey_section(&self, eye: glam::Vec3) -> Option<f32> {
        let ceiling_above = |from: glam::Vec3| self.trace(from.as_dvec3(), DVec3::Z).map(|(_, d)| from.z + d as f32);
        let (lo, hi) = self.scene.bounds;
        let inside = ceiling_above(eye).filter(|&c| c < hi.z + 1e-3 && self.trace(eye.as_dvec3(), -DVec3::Z).is_some());
        let ceiling = inside
            .or_else(|| self.interior_view().and_then(|v| ceiling_above(v.eye)))
            .or_else(|| ceiling_above(glam::Vec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), lo.z + 0.1)))?;
        Some(ceiling - SECTION_BELOW_CEILING)
    }
}

/// How far under a ceiling a plan's section cuts, m.
const SECTION_BELOW_CEILING: f32 = 0.3;
