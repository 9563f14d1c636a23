//! The patch mesh for lighting: each surface cut along a square grid of
//! `patch_size` laid in its plane. A patch is one grid cell's part of the
//! surface; the pieces of triangles inside the cell are its render
//! triangles. Triangles smaller than a cell are not cut: they join the cell
//! that holds their centroid.

use std::collections::BTreeMap;
use std::ops::Range;

use glam::Vec3;

use super::{Surface, Triangle};

/// One lighting patch.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// Index into [`super::Scene::surfaces`].
    pub surface: u32,
    /// Index into [`super::Scene::materials`]: the surface's.
    pub material: u32,
    /// Sum of its render triangles' areas, m².
    pub area: f32,
    /// The surface's normal.
    pub normal: Vec3,
    /// Area-weighted centroid of the patch's render triangles.
    pub centroid: Vec3,
    /// Range into [`PatchMesh::triangles`].
    pub triangles: Range<u32>,
}

/// Patches and the render triangles they cover.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PatchMesh {
    /// Ordered by surface: each [`super::Surface::patches`] range indexes here.
    pub patches: Vec<Patch>,
    /// Render triangles in the canonical frame, ordered by patch, with the
    /// winding of the model triangle they came from.
    pub triangles: Vec<[Vec3; 3]>,
}

impl PatchMesh {
    /// The patch each render triangle belongs to.
    pub fn triangle_patches(&self) -> Vec<u32> {
        let mut owner = vec![0; self.triangles.len()];
        for (p, patch) in self.patches.iter().enumerate() {
            owner[patch.triangles.start as usize..patch.triangles.end as usize].fill(p as u32);
        }
        owner
    }
}

/// Pieces smaller than this (m²) are rounding slivers of clipping.
const SLIVER_AREA: f32 = 1e-8;

/// Cuts every surface into patches no larger than `size` × `size` and sets
/// each surface's patch range.
pub fn subdivide(triangles: &[Triangle], surfaces: &mut [Surface], size: f32) -> PatchMesh {
    let mut mesh = PatchMesh::default();
    for (index, surface) in surfaces.iter_mut().enumerate() {
        let tris = &triangles[surface.triangles.start as usize..surface.triangles.end as usize];
        let (u, v) = plane_axes(surface.normal);
        let origin =
            tris.iter().flat_map(|t| t.vertices).fold((f32::INFINITY, f32::INFINITY), |(a, b), p| (a.min(p.dot(u)), b.min(p.dot(v))));
        let cell_of = |p: Vec3| (((p.dot(u) - origin.0) / size).floor() as i32, ((p.dot(v) - origin.1) / size).floor() as i32);
        let mut cells: BTreeMap<(i32, i32), Vec<[Vec3; 3]>> = BTreeMap::new();
        for triangle in tris {
            let [a, b, c] = triangle.vertices;
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            if longest <= size {
                cells.entry(cell_of(triangle.centroid())).or_default().push(triangle.vertices);
                continue;
            }
            let (lo, hi) =
                triangle.vertices.iter().map(|&p| cell_of(p)).fold(((i32::MAX, i32::MAX), (i32::MIN, i32::MIN)), |(lo, hi), (i, j)| {
                    ((lo.0.min(i), lo.1.min(j)), (hi.0.max(i), hi.1.max(j)))
                });
            for i in lo.0..=hi.0 {
                for j in lo.1..=hi.1 {
                    let u0 = origin.0 + i as f32 * size;
                    let v0 = origin.1 + j as f32 * size;
                    let mut polygon = triangle.vertices.to_vec();
                    for (axis, bound, keep_above) in [(u, u0, true), (u, u0 + size, false), (v, v0, true), (v, v0 + size, false)] {
                        polygon = clip(&polygon, axis, bound, keep_above);
                        if polygon.len() < 3 {
                            break;
                        }
                    }
                    let pieces = cells.entry((i, j)).or_default();
                    for k in 1..polygon.len().saturating_sub(1) {
                        let piece = [polygon[0], polygon[k], polygon[k + 1]];
                        if 0.5 * (piece[1] - piece[0]).cross(piece[2] - piece[0]).length() > SLIVER_AREA {
                            pieces.push(piece);
                        }
                    }
                }
            }
        }
        let first_patch = mesh.patches.len() as u32;
        for pieces in cells.into_values().filter(|p| !p.is_empty()) {
            let start = mesh.triangles.len() as u32;
            let mut area = 0.0;
            let mut moment = Vec3::ZERO;
            for piece in pieces {
                let a = 0.5 * (piece[1] - piece[0]).cross(piece[2] - piece[0]).length();
                area += a;
                moment += a * (piece[0] + piece[1] + piece[2]) / 3.0;
                mesh.triangles.push(piece);
            }
            mesh.patches.push(Patch {
                surface: index as u32,
                material: surface.material,
                area,
                normal: surface.normal,
                centroid: moment / area,
                triangles: start..mesh.triangles.len() as u32,
            });
        }
        surface.patches = first_patch..mesh.patches.len() as u32;
    }
    mesh
}

