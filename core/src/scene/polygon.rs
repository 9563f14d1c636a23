//! Triangulating the model's polygons. A convex face is fanned from its first
//! vertex (as before, so convex models keep their triangles); any other face
//! is ear-clipped in its own plane, where a fan would overlap itself (a 3 m²
//! L-shaped window fanned wrongly covers 4 m²). Faces that return through
//! repeated vertices ("keyholes", how exporters write a wall with a hole) are
//! split into their loops: the largest is the outline, the others holes,
//! bridged into it before clipping, as Radiance and the even-odd rule read
//! them.

use glam::{DVec2, DVec3, Vec3};

/// Below this (twice the area, in the polygon's units squared) a corner is
/// straight or a triangle empty.
const FLAT: f64 = 1e-12;

/// Triangles of the face `points` (index triples in its own winding).
pub fn triangulate(points: &[Vec3]) -> Vec<[usize; 3]> {
    match points.len() {
        0..=2 => return Vec::new(),
        3 => return vec![[0, 1, 2]], // degenerate or not, the caller judges
        _ => {}
    }
    let normal = newell(points);
    // Project onto the plane most facing the normal, counter-clockwise.
    let axis = normal.abs().max_position();
    let (u, v) = [(1, 2), (2, 0), (0, 1)][axis];
    let flip = normal[axis] < 0.0;
    let flat: Vec<DVec2> = points
        .iter()
        .map(|p| {
            let p = p.as_dvec3();
            DVec2::new(p[u], if flip { -p[v] } else { p[v] })
        })
        .collect();
    if is_convex(&flat) {
        return (1..points.len() - 1).map(|k| [0, k, k + 1]).collect();
    }
    let mut loops = split_loops(&flat);
    loops.retain(|l| l.len() >= 3 && signed_area(&flat, l).abs() > FLAT);
    if loops.is_empty() {
        return Vec::new();
    }
    loops.sort_by(|a, b| signed_area(&flat, b).abs().total_cmp(&signed_area(&flat, a).abs()));
    let mut ring = loops[0].clone();
    if signed_area(&flat, &ring) < 0.0 {
        ring.reverse();
    }
    let mut holes: Vec<Vec<usize>> = loops[1..].to_vec();
    holes.sort_by(|a, b| rightmost(&flat, b).1.total_cmp(&rightmost(&flat, a).1));
    for mut hole in holes {
        if signed_area(&flat, &hole) > 0.0 {
            hole.reverse();
        }
        ring = bridge(&flat, ring, &hole);
    }
    let mut triangles = clip_ears(&flat, ring);
    // Back to the face's own winding when the outline ran clockwise.
    let area = |t: &[usize; 3]| cross(flat[t[0]], flat[t[1]], flat[t[2]]);
    if signed_area(&flat, &loops[0]) < 0.0 {
        triangles.iter_mut().filter(|t| area(t) > 0.0).for_each(|t| t.swap(1, 2));
    }
    triangles
}

