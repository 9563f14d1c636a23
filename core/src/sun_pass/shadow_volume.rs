//! Shadow volumes for a directional light, as triangle lists of homogeneous
//! points (w = 0 for points at infinity), for the depth-fail stencil test.
//! Plain geometry, no Bevy types.
//!
//! Each caster triangle, turned to face the light, bounds the volume of
//! space it shades: its own face (the near cap) and one side per edge,
//! reaching away from the light to where the volume ends ([`VolumeEnd`]):
//! the point at infinity (for a directional light the far cap shrinks to
//! that point), or a plane beyond every receiver, where the far cap is the
//! face projected along the light. Where two casters
//! share an edge with opposite directions, as in a manifold mesh, their side
//! triangles coincide with opposite windings and cancel: both are left out,
//! so only silhouette and open edges get sides. Elsewhere (open meshes,
//! T-junctions, duplicated faces) every triangle keeps its own closed volume,
//! so the stencil count stays exact whatever the model's quality.
//!
//! A closed shell (faces joined edge to edge, each edge met by exactly one
//! other: a wall, a slab, a desk modelled as a solid, a closed room), wound
//! alike and outward, casts from its faces toward the light alone: a ray
//! from any point that crosses the shell leaves the solid it bounds, last,
//! through one of them, so the faces turned away add nothing to where the
//! count is zero; they only doubled the sides and far caps to rasterize.
//! Real models are mostly such solids (a converted IFC model's walls and
//! slabs); their volumes' fill, most of a GPU frame, goes down by half.

use std::ops::Range;

use glam::{Vec3, Vec4};

use crate::scene::shells::{Edges, Meeting, closed_shells, model_shells};

/// Triangles whose normal is this close to perpendicular to the light cast
/// no volume (their shadow has no area).
const EDGE_ON: f32 = 1e-6;

/// Where volumes end away from the light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VolumeEnd {
    /// At infinity: every side a triangle to the point at infinity.
    Infinity,
    /// On the horizontal plane at this height, beyond everything that
    /// receives light: sides and far caps cover far less of the screen than
    /// sides to infinity (rasterizing them is most of a frame of a model
    /// with many casters).
    Plane(f32),
}

impl VolumeEnd {
    /// The plane beyond every receiver at heights `low..high` (the ground
    /// drawn outside included) for light along `-to_light`: a metre below
    /// for light going down, above for light going up; infinity for light
    /// within 3° of level, whose volumes would reach almost as far.
    pub fn beyond(low: f32, high: f32, to_light: Vec3) -> Self {
        const LEVEL: f32 = 0.05;
        match to_light.z {
            z if z > LEVEL => Self::Plane(low - 1.0),
            z if z < -LEVEL => Self::Plane(high + 1.0),
            _ => Self::Infinity,
        }
    }
}

/// Casters with their shared edges found once: which edges meet does not
/// depend on the light, so a volume along each new direction is one pass
/// over the triangles (the sun pass keeps a scene's opaque casters so).
#[derive(Debug, Clone, Default)]
pub struct Casters {
    triangles: Vec<[Vec3; 3]>,
    /// What meets edge k of triangle t (index 3t + k, from corner k to k + 1).
    meets: Vec<Meeting>,
    /// The edges of each place where three or more casters meet.
    crowds: Vec<Vec<u32>>,
    /// Per caster: 0 where it belongs to no closed shell, else ±1, the way
    /// its winding runs against its shell's outward one (its side that
    /// faces the light, so wound, is the one that casts).
    shell_winding: Vec<i8>,
}

impl Casters {
    /// `triangles` with their shared edges found (points that are equal
    /// to the bit meet), closed shells too.
    pub fn new(triangles: Vec<[Vec3; 3]>) -> Self {
        let edges = Edges::by_points(&triangles);
        let shell_winding = closed_shells(&triangles, &edges).winding;
        Self::with_shells(triangles, edges, shell_winding)
    }

    /// A model's casters, with the vertices of its file each corner is
    /// (`vertices[t][k]`, equal numbers for one vertex): shells are found
    /// by those too, so a solid that touches another along an edge (a wall
    /// standing on a slab's edge: four faces meet there) is still a shell;
    /// sides still cancel wherever points are equal ([`model_shells`]).
    pub fn of_model(triangles: Vec<[Vec3; 3]>, vertices: &[[u32; 3]]) -> Self {
        let (shells, edges) = model_shells(&triangles, vertices);
        Self::with_shells(triangles, edges, shells.winding)
    }

