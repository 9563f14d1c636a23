//! The planes along which a surface's patches are cut, because the light
//! may step there: a window's plane through the reveals, sills and frames
//! around it ([`super::patches`]), and the face of another surface that
//! meets this one ([`super::contacts`]).

use glam::Vec3;

use super::Triangle;

/// Surfaces come this near a window (m) for its plane to cut them: the
/// frame and the wall opening around the glass.
const NEAR_WINDOW: f32 = 0.3;
/// Points this near a cutting plane (m) lie in it: a surface must reach
/// further to both sides to be cut.
pub(crate) const IN_PLANE: f32 = 2e-3;

/// A plane along which the light on a surface may step, so patches are
/// cut there: a window's plane (see the module's docs) or the face of
/// another surface that meets this one ([`super::contacts`]). It cuts only
/// within its `near` box, so a table leg does not cut a floor across the
/// room.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutPlane {
    pub(crate) normal: Vec3,
    pub(crate) offset: f32,
    /// Where it cuts: pieces whose box meets this one.
    pub(crate) near: (Vec3, Vec3),
}

impl CutPlane {
    /// The plane of a window made of `triangles`, with unit `normal`,
    /// cutting within [`NEAR_WINDOW`] of it.
    pub fn around_window(normal: Vec3, triangles: &[Triangle]) -> Self {
        let (lo, hi) = super::bounds(triangles);
        let points = triangles.iter().flat_map(|t| t.vertices);
        let count = (3 * triangles.len()).max(1) as f32;
        let offset = points.map(|p| p.dot(normal)).sum::<f32>() / count;
        CutPlane { normal, offset, near: (lo - Vec3::splat(NEAR_WINDOW), hi + Vec3::splat(NEAR_WINDOW)) }
    }

    pub(super) fn height(&self, p: Vec3) -> f32 {
        p.dot(self.normal) - self.offset
    }

    /// Whether the box (lo, hi) meets the plane's `near` box.
    pub(super) fn is_near(&self, (lo, hi): (Vec3, Vec3)) -> bool {
        lo.cmple(self.near.1).all() && hi.cmpge(self.near.0).all()
    }

    /// Whether `tris`, lying in the box `bounds`, pass through the plane
    /// where it cuts.
    pub(super) fn cuts(&self, tris: &[Triangle], bounds: (Vec3, Vec3)) -> bool {
        let heights = || tris.iter().flat_map(|t| t.vertices).map(|p| self.height(p));
        self.is_near(bounds) && heights().any(|h| h > IN_PLANE) && heights().any(|h| h < -IN_PLANE)
    }
}
