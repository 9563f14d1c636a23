//! Contacts: where another face meets a surface — a wall standing on a
//! slab, a slab running through a wall, a roof's underside running on past
//! the walls as eaves. The light steps there (a room on one side; the
//! inside of a wall, or outdoors, on the other), so the patches of the
//! surface are cut along the meeting face's plane, near where they meet
//! ([`CutPlane`]). Without it one patch is lit as the mean of both sides,
//! and the room reads the soffit's light, or the dark under a wall, in its
//! ceiling and floor. This is discontinuity meshing along the model's own
//! contact lines, not along shadow edges.
//!
//! The same large faces keep clutter apart ([`LargeFaces::separating`]):
//! small parts on the two sides of a door leaf or a wall (a door's handles
//! outside and in) see different light, so they never share a cluster. And
//! they find glass that an opaque face covers in their own plane
//! ([`LargeFaces::covered_quarters`]), which the loader reads as that face.

use std::collections::HashMap;

use glam::{IVec3, Vec2, Vec3};

use super::bounds;
use super::cut_plane::{CutPlane, IN_PLANE};
use super::{Surface, Triangle};
use crate::parallel::par_map;

/// A surface takes at most this many contact planes (the longest contacts).
const MAX_CUTS: usize = 64;
/// Side of the grid cells that find the faces near a surface, m.
const CELL: f32 = 1.0;
/// Faces spanning more cells than this are checked against every surface.
const MAX_CELLS: i64 = 4096;
/// Contacts shorter than this (m) in all, per plane, are points, not lines.
const MIN_CONTACT: f32 = 0.01;
/// One face's piece of a contact shorter than this (m) is a point.
const MIN_PIECE: f32 = 1e-4;
/// A contact cuts the pieces within this distance of it, m.
const CONTACT_REACH: f32 = 0.01;
/// A face whose edge comes this close to a surface (m) meets it: a door leaf
/// a few millimetres over its threshold, beside its jamb. The light steps
/// there as under a wall standing on the floor; uncut, the threshold's
/// patch spanned the door, and the side of the gap under the leaf, lit by
/// the sunlit step outside, shone into the closed hall behind (SampleHouse's
/// entrance hall read 7-9 lx where Radiance reads 0.9-1.5).
const CONTACT_GAP: f32 = 0.01;

/// How far to either side of a contact line its points are looked for in
/// the surface's triangles, where the line runs along an edge between two
/// of them.
const ACROSS_EDGE: f32 = 0.002;

/// A plane: its unit normal and offset (the points x with normal · x = offset).
pub type Plane = (Vec3, f32);

/// The faces of the model's large surfaces, found by place: those of at
/// least `min_area` (m²). Walls, slabs, roofs and doors make the steps of
/// the light that matter; a chair leg or a window frame would cut a floor
/// or a wall into slivers for a step no sensor sees.
pub struct LargeFaces<'a> {
    triangles: &'a [Triangle],
    /// Per triangle, its surface's span: the longest side of its box (m).
    surface_span: Vec<f32>,
    grid: Grid,
}

impl<'a> LargeFaces<'a> {
    pub fn new(triangles: &'a [Triangle], surfaces: &[Surface], min_area: f32) -> Self {
        let mut large = vec![false; triangles.len()];
        let mut surface_span = vec![0.0; triangles.len()];
        for surface in surfaces {
            let own = surface.triangle_indices();
            let (lo, hi) = bounds(&triangles[own.clone()]);
            surface_span[own.clone()].fill((hi - lo).max_element());
            large[own].fill(surface.area >= min_area);
        }
        LargeFaces { triangles, surface_span, grid: Grid::new(triangles, &large) }
    }

