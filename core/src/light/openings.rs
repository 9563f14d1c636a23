//! Where the sun can come in: a cheap, conservative test that spares shadow
//! rays from sides the sun cannot reach.
//!
//! A patch side is *enclosed* when no ray from its space (below) left
//! straight to the open sky: sunlight reaches it only through a window. The sun itself passes glass windows only, a panel lobe
//! only the windows of its panel group ([`super::sun`]). So a point of an
//! enclosed side can be sunlit only when its ray toward a beam crosses the
//! bounding box of such a window; a side only when the ray from its centre,
//! widened by the patch's radius, does. Everything that passes is traced as
//! before, so the test changes no lit sample, and an open side is always
//! traced.
//!
//! A side is open when its *space* is ([`Spaces`]): the sides joined by
//! rays that cross no window, one of which left straight to the open sky.
//! A room with an opening no window fills (a doorway or passage with no
//! door, a gap in the envelope) lets the sun in there, onto sides whose
//! own rays may all have missed the opening (a side far from the sensors
//! traces a sixty-fourth of them): such a room is one space with the
//! outside. Rooms closed but for their windows stay apart and enclosed. A
//! crack a ray slips through joins a room to the outside too, which costs
//! shadow rays and never light. (The Aachen "3 rooms" IFC of bim2sim, an
//! L-shaped room open to the outside: its sun's interreflected light read
//! 6% low on average and 16% deep in the L, where each side's own rays
//! decided.)

use glam::DVec3;

use super::SunBeam;
use crate::scene::Scene;

/// Widening of every box, metres: rays along a window's plane and points on
/// its frame stay inside.
const MARGIN: f64 = 1e-3;

/// The least opening (m²) that opens a space to the sun: a doorway is
/// square metres, while the sides of furniture and frames in contact with
/// a floor or wall see the open sky from a few square millimetres each
/// (rays from just past their edge), which a floor of offices sums to a
/// few hundredths (the furnished floor of the benches: 0.02 m²).
pub(super) const LEAST_OPENING: f64 = 0.1;

/// The least patch that is a member of a space, in finest cells: the small
/// pieces of frames, sills and furniture would bridge spaces apart (a
/// frame's profile poking through the glass plane sees the sky outside and
/// the floor inside) and their contacts leak rays to the open sky.
pub(super) const SPACE_MEMBER: f32 = 0.25;

/// The least share of a side's rays that joins it to a side they met: two
/// of the default 256, so that one ray slipping through a seam between two
/// surfaces does not join a room to the outside, while a side far from the
/// sensors, tracing a few rays, joins by any of them.
pub(super) const LEAST_JOINING_SHARE: f64 = 1.0 / 128.0;

/// Patch sides joined into spaces by their rays that cross no window (a
/// union–find over the sides), each space with the opening its sides saw
/// the open sky through: the sum of each side's area times the share of
/// its rays that left straight up into the sky (by reciprocity, about the
/// opening's area).
pub(super) struct Spaces {
    parent: Vec<u32>,
    /// Per root, its space's opening, m².
    opening: Vec<f64>,
}

impl Spaces {
    pub(super) fn new(sides: usize) -> Self {
        Self { parent: (0..sides as u32).collect(), opening: vec![0.0; sides] }
    }

    /// Joins `side`, which saw the open sky through `opening` (m²), with
    /// the sides its rays met crossing no window.
    pub(super) fn join(&mut self, side: u32, opening: f64, unglazed: &[u32]) {
        let mut root = self.root(side);
        self.opening[root as usize] += opening;
        for &other in unglazed {
            let theirs = self.root(other);
            if theirs != root {
                // The smaller index becomes the root: the same spaces in any order.
                let (keep, drop) = (root.min(theirs), root.max(theirs));
                self.parent[drop as usize] = keep;
                self.opening[keep as usize] += std::mem::take(&mut self.opening[drop as usize]);
                root = keep;
            }
        }
    }

