//! The insides of solids. A patch side that looks into a closed opaque
//! shell (the inner side of a wall's or a slab's face: half the patch
//! sides of a model built of solids, as a converted IFC model is) sees no
//! daylight: every path from the sky to it crosses the shell. Its gather
//! would trace rays that find only other such sides, and its form factors
//! would be half the cache; it is left dark and untraced instead.
//!
//! A shell that holds a window (a pane inside a wall with no opening cut
//! for it, a window pasted onto a closed room's wall) is left to the ray
//! tracer: whether light passes there depends on which face a ray meets
//! first, and that is not this module's to decide.
//!
//! A side that faces another opaque face a few millimetres away all over
//! (the meeting stiles of a double door, a leaf's edge in its frame, the
//! wall behind a cabinet) looks into a slot ([`slot_sides`]). Light that
//! enters a slot is reflected to and fro between its walls and dies there;
//! what passes straight through is the tracer's. Left lit, such a side is
//! one patch from the slot's sunlit outer end to its inner end, lit as
//! their mean, and that mean shines into the room behind (SampleHouse's
//! closed entrance hall, behind a double door whose leaves meet 3 mm apart:
//! a stile's face in the slot, 0.02 m², sun 31 W/m² on it as its mean,
//! lit the hall's wall beside it with 85% of that wall's light).

use glam::DVec3;

use super::sampling::{Rng, stratified_area_points};
use super::{LightModel, Surface, side_of};
use crate::parallel::par_map;
use crate::scene::shells::{Shells, model_shells, winding_number};
use crate::scene::{MaterialKind, Scene};

/// How far (m) from a window's face its inside is probed.
const WINDOW_PROBE: f64 = 1e-3;

/// Per patch side ([`side_of`]): whether it looks into a closed shell of
/// opaque surfaces that holds no window, so no daylight reaches it. The
/// surfaces' materials are the scene's as they are now (a material made
/// glass at run time opens its shells).
pub(super) fn dark_sides(scene: &Scene) -> Vec<bool> {
    let opaque = |material: u32| matches!(scene.materials[material as usize].kind, MaterialKind::Diffuse { .. });
    // The opaque surfaces' triangles, and where each surface's triangles begin there.
    let mut triangles = Vec::new();
    let mut vertices = Vec::new();
    let mut first = vec![None; scene.surfaces.len()];
    for (k, surface) in scene.surfaces.iter().enumerate().filter(|(_, s)| opaque(s.material)) {
        first[k] = Some(triangles.len());
        for triangle in &scene.triangles[surface.triangle_indices()] {
            triangles.push(triangle.vertices);
            vertices.push(triangle.file_vertices);
        }
    }
    let (mut shells, _) = model_shells(&triangles, &vertices);
    open_shells_holding_windows(scene, &triangles, &mut shells, |material| !opaque(material));
    // Per surface: +1 where its shells' outside is the way its normal
    // points, −1 the other way, 0 where it is not wholly a shell's face.
    let outward: Vec<i8> = scene
        .surfaces
        .iter()
        .zip(&first)
        .map(|(surface, first)| {
            let Some(first) = *first else { return 0 };
            let own = first..first + surface.triangles.len();
            agreed(
                triangles[own.clone()]
                    .iter()
                    .zip(&shells.winding[own])
                    .map(|(&[a, b, c], &winding)| as_seen_along((b - a).cross(c - a).dot(surface.normal), winding)),
            )
        })
        .collect();
    let mesh = &scene.patches;
    let mut dark = vec![false; mesh.patches.len() * 2];
    for (p, patch) in mesh.patches.iter().enumerate() {
        // A cluster's surfaces must agree, each as it faces the patch's normal.
        let way = agreed(
            mesh.surfaces_of(p as u32)
                .iter()
                .map(|&s| as_seen_along(scene.surfaces[s as usize].normal.dot(patch.normal), outward[s as usize])),
        );
        if way != 0 {
            // Outside along the normal: the back side looks in.
            dark[side_of(p as u32, way > 0) as usize] = true;
        }
    }
    dark
}

/// A side whose every probe meets an opaque face closer than this (m)
/// looks into a slot.
const SLOT_WIDTH: f64 = 0.005;
/// Points of a side probed for a slot, spread over it.
const SLOT_PROBES: usize = 9;

