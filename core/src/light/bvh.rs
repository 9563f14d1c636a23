//! Ray casting over the scene's render triangles with obvhs (a compressed
//! wide BVH). obvhs speaks glam 0.34 while heliodon uses Bevy's glam 0.32:
//! this module is where the two meet, and nothing else sees obvhs types.

use std::time::Duration;

use glam::DVec3;
use glam_bvh::{UVec2, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::node::{CwBvhNode, extract_byte64};
use obvhs::ray::{Ray, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;

use crate::scene::PatchMesh;

/// obvhs's traversal passes over a box the ray leaves within 0.1 mm of its
/// start (`CwBvhNode::intersect_ray` clamps the entry to 1e-4): a ray from
/// a patch's point that close to a wall meeting it went through the wall
/// (a ceiling's corner patch in a closed room saw the sky below the ground
/// beyond it). Rays start this far (m) behind their origin instead, and
/// count hits from the origin on.
const STEP_BACK: f64 = 2e-4;

fn to_bvh(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

fn bvh_triangles(triangles: &[[glam::Vec3; 3]]) -> Vec<Triangle> {
    triangles.iter().map(|t| Triangle { v0: to_bvh(t[0].as_dvec3()), v1: to_bvh(t[1].as_dvec3()), v2: to_bvh(t[2].as_dvec3()) }).collect()
}

/// The closest surface along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// The patch owning the triangle hit (or the owner the tracer was built with).
    pub patch: u32,
    pub distance: f64,
}

/// A BVH over a patch mesh's render triangles.
pub struct Tracer {
    bvh: CwBvh,
    /// The triangles in the BVH's leaf order (`bvh.primitive_indices`),
    /// edges and normal ready for intersection (the same arithmetic as
    /// [`Triangle::intersect`], with no lookup through the index).
    triangles: Vec<RtTriangle>,
    /// Each of them's owner, in that order.
    owner: Vec<u32>,
}

impl Tracer {
    pub fn new(mesh: &PatchMesh) -> Self {
        Self::over(&mesh.triangles, mesh.triangle_patches())
    }

    /// A BVH over any triangles, each hit naming `owner[triangle]` as its
    /// [`Hit::patch`] (a surface, say).
    pub fn over(triangles: &[[glam::Vec3; 3]], owner: Vec<u32>) -> Self {
        let triangles = bvh_triangles(triangles);
        // obvhs' fast build: a cold few-sensor run on a large model spends
        // more on building the two BVHs than on the rays that the medium
        // build's tighter tree would save (the furnished floor with 48
        // sensors: about 5% faster, the same readings).
        let bvh = build_cwbvh_from_tris(&triangles, BvhBuildParams::fast_build(), &mut Duration::default());
        Self::with_bvh(bvh, &triangles, &owner)
    }

    fn with_bvh(bvh: CwBvh, triangles: &[Triangle], owner: &[u32]) -> Self {
        let leaf_order = || bvh.primitive_indices.iter().map(|&k| k as usize);
        let owner = leaf_order().map(|k| owner[k]).collect();
        let triangles = leaf_order().map(|k| RtTriangle::from(&triangles[k])).collect();
        Self { bvh, triangles, owner }
    }

    /// The BVH as bytes for the cache: its nodes, leaf order and bounds,
    /// little-endian (the triangles and their owners are the scene's, given
    /// again to [`Self::from_bytes`]). Building it was most of a warm start
    /// on a large model: 0.2 s of the furnished floor's 0.37 s.
    pub(crate) fn to_bytes(&self) -> Vec<u8> {
        let bvh = &self.bvh;
        let mut out = Vec::with_capacity(8 + size_of_val(bvh.nodes.as_slice()) + 4 * bvh.primitive_indices.len() + 24);
        out.extend_from_slice(&(bvh.nodes.len() as u32).to_le_bytes());
        for node in &bvh.nodes {
            // A node's fields are 4-byte words and bytes: each word little-endian.
            out.extend(bytemuck::cast_slice::<_, u32>(std::slice::from_ref(node)).iter().flat_map(|w| w.to_le_bytes()));
        }
        out.extend_from_slice(&(bvh.primitive_indices.len() as u32).to_le_bytes());
        out.extend(bvh.primitive_indices.iter().flat_map(|k| k.to_le_bytes()));
        let corners = bvh.total_aabb.min.to_array().into_iter().chain(bvh.total_aabb.max.to_array());
        out.extend(corners.flat_map(f32::to_le_bytes));
        out
    }

    /// The tracer [`Self::to_bytes`] stored, over the same `triangles` and
    /// `owner` as it was built on; `None` when the bytes do not fit them.
    pub(crate) fn from_bytes(bytes: &[u8], triangles: &[[glam::Vec3; 3]], owner: &[u32]) -> Option<Self> {
        if !bytes.len().is_multiple_of(4) {
            return None;
        }
        let mut words = bytes.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes")));
        let node_words = size_of::<CwBvhNode>() / 4;
        let node_count = words.next()? as usize;
        if node_count.checked_mul(node_words)? > bytes.len() / 4 {
            return None;
        }
        let node_data: Vec<u32> = words.by_ref().take(node_count * node_words).collect();
        let nodes: Vec<CwBvhNode> = bytemuck::pod_collect_to_vec(&node_data);
        // Without spatial splits, the leaves hold each triangle once.
        if words.next()? as usize != triangles.len() || owner.len() != triangles.len() {
            return None;
        }
        let primitive_indices = words.by_ref().take(triangles.len()).filter(|&k| (k as usize) < triangles.len()).collect::<Vec<_>>();
        let corners: Vec<f32> = words.map(f32::from_bits).collect();
        if nodes.len() != node_count || primitive_indices.len() != triangles.len() || corners.len() != 6 {
            return None;
        }
        let total_aabb = Aabb { min: Vec3A::from_slice(&corners[..3]), max: Vec3A::from_slice(&corners[3..]) };
        let bvh = CwBvh { nodes, primitive_indices, total_aabb, exact_node_aabbs: None, uses_spatial_splits: false };
        Some(Self::with_bvh(bvh, &bvh_triangles(triangles), owner))
    }

    /// The closest hit beyond `t_min` along a unit direction.
    pub fn closest(&self, origin: DVec3, direction: DVec3, t_min: f64) -> Option<Hit> {
        // obvhs picks the traversal octant from the sign bits: a −0.0 component
        // (from negating an axis) must become +0.0 or axis-aligned rays miss.
        let direction = direction + DVec3::ZERO;
        let ray = Ray::new(to_bvh(origin - direction * STEP_BACK), to_bvh(direction), (t_min + STEP_BACK) as f32, f32::INFINITY);
        let mut hit = RayHit::none();
        self.bvh
            .ray_traverse(ray, &mut hit, |ray, id| self.triangles[id].intersect(ray))
            .then(|| Hit { patch: self.owner[hit.primitive_id as usize], distance: f64::from(hit.t) - STEP_BACK })
    }

    /// Every surface along a ray between `t_min` and `t_max`, in no
    /// particular order, until `visit` returns false: one traversal for
    /// shadow rays through glass, which stops at the first opaque surface.
    pub fn each_hit(&self, origin: DVec3, direction: DVec3, t_min: f64, t_max: f64, mut visit: impl FnMut(Hit) -> bool) {
        let direction = direction + DVec3::ZERO;
        let ray =
            Ray::new(to_bvh(origin - direction * STEP_BACK), to_bvh(direction), (t_min + STEP_BACK) as f32, (t_max + STEP_BACK) as f32);
        let mut state = self.bvh.new_traversal(ray.direction);
        let mut node;
        'traversal: {
            obvhs::traverse!(self.bvh, node, state, node.intersect_ray(&ray, state.oct_inv4), {
                let triangle = state.primitive_id as usize;
                let t = self.triangles[triangle].intersect(&ray);
                if t < ray.tmax && !visit(Hit { patch: self.owner[triangle], distance: f64::from(t) - STEP_BACK }) {
                    break 'traversal;
                }
            });
        }
    }

    /// The triangles a ray along the unit `direction` from any point of the
    /// box `lo..hi` may meet, at most `limit` (`None` when more), ready for
    /// such rays ([`ParallelHits`]): one traversal for the box's many
    /// parallel rays. A ray from `p` meets a box where the box's centre ray
    /// meets that box moved by `centre − p`, so within it grown by the
    /// half-size: the centre ray against grown child boxes misses nothing
    /// any such ray meets.
    pub fn parallel_hits(&self, lo: DVec3, hi: DVec3, direction: DVec3, limit: usize) -> Option<ParallelHits> {
        let direction = direction + DVec3::ZERO;
        let centre = (lo + hi) * 0.5;
        let centre_ray = Ray::new(to_bvh(centre), to_bvh(direction), 0.0, f32::INFINITY);
        // The grid of the compressed child boxes already rounds outward; the
        // margin covers the centre's own rounding to f32.
        let grow = to_bvh((hi - lo) * 0.5) + Vec3A::splat(1e-4);
        let mut triangles = Vec::with_capacity(limit.min(64));
        let mut state = self.bvh.new_traversal(centre_ray.direction);
        let mut node;
        obvhs::traverse!(self.bvh, node, state, grown_child_hits(node, &centre_ray, grow, state.oct_inv4), {
            let k = state.primitive_id as usize;
            if let Some(triangle) = ParallelTriangle::new(&self.triangles[k], self.owner[k], centre, direction) {
                if triangles.len() == limit {
                    return None;
                }
                triangles.push(triangle);
            }
        });
        Some(ParallelHits { centre, triangles: triangles.into_boxed_slice() })
    }
}

/// Triangles as rays of one direction from near a centre meet them. Such a
/// ray's barycentric coordinates and distance at a triangle are affine in
/// its origin (Möller–Trumbore with the direction fixed), so each costs
/// three dot products: no traversal, no cross product.
#[derive(Debug, Clone, PartialEq)]
pub struct ParallelHits {
    centre: DVec3,
    triangles: Box<[ParallelTriangle]>,
}

/// A triangle's (u, v, t) for a ray from `centre + offset`: each row's
/// dot with the offset plus its constant.
#[derive(Debug, Clone, PartialEq)]
struct ParallelTriangle {
    owner: u32,
    rows: [(DVec3, f64); 3],
}

impl ParallelTriangle {
    /// `None` for a triangle the direction runs along (no ray meets it).
    fn new(triangle: &RtTriangle, owner: u32, centre: DVec3, direction: DVec3) -> Option<Self> {
        let v0 = DVec3::new(triangle.v0.x.into(), triangle.v0.y.into(), triangle.v0.z.into());
        // RtTriangle keeps e1 = v0 − v1 and e2 = v2 − v0.
        let a = -DVec3::new(triangle.e1.x.into(), triangle.e1.y.into(), triangle.e1.z.into());
        let b = DVec3::new(triangle.e2.x.into(), triangle.e2.y.into(), triangle.e2.z.into());
        let det = a.dot(direction.cross(b));
        if det == 0.0 {
            return None;
        }
        // With s = origin − v0: u = s·(d × b)/det, v = s·(a × d)/det, t = s·(a × b)/det.
        let row = |axis: DVec3| {
            let axis = axis / det;
            (axis, (centre - v0).dot(axis))
        };
        Some(Self { owner, rows: [row(direction.cross(b)), row(a.cross(direction)), row(a.cross(b))] })
    }
}

impl ParallelHits {
    /// [`Tracer::each_hit`] for a ray from `origin` (in the box these were
    /// made for) along their direction: the same surfaces, in list order
    /// (in f64, where the BVH tests in f32: a ray grazing an edge within a
    /// few hundredths of a millimetre may differ).
    pub fn each_hit(&self, origin: DVec3, t_min: f64, t_max: f64, mut visit: impl FnMut(Hit) -> bool) {
        let offset = origin - self.centre;
        for triangle in &self.triangles {
            let [u, v, t] = triangle.rows.map(|(axis, constant)| offset.dot(axis) + constant);
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > t_min && t < t_max && !visit(Hit { patch: triangle.owner, distance: t }) {
                return;
            }
        }
    }
}

/// The children of `node` that `ray` meets beyond its origin, each grown by
/// `grow` per axis, as the traversal's hit mask (as
/// `CwBvhNode::intersect_ray_basic` builds it).
fn grown_child_hits(node: &CwBvhNode, ray: &Ray, grow: Vec3A, oct_inv4: u32) -> u32 {
    let (child_bits, bit_index) = node.get_child_and_index_bits(oct_inv4);
    let mut mask = 0;
    for child in (0..8).filter(|&c| !node.is_child_empty(c)) {
        let aabb = node.child_aabb(child);
        let near = (aabb.min - grow - ray.origin) * ray.inv_direction;
        let far = (aabb.max + grow - ray.origin) * ray.inv_direction;
        let (enter, exit) = (near.min(far).max_element().max(0.0), near.max(far).min_element());
        if enter <= exit {
            mask |= extract_byte64(child_bits, child) << extract_byte64(bit_index, child);
        }
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Patch, PatchMesh};
    use glam::Vec3;

    /// A ray from a point a hundredth of a millimetre from a wall, toward
    /// it, meets it (obvhs's traversal alone passed over the wall's box: a
    /// ceiling's corner patch saw through the wall beside it).
    #[test]
    fn a_ray_from_a_hair_off_a_wall_meets_it() {
        let v = |y: f32, z: f32| Vec3::new(0.0, y, z);
        let wall = [[v(0.0, 0.0), v(6.0, 0.0), v(6.0, 3.0)], [v(0.0, 0.0), v(6.0, 3.0), v(0.0, 3.0)]];
        let tracer = Tracer::over(&wall, vec![7, 7]);
        let origin = DVec3::new(1.2e-5, 0.39, 2.9999);
        let direction = DVec3::new(-0.852, 0.392, -0.346).normalize();
        let hit = tracer.closest(origin, direction, 1e-6).expect("the wall");
        assert_eq!(hit.patch, 7);
        assert!((hit.distance - 1.2e-5 / direction.x.abs()).abs() < 1e-6, "{}", hit.distance);
        let mut met = Vec::new();
        tracer.each_hit(origin, direction, 1e-6, 1.0, |hit| {
            met.push(hit.patch);
            true
        });
        assert_eq!(met, [7]);
        // Nor does stepping back meet what lies behind the origin.
        assert!(tracer.closest(origin, -direction, 1e-6).is_none());
    }

    #[test]
    fn axis_aligned_rays_with_negative_zeros_hit() {
        let mesh = PatchMesh {
            patches: vec![Patch { surface: 0, material: 0, area: 1.0, normal: Vec3::Z, centroid: Vec3::ZERO, triangles: 0..2 }],
            triangles: vec![
                [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)],
                [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)],
            ],
            clusters: Vec::new(),
        };
        let tracer = Tracer::new(&mesh);
        for origin in [DVec3::new(0.0, 0.0, 0.5), DVec3::new(0.3, -0.2, 0.5)] {
            let hit = tracer.closest(origin, -DVec3::Z, 0.0).expect("straight down hits");
            assert!((hit.distance - 0.5).abs() < 1e-6);
        }
        assert!(tracer.closest(DVec3::new(0.0, 0.0, 0.5), DVec3::Z, 0.0).is_none());
    }

    /// `count` triangles, each with its centre drawn in the box `(lo, hi)`
    /// and its corners within `half` of it on each axis.
    fn random_triangles(
        random: &mut impl FnMut(f64, f64) -> f64,
        count: usize,
        (lo, hi): ([f64; 3], [f64; 3]),
        half: f64,
    ) -> Vec<[Vec3; 3]> {
        (0..count)
            .map(|_| {
                let centre = DVec3::new(random(lo[0], hi[0]), random(lo[1], hi[1]), random(lo[2], hi[2]));
                [0, 1, 2].map(|_| (centre + DVec3::new(random(-half, half), random(-half, half), random(-half, half))).as_vec3())
            })
            .collect()
    }

    /// Rays of one direction from anywhere in a box meet the same surfaces at
    /// the same distances whether they traverse the BVH or test the box's
    /// parallel hits: 400 random triangles, boxes from a point to 3 m wide,
    /// directions from grazing to straight up.
    #[test]
    fn parallel_hits_meet_what_the_bvh_meets() {
        use crate::light::sampling::Rng;
        let mut rng = Rng::new(11, 0);
        let mut random = |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
        let triangles = random_triangles(&mut random, 400, ([-10.0, -10.0, 0.0], [10.0; 3]), 2.0);
        let owner: Vec<u32> = (0..400).map(|k| k / 3).collect();
        let tracer = Tracer::over(&triangles, owner);
        let (mut rays, mut met) = (0, 0);
        for case in 0..60 {
            let half = [0.0, 0.05, 0.5, 1.5][case % 4];
            let centre = DVec3::new(random(-8.0, 8.0), random(-8.0, 8.0), random(0.0, 8.0));
            let (lo, hi) = (centre - DVec3::splat(half), centre + DVec3::splat(half));
            let direction = DVec3::new(random(-1.0, 1.0), random(-1.0, 1.0), random(0.02, 1.0)).normalize();
            let parallel = tracer.parallel_hits(lo, hi, direction, usize::MAX).expect("no limit");
            for _ in 0..20 {
                let origin = lo + (hi - lo) * DVec3::new(random(0.0, 1.0), random(0.0, 1.0), random(0.0, 1.0));
                let (mut by_bvh, mut by_parallel) = (Vec::new(), Vec::new());
                tracer.each_hit(origin, direction, 1e-6, f64::INFINITY, |hit| {
                    by_bvh.push((hit.patch, hit.distance));
                    true
                });
                parallel.each_hit(origin, 1e-6, f64::INFINITY, |hit| {
                    by_parallel.push((hit.patch, hit.distance));
                    true
                });
                for hits in [&mut by_bvh, &mut by_parallel] {
                    hits.sort_by(|a, b| a.1.total_cmp(&b.1));
                }
                assert_eq!(by_bvh.len(), by_parallel.len(), "case {case}: {by_bvh:?} vs {by_parallel:?}");
                for (a, b) in by_bvh.iter().zip(&by_parallel) {
                    assert!(a.0 == b.0 && (a.1 - b.1).abs() < 1e-4, "case {case}: {a:?} vs {b:?}");
                }
                rays += 1;
                met += by_bvh.len();
            }
        }
        // The rays meet something: the test compares hits, not empty lists.
        assert!(met > rays / 2, "{met} hits over {rays} rays");
        // A limit below the triangles a wide box may meet gives none.
        let wide = tracer.parallel_hits(DVec3::splat(-10.0), DVec3::splat(10.0), DVec3::Z, 10);
        assert!(wide.is_none());
    }

    /// The BVH read back from the cache meets what the built one meets, and
    /// is refused over other triangles or when cut short.
    #[test]
    fn a_tracer_read_back_meets_what_it_met() {
        use crate::light::sampling::Rng;
        let mut rng = Rng::new(12, 0);
        let mut random = |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
        let triangles = random_triangles(&mut random, 300, ([-5.0; 3], [5.0; 3]), 1.0);
        let owner: Vec<u32> = (0..300).map(|k| k / 2).collect();
        let built = Tracer::over(&triangles, owner.clone());
        let bytes = built.to_bytes();
        let read = Tracer::from_bytes(&bytes, &triangles, &owner).expect("reads back");
        let mut met = 0;
        for _ in 0..500 {
            let origin = DVec3::new(random(-6.0, 6.0), random(-6.0, 6.0), random(-6.0, 6.0));
            let direction = DVec3::new(random(-1.0, 1.0), random(-1.0, 1.0), random(-1.0, 1.0)).normalize();
            let hit = built.closest(origin, direction, 0.0);
            assert_eq!(read.closest(origin, direction, 0.0), hit);
            met += usize::from(hit.is_some());
        }
        assert!(met > 100, "{met} of 500 rays hit");
        assert!(Tracer::from_bytes(&bytes, &triangles[1..], &owner[1..]).is_none());
        assert!(Tracer::from_bytes(&bytes[..bytes.len() - 4], &triangles, &owner).is_none());
        assert!(Tracer::from_bytes(&bytes[..bytes.len() - 1], &triangles, &owner).is_none());
    }
}
