//! Surfaces: the model's triangles grouped into connected planar pieces of one
//! material (a wall, a desk top, a window pane), and the windows among them.

use glam::Vec3;

use super::material::Material;
use super::{Surface, Triangle, Window};

/// Positions closer than this (metres) are the same vertex when finding
/// shared edges.
const WELD: f32 = 1e-4;
/// Neighbouring triangles whose normals differ by less than about 1.5° lie in
/// one surface.
const COPLANAR_COS: f32 = 0.99966;

/// Groups triangles into surfaces; returns the triangles reordered so that
/// each surface's triangles are contiguous, and the surfaces (patch ranges
/// still empty). The order is deterministic: surfaces by their first triangle.
pub fn group(triangles: Vec<Triangle>) -> (Vec<Triangle>, Vec<Surface>) {
    let normals: Vec<Vec3> = triangles.iter().map(Triangle::normal).collect();
    let mut sets = DisjointSets::new(triangles.len());
    // The welded corners numbered, each edge the pair of its corners'
    // numbers beside its triangle, sorted: the triangles on one edge lie
    // together, in their order.
    let numbers = crate::parallel::number_alike(triangles.len() * 3, |corner| weld_key(triangles[corner / 3].vertices[corner % 3]));
    let mut edges: Vec<(u64, u32)> = Vec::with_capacity(triangles.len() * 3);
    for t in 0..triangles.len() {
        let corners: [u32; 3] = std::array::from_fn(|k| numbers[3 * t + k]);
        for (a, b) in [(corners[0], corners[1]), (corners[1], corners[2]), (corners[2], corners[0])] {
            edges.push(((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), t as u32));
        }
    }
    edges.sort_unstable();
    // Each triangle on an edge joins every earlier *representative* it
    // fits (same material, coplanar), or becomes one: near-linear even
    // when thousands of copies of a face share its edges.
    let mut representatives: Vec<u32> = Vec::new();
    for sharing in edges.chunk_by(|a, b| a.0 == b.0) {
        representatives.clear();
        for &(_, t) in sharing {
            let fits = |r: &u32| {
                triangles[*r as usize].material == triangles[t as usize].material
                    && normals[*r as usize].dot(normals[t as usize]) >= COPLANAR_COS
            };
            let mut joined = false;
            for &r in representatives.iter().filter(|r| fits(r)) {
                sets.union(r, t);
                joined = true;
            }
            if !joined {
                representatives.push(t);
            }
        }
    }
    // Surfaces numbered in the order of their first triangle.
    let mut surface_of_root = vec![u32::MAX; triangles.len()];
    let mut members: Vec<Vec<u32>> = Vec::new();
    for t in 0..triangles.len() as u32 {
        let root = sets.find(t) as usize;
        if surface_of_root[root] == u32::MAX {
            surface_of_root[root] = members.len() as u32;
            members.push(Vec::new());
        }
        members[surface_of_root[root] as usize].push(t);
    }
    let mut ordered = Vec::with_capacity(triangles.len());
    let mut surfaces = Vec::with_capacity(members.len());
    for group in members {
        let start = ordered.len() as u32;
        let mut weighted_normal = Vec3::ZERO;
        let mut area = 0.0;
        for &t in &group {
            let triangle = triangles[t as usize];
            weighted_normal += triangle.cross();
            area += triangle.area();
            ordered.push(triangle);
        }
        surfaces.push(Surface {
            material: triangles[group[0] as usize].material,
            triangles: start..ordered.len() as u32,
            patches: 0..0,
            normal: weighted_normal.normalize_or_zero(),
            area,
        });
    }
    (ordered, surfaces)
}

/// The surfaces of transmitting materials, as apertures.
pub fn windows(triangles: &[Triangle], surfaces: &[Surface], materials: &[Material]) -> Vec<Window> {
    surfaces
        .iter()
        .enumerate()
        .filter(|(_, s)| materials[s.material as usize].kind.transmits())
        .map(|(index, surface)| {
            let centroid = surface.centroid(triangles);
            Window { surface: index as u32, material: surface.material, area: surface.area, normal: surface.normal, centroid }
        })
        .collect()
}

fn weld_key(p: Vec3) -> [i64; 3] {
    (p / WELD).round().as_i64vec3().to_array()
}

/// Union-find with path halving.
struct DisjointSets {
    parent: Vec<u32>,
}

impl DisjointSets {
    fn new(n: usize) -> Self {
        Self { parent: (0..n as u32).collect() }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grandparent = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grandparent;
            x = grandparent;
        }
        x
    }

    /// Joins two sets; the smaller root becomes the root, so roots (and with
    /// them the surface order) do not depend on the order of unions.
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi as usize] = lo;
        }
    }
}