    fn root(&mut self, mut side: u32) -> u32 {
        while self.parent[side as usize] != side {
            let up = self.parent[self.parent[side as usize] as usize];
            self.parent[side as usize] = up;
            side = up;
        }
        side
    }

    /// Per side, whether its space is open: an opening of at least
    /// [`LEAST_OPENING`].
    pub(super) fn open_sides(mut self) -> Vec<bool> {
        (0..self.parent.len() as u32)
            .map(|side| {
                let root = self.root(side);
                self.opening[root as usize] >= LEAST_OPENING
            })
            .collect()
    }
}

/// The windows as boxes and the patches as spheres, for [`Openings::ways_in`].
#[derive(Debug, Clone, Default)]
pub(super) struct Openings {
    /// Per scene window: its bounding box and panel group (`None`: glass).
    windows: Vec<([DVec3; 2], Option<u32>)>,
    /// Per patch: the centre and radius of a sphere holding it.
    spheres: Vec<(DVec3, f64)>,
}

impl Openings {
    /// `group_of_surface`: each surface's panel group, as [`super::panels`] made them.
    pub(super) fn new(scene: &Scene, group_of_surface: &[Option<u32>]) -> Self {
        let windows = scene
            .windows
            .iter()
            .map(|window| {
                let corners = scene.surface_triangles(window.surface).iter().flat_map(|t| t.vertices);
                let (min, max) =
                    corners.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| (lo.min(v.as_dvec3()), hi.max(v.as_dvec3())));
                ([min - MARGIN, max + MARGIN], group_of_surface[window.surface as usize])
            })
            .collect();
        let spheres = scene
            .patches
            .patches
            .iter()
            .map(|patch| {
                let centre = patch.centroid.as_dvec3();
                let triangles = &scene.patches.triangles[patch.triangle_indices()];
                let radius = triangles.iter().flatten().map(|v| v.as_dvec3().distance(centre)).fold(0.0, f64::max);
                (centre, radius)
            })
            .collect();
        Self { windows, spheres }
    }

    /// The windows as seen along `beams`, for their ways in.
    pub(super) fn along<'a>(&'a self, beams: &[SunBeam]) -> OpeningsAlong<'a> {
        OpeningsAlong { openings: self, beams: beams.iter().map(|beam| self.across(beam)).collect() }
    }

    /// The boxes of the windows `beam` passes, projected on a plane across
    /// it and binned in a grid there.
    fn across(&self, beam: &SunBeam) -> WindowsAcross {
        let ray = Ray::new(beam.to_light);
        let (u, v) = beam.to_light.any_orthonormal_pair();
        let rects: Vec<(u32, Rect)> = (self.windows.iter().enumerate())
            .filter(|(_, (_, group))| *group == beam.panel_group)
            .map(|(w, ([min, max], _))| {
                let corners = (0..8).map(|k| DVec3::select(glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), *max, *min));
                let rect = corners.fold(NO_RECT, |r, c| union(r, [c.dot(u), c.dot(u), c.dot(v), c.dot(v)]));
                (w as u32, rect)
            })
            .collect();
        let bounds = rects.iter().fold(NO_RECT, |b, (_, r)| union(b, *r));
        let cells = ((2.0 * (rects.len() as f64).sqrt()).ceil() as usize).clamp(1, MAX_CELLS_ACROSS);
        let grid = Grid {
            u,
            v,
            lo: [bounds[0], bounds[2]],
            cell: [(bounds[1] - bounds[0]) / cells as f64, (bounds[3] - bounds[2]) / cells as f64],
            cells,
        };
        // Each window in every cell its rectangle overlaps (compressed rows).
        let spans: Vec<_> = rects.iter().map(|(w, r)| (*w, grid.cells_over([r[0], r[1]], [r[2], r[3]]))).collect();
        let mut starts = vec![0u32; cells * cells + 1];
        for (_, span) in &spans {
            span.clone().for_each(|cell| starts[cell + 1] += 1);
        }
        for cell in 0..cells * cells {
            starts[cell + 1] += starts[cell];
        }
        let mut filled = starts.clone();
        let mut windows = vec![0u32; *starts.last().expect("a cell") as usize];
        for (w, span) in spans {
            for cell in span {
                windows[filled[cell] as usize] = w;
                filled[cell] += 1;
            }
        }
        WindowsAcross { ray, grid, starts, windows }
    }

    /// The beams (indices, ascending, each once) that may reach a point of a
    /// patch by one of its `ways` in; the others cannot. No allocation: it
    /// runs for every traced point.
    pub(super) fn beams_reaching<'a>(&'a self, point: DVec3, ways: &'a [WayIn]) -> impl Iterator<Item = usize> + 'a {
        // Ways come beam by beam: a beam already let through skips its other windows.
        let mut last = None;
        ways.iter().filter_map(move |way| {
            let beam = way.beam as usize;
            let [min, max] = self.windows[way.window as usize].0;
            let through = last != Some(beam) && way.ray.meets_box(point, min, max);
            through.then(|| {
                last = Some(beam);
                beam
            })
        })
    }
}