/// Marks in `dark` the sides of `model`'s opaque patches that look into a
/// slot: from each of [`SLOT_PROBES`] points spread over the side, the ray
/// along its normal meets an opaque face within [`SLOT_WIDTH`].
pub(super) fn slot_sides(model: &LightModel, dark: &mut [bool]) {
    let opaque = |patch: u32| matches!(model.surface_of_patch(patch), Surface::Diffuse(_));
    let in_slot = par_map(model.settings.threads, dark.len(), |side| {
        let patch = (side / 2) as u32;
        if dark[side] || !opaque(patch) {
            return false;
        }
        let triangles = model.patch_triangles(patch as usize);
        let normal = model.patch_normal(patch) * if side % 2 == 1 { -1.0 } else { 1.0 };
        let mut rng = Rng::new(7, side as u64);
        let mut points = stratified_area_points(&triangles, SLOT_PROBES, &mut rng);
        points.all(|point| {
            model
                .tracer()
                .closest(point + normal * super::SURFACE_OFFSET, normal, 1e-6)
                .is_some_and(|hit| hit.distance < SLOT_WIDTH && opaque(hit.patch))
        })
    });
    for (side, in_slot) in in_slot.into_iter().enumerate() {
        dark[side] |= in_slot;
    }
}

/// `way` (±1, or 0) as seen from a direction that makes the cosine
/// `facing` with the one it was given along: turned where that is
/// opposite, 0 where it is square to it.
fn as_seen_along(facing: f32, way: i8) -> i8 {
    if facing > 0.0 {
        way
    } else if facing < 0.0 {
        -way
    } else {
        0
    }
}

/// The one way all of `ways` go, or 0 where one is 0, two differ or
/// there are none.
fn agreed(mut ways: impl Iterator<Item = i8>) -> i8 {
    let Some(first) = ways.next() else { return 0 };
    if ways.all(|way| way == first) { first } else { 0 }
}

