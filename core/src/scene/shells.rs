//! Closed shells: the solids of a model. A shell is a set of triangles
//! joined edge to edge, each edge met by exactly one other (no open edge,
//! no place where three or more faces meet), wound alike and outward: a
//! wall, a slab, a desk modelled as a solid, or a closed room modelled
//! from within. Their faces toward a light are all that shadows need
//! (`sun_pass`), and the side of an opaque shell's faces that looks into
//! it sees no daylight at all (`light`): nothing there to trace.
//!
//! Shells are found by points that are equal to the bit, and where those
//! close none (solids touching along an edge, where four faces meet), by
//! the model file's vertices ([`super::Triangle::file_vertices`]).

use glam::{DVec3, Vec3};

/// What else meets a triangle's edge.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Meeting {
    Open,
    /// One other edge between the same two points, and whether it runs the same way.
    Pair(u32, bool),
    /// Several: one of [`Edges::crowds`].
    Crowd,
}

/// The edges of a set of triangles grouped by the two corners they join,
/// corners being the same where `corner` says so.
pub(crate) struct Edges {
    /// What meets each edge (index 3t + k, from corner k to k + 1).
    pub(crate) meets: Vec<Meeting>,
    /// The edges of each place where three or more meet.
    pub(crate) crowds: Vec<Vec<u32>>,
}

impl Edges {
    /// Edges between points that are equal to the bit. Each point is
    /// numbered first ([`crate::parallel::number_alike`]): sorting the
    /// edges by their ends' twelve-byte coordinates took twice as long on a
    /// large model.
    pub(crate) fn by_points(triangles: &[[Vec3; 3]]) -> Self {
        let corners =
            crate::parallel::number_alike(triangles.len() * 3, |corner| triangles[corner / 3][corner % 3].to_array().map(f32::to_bits));
        Self::between(triangles.len(), |corner| corners[corner])
    }

    /// `corner(3t + k)` is corner k of triangle t, as something equal where
    /// the corners are one. The edges are grouped by sorting them by their
    /// ends, not through a map of lists (a list allocated per edge was most
    /// of finding a large model's shells).
    pub(crate) fn between<K: Copy + Ord>(triangles: usize, corner: impl Fn(usize) -> K) -> Self {
        let mut forward = Vec::with_capacity(triangles * 3);
        let mut by_ends: Vec<((K, K), u32)> = Vec::with_capacity(triangles * 3);
        for edge in 0..triangles * 3 {
            let (p, q) = (corner(edge), corner(edge - edge % 3 + (edge + 1) % 3));
            forward.push(p < q);
            by_ends.push(((p.min(q), p.max(q)), edge as u32));
        }
        by_ends.sort_unstable();
        let mut meets = vec![Meeting::Open; triangles * 3];
        let mut crowds = Vec::new();
        for edges in by_ends.chunk_by(|a, b| a.0 == b.0) {
            match *edges {
                [_] => {}
                [(_, first), (_, second)] => {
                    let same = forward[first as usize] == forward[second as usize];
                    meets[first as usize] = Meeting::Pair(second, same);
                    meets[second as usize] = Meeting::Pair(first, same);
                }
                _ => {
                    edges.iter().for_each(|&(_, edge)| meets[edge as usize] = Meeting::Crowd);
                    crowds.push(edges.iter().map(|&(_, edge)| edge).collect());
                }
            }
        }
        Self { meets, crowds }
    }
}

/// Which triangles of a set form closed shells.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Shells {
    /// Per triangle, 0 where it belongs to no closed shell, else ±1, the
    /// way its winding runs against its shell's outward one.
    pub(crate) winding: Vec<i8>,
    /// Per triangle in a shell, a number its shell's triangles alone share.
    pub(crate) shell: Vec<u32>,
}