/// A rectangle `[a0, a1, b0, b1]` in a plane's (u, v), and the empty one.
type Rect = [f64; 4];
const NO_RECT: Rect = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];

/// The smallest rectangle holding `r` and `s`.
fn union(r: Rect, s: Rect) -> Rect {
    [r[0].min(s[0]), r[1].max(s[1]), r[2].min(s[2]), r[3].max(s[3])]
}

/// The most grid cells along each axis of a [`WindowsAcross`].
const MAX_CELLS_ACROSS: usize = 128;

/// The openings as seen along some beams ([`Openings::along`]): each
/// beam's windows binned across it, so that a patch tests the few windows
/// whose shadow along the beam its centre falls in, not every window of a
/// building. AC20-Institute-Var-2 has 206 windows; a year's sun path
/// asked every one of them for every side it traced.
pub(super) struct OpeningsAlong<'a> {
    openings: &'a Openings,
    beams: Vec<WindowsAcross>,
}

impl OpeningsAlong<'_> {
    /// How the beams may reach an enclosed patch: the (beam, window) pairs
    /// whose ray from the patch's centre, widened by its radius, crosses the
    /// window; empty when none can.
    pub(super) fn ways_in(&self, patch: usize) -> Vec<WayIn> {
        let (centre, radius) = self.openings.spheres[patch];
        self.ways_into_sphere(centre, radius)
    }

    /// [`Self::ways_in`] for any sphere (a sensor's points, say): beam by
    /// beam, windows in ascending order.
    pub(super) fn ways_into_sphere(&self, centre: DVec3, radius: f64) -> Vec<WayIn> {
        let mut ways = Vec::new();
        let mut candidates = Vec::new();
        for (b, across) in self.beams.iter().enumerate() {
            across.candidates(centre, radius, &mut candidates);
            for &w in &candidates {
                let [min, max] = self.openings.windows[w as usize].0;
                if across.ray.meets_box(centre, min - radius, max + radius) {
                    ways.push(WayIn { beam: b as u32, window: w, ray: across.ray });
                }
            }
        }
        ways
    }
}

/// One beam's windows, their boxes projected on a plane across the beam
/// and binned in a grid of that plane.
struct WindowsAcross {
    /// Toward the beam's light.
    ray: Ray,
    grid: Grid,
    /// Cell `c`'s windows are `windows[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    windows: Vec<u32>,
}

