//! What real exports need before their light is right, each found problem
//! reported in one warning line.
//!
//! - **Thick glass.** BIM exports model a pane as a glass box (two faces
//!   a couple of centimetres apart and four thin edges). Read as it is, light
//!   would cross glass twice (τ²) and the edges would count as windows. A
//!   pair of parallel glass faces of one material, facing apart, of about
//!   the same area and no more than [`MAX_PANE_THICKNESS`] apart is one pane:
//!   the face that sees more of the outside is kept (either works: the
//!   windows' outward side is ray-tested later), the other and the glass
//!   edges between them are dropped.
//! - **Glass on a solid.** Glass lying on a face of a solid in that face's
//!   plane (a window lining's glazed face on the wall's reveal, as
//!   IfcOpenHouse models its windows; a zone box over a façade) leads into
//!   the solid: no window is there. Radiance reads the opaque face, and so
//!   do the sun's shadow rays; the gathers' rays would cross the glass into
//!   the solid's dark inside. Such glass is dropped ([`glass_on_solids`]).
//!   A pane pasted on a wall modelled as one sheet, or on a closed room
//!   modelled from within, leads outside and stays a window.
//! - **Hidden faces.** An opaque face lying wholly on a larger opaque face
//!   of another material, in its plane and facing the same way (FZK-Haus's
//!   rafters, whose undersides are the roof slab's underside): which of the
//!   two a ray meets is a matter of rounding, in Radiance as here, and the
//!   two tracers round apart. The larger face is what shows; the other is
//!   dropped ([`hidden_faces`]), so both read the same surface.

use std::collections::HashMap;

use glam::Vec3;

use super::contacts::LargeFaces;
use super::material::Material;
use super::shells::model_shells;
use super::{Surface, Triangle, Window};
use crate::parallel::par_map;

/// Glass faces closer than this (m) are the two sides of one pane.
pub const MAX_PANE_THICKNESS: f32 = 0.06;