    /// The planes (unit normal, offset) of the faces of surfaces spanning
    /// at least the side of the cube (lo, hi) that pass through it with
    /// room on both sides, each plane once, in the order of the faces: what
    /// parts of the cube lie apart. (A book's or a chair seat's faces in a
    /// cube of half a metre do not part it; a door leaf or a window's frame
    /// does.)
    pub fn separating(&self, lo: Vec3, hi: Vec3) -> Vec<Plane> {
        let (centre, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let mut planes: Vec<Plane> = Vec::new();
        for t in self.grid.near(lo, hi) {
            if self.surface_span[t as usize] < 2.0 * half.x {
                continue;
            }
            let face = &self.triangles[t as usize];
            let (face_lo, face_hi) = bounds(std::slice::from_ref(face));
            if face_lo.cmpgt(hi).any() || face_hi.cmplt(lo).any() {
                continue;
            }
            let normal = face.normal();
            let offset = normal.dot(face.vertices[0]);
            let (middle, reach) = (normal.dot(centre), normal.abs().dot(half));
            if middle - reach > offset - IN_PLANE || middle + reach < offset + IN_PLANE {
                continue;
            }
            if !planes.iter().any(|&plane| same_plane(plane, (normal, offset))) {
                planes.push((normal, offset));
            }
        }
        planes
    }

    /// Per triangle of `surface`, how many of its quarters (0-4, a point
    /// standing for each) large faces in its own plane lie over, counting
    /// the model's triangles that `counts` accepts (by index): glass under a
    /// zone box an export drew over the façade, or the glazed face of a
    /// window's lining lying on the wall's reveal.
    pub fn covered_quarters(&self, surface: &Surface, counts: impl Fn(usize) -> bool) -> Vec<u8> {
        let own = surface.triangle_indices();
        let tris = &self.triangles[own.clone()];
        let (lo, hi) = bounds(tris);
        let (normal, offset) = (surface.normal, surface.normal.dot(tris[0].vertices[0]));
        let over: Vec<Triangle> = self
            .grid
            .near(lo - Vec3::splat(IN_PLANE), hi + Vec3::splat(IN_PLANE))
            .into_iter()
            .filter(|&t| !own.contains(&(t as usize)) && counts(t as usize))
            .map(|t| self.triangles[t as usize])
            .filter(|f| f.normal().dot(normal).abs() > 0.9999)
            .filter(|f| f.vertices.iter().all(|&v| (normal.dot(v) - offset).abs() <= IN_PLANE))
            .collect();
        if over.is_empty() {
            return vec![0; tris.len()];
        }
        let flat = Flat::new(normal, &over);
        const POINTS: [[f32; 3]; 4] =
            [[1.0 / 3.0; 3], [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0], [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0]];
        tris.iter()
            .map(|t| POINTS.iter().filter(|w| flat.holds(t.vertices[0] * w[0] + t.vertices[1] * w[1] + t.vertices[2] * w[2])).count() as u8)
            .collect()
    }

    /// The share (0-1) of `surface`'s area under opaque faces in its own
    /// plane ([`Self::covered_quarters`]).
    pub fn covered_share(&self, surface: &Surface, opaque: impl Fn(u32) -> bool) -> f32 {
        let tris = &self.triangles[surface.triangle_indices()];
        let quarters = self.covered_quarters(surface, |t| opaque(self.triangles[t].material));
        let covered: f32 = tris.iter().zip(quarters).map(|(t, q)| t.area() * f32::from(q) / 4.0).sum();
        covered / surface.area.max(f32::MIN_POSITIVE)
    }
}

/// Whether two planes (unit normal, offset) are one, facing either way.
fn same_plane((n, d): Plane, (m, e): Plane) -> bool {
    let cos = n.dot(m);
    cos.abs() > 0.9999 && (d - cos.signum() * e).abs() < IN_PLANE
}

/// Per surface, the planes of the large faces that meet it along a line
/// inside it, where its patches are cut; none for the surfaces not
/// `wanted`.
pub fn contact_cuts(large: &LargeFaces, surfaces: &[Surface], wanted: impl Fn(usize) -> bool + Sync) -> Vec<Vec<CutPlane>> {
    let (triangles, grid) = (large.triangles, &large.grid);
    par_map(None, surfaces.len(), |index| {
        if !wanted(index) {
            return Vec::new();
        }
        let surface = &surfaces[index];
        let own = surface.triangle_indices();
        let tris = &triangles[own.clone()];
        let (lo, hi) = bounds(tris);
        let flat = Flat::new(surface.normal, tris);
        let mut cuts: Vec<(CutPlane, f32)> = Vec::new();
        for t in grid.near(lo - Vec3::splat(IN_PLANE), hi + Vec3::splat(IN_PLANE)) {
            let face = &triangles[t as usize];
            if own.contains(&(t as usize)) || !face_near(face, (lo, hi)) {
                continue;
            }
            let Some((p, q)) = flat.contact(face) else { continue };
            let normal = face.normal();
            // A cut must leave more than a sliver on either side (a chair's
            // leg sunk a millimetre into the floor is not cut): tested after
            // `contact`, which turns most faces away from their corners alone.
            let heights = tris.iter().flat_map(|t| t.vertices).map(|v| normal.dot(v - face.vertices[0]));
            let (below, above) = heights.fold((0.0f32, 0.0f32), |(lo, hi), h| (lo.min(h), hi.max(h)));
            if below > -CONTACT_GAP || above < CONTACT_GAP {
                continue;
            }
            let cut = CutPlane {
                normal,
                offset: normal.dot(face.vertices[0]),
                near: (p.min(q) - Vec3::splat(CONTACT_REACH), p.max(q) + Vec3::splat(CONTACT_REACH)),
            };
            let length = p.distance(q);
            match cuts.iter_mut().find(|(c, _)| same_plane((c.normal, c.offset), (cut.normal, cut.offset))) {
                Some((c, total)) => {
                    c.near = (c.near.0.min(cut.near.0), c.near.1.max(cut.near.1));
                    *total += length;
                }
                None => cuts.push((cut, length)),
            }
        }
        // A plane's contacts count together: a gable fanned from its apex
        // round a window meets a beam through it in slivers of a few
        // millimetres each.
        cuts.retain(|(_, total)| *total >= MIN_CONTACT);
        cuts.sort_by(|a, b| b.1.total_cmp(&a.1));
        cuts.into_iter().take(MAX_CUTS).map(|(c, _)| c).collect()
    })
}

/// Whether `face` comes near enough to the box (lo, hi) of a surface's
/// triangles to meet it: within [`CONTACT_GAP`] and the width looked across
/// an edge. The grid's cells are a metre wide; most faces they hold for a
/// small surface lie well away from it. (With the triangles' boxes in
/// [`Flat`], FZK-Haus's contact cuts went from 30% of its loading's CPU
/// time to 8%; the cuts are the same.)
fn face_near(face: &Triangle, (lo, hi): (Vec3, Vec3)) -> bool {
    let reach = Vec3::splat(CONTACT_GAP + ACROSS_EDGE + IN_PLANE);
    let (face_lo, face_hi) = bounds(std::slice::from_ref(face));
    face_lo.cmple(hi + reach).all() && face_hi.cmpge(lo - reach).all()
}

/// A surface's plane and its triangles in the plane, to find where other
/// faces meet it.
struct Flat {
    normal: Vec3,
    offset: f32,
    u: Vec3,
    v: Vec3,
    triangles: Vec<[Vec2; 3]>,
    /// Per triangle, its box in the plane: a contact line or a point is
    /// tested only against the triangles whose boxes it meets.
    boxes: Vec<(Vec2, Vec2)>,
}

/// How far (m) a segment's or a point's box may pass a triangle's box and
/// the triangle still be tested: the tests inset the triangle by a tenth of
/// a millimetre, so this skips none that could hold a point.
const BOX_MARGIN: f32 = 1e-3;

/// Whether the boxes (lo, hi) and (a, b) come within [`BOX_MARGIN`].
fn boxes_meet((lo, hi): (Vec2, Vec2), (a, b): (Vec2, Vec2)) -> bool {
    lo.cmple(b + Vec2::splat(BOX_MARGIN)).all() && hi.cmpge(a - Vec2::splat(BOX_MARGIN)).all()
}

impl Flat {
    fn new(normal: Vec3, tris: &[Triangle]) -> Self {
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let offset = normal.dot(tris[0].vertices[0]);
        let triangles: Vec<[Vec2; 3]> = tris.iter().map(|t| t.vertices.map(|p| Vec2::new(p.dot(u), p.dot(v)))).collect();
        let boxes = triangles.iter().map(|&[a, b, c]| (a.min(b).min(c), a.max(b).max(c))).collect();
        Flat { normal, offset, u, v, triangles, boxes }
    }