/// Two in-plane axes: horizontal and up-slope for walls, east and north for
/// floors and ceilings.
fn plane_axes(normal: Vec3) -> (Vec3, Vec3) {
    let u = if normal.z.abs() > 0.999 { Vec3::X } else { Vec3::Z.cross(normal).normalize() };
    (u, normal.cross(u).normalize())
}

/// Sutherland–Hodgman: the part of a convex polygon on one side of the plane
/// `p·axis = bound`.
pub(crate) fn clip(polygon: &[Vec3], axis: Vec3, bound: f32, keep_above: bool) -> Vec<Vec3> {
    let side = |p: Vec3| if keep_above { p.dot(axis) - bound } else { bound - p.dot(axis) };
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (k, &current) in polygon.iter().enumerate() {
        let next = polygon[(k + 1) % polygon.len()];
        let (dc, dn) = (side(current), side(next));
        if dc >= 0.0 {
            out.push(current);
        }
        if (dc >= 0.0) != (dn >= 0.0) {
            out.push(current + (next - current) * (dc / (dc - dn)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(w: f32, h: f32) -> Vec<Triangle> {
        // A w × h wall in the xz plane, facing -y (south).
        let (a, b, c, d) = (Vec3::ZERO, Vec3::new(w, 0.0, 0.0), Vec3::new(w, 0.0, h), Vec3::new(0.0, 0.0, h));
        vec![Triangle { vertices: [a, b, c], material: 0 }, Triangle { vertices: [a, c, d], material: 0 }]
    }

    fn surface_of(triangles: &[Triangle]) -> Surface {
        let cross: Vec3 = triangles.iter().map(Triangle::cross).sum();
        Surface {
            material: 0,
            triangles: 0..triangles.len() as u32,
            patches: 0..0,
            normal: cross.normalize(),
            area: triangles.iter().map(Triangle::area).sum(),
        }
    }

    #[test]
    fn a_wall_becomes_a_grid_of_square_patches_that_conserve_area() {
        let tris = quad(4.0, 3.0);
        let mut surfaces = vec![surface_of(&tris)];
        let mesh = subdivide(&tris, &mut surfaces, 0.5);
        assert_eq!(mesh.patches.len(), 8 * 6);
        assert_eq!(surfaces[0].patches, 0..48);
        for patch in &mesh.patches {
            assert!((patch.area - 0.25).abs() < 1e-5, "patch area {}", patch.area);
            assert!((patch.normal - Vec3::NEG_Y).length() < 1e-6);
            let pieces = &mesh.triangles[patch.triangles.start as usize..patch.triangles.end as usize];
            for piece in pieces {
                // Same winding as the source: the piece's normal is the surface's.
                let n = (piece[1] - piece[0]).cross(piece[2] - piece[0]).normalize();
                assert!(n.dot(patch.normal) > 0.999);
                for p in piece {
                    assert!((p - patch.centroid).abs().max_element() <= 0.5 + 1e-5);
                }
            }
        }
        let total: f32 = mesh.patches.iter().map(|p| p.area).sum();
        assert!((total - 12.0).abs() < 1e-4);
    }

    #[test]
    fn a_partial_cell_keeps_its_share() {
        let tris = quad(1.2, 0.5);
        let mut surfaces = vec![surface_of(&tris)];
        let mesh = subdivide(&tris, &mut surfaces, 0.5);
        let mut areas: Vec<f32> = mesh.patches.iter().map(|p| p.area).collect();
        areas.sort_by(f32::total_cmp);
        assert_eq!(areas.len(), 3);
        assert!((areas[0] - 0.1).abs() < 1e-5 && (areas[2] - 0.25).abs() < 1e-5);
    }

    #[test]
    fn small_triangles_are_not_split() {
        // A 0.9 × 0.3 strip of three 0.3 m squares; the middle one straddles
        // the cell edge at 0.5 but its triangles are smaller than a cell.
        let tris: Vec<Triangle> = (0..3)
            .flat_map(|k| {
                quad(0.3, 0.3).into_iter().map(move |mut t| {
                    t.vertices = t.vertices.map(|p| p + Vec3::new(0.3 * k as f32, 0.0, 0.0));
                    t
                })
            })
            .collect();
        let mut surfaces = vec![surface_of(&tris)];
        let mesh = subdivide(&tris, &mut surfaces, 0.5);
        assert_eq!(mesh.triangles.len(), 6);
        assert_eq!(mesh.patches.len(), 2);
        let total: f32 = mesh.patches.iter().map(|p| p.area).sum();
        assert!((total - 0.27).abs() < 1e-5);
    }
}