impl WindowsAcross {
    /// Into `out` (cleared first), ascending and each once, the windows
    /// whose box the ray from `centre`, widened by `radius`, may meet: a
    /// ray meets a box only where its origin projects into the box's
    /// projection, and the box grown by `radius` projects into the
    /// rectangle grown by at most √3 `radius`.
    fn candidates(&self, centre: DVec3, radius: f64, out: &mut Vec<u32>) {
        out.clear();
        let reach = radius * 3f64.sqrt() + MARGIN;
        let (a, b) = (centre.dot(self.grid.u), centre.dot(self.grid.v));
        for cell in self.grid.cells_over([a - reach, a + reach], [b - reach, b + reach]) {
            out.extend_from_slice(&self.windows[self.starts[cell] as usize..self.starts[cell + 1] as usize]);
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// A square grid of `cells` × `cells` over a plane spanned by `u` and `v`.
struct Grid {
    u: DVec3,
    v: DVec3,
    /// The lowest corner, in (u, v).
    lo: [f64; 2],
    /// A cell's size along u and v (0 where every window lies on one line).
    cell: [f64; 2],
    cells: usize,
}

impl Grid {
    /// The cells a rectangle `[a0, a1] × [b0, b1]` overlaps (row-major);
    /// none where it lies beside the grid.
    fn cells_over(&self, a: [f64; 2], b: [f64; 2]) -> impl Iterator<Item = usize> + Clone + use<> {
        let n = self.cells;
        let span = |[x0, x1]: [f64; 2], lo: f64, size: f64| {
            let far = lo + size * n as f64;
            if x1 < lo || x0 > far || x0.is_nan() || x1.is_nan() {
                return 0..0;
            }
            let index = |x: f64| if size > 0.0 { (((x - lo) / size).floor().max(0.0) as usize).min(n - 1) } else { 0 };
            index(x0)..index(x1) + 1
        };
        let (rows, columns) = (span(b, self.lo[1], self.cell[1]), span(a, self.lo[0], self.cell[0]));
        rows.flat_map(move |row| columns.clone().map(move |column| row * n + column))
    }
}

/// A beam and a window it may come in by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct WayIn {
    beam: u32,
    window: u32,
    /// Toward the beam's light.
    ray: Ray,
}

/// A direction of rays with its reciprocal kept: the box test runs for
/// every traced point, and multiplies where it would divide.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Ray {
    direction: DVec3,
    /// 1 / direction, per axis (unused where the direction lies along the axis's plane).
    reciprocal: DVec3,
}

impl Ray {
    fn new(direction: DVec3) -> Self {
        Self { direction, reciprocal: direction.recip() }
    }

    /// Whether the ray from `origin` (t ≥ 0) meets the box.
    fn meets_box(&self, origin: DVec3, min: DVec3, max: DVec3) -> bool {
        let (mut enter, mut exit) = (0.0_f64, f64::INFINITY);
        for axis in 0..3 {
            let o = origin[axis];
            if self.direction[axis].abs() < 1e-12 {
                if o < min[axis] || o > max[axis] {
                    return false;
                }
                continue;
            }
            let r = self.reciprocal[axis];
            let (a, b) = ((min[axis] - o) * r, (max[axis] - o) * r);
            // No NaN here (the direction is off the axis's plane): plain comparisons.
            let (near, far) = if a < b { (a, b) } else { (b, a) };
            if near > enter {
                enter = near;
            }
            if far < exit {
                exit = far;
            }
        }
        enter <= exit
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_space_is_open_when_its_sides_saw_the_sky_through_an_opening_however_they_were_joined() {
        // Three rooms: sides 0-2 (sides 0 and 2 saw the open sky through a
        // doorway), sides 3-4 (closed but for windows; side 4, a chair's
        // foot on the floor, saw it from past its edge); side 5 alone.
        let half = LEAST_OPENING / 2.0;
        let joins: [(u32, f64, &[u32]); 5] = [(0, half, &[1]), (1, 0.0, &[0, 2]), (3, 0.0, &[4]), (2, half, &[1]), (4, 1e-5, &[3])];
        for order in [[0, 1, 2, 3, 4], [4, 3, 2, 1, 0], [3, 0, 4, 2, 1]] {
            let mut spaces = Spaces::new(6);
            for k in order {
                let (side, opening, unglazed) = joins[k];
                spaces.join(side, opening, unglazed);
            }
            assert_eq!(spaces.open_sides(), [true, true, true, false, false, false], "order {order:?}");
        }
    }

    use super::*;

    #[test]
    fn rays_meet_boxes_ahead_of_them_only() {
        let (min, max) = (DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 1.0, 1.0));
        let (up, down) = (Ray::new(DVec3::Z), Ray::new(-DVec3::Z));
        assert!(up.meets_box(DVec3::new(0.5, 0.5, 0.0), min, max));
        assert!(!down.meets_box(DVec3::new(0.5, 0.5, 0.0), min, max));
        assert!(!up.meets_box(DVec3::new(1.5, 0.5, 0.0), min, max));
        let slanted = Ray::new(DVec3::new(1.0, 0.0, 1.0).normalize());
        assert!(slanted.meets_box(DVec3::new(-0.5, 0.5, 0.0), min, max));
        assert!(!slanted.meets_box(DVec3::new(-1.5, 0.5, 0.0), min, max));
    }