    /// Where `face` meets the surface, or comes within [`CONTACT_GAP`] of
    /// it, along a line inside it: the line's ends, in the surface's plane
    /// (its corners within the gap, and where its edges cross the plane).
    /// `None` when it lies wholly to one side, spans no more than twice the
    /// gap across the plane (lying along it, or a sliver crossing it), or
    /// meets it only at a point or outside the surface.
    fn contact(&self, face: &Triangle) -> Option<(Vec3, Vec3)> {
        let h = face.vertices.map(|p| self.normal.dot(p) - self.offset);
        let (low, high) = (h.iter().copied().fold(f32::INFINITY, f32::min), h.iter().copied().fold(f32::NEG_INFINITY, f32::max));
        if low > CONTACT_GAP || high < -CONTACT_GAP || high - low <= 2.0 * CONTACT_GAP {
            return None;
        }
        let mut points: Vec<Vec3> = (0..3).filter(|&k| h[k].abs() <= CONTACT_GAP).map(|k| face.vertices[k] - self.normal * h[k]).collect();
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            if (h[a] > IN_PLANE && h[b] < -IN_PLANE) || (h[a] < -IN_PLANE && h[b] > IN_PLANE) {
                let (pa, pb) = (face.vertices[a], face.vertices[b]);
                points.push(pa + (pb - pa) * (h[a] / (h[a] - h[b])));
            }
        }
        let (p, q) = points
            .iter()
            .flat_map(|&p| points.iter().map(move |&q| (p, q)))
            .max_by(|a, b| a.0.distance_squared(a.1).total_cmp(&b.0.distance_squared(b.1)))?;
        if p.distance(q) < MIN_PIECE {
            return None;
        }
        // The part of the line inside the surface: a wall's face crossing a
        // rafter or a beam that runs through it meets the rafter's plane
        // along the whole wall, the rafter for a hand's width of it.
        if let Some((a, b)) = self.part_inside(p, q).filter(|(a, b)| a.distance(*b) >= MIN_PIECE) {
            return Some((a, b));
        }
        // A line along an edge between two of the surface's own triangles
        // (a wall triangulated along the slab's top) is inside it where
        // the surface lies on both sides of it.
        let across = self.normal.cross(q - p).normalize_or_zero() * ACROSS_EDGE;
        let inside = [0.1, 0.3, 0.5, 0.7, 0.9].iter().map(|&t| p.lerp(q, t)).any(|x| self.holds(x + across) && self.holds(x - across));
        inside.then_some((p, q))
    }