/// Surfaces that are the far side or the edges of a glass pane modelled as
/// a box (indices into `surfaces`), and how many panes were found.
pub fn thick_glass(triangles: &[Triangle], surfaces: &[Surface], materials: &[Material]) -> (Vec<u32>, usize) {
    let glass: Vec<usize> = (0..surfaces.len()).filter(|&s| materials[surfaces[s].material as usize].kind.transmits()).collect();
    let tris = |s: usize| &triangles[surfaces[s].triangle_indices()];
    let centres: HashMap<usize, Vec3> = glass.iter().map(|&s| (s, surfaces[s].centroid(triangles))).collect();
    // Glass surfaces by the cell of their centre, for neighbours in near-linear time.
    let cell = |p: Vec3| (p / (2.0 * MAX_PANE_THICKNESS)).floor().as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<usize>> = HashMap::new();
    for &s in &glass {
        grid.entry(cell(centres[&s])).or_default().push(s);
    }
    let mut dropped = vec![false; surfaces.len()];
    let mut panes = Vec::new();
    for &s in &glass {
        if dropped[s] {
            continue;
        }
        let (a, n, c) = (&surfaces[s], surfaces[s].normal, centres[&s]);
        let [x, y, z] = cell(c);
        let partner = (-1..=1)
            .flat_map(|dx| (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| [x + dx, y + dy, z + dz])))
            .filter_map(|k| grid.get(&k))
            .flatten()
            .copied()
            .find(|&t| {
                let b = &surfaces[t];
                let gap = (centres[&t] - c).dot(n).abs();
                let beside = (centres[&t] - c) - n * (centres[&t] - c).dot(n);
                t != s
                    && !dropped[t]
                    && b.material == a.material
                    && b.normal.dot(n) < -0.999
                    && gap > 1e-4
                    && gap <= MAX_PANE_THICKNESS
                    && beside.length() <= MAX_PANE_THICKNESS
                    && (a.area - b.area).abs() <= 0.1 * a.area.max(b.area)
            });
        if let Some(t) = partner {
            dropped[t] = true;
            panes.push((s, t));
        }
    }
    // The box's edges: glass lying within a pane's slab and footprint
    // (found through a metre grid of the glass surfaces' centres).
    let metre = |p: Vec3| p.floor().as_ivec3();
    let mut coarse: HashMap<[i32; 3], Vec<usize>> = HashMap::new();
    for &s in &glass {
        coarse.entry(metre(centres[&s]).to_array()).or_default().push(s);
    }
    for &(s, t) in &panes {
        let (n, c) = (surfaces[s].normal, centres[&s]);
        let gap = (centres[&t] - c).dot(n);
        let (lo, hi) = tris(s).iter().flat_map(|t| t.vertices).fold((Vec3::MAX, Vec3::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let (lo, hi) = (lo - Vec3::splat(MAX_PANE_THICKNESS), hi + Vec3::splat(MAX_PANE_THICKNESS));
        let (first, last) = (metre(lo), metre(hi));
        for x in first.x..=last.x {
            for y in first.y..=last.y {
                for z in first.z..=last.z {
                    for &e in coarse.get(&[x, y, z]).into_iter().flatten() {
                        if dropped[e] || e == s || surfaces[e].material != surfaces[s].material || surfaces[e].normal.dot(n).abs() > 0.1 {
                            continue;
                        }
                        let within = tris(e).iter().flat_map(|t| t.vertices).all(|v| {
                            let along = (v - c).dot(n);
                            along >= gap.min(0.0) - 1e-4 && along <= gap.max(0.0) + 1e-4 && v.cmpge(lo).all() && v.cmple(hi).all()
                        });
                        dropped[e] |= within;
                    }
                }
            }
        }
    }
    ((0..surfaces.len() as u32).filter(|&s| dropped[s as usize]).collect(), panes.len())
}

/// The glass triangles of `windows` lying wholly on faces of solids in
/// their own plane: (window, triangle index). A face of a solid is an
/// `opaque` triangle of a closed shell wound as the model wrote it,
/// outward, so what lies behind it is the solid ([`super::shells`]); the
/// shells are found only when some glass lies on an opaque face at all.
pub(crate) fn glass_on_solids(
    large: &LargeFaces,
    triangles: &[Triangle],
    surfaces: &[Surface],
    windows: &[Window],
    opaque: impl Fn(u32) -> bool,
) -> Vec<(usize, u32)> {
    let covered_by = |counts: &dyn Fn(usize) -> bool| -> Vec<(usize, u32)> {
        windows
            .iter()
            .enumerate()
            .flat_map(|(k, window)| {
                let surface = &surfaces[window.surface as usize];
                let quarters = large.covered_quarters(surface, counts);
                surface.triangles.clone().zip(quarters).filter(|&(_, q)| q == 4).map(move |(t, _)| (k, t))
            })
            .collect()
    };
    if covered_by(&|t| opaque(triangles[t].material)).is_empty() {
        return Vec::new();
    }
    let faces: Vec<usize> = (0..triangles.len()).filter(|&t| opaque(triangles[t].material)).collect();
    let corners: Vec<[Vec3; 3]> = faces.iter().map(|&t| triangles[t].vertices).collect();
    let vertices: Vec<[u32; 3]> = faces.iter().map(|&t| triangles[t].file_vertices).collect();
    let (shells, _) = model_shells(&corners, &vertices);
    let mut of_solid = vec![false; triangles.len()];
    for (k, &t) in faces.iter().enumerate() {
        of_solid[t] = shells.winding[k] == 1;
    }
    covered_by(&|t| of_solid[t])
}

/// The opaque triangles lying wholly on a larger opaque face of another
/// material in their own plane, facing the same way (a tie in area goes to
/// the surface listed first), by index into `triangles`, sorted.
pub(crate) fn hidden_faces(
    large: &LargeFaces,
    triangles: &[Triangle],
    surfaces: &[Surface],
    opaque: impl Fn(u32) -> bool + Sync,
) -> Vec<u32> {
    let mut surface_of = vec![0; triangles.len()];
    for (index, surface) in surfaces.iter().enumerate() {
        surface_of[surface.triangle_indices()].fill(index);
    }
    let hidden = par_map(None, surfaces.len(), |index| {
        let surface = &surfaces[index];
        if !opaque(surface.material) {
            return Vec::new();
        }
        let shows_over = |t: usize| {
            let (other, face) = (surface_of[t], &triangles[t]);
            let over = &surfaces[other];
            opaque(face.material)
                && face.material != surface.material
                && face.normal().dot(surface.normal) > 0.0
                && (over.area > surface.area || (over.area == surface.area && other < index))
        };
        let quarters = large.covered_quarters(surface, shows_over);
        surface.triangles.clone().zip(quarters).filter(|&(_, q)| q == 4).map(|(t, _)| t).collect()
    });
    hidden.into_iter().flatten().collect()
}