    fn with_shells(triangles: Vec<[Vec3; 3]>, edges: Edges, shell_winding: Vec<i8>) -> Self {
        Self { triangles, meets: edges.meets, crowds: edges.crowds, shell_winding }
    }

    /// The casters, as given.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// Appends the volume they shade from light arriving along `-to_light`
    /// (`to_light` is the unit vector toward the light) to `out` (a large
    /// model's is tens of megabytes, made again each sun move, so it is
    /// written once, in place): the near caps, then the sides and the far
    /// caps. Returns the caps' range there and that of the rest.
    ///
    /// Each caster is turned to face the light; two edges between the same
    /// points that, turned, run opposite ways belong to one shell and cast
    /// no side. A caster's lit face is its volume's near cap: the stencil
    /// pass biases the caps, and only them, away from the camera so that
    /// face counts as outside; biased sides would move the shadow's edges.
    pub fn volume_into(&self, to_light: Vec3, end: VolumeEnd, out: &mut Vec<Vec4>) -> (Range<u32>, Range<u32>) {
        // Where a point's shadow ends (every caster lies on the light's side of the plane).
        let far = |p: Vec3| match end {
            VolumeEnd::Infinity => (-to_light).extend(0.0),
            VolumeEnd::Plane(z) => (p - to_light * ((p.z - z) / to_light.z)).extend(1.0),
        };
        // +1: the winding faces the light, −1: turned, 0: no volume (edge-on,
        // or a closed shell's face turned from the light).
        let facing: Vec<i8> = self
            .triangles
            .iter()
            .map(|&[a, b, c]| {
                let normal = (b - a).cross(c - a);
                let facing = normal.dot(to_light);
                if facing.abs() <= EDGE_ON * normal.length() { 0 } else { facing.signum() as i8 }
            })
            .zip(&self.shell_winding)
            .map(|(facing, &winding)| if facing * winding < 0 { 0 } else { facing })
            .collect();
        // Where several edges meet, as many cancel each way as both ways have.
        let mut cancelled_in_crowds = vec![false; if self.crowds.is_empty() { 0 } else { self.meets.len() }];
        for edges in &self.crowds {
            let reference = self.triangles[edges[0] as usize / 3][edges[0] as usize % 3];
            let way = |edge: u32| {
                let forward = self.triangles[edge as usize / 3][edge as usize % 3] == reference;
                facing[edge as usize / 3] * if forward { 1 } else { -1 }
            };
            let (forward, backward): (Vec<u32>, Vec<u32>) = edges.iter().filter(|&&e| way(e) != 0).partition(|&&e| way(e) > 0);
            for (&a, &b) in forward.iter().zip(&backward) {
                cancelled_in_crowds[a as usize] = true;
                cancelled_in_crowds[b as usize] = true;
            }
        }
        let casts_side = |edge: usize| match self.meets[edge] {
            Meeting::Open => true,
            Meeting::Pair(other, same) => {
                let (face, other_face) = (facing[edge / 3], facing[other as usize / 3]);
                other_face == 0 || if same { other_face == face } else { other_face != face }
            }
            Meeting::Crowd => !cancelled_in_crowds[edge],
        };
        // Each caster turned to face the light, and its edges (start, end) so turned.
        let casting = || facing.iter().enumerate().filter(|(_, f)| **f != 0);
        let turned = |t: usize| {
            let [a, b, c] = self.triangles[t];
            if facing[t] > 0 { [a, b, c] } else { [a, c, b] }
        };
        let sides: usize = casting().map(|(t, _)| (0..3).filter(|&k| casts_side(3 * t + k)).count()).sum();
        let casters = casting().count();
        let (per_side, far_caps) = if end == VolumeEnd::Infinity { (3, 0) } else { (6, 3 * casters) };
        out.reserve(3 * casters + per_side * sides + far_caps);
        let start = out.len() as u32;
        for (t, _) in casting() {
            out.extend(turned(t).map(|v| v.extend(1.0)));
        }
        let caps_end = out.len() as u32;
        for (t, &face) in casting() {
            for k in (0..3).filter(|&k| casts_side(3 * t + k)) {
                let (p, q) = (self.triangles[t][k], self.triangles[t][(k + 1) % 3]);
                let (p, q) = if face > 0 { (p, q) } else { (q, p) };
                match end {
                    VolumeEnd::Infinity => out.extend([q.extend(1.0), p.extend(1.0), far(p)]),
                    VolumeEnd::Plane(_) => out.extend([q.extend(1.0), p.extend(1.0), far(p), q.extend(1.0), far(p), far(q)]),
                }
            }
        }
        if end != VolumeEnd::Infinity {
            for (t, _) in casting() {
                let [a, b, c] = turned(t);
                out.extend([far(a), far(c), far(b)]);
            }
        }
        (start..caps_end, caps_end..out.len() as u32)
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;

    /// A volume's near caps and the rest (sides and far caps), apart.
    #[derive(Debug, Default, PartialEq)]
    struct ShadowVolume {
        caps: Vec<Vec4>,
        sides: Vec<Vec4>,
    }

    fn shadow_volume(casters: &[[Vec3; 3]], to_light: Vec3, end: VolumeEnd) -> ShadowVolume {
        let mut caps = Vec::new();
        let (near, _) = Casters::new(casters.to_vec()).volume_into(to_light, end, &mut caps);
        let sides = caps.split_off(near.end as usize);
        ShadowVolume { caps, sides }
    }

    /// A closed surface: every directed edge meets its reverse equally often.
    fn is_closed(volume: &ShadowVolume) -> bool {
        let triangles: Vec<Vec4> = volume.caps.iter().chain(&volume.sides).copied().collect();
        let key = |v: Vec4| v.to_array().map(f32::to_bits);
        let mut balance: HashMap<([u32; 4], [u32; 4]), i32> = HashMap::new();
        for t in triangles.chunks(3) {
            for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *balance.entry((key(p), key(q))).or_default() += 1;
                *balance.entry((key(q), key(p))).or_default() -= 1;
            }
        }
        balance.values().all(|&b| b == 0)
    }