    /// The ends of the part of the segment `p`–`q` (in the plane) inside
    /// the surface's triangles, from the first point inside one to the last.
    fn part_inside(&self, p: Vec3, q: Vec3) -> Option<(Vec3, Vec3)> {
        let flat = |x: Vec3| Vec2::new(x.dot(self.u), x.dot(self.v));
        let (start, along) = (flat(p), flat(q) - flat(p));
        let segment = (start.min(start + along), start.max(start + along));
        let mut span: Option<(f32, f32)> = None;
        for [a, b, c] in self.triangles_meeting(segment) {
            let turn = (b - a).perp_dot(c - a);
            if turn.abs() < 1e-12 {
                continue;
            }
            // Each edge keeps the points on the triangle's side of it, a
            // tenth of a millimetre in (as `holds` does).
            let (mut from, mut to) = (0.0f32, 1.0f32);
            for (e0, e1) in [(a, b), (b, c), (c, a)] {
                let inward = (e1 - e0).perp() * turn.signum();
                let inward = inward / inward.length().max(f32::MIN_POSITIVE);
                let (height, rate) = (inward.dot(start - e0) - 1e-4, inward.dot(along));
                if rate.abs() < 1e-12 {
                    if height < 0.0 {
                        to = -1.0;
                    }
                } else if rate > 0.0 {
                    from = from.max(-height / rate);
                } else {
                    to = to.min(-height / rate);
                }
            }
            if from < to {
                span = Some(span.map_or((from, to), |(lo, hi)| (lo.min(from), hi.max(to))));
            }
        }
        span.map(|(lo, hi)| (p.lerp(q, lo), p.lerp(q, hi)))
    }

