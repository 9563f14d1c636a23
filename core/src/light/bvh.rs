//! Ray casting over the scene's render triangles with obvhs (a compressed
//! wide BVH). obvhs speaks glam 0.34 while heliodon uses Bevy's glam 0.32:
//! this module is where the two meet, and nothing else sees obvhs types.

use std::time::Duration;

use glam::DVec3;
use glam_bvh::{UVec2, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;

use crate::scene::PatchMesh;

fn to_bvh(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
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
        let triangles: Vec<Triangle> = triangles
            .iter()
            .map(|t| Triangle { v0: to_bvh(t[0].as_dvec3()), v1: to_bvh(t[1].as_dvec3()), v2: to_bvh(t[2].as_dvec3()) })
            .collect();
        let bvh = build_cwbvh_from_tris(&triangles, BvhBuildParams::medium_build(), &mut Duration::default());
        let leaf_order = || bvh.primitive_indices.iter().map(|&k| k as usize);
        let owner = leaf_order().map(|k| owner[k]).collect();
        let triangles = leaf_order().map(|k| RtTriangle::from(&triangles[k])).collect();
        Self { bvh, triangles, owner }
    }

    /// The closest hit beyond `t_min` along a unit direction.
    pub fn closest(&self, origin: DVec3, direction: DVec3, t_min: f64) -> Option<Hit> {
        // obvhs picks the traversal octant from the sign bits: a −0.0 component
        // (from negating an axis) must become +0.0 or axis-aligned rays miss.
        let direction = direction + DVec3::ZERO;
        let ray = Ray::new(to_bvh(origin), to_bvh(direction), t_min as f32, f32::INFINITY);
        let mut hit = RayHit::none();
        self.bvh
            .ray_traverse(ray, &mut hit, |ray, id| self.triangles[id].intersect(ray))
            .then(|| Hit { patch: self.owner[hit.primitive_id as usize], distance: f64::from(hit.t) })
    }

    /// Every surface along a ray between `t_min` and `t_max`, in no
    /// particular order, until `visit` returns false: one traversal for
    /// shadow rays through glass, which stops at the first opaque surface.
    pub fn each_hit(&self, origin: DVec3, direction: DVec3, t_min: f64, t_max: f64, mut visit: impl FnMut(Hit) -> bool) {
        let direction = direction + DVec3::ZERO;
        let ray = Ray::new(to_bvh(origin), to_bvh(direction), t_min as f32, t_max as f32);
        let mut state = self.bvh.new_traversal(ray.direction);
        let mut node;
        'traversal: {
            obvhs::traverse!(self.bvh, node, state, node.intersect_ray(&ray, state.oct_inv4), {
                let triangle = state.primitive_id as usize;
                let t = self.triangles[triangle].intersect(&ray);
                if t < ray.tmax && !visit(Hit { patch: self.owner[triangle], distance: f64::from(t) }) {
                    break 'traversal;
                }
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Patch, PatchMesh};
    use glam::Vec3;

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
}