/// The closed shells among `triangles`, whose edges are [`Edges`]: sets
/// of triangles joined edge to edge, each edge met by exactly one other
/// (no open edge, no place where three or more faces meet), their
/// windings made to agree across each edge and then turned
/// outward (the solid they bound has a positive volume). Turned outward,
/// the faces toward the light shade the shell's inside too: a point within
/// the solid, or within a closed room modelled as one, sees the light
/// through one of them.
pub(crate) fn closed_shells(triangles: &[[Vec3; 3]], edges: &Edges) -> Shells {
    let n = triangles.len();
    // Windings as made to agree (0: not reached yet), and the shells'.
    let mut winding = vec![0i8; n];
    let mut shells = Shells { winding: vec![0; n], shell: vec![u32::MAX; n] };
    let mut stack = Vec::new();
    let mut shell = Vec::new();
    for seed in 0..n {
        if winding[seed] != 0 {
            continue;
        }
        // The set joined to `seed` edge to edge, windings made to agree.
        winding[seed] = 1;
        stack.push(seed);
        shell.clear();
        let mut closed = true;
        while let Some(t) = stack.pop() {
            shell.push(t);
            for edge in 3 * t..3 * t + 3 {
                let Meeting::Pair(other, same) = edges.meets[edge] else {
                    closed = false;
                    continue;
                };
                let (other, agreeing) = (other as usize / 3, if same { -winding[t] } else { winding[t] });
                if winding[other] == 0 {
                    winding[other] = agreeing;
                    stack.push(other);
                } else if winding[other] != agreeing {
                    closed = false; // a one-sided surface (a twisted band)
                }
            }
        }
        // Six times the signed volume, about a corner of the shell (f64: a
        // thin slab far from the origin is still told apart).
        let origin = triangles[seed][0].as_dvec3();
        let volume: f64 = shell
            .iter()
            .map(|&t| {
                let [a, b, c] = triangles[t].map(|v| v.as_dvec3() - origin);
                f64::from(winding[t]) * a.dot(b.cross(c))
            })
            .sum();
        if closed {
            let outward = if volume < 0.0 { -1 } else { 1 };
            for &t in &shell {
                shells.winding[t] = winding[t] * outward;
                shells.shell[t] = seed as u32;
            }
        }
    }
    shells
}

/// [`closed_shells`] of a model's `triangles`, with the vertices of its
/// file each corner is (`vertices[t][k]`, equal numbers for one vertex):
/// shells are found by those too, so a solid that touches another along an
/// edge (a wall standing on a slab's edge: four faces meet there) is still
/// a shell. Returns the shells and the triangles' [`Edges::by_points`].
///
/// Where points close a shell (a file of faces that share no vertices)
/// that shell is kept; else the vertices' shells, which lie within one
/// set of triangles joined by points, never across two: each shell found
/// one way or the other is whole. The two ways are found side by side.
pub(crate) fn model_shells(triangles: &[[Vec3; 3]], vertices: &[[u32; 3]]) -> (Shells, Edges) {
    debug_assert_eq!(triangles.len(), vertices.len());
    let ((mut shells, by_points), by_vertices) = crate::parallel::par_join(
        None,
        || {
            let by_points = Edges::by_points(triangles);
            (closed_shells(triangles, &by_points), by_points)
        },
        || closed_shells(triangles, &Edges::between(triangles.len(), |corner| vertices[corner / 3][corner % 3])),
    );
    let numbered_apart = triangles.len() as u32;
    for t in 0..triangles.len() {
        if shells.winding[t] != 0 || by_vertices.winding[t] == 0 {
            continue;
        }
        shells.winding[t] = by_vertices.winding[t];
        shells.shell[t] = numbered_apart + by_vertices.shell[t];
    }
    (shells, by_points)
}

/// The solid angle triangle `t` fills seen from `eye`, positive where
/// `eye` lies behind its winding's face (van Oosterom and Strackee 1983).
pub(crate) fn signed_solid_angle(eye: DVec3, t: &[DVec3; 3]) -> f64 {
    let [a, b, c] = t.map(|v| (v - eye).normalize_or_zero());
    let det = a.dot(b.cross(c));
    let denominator = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * det.atan2(denominator)
}

/// How many times the outward-wound closed surface `faces` winds around
/// `point`: about 1 inside the solid it bounds, 0 outside.
pub(crate) fn winding_number(point: DVec3, faces: impl Iterator<Item = [DVec3; 3]>) -> f64 {
    faces.map(|t| signed_solid_angle(point, &t)).sum::<f64>() / (4.0 * std::f64::consts::PI)
}