    /// The triangles whose boxes come within [`BOX_MARGIN`] of the box
    /// `bounds` (in the plane's coordinates).
    fn triangles_meeting(&self, bounds: (Vec2, Vec2)) -> impl Iterator<Item = [Vec2; 3]> + '_ {
        self.triangles.iter().zip(&self.boxes).filter(move |(_, b)| boxes_meet(bounds, **b)).map(|(t, _)| *t)
    }

    /// Whether `point` (near the plane) lies inside one of the triangles.
    fn holds(&self, point: Vec3) -> bool {
        let x = Vec2::new(point.dot(self.u), point.dot(self.v));
        self.triangles_meeting((x, x)).any(|[a, b, c]| {
            let d = (b - a).perp_dot(c - a);
            if d.abs() < 1e-12 {
                return false;
            }
            let (s, t) = ((x - a).perp_dot(c - a) / d, (b - a).perp_dot(x - a) / d);
            s > 1e-4 && t > 1e-4 && s + t < 1.0 - 1e-4
        })
    }
}

/// Triangles by the grid cells their boxes cover; the largest kept apart.
struct Grid {
    cells: HashMap<IVec3, Vec<u32>>,
    large: Vec<u32>,
}

impl Grid {
    /// The grid of the triangles `keep` marks.
    fn new(triangles: &[Triangle], keep: &[bool]) -> Self {
        let mut grid = Grid { cells: HashMap::new(), large: Vec::new() };
        for (t, triangle) in triangles.iter().enumerate().filter(|(t, _)| keep[*t]) {
            let (lo, hi) = bounds(std::slice::from_ref(triangle));
            let (a, b) = (cell(lo - Vec3::splat(IN_PLANE)), cell(hi + Vec3::splat(IN_PLANE)));
            let span = (b - a + IVec3::ONE).as_i64vec3();
            if span.x * span.y * span.z > MAX_CELLS {
                grid.large.push(t as u32);
                continue;
            }
            for x in a.x..=b.x {
                for y in a.y..=b.y {
                    for z in a.z..=b.z {
                        grid.cells.entry(IVec3::new(x, y, z)).or_default().push(t as u32);
                    }
                }
            }
        }
        grid
    }

    /// The triangles whose cells meet the box (lo, hi), in index order:
    /// the same order whatever the hash map's.
    fn near(&self, lo: Vec3, hi: Vec3) -> Vec<u32> {
        let mut found = self.large.clone();
        let (a, b) = (cell(lo), cell(hi));
        let span = (b - a + IVec3::ONE).as_i64vec3();
        if span.x * span.y * span.z > self.cells.len() as i64 {
            // A box larger than the occupied grid: walk the grid instead.
            let inside = |c: &IVec3| c.cmpge(a).all() && c.cmple(b).all();
            self.cells.iter().filter(|(c, _)| inside(c)).for_each(|(_, list)| found.extend(list));
        } else {
            for x in a.x..=b.x {
                for y in a.y..=b.y {
                    for z in a.z..=b.z {
                        found.extend(self.cells.get(&IVec3::new(x, y, z)).into_iter().flatten());
                    }
                }
            }
        }
        found.sort_unstable();
        found.dedup();
        found
    }
}