fn newell(points: &[Vec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for (i, p) in points.iter().enumerate() {
        let (p, q) = (p.as_dvec3(), points[(i + 1) % points.len()].as_dvec3());
        n += DVec3::new((p.y - q.y) * (p.z + q.z), (p.z - q.z) * (p.x + q.x), (p.x - q.x) * (p.y + q.y));
    }
    n
}

fn cross(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

fn signed_area(flat: &[DVec2], ring: &[usize]) -> f64 {
    0.5 * (0..ring.len()).map(|k| flat[ring[k]].perp_dot(flat[ring[(k + 1) % ring.len()]])).sum::<f64>()
}

/// Convex, counter-clockwise, no vertex repeated: every corner turns left or runs straight.
fn is_convex(flat: &[DVec2]) -> bool {
    let n = flat.len();
    let distinct = (0..n).all(|i| (i + 1..n).all(|j| flat[i] != flat[j]));
    distinct && (0..n).all(|k| cross(flat[k], flat[(k + 1) % n], flat[(k + 2) % n]) >= -FLAT)
}

/// The loops of a face that returns through repeated vertices.
fn split_loops(flat: &[DVec2]) -> Vec<Vec<usize>> {
    let (mut loops, mut path): (Vec<Vec<usize>>, Vec<usize>) = (Vec::new(), Vec::new());
    for (i, p) in flat.iter().enumerate() {
        match path.iter().position(|&j| flat[j] == *p) {
            Some(at) => {
                loops.push(path.split_off(at));
                path.push(loops.last().expect("just pushed")[0]);
            }
            None => path.push(i),
        }
    }
    loops.push(path);
    loops
}

fn rightmost(flat: &[DVec2], ring: &[usize]) -> (usize, f64) {
    ring.iter().enumerate().map(|(k, &i)| (k, flat[i].x)).fold((0, f64::MIN), |best, c| if c.1 > best.1 { c } else { best })
}

/// Whether segments ab and cd cross inside both.
fn crosses(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (d1, d2, d3, d4) = (cross(c, d, a), cross(c, d, b), cross(a, b, c), cross(a, b, d));
    ((d1 > FLAT && d2 < -FLAT) || (d1 < -FLAT && d2 > FLAT)) && ((d3 > FLAT && d4 < -FLAT) || (d3 < -FLAT && d4 > FLAT))
}

/// The outline with a hole joined to it by a seam from the hole's rightmost
/// vertex to the nearest outline vertex it sees.
fn bridge(flat: &[DVec2], ring: Vec<usize>, hole: &[usize]) -> Vec<usize> {
    let (start, _) = rightmost(flat, hole);
    let h = hole[start];
    let edges: Vec<(usize, usize)> = (0..ring.len())
        .map(|k| (ring[k], ring[(k + 1) % ring.len()]))
        .chain((0..hole.len()).map(|k| (hole[k], hole[(k + 1) % hole.len()])))
        .collect();
    let mut order: Vec<usize> = (0..ring.len()).collect();
    order.sort_by(|&a, &b| flat[ring[a]].distance_squared(flat[h]).total_cmp(&flat[ring[b]].distance_squared(flat[h])));
    let visible = order.into_iter().find(|&k| {
        let o = ring[k];
        !edges.iter().any(|&(e0, e1)| ![e0, e1].contains(&o) && ![e0, e1].contains(&h) && crosses(flat[h], flat[o], flat[e0], flat[e1]))
    });
    let Some(k) = visible else { return ring };
    let mut joined = ring[..=k].to_vec();
    joined.extend(hole[start..].iter().chain(&hole[..start]).copied());
    joined.push(h);
    joined.extend(&ring[k..]);
    joined
}

/// Ear clipping of a counter-clockwise ring (repeated points allowed).
fn clip_ears(flat: &[DVec2], mut ring: Vec<usize>) -> Vec<[usize; 3]> {
    // Inside or on the border: a vertex on an ear's edge also blocks it.
    let inside = |p: DVec2, a: DVec2, b: DVec2, c: DVec2| cross(a, b, p) >= -FLAT && cross(b, c, p) >= -FLAT && cross(c, a, p) >= -FLAT;
    let mut out = Vec::new();
    while ring.len() > 3 {
        let n = ring.len();
        let ear = (0..n).find_map(|k| {
            let (i0, i1, i2) = (ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]);
            let (a, b, c) = (flat[i0], flat[i1], flat[i2]);
            let turn = cross(a, b, c);
            if turn.abs() <= FLAT && (b == a || b == c || (b - a).dot(c - b) >= 0.0) {
                return Some((k, None)); // a repeated or straight-through corner: drop it
            }
            let empty = ring.iter().all(|&j| {
                let p = flat[j];
                p == a || p == b || p == c || !inside(p, a, b, c)
            });
            (turn > FLAT && empty).then_some((k, Some([i0, i1, i2])))
        });
        let Some((k, triangle)) = ear else { break };
        out.extend(triangle);
        ring.remove(k);
    }
    if ring.len() == 3 && cross(flat[ring[0]], flat[ring[1]], flat[ring[2]]) > FLAT {
        out.push([ring[0], ring[1], ring[2]]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(points: &[Vec3], triangles: &[[usize; 3]]) -> f32 {
        triangles.iter().map(|t| 0.5 * (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).length()).sum()
    }

    fn winding_kept(points: &[Vec3], triangles: &[[usize; 3]]) -> bool {
        let n = newell(points).as_vec3();
        triangles.iter().all(|t| (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).dot(n) > 0.0)
    }

    #[test]
    fn convex_faces_are_fanned_as_before() {
        let quad = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        assert_eq!(triangulate(&quad), vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn a_concave_face_is_clipped_not_fanned() {
        // An L of 3 m² in a wall (x, z); a fan from its first vertex covers 4 m².
        let l: Vec<Vec3> =
            [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)].iter().map(|&(x, z)| Vec3::new(x, 0.0, z)).collect();
        for points in [l.clone(), l.iter().rev().copied().collect()] {
            let triangles = triangulate(&points);
            assert_eq!(triangles.len(), 4, "{triangles:?} {:?}", area(&points, &triangles));
            assert!((area(&points, &triangles) - 3.0).abs() < 1e-5, "{}", area(&points, &triangles));
            assert!(winding_kept(&points, &triangles));
        }
    }

    #[test]
    fn a_keyhole_face_keeps_its_hole() {
        // The Radiance tutorial room's south wall: 6.45 × 3.06 m with a
        // 6.10 × 1.52 m window, written as one polygon with a seam.
        let wall: Vec<Vec3> = [
            (-0.178262, 3.055937),
            (0.0, 2.4384),
            (0.0, 0.9144),
            (6.096, 0.9144),
            (6.096, 2.4384),
            (0.0, 2.4384),
            (-0.178262, 3.055937),
            (-0.178262, 0.0),
            (6.274262, 0.0),
            (6.274262, 3.055937),
        ]
        .iter()
        .map(|&(x, z)| Vec3::new(x, -0.178262, z))
        .collect();
        let triangles = triangulate(&wall);
        let expected = 6.452524 * 3.055937 - 6.096 * 1.524;
        assert!((area(&wall, &triangles) - expected).abs() < 1e-3, "{} vs {expected}", area(&wall, &triangles));
        assert!(winding_kept(&wall, &triangles));
        // Nothing covers the window.
        let inside_window = Vec3::new(3.0, -0.178262, 1.7);
        for t in &triangles {
            let [a, b, c] = t.map(|i| wall[i]);
            let side = |p: Vec3, q: Vec3| (q - p).cross(inside_window - p).y;
            let (s0, s1, s2) = (side(a, b), side(b, c), side(c, a));
            assert!(!((s0 > 0.0 && s1 > 0.0 && s2 > 0.0) || (s0 < 0.0 && s1 < 0.0 && s2 < 0.0)), "{t:?} covers the window");
        }
    }
}