/// Takes out of `shells` every shell that has a window (a surface whose
/// material `passes_light`) inside it or on its faces: a point just off
/// either face of a window triangle lies within the solid.
fn open_shells_holding_windows(scene: &Scene, triangles: &[[glam::Vec3; 3]], shells: &mut Shells, passes_light: impl Fn(u32) -> bool) {
    // Each shell's triangles and box.
    let mut members: std::collections::BTreeMap<u32, (Vec<usize>, DVec3, DVec3)> = std::collections::BTreeMap::new();
    for (t, &shell) in shells.shell.iter().enumerate().filter(|(t, _)| shells.winding[*t] != 0) {
        let entry = members.entry(shell).or_insert((Vec::new(), DVec3::INFINITY, DVec3::NEG_INFINITY));
        entry.0.push(t);
        for v in triangles[t] {
            entry.1 = entry.1.min(v.as_dvec3());
            entry.2 = entry.2.max(v.as_dvec3());
        }
    }
    let probes: Vec<DVec3> = scene
        .surfaces
        .iter()
        .filter(|s| passes_light(s.material))
        .flat_map(|s| &scene.triangles[s.triangle_indices()])
        .flat_map(|t| {
            let centre = t.centroid().as_dvec3();
            let normal = t.normal().as_dvec3() * WINDOW_PROBE;
            [centre + normal, centre - normal]
        })
        .collect();
    for (faces, lo, hi) in members.values() {
        let holds_window = probes.iter().filter(|p| p.cmpge(*lo).all() && p.cmple(*hi).all()).any(|&p| {
            let outward = faces.iter().map(|&t| {
                let [a, b, c] = triangles[t].map(|v| v.as_dvec3());
                if shells.winding[t] > 0 { [a, b, c] } else { [a, c, b] }
            });
            winding_number(p, outward).abs() > 0.5
        });
        if holds_window {
            faces.iter().for_each(|&t| shells.winding[t] = 0);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::fmt::Write as _;

    use super::super::test_scene::scene_of;
    use super::*;

    /// The faces of a union of grid cells, each wound outward (or inward,
    /// `inward`), as OBJ quads of material `material`: cells `filled(i, j,
    /// k)` of the grid with lines `xs`, `ys`, `zs`. Faces between two filled
    /// cells are left out, so the surface is closed and every edge meets
    /// exactly one other (no two cells meet along an edge alone here).
    fn cells_obj(obj: &mut String, material: &str, [xs, ys, zs]: [&[f64]; 3], filled: impl Fn([usize; 3]) -> bool, inward: bool) {
        let n = [xs.len() - 1, ys.len() - 1, zs.len() - 1];
        let lines = [xs, ys, zs];
        let is_filled = |c: [i64; 3]| (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < n[a]) && filled(c.map(|v| v as usize));
        let _ = writeln!(obj, "usemtl {material}");
        for i in 0..n[0] {
            for j in 0..n[1] {
                for k in 0..n[2] {
                    let cell = [i, j, k];
                    if !filled(cell) {
                        continue;
                    }
                    for axis in 0..3 {
                        for step in [-1i64, 1] {
                            let mut next = cell.map(|v| v as i64);
                            next[axis] += step;
                            if is_filled(next) {
                                continue;
                            }
                            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                            let at = |du: usize, dv: usize| {
                                let mut p = [0.0; 3];
                                p[axis] = lines[axis][cell[axis] + usize::from(step > 0)];
                                p[u] = lines[u][cell[u] + du];
                                p[v] = lines[v][cell[v] + dv];
                                p
                            };
                            // (u, v) counter-clockwise faces +axis.
                            let mut quad = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
                            if (step < 0) != inward {
                                quad.reverse();
                            }
                            for p in quad {
                                let _ = writeln!(obj, "v {} {} {}", p[0], p[1], p[2]);
                            }
                            let _ = writeln!(obj, "f -4 -3 -2 -1");
                        }
                    }
                }
            }
        }
    }

    /// Per patch of material `name`: (front dark, back dark).
    fn dark_of(scene: &Scene, name: &str) -> Vec<(bool, bool)> {
        let material = scene.materials.iter().position(|m| m.name == name).unwrap() as u32;
        let dark = dark_sides(scene);
        (0..scene.patches.patches.len() as u32)
            .filter(|&p| scene.patches.patches[p as usize].material == material)
            .map(|p| (dark[side_of(p, false) as usize], dark[side_of(p, true) as usize]))
            .collect()
    }

    /// The leaves of a double door, solids 4.4 cm thick meeting 3 mm apart:
    /// the faces across the slot between them are dark, the leaves' faces
    /// to either room are not. Leaves 2 cm apart leave no slot.
    #[test]
    fn the_faces_across_a_slot_between_two_leaves_are_dark() {
        let slot_of = |gap: f64| {
            let mut obj = String::new();
            for x0 in [0.0, 0.85 + gap] {
                cells_obj(&mut obj, "wall", [&[x0, x0 + 0.85], &[0.0, 0.044], &[0.0, 2.0]], |_| true, false);
            }
            let scene = scene_of(&format!("solids-slot-{gap}"), &obj, "");
            let mut dark = dark_sides(&scene);
            slot_sides(&LightModel::unlit(std::sync::Arc::new(scene.clone())), &mut dark);
            // Per patch: its normal's x, and whether its front is dark.
            (0..scene.patches.patches.len() as u32)
                .map(|p| {
                    (
                        scene.patches.patches[p as usize].normal,
                        scene.patches.patches[p as usize].centroid.x,
                        dark[side_of(p, false) as usize],
                    )
                })
                .collect::<Vec<_>>()
        };
        let facing_the_slot = |&(normal, x, _): &(glam::Vec3, f32, bool)| (normal.x > 0.9 && x < 0.9) || (normal.x < -0.9 && x > 0.8);
        let slot = slot_of(0.003);
        assert!(slot.iter().filter(|p| facing_the_slot(p)).count() >= 2);
        assert!(slot.iter().all(|p| p.2 == facing_the_slot(p)), "{slot:?}");
        assert!(slot_of(0.02).iter().all(|p| !p.2));
    }

    /// A wall 4 × 0.3 × 3 m with an opening for its window, glazed in the
    /// middle of its depth: the inside of the wall is dark, its outside
    /// faces and the pane are not. The same wall without the opening, the
    /// pane inside it, is left to the ray tracer; so is a closed room
    /// (modelled from within) with a pane on a wall, and a closed room
    /// without one is dark inside.
    #[test]
    fn the_inside_of_a_solid_without_windows_is_dark() {
        let grid: [&[f64]; 3] = [&[0.0, 1.0, 3.0, 4.0], &[0.0, 0.3], &[0.0, 0.9, 2.3, 3.0]];
        let pane = "usemtl glass\nv 1 0.15 0.9\nv 3 0.15 0.9\nv 3 0.15 2.3\nv 1 0.15 2.3\nf -4 -3 -2 -1\n";
        let mut obj = String::new();
        cells_obj(&mut obj, "wall", grid, |c| c != [1, 0, 1], false);
        let scene = scene_of("solids-opening", &(obj + pane), "");
        let wall = dark_of(&scene, "wall");
        assert!(wall.len() > 8 && wall.iter().all(|&d| d == (false, true)), "{wall:?}");
        assert!(dark_of(&scene, "glass").iter().all(|&d| d == (false, false)));

        let mut obj = String::new();
        cells_obj(&mut obj, "wall", grid, |_| true, false);
        let scene = scene_of("solids-no-opening", &(obj + pane), "");
        assert!(dark_of(&scene, "wall").iter().all(|&d| d == (false, false)));

        let room: [&[f64]; 3] = [&[0.0, 4.0], &[0.0, 5.0], &[0.0, 3.0]];
        let mut obj = String::new();
        cells_obj(&mut obj, "wall", room, |_| true, true);
        let closed = scene_of("solids-closed-room", &obj, "");
        let inside = dark_of(&closed, "wall");
        assert!(!inside.is_empty() && inside.iter().all(|&d| d == (true, false)), "{inside:?}");
        let on_the_wall = "usemtl glass\nv 1 0 0.9\nv 3 0 0.9\nv 3 0 2.3\nv 1 0 2.3\nf -1 -2 -3 -4\n";
        let scene = scene_of("solids-room-with-pane", &(obj + on_the_wall), "");
        assert!(dark_of(&scene, "wall").iter().all(|&d| d == (false, false)));
    }
}