    /// The windows binned across each beam give the ways in that testing
    /// every window gives, in the same order: 300 windows (thin boxes,
    /// some in panel groups) over a 60 m block, beams from grazing to
    /// overhead, spheres from a point to 8 m across.
    #[test]
    fn ways_in_from_the_grid_are_those_of_every_window() {
        let mut rng = super::super::sampling::Rng::new(11, 0);
        let mut uniform = |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
        let windows: Vec<([DVec3; 2], Option<u32>)> = (0..300)
            .map(|k| {
                let corner = DVec3::new(uniform(-30.0, 30.0), uniform(-30.0, 30.0), uniform(0.0, 20.0));
                let size = match k % 3 {
                    0 => DVec3::new(uniform(0.5, 4.0), 0.0, uniform(0.5, 2.5)),
                    1 => DVec3::new(0.0, uniform(0.5, 4.0), uniform(0.5, 2.5)),
                    _ => DVec3::new(uniform(0.5, 3.0), uniform(0.5, 3.0), 0.0),
                };
                ([corner - MARGIN, corner + size + MARGIN], (k % 7 == 0).then_some((k % 2) as u32))
            })
            .collect();
        let openings = Openings { windows, spheres: Vec::new() };
        let beams: Vec<SunBeam> = (0..12)
            .map(|k| {
                let (azimuth, altitude) = (uniform(0.0, std::f64::consts::TAU), uniform(0.01, 1.57));
                let to_light = DVec3::new(azimuth.cos() * altitude.cos(), azimuth.sin() * altitude.cos(), altitude.sin());
                SunBeam { to_light, normal_irradiance: 1.0, panel_group: [None, Some(0), Some(1)][k % 3], window_sun: None }
            })
            .collect();
        let along = openings.along(&beams);
        let mut ways = 0;
        for _ in 0..2000 {
            let centre = DVec3::new(uniform(-40.0, 40.0), uniform(-40.0, 40.0), uniform(-5.0, 25.0));
            let radius = uniform(0.0, 1.0).powi(3) * 4.0;
            let every_window: Vec<WayIn> = (beams.iter().enumerate())
                .flat_map(|(b, beam)| {
                    let ray = Ray::new(beam.to_light);
                    (openings.windows.iter().enumerate())
                        .filter(move |(_, ([min, max], group))| {
                            *group == beam.panel_group && ray.meets_box(centre, *min - radius, *max + radius)
                        })
                        .map(move |(w, _)| WayIn { beam: b as u32, window: w as u32, ray })
                })
                .collect();
            assert_eq!(along.ways_into_sphere(centre, radius), every_window, "sphere at {centre} of radius {radius}");
            ways += every_window.len();
        }
        assert!(ways > 2000, "{ways} ways in found");
    }
}
