//! Window groups: the one rule by which windows are grouped everywhere —
//! the light engine's panel groups, the sun pass's apertures, the viewer's
//! windows panel and `info`. A group is the windows of one material whose
//! **outward** normals agree. A window's outward side is the side from
//! which more sky is seen (ray-tested), not the side its polygon's normal
//! happens to point to: exported models wind their faces either way.

use glam::DVec3;

use super::bvh::Tracer;
use super::sampling::{Rng, cosine_directions};
use crate::scene::{Scene, Window};

/// Rays per hemisphere that decide which side of a window is outside.
const SIDE_RAYS: usize = 64;

/// Outward normals closer than this (1 − cos, about 0.003°) face one way.
const SAME_FACING: f64 = 1e-9;

/// Windows of one material that face one way.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowGroup {
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Unit normal toward the outside (the side that sees the sky).
    pub outward: DVec3,
    /// Indices into [`Scene::windows`].
    pub windows: Vec<u32>,
}

/// Every window's outward normal and group.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WindowGroups {
    /// In the order their first window appears in [`Scene::windows`].
    pub groups: Vec<WindowGroup>,
    /// Per window of [`Scene::windows`]: its group.
    pub group_of_window: Vec<u32>,
    /// Per window: its outward unit normal.
    pub outward: Vec<DVec3>,
}

impl WindowGroups {
    /// Groups `scene`'s windows, testing each window's sides with `tracer`.
    pub(super) fn new(scene: &Scene, tracer: &Tracer) -> Self {
        let mut out = Self::default();
        for (index, window) in scene.windows.iter().enumerate() {
            let outward = outward_normal(tracer, window);
            let same = |g: &WindowGroup| g.material == window.material && g.outward.dot(outward) > 1.0 - SAME_FACING;
            let group = match out.groups.iter().position(same) {
                Some(group) => group,
                None => {
                    out.groups.push(WindowGroup { material: window.material, outward, windows: Vec::new() });
                    out.groups.len() - 1
                }
            };
            out.groups[group].windows.push(index as u32);
            out.group_of_window.push(group as u32);
            out.outward.push(outward);
        }
        out
    }
}

/// The normal of `window` turned toward the outside: the side from which
/// more of the sky is seen (on a tie, against the polygon's normal).
fn outward_normal(tracer: &Tracer, window: &Window) -> DVec3 {
    let normal = window.normal.as_dvec3();
    let centre = window.centroid.as_dvec3();
    let mut rng = Rng::new(5, u64::from(window.surface));
    let open = |side: DVec3, rng: &mut Rng| {
        cosine_directions(side, SIDE_RAYS, rng).into_iter().filter(|&d| tracer.closest(centre + side * 1e-3, d, 1e-6).is_none()).count()
    };
    let along = open(normal, &mut rng);
    let against = open(-normal, &mut rng);
    if along > against { normal } else { -normal }
}