fn cell(p: Vec3) -> IVec3 {
    (p / CELL).floor().as_ivec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(material: u32, [a, b, c, d]: [[f32; 3]; 4]) -> Vec<Triangle> {
        let [a, b, c, d] = [a, b, c, d].map(Vec3::from);
        vec![
            Triangle { vertices: [a, b, c], material, file_vertices: [0, 1, 2] },
            Triangle { vertices: [a, c, d], material, file_vertices: [0, 2, 3] },
        ]
    }

    /// The surfaces of `quads`, one each.
    fn surfaces(quads: &[Vec<Triangle>]) -> (Vec<Triangle>, Vec<Surface>) {
        let mut triangles = Vec::new();
        let mut surfaces = Vec::new();
        for q in quads {
            let start = triangles.len() as u32;
            triangles.extend(q.iter().copied());
            let cross: Vec3 = q.iter().map(Triangle::cross).sum();
            surfaces.push(Surface {
                material: q[0].material,
                triangles: start..triangles.len() as u32,
                patches: 0..0,
                normal: cross.normalize(),
                area: q.iter().map(Triangle::area).sum(),
            });
        }
        (triangles, surfaces)
    }

    #[test]
    fn a_wall_standing_on_a_slab_cuts_it_along_its_foot_only() {
        let slab = quad(0, [[-2.0, -2.0, 0.0], [6.0, -2.0, 0.0], [6.0, 6.0, 0.0], [-2.0, 6.0, 0.0]]);
        let wall = quad(1, [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 0.0, 3.0], [0.0, 0.0, 3.0]]);
        let beside = quad(1, [[0.0, 3.0, 0.5], [4.0, 3.0, 0.5], [4.0, 3.0, 3.0], [0.0, 3.0, 3.0]]);
        let lying = quad(2, [[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [2.0, 2.0, 0.0], [1.0, 2.0, 0.0]]);
        let (triangles, surfaces) = surfaces(&[slab, wall, beside, lying]);
        let cuts = contact_cuts(&LargeFaces::new(&triangles, &surfaces, 0.01), &surfaces, |_| true);
        // The slab: one plane, the wall's (y = 0), cutting along its foot.
        assert_eq!(cuts[0].len(), 1, "{:?}", cuts[0]);
        let cut = cuts[0][0];
        assert!(cut.normal.y.abs() > 0.999 && cut.offset.abs() < 1e-6);
        assert!(cut.near.0.x > -0.1 && cut.near.1.x < 4.1 && cut.near.1.y - cut.near.0.y < 0.1);
        // The wall meets the slab along its own bottom edge: not inside it.
        assert!(cuts[1].is_empty(), "{:?}", cuts[1]);
        // A face half a metre above and one lying flat on the slab cut nothing.
        assert!(cuts[2].is_empty() && cuts[3].is_empty());
    }

    /// A slab meeting a wall whose triangles have an edge along the slab's
    /// top (as IFC exports triangulate a storey's wall) cuts it there, as
    /// it cuts a wall whose triangles cross that line. Before, the line
    /// lay inside none of the wall's triangles and the wall's patches
    /// spanned the slab, lit as the mean of the storey below and above.
    #[test]
    fn a_slab_meeting_a_wall_along_an_edge_of_its_triangles_cuts_it() {
        let below = quad(1, [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 0.0, 2.7], [0.0, 0.0, 2.7]]);
        let above = quad(1, [[0.0, 0.0, 2.7], [4.0, 0.0, 2.7], [4.0, 0.0, 5.0], [0.0, 0.0, 5.0]]);
        let whole = quad(1, [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 0.0, 5.0], [0.0, 0.0, 5.0]]);
        let slab_top = quad(0, [[0.0, 0.0, 2.7], [0.0, -3.0, 2.7], [4.0, -3.0, 2.7], [4.0, 0.0, 2.7]]);
        for wall in [[below, above].concat(), whole] {
            let (triangles, surfaces) = surfaces(&[wall, slab_top.clone()]);
            let cuts = contact_cuts(&LargeFaces::new(&triangles, &surfaces, 0.01), &surfaces, |_| true);
            assert_eq!(cuts[0].len(), 1, "{:?}", cuts[0]);
            assert!(cuts[0][0].normal.z.abs() > 0.999 && (cuts[0][0].offset.abs() - 2.7).abs() < 1e-5, "{:?}", cuts[0][0]);
        }
    }

    /// A wall that a rafter runs through, out to the eaves, cuts the
    /// rafter where it passes, though the wall's line in the rafter's plane
    /// runs 12 m and the rafter is 10 cm wide (before, five points along
    /// that line were tested, and none fell in the rafter: FZK-Haus's
    /// rafters, clustered whole, lit its gallery with their sunlit ends).
    /// A leg sunk a millimetre into the floor is not cut off.
    #[test]
    fn a_wall_a_rafter_runs_through_cuts_it_where_it_passes() {
        let wall = quad(0, [[0.0, 0.0, 0.0], [12.0, 0.0, 0.0], [12.0, 0.0, 3.0], [0.0, 0.0, 3.0]]);
        let rafter = quad(1, [[5.3, -0.5, 2.5], [5.3, 2.0, 2.5], [5.4, 2.0, 2.5], [5.4, -0.5, 2.5]]);
        let floor = quad(0, [[0.0, 0.5, 0.0], [12.0, 0.5, 0.0], [12.0, 6.0, 0.0], [0.0, 6.0, 0.0]]);
        let leg = quad(2, [[8.0, 3.0, -0.001], [8.05, 3.0, -0.001], [8.05, 3.0, 0.45], [8.0, 3.0, 0.45]]);
        let (triangles, surfaces) = surfaces(&[wall, rafter, floor, leg]);
        let cuts = contact_cuts(&LargeFaces::new(&triangles, &surfaces, 1.0), &surfaces, |_| true);
        assert_eq!(cuts[1].len(), 1, "{:?}", cuts[1]);
        let cut = cuts[1][0];
        assert!(cut.normal.y.abs() > 0.999 && cut.offset.abs() < 1e-6, "{cut:?}");
        assert!(cut.near.0.x > 5.2 && cut.near.1.x < 5.5, "the part inside the rafter: {cut:?}");
        assert!(cuts[3].is_empty(), "{:?}", cuts[3]);

        // A gable fanned from its apex meets a ridge beam through it in
        // slivers a millimetre wide each: together they cut it.
        let apex = Vec3::new(0.0, 5.0, 6.0);
        let fan: Vec<Triangle> = (0..100)
            .map(|k| {
                let at = |k: i32| Vec3::new(0.0, 4.0 + 0.02 * k as f32, 4.0);
                Triangle { vertices: [apex, at(k + 1), at(k)], material: 0, file_vertices: [0, 1, 2] }
            })
            .collect();
        let beam = quad(1, [[-0.5, 4.96, 5.9], [-0.5, 5.04, 5.9], [12.0, 5.04, 5.9], [12.0, 4.96, 5.9]]);
        let (triangles, surfaces) = self::surfaces(&[fan, beam]);
        let cuts = contact_cuts(&LargeFaces::new(&triangles, &surfaces, 1.0), &surfaces, |_| true);
        assert!(cuts[1].iter().any(|c| c.normal.x.abs() > 0.999 && c.offset.abs() < 1e-6), "{:?}", cuts[1]);
    }

    /// A door leaf 4 mm over its threshold parts the light on it as a wall
    /// on the floor does; one 5 cm over leaves it whole, and so does a board
    /// lying 4 mm over it.
    #[test]
    fn a_door_leaf_a_few_millimetres_over_the_floor_cuts_it() {
        let floor = quad(0, [[-2.0, -2.0, 0.0], [6.0, -2.0, 0.0], [6.0, 6.0, 0.0], [-2.0, 6.0, 0.0]]);
        let leaf = |y: f32, z: f32| quad(1, [[0.0, y, z], [1.0, y, z], [1.0, y, 2.0], [0.0, y, 2.0]]);
        let board = quad(2, [[3.0, 3.0, 0.004], [4.0, 3.0, 0.004], [4.0, 4.0, 0.004], [3.0, 4.0, 0.004]]);
        let (triangles, surfaces) = surfaces(&[floor, leaf(0.0, 0.004), leaf(2.0, 0.05), board]);
        let cuts = contact_cuts(&LargeFaces::new(&triangles, &surfaces, 0.01), &surfaces, |_| true);
        assert_eq!(cuts[0].len(), 1, "{:?}", cuts[0]);
        let cut = cuts[0][0];
        assert!(cut.normal.y.abs() > 0.999 && cut.offset.abs() < 1e-6, "{cut:?}");
        assert!(cut.near.0.z <= 0.0 && cut.near.1.x < 1.1, "{cut:?}");
    }
}
