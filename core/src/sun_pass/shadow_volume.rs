//! Shadow volumes for a directional light, as triangle lists of homogeneous
//! points (w = 0 for points at infinity), for the depth-fail stencil test.
//! Plain geometry, no Bevy types.
//!
//! Each caster triangle, turned to face the light, bounds the volume of
//! space it shades: its own face (the near cap) and one side triangle per
//! edge, reaching the point at infinity away from the light (for a
//! directional light the far cap shrinks to that point). Where two casters
//! share an edge with opposite directions, as in a manifold mesh, their side
//! triangles coincide with opposite windings and cancel: both are left out,
//! so only silhouette and open edges get sides. Elsewhere (open meshes,
//! T-junctions, duplicated faces) every triangle keeps its own closed volume,
//! so the stencil count stays exact whatever the model's quality.

use std::collections::HashMap;

use glam::{Vec3, Vec4};

/// Triangles whose normal is this close to perpendicular to the light cast
/// no volume (their shadow has no area).
const EDGE_ON: f32 = 1e-6;

/// A closed shadow volume as triangles: the casters' faces (near caps) and
/// the sides from their silhouette and open edges to infinity.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShadowVolume {
    /// The casters' own faces, turned to face the light (the near caps).
    pub caps: Vec<Vec4>,
    /// One triangle per silhouette or open edge: its two ends and the point
    /// at infinity away from the light (w = 0).
    pub sides: Vec<Vec4>,
}

/// The volume shaded by `casters` from light arriving along `-to_light`
/// (`to_light` is the unit vector toward the light). A caster's lit face is
/// its volume's near cap: the stencil pass biases the caps, and only them,
/// away from the camera so that face counts as outside; biased sides would
/// move the shadow's edges.
pub fn shadow_volume(casters: &[[Vec3; 3]], to_light: Vec3) -> ShadowVolume {
    let infinity = (-to_light).extend(0.0);
    let mut oriented: Vec<[Vec3; 3]> = Vec::with_capacity(casters.len());
    for &[a, b, c] in casters {
        let normal = (b - a).cross(c - a);
        let facing = normal.dot(to_light);
        if facing.abs() <= EDGE_ON * normal.length() {
            continue;
        }
        oriented.push(if facing > 0.0 { [a, b, c] } else { [a, c, b] });
    }
    // Directed edges by their end points; an edge meeting its reverse cancels.
    let key = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut open_edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    for t in &oriented {
        for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let reverse = (key(q), key(p));
            match open_edges.get_mut(&reverse) {
                Some(count) if *count > 0 => *count -= 1,
                _ => *open_edges.entry((key(p), key(q))).or_default() += 1,
            }
        }
    }
    let caps = oriented.iter().flat_map(|t| t.map(|v| v.extend(1.0))).collect();
    let mut sides = Vec::with_capacity(oriented.len() * 3);
    for t in &oriented {
        for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if let Some(count) = open_edges.get_mut(&(key(p), key(q)))
                && *count > 0
            {
                *count -= 1;
                sides.extend([q.extend(1.0), p.extend(1.0), infinity]);
            }
        }
    }
    ShadowVolume { caps, sides }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let volume = shadow_volume(&cube(), light);
        assert!(is_closed(&volume));
        // Faces turned to the light: all 12 triangles (back faces flipped);
        // each of the two shells keeps only its 6 silhouette edges.
        assert_eq!((volume.caps.len() / 3, volume.sides.len() / 3), (12, 12));
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
        let volume = shadow_volume(&casters, Vec3::new(0.2, 0.1, 1.0).normalize());
        assert!(is_closed(&volume));
    }

    #[test]
    fn edge_on_casters_cast_nothing() {
        let wall = [[Vec3::ZERO, Vec3::X, Vec3::Z]];
        assert_eq!(shadow_volume(&wall, Vec3::Y).caps.len(), 3);
        assert_eq!(shadow_volume(&wall, Vec3::Z), ShadowVolume::default(), "a wall edge-on to the light casts nothing");
        let floor = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
        let volume = shadow_volume(&floor, Vec3::Z);
        assert!(volume.caps.iter().all(|v| v.z == 0.0 && v.w == 1.0));
        assert!(volume.sides.chunks(3).all(|t| t[2] == Vec4::new(0., 0., -1., 0.)));
    }
}
