//! Where the sun can come in: a cheap, conservative test that spares shadow
//! rays from sides the sun cannot reach.
//!
//! A patch side whose gather rays all met windows or patches (none left
//! straight to the open sky) is *enclosed*: sunlight reaches it only
//! through a window. The sun itself passes glass windows only, a panel lobe
//! only the windows of its panel group ([`super::sun`]). So a point of an
//! enclosed side can be sunlit only when its ray toward a beam crosses the
//! bounding box of such a window; a side only when the ray from its centre,
//! widened by the patch's radius, does. Everything that passes is traced as
//! before, so the test changes no lit sample, and an open side is always
//! traced. What it cannot see: a side whose gather missed a gap to the open
//! sky narrower than its rays' spacing (1 of `rays_per_patch`) is treated as
//! enclosed, and sun through that gap alone is lost.

use glam::DVec3;

use super::SunBeam;
use crate::scene::Scene;

/// Widening of every box, metres: rays along a window's plane and points on
/// its frame stay inside.
const MARGIN: f64 = 1e-3;

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
                let range = scene.surfaces[window.surface as usize].triangles.clone();
                let corners = scene.triangles[range.start as usize..range.end as usize].iter().flat_map(|t| t.vertices);
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
                let triangles = &scene.patches.triangles[patch.triangles.start as usize..patch.triangles.end as usize];
                let radius = triangles.iter().flatten().map(|v| v.as_dvec3().distance(centre)).fold(0.0, f64::max);
                (centre, radius)
            })
            .collect();
        Self { windows, spheres }
    }

    /// How beams may reach an enclosed patch: the (beam, window) pairs
    /// whose ray from the patch's centre, widened by its radius, crosses the
    /// window; empty when none can.
    pub(super) fn ways_in(&self, patch: usize, beams: &[SunBeam]) -> Vec<WayIn> {
        let (centre, radius) = self.spheres[patch];
        self.ways_into_sphere(centre, radius, beams)
    }

    /// [`Self::ways_in`] for any sphere (a sensor's points, say).
    pub(super) fn ways_into_sphere(&self, centre: DVec3, radius: f64, beams: &[SunBeam]) -> Vec<WayIn> {
        let mut ways = Vec::new();
        for (b, beam) in beams.iter().enumerate() {
            let ray = Ray::new(beam.to_light);
            for (w, ([min, max], group)) in self.windows.iter().enumerate() {
                if *group == beam.panel_group && ray.meets_box(centre, *min - radius, *max + radius) {
                    ways.push(WayIn { beam: b as u32, window: w as u32, ray });
                }
            }
        }
        ways
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
}