    fn cube() -> Vec<[Vec3; 3]> {
        let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let quads = [
            [v(0., 0., 0.), v(0., 1., 0.), v(1., 1., 0.), v(1., 0., 0.)],
            [v(0., 0., 1.), v(1., 0., 1.), v(1., 1., 1.), v(0., 1., 1.)],
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 0., 1.), v(0., 0., 1.)],
            [v(0., 1., 0.), v(0., 1., 1.), v(1., 1., 1.), v(1., 1., 0.)],
            [v(0., 0., 0.), v(0., 0., 1.), v(0., 1., 1.), v(0., 1., 0.)],
            [v(1., 0., 0.), v(1., 1., 0.), v(1., 1., 1.), v(1., 0., 1.)],
        ];
        quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect()
    }

    #[test]
    fn a_manifold_cube_gets_sides_only_on_its_silhouette() {
        let light = Vec3::new(0.3, -0.4, 0.866).normalize();
        let volume = shadow_volume(&cube(), light, VolumeEnd::Infinity);
        assert!(is_closed(&volume));
        // A closed shell casts from its three faces toward the light (six
        // triangles) and gets a side on each of its six silhouette edges.
        assert_eq!((volume.caps.len() / 3, volume.sides.len() / 3), (6, 6));
    }

    /// Winding number of a closed volume (points on a plane, w = 1) about
    /// `p`: the signed solid angles of its triangles over 4π (Van Oosterom
    /// and Strackee's formula).
    fn winding_number(volume: &ShadowVolume, p: Vec3) -> f32 {
        let triangles: Vec<Vec3> = volume.caps.iter().chain(&volume.sides).map(|v| v.truncate() - p).collect();
        let solid_angle = |t: &[Vec3]| {
            let (a, b, c) = (t[0], t[1], t[2]);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * a.dot(b.cross(c)).atan2(denominator)
        };
        triangles.chunks(3).map(solid_angle).sum::<f32>() / (4.0 * std::f32::consts::PI)
    }

    /// The one-sided volume of a closed shell holds exactly the points the
    /// shell shades, those inside it too: wound outward, wound inward (a
    /// closed room modelled from within), wound inconsistently (a
    /// converted model's flipped faces), and two solids touching along an
    /// edge (four casters meeting there: no shell by points, both sides cast).
    #[test]
    fn a_closed_shell_shades_what_it_hides_from_the_light() {
        let light = Vec3::new(0.3, -0.4, 0.866).normalize();
        let inverted: Vec<[Vec3; 3]> = cube().iter().map(|&[a, b, c]| [a, c, b]).collect();
        let mixed: Vec<[Vec3; 3]> =
            cube().iter().enumerate().map(|(i, &[a, b, c])| if i % 3 == 0 { [a, c, b] } else { [a, b, c] }).collect();
        let offset = Vec3::new(1.0, 0.0, 1.0);
        let touching: Vec<[Vec3; 3]> = cube().into_iter().chain(cube().iter().map(|t| t.map(|v| v + offset))).collect();
        // The ray toward the light from p meets the unit cube at `corner` (slab test).
        let hits = |p: Vec3, corner: Vec3| {
            let (t0, t1) = ((corner - p) / light, (corner + Vec3::ONE - p) / light);
            let (near, far) = (t0.min(t1).max_element(), t0.max(t1).min_element());
            near <= far && far > 0.0
        };
        let one = [Vec3::ZERO];
        let two = [Vec3::ZERO, offset];
        for (casters, corners) in [(cube(), &one[..]), (inverted, &one), (mixed, &one), (touching, &two)] {
            let volume = shadow_volume(&casters, light, VolumeEnd::Plane(-3.0));
            assert!(is_closed(&volume));
            if corners.len() == 1 {
                assert_eq!((volume.caps.len() / 3, volume.sides.len() / 3), (6, 6 * 2 + 6), "one shell, lit side only");
            }
            let mut shaded_points = 0;
            for (i, j, k) in (0..17).flat_map(|i| (0..17).flat_map(move |j| (0..11).map(move |k| (i, j, k)))) {
                let p = Vec3::new(-2.03 + 0.25 * i as f32, -2.01 + 0.25 * j as f32, -2.9 + 0.47 * k as f32);
                // Inside a solid counts as shaded (the slab test says so too).
                let shaded = corners.iter().any(|&c| hits(p, c));
                let winding = winding_number(&volume, p).round();
                assert_eq!(winding != 0.0, shaded, "{p}: winding number {winding}");
                shaded_points += usize::from(shaded);
            }
            assert!(shaded_points > 100, "{shaded_points} points in the shadow");
        }
    }

    /// A model's solids are shells by its own vertices: a box with a face
    /// wound the other way, under a box standing on that face, is no shell
    /// by its points (that face meets the rest only where four faces meet,
    /// so its winding cannot be put right), but is one by its vertices.
    /// Faces that share no vertices (a triangle soup) close by points still.
    #[test]
    fn a_model_s_solids_are_shells_by_their_own_vertices() {
        let light = Vec3::new(0.3, -0.4, 0.866).normalize();
        // The lower box's top face (quad 1) wound the other way.
        let lower: Vec<[Vec3; 3]> =
            cube().iter().enumerate().map(|(i, &[a, b, c])| if i / 2 == 1 { [a, c, b] } else { [a, b, c] }).collect();
        let upper: Vec<[Vec3; 3]> = cube().iter().map(|t| t.map(|v| v + Vec3::Z)).collect();
        let casters: Vec<[Vec3; 3]> = lower.iter().chain(&upper).copied().collect();
        // Vertex numbers: one per point of each box.
        let mut numbers: HashMap<(usize, [u32; 3]), u32> = HashMap::new();
        let vertices: Vec<[u32; 3]> = casters
            .iter()
            .enumerate()
            .map(|(t, triangle)| {
                triangle.map(|v| {
                    let next = numbers.len() as u32;
                    *numbers.entry((t / 12, v.to_array().map(f32::to_bits))).or_insert(next)
                })
            })
            .collect();
        let caps = |casters: &Casters| {
            let mut out = Vec::new();
            casters.volume_into(light, VolumeEnd::Plane(-3.0), &mut out).0.len() / 3
        };
        assert_eq!(caps(&Casters::new(casters.clone())), 24, "by points: no shell, every face casts");
        let by_vertices = Casters::of_model(casters.clone(), &vertices);
        assert_eq!(caps(&by_vertices), 12, "by vertices: two shells, their faces toward the light cast");
        let mut volume = ShadowVolume::default();
        let (near, _) = by_vertices.volume_into(light, VolumeEnd::Plane(-3.0), &mut volume.caps);
        volume.sides = volume.caps.split_off(near.end as usize);
        assert!(is_closed(&volume));
        for (i, j, k) in (0..13).flat_map(|i| (0..13).flat_map(move |j| (0..13).map(move |k| (i, j, k)))) {
            let p = Vec3::new(-2.03 + 0.33 * i as f32, -2.01 + 0.33 * j as f32, -2.9 + 0.43 * k as f32);
            let (t0, t1) = ((Vec3::ZERO - p) / light, (Vec3::new(1.0, 1.0, 2.0) - p) / light);
            let shaded = t0.min(t1).max_element() <= t0.max(t1).min_element() && t0.max(t1).min_element() > 0.0;
            assert_eq!(winding_number(&volume, p).round() != 0.0, shaded, "{p}");
        }
        let soup: Vec<[u32; 3]> = (0..12).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        assert_eq!(caps(&Casters::of_model(cube(), &soup)), 6, "a soup closes by points");
    }

    /// Ending on a plane below: the volume is still closed, the silhouette's
    /// sides are quads down to the plane, and every caster gets a far cap there.
    #[test]
    fn volumes_ending_on_a_plane_are_closed_and_stop_there() {
        let light = Vec3::new(0.3, -0.4, 0.866).normalize();
        let volume = shadow_volume(&cube(), light, VolumeEnd::Plane(-2.0));
        assert!(is_closed(&volume));
        assert_eq!((volume.caps.len() / 3, volume.sides.len() / 3), (6, 6 * 2 + 6));
        assert!(volume.caps.iter().chain(&volume.sides).all(|v| v.w == 1.0 && (-2.0 - 1e-5..=1.0).contains(&v.z)));
        let on_the_plane = volume.sides.iter().filter(|v| (v.z + 2.0).abs() < 1e-5).count();
        assert_eq!(on_the_plane, 6 * 3 + 6 * 3, "the far corners of each side's two triangles, and the far caps");
        assert_eq!(VolumeEnd::beyond(0.0, 9.0, light), VolumeEnd::Plane(-1.0));
        assert_eq!(VolumeEnd::beyond(0.0, 9.0, -light), VolumeEnd::Plane(10.0));
        assert_eq!(VolumeEnd::beyond(0.0, 9.0, Vec3::X), VolumeEnd::Infinity);
    }

    #[test]
    fn open_and_duplicated_geometry_still_gives_closed_volumes() {
        let mut casters = cube();
        casters.truncate(10); // an open box
        casters.push(casters[3]); // a duplicated face
        // A T-junction: one edge of this pair is split in two on the other side.
        let (a, b, c) = (Vec3::new(2., 0., 0.), Vec3::new(4., 0., 0.), Vec3::new(3., 1., 0.));
        let m = Vec3::new(3., 0., 0.);
        casters.extend([[a, b, c], [b, a, Vec3::new(2.5, -1., 0.)], [m, a, Vec3::new(3., -1., 0.)]]);
        let volume = shadow_volume(&casters, Vec3::new(0.2, 0.1, 1.0).normalize(), VolumeEnd::Infinity);
        assert!(is_closed(&volume));
    }

    #[test]
    fn edge_on_casters_cast_nothing() {
        let wall = [[Vec3::ZERO, Vec3::X, Vec3::Z]];
        assert_eq!(shadow_volume(&wall, Vec3::Y, VolumeEnd::Infinity).caps.len(), 3);
        assert_eq!(
            shadow_volume(&wall, Vec3::Z, VolumeEnd::Infinity),
            ShadowVolume::default(),
            "a wall edge-on to the light casts nothing"
        );
        let floor = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
        let volume = shadow_volume(&floor, Vec3::Z, VolumeEnd::Infinity);
        assert!(volume.caps.iter().all(|v| v.z == 0.0 && v.w == 1.0));
        assert!(volume.sides.chunks(3).all(|t| t[2] == Vec4::new(0., 0., -1., 0.)));
    }
}
