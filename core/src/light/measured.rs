//! Direct sun through panels with measured transmission (a BSDF file), at
//! sensors: the data itself integrated over the windows the sensor sees,
//! as Radiance's rtrace does, in place of the fitted lobes' beams.
//!
//! A lobe's beams ([`super::panels::spread`]) stand for its cone of light,
//! and a sensor near the edge of where that light falls gets all of a
//! beam or none of it. Under a genBSDF metal-slat tree, two sensors that
//! saw the windows across the lower edge of the light's cone read 59% of
//! what the beams gave them, others 1.6-2× (measured against this integral
//! and rtrace; see ARCHITECTURE.md). So for a sensor:
//!
//! ```text
//! E = Eₙ cos θᵢ Σ (f(i, o) − τd/π) · cos θₛ cos θₒ ΔA / r² · sunlit
//! ```
//!
//! over points on the panel group's windows ([`WindowSamples`], stratified
//! and seeded) that the sensor's points see ([`SeenSample`], found once per
//! sensor with the data's outgoing cell of each), with `f` the panel's
//! [`MeasuredTransmission`] (one row of it per sun) and `sunlit` the share
//! of sun each window point gets (one shadow ray per point and sun, shared
//! by all sensors). The diffuse part τd/π reaches sensors as
//! for every panel, by their gather rays (the group's diffusely transmitted
//! sun), so that the two add up to the data's whole transmission.
//! Patch sides and the renderer keep the beams: a side averages over its
//! area, as the beams' footprints do.
//!
//! [`MeasuredTransmission`]: crate::panel::MeasuredTransmission

use glam::DVec3;

use super::bvh::ParallelHits;
use super::panels::SunBeam;
use super::sampling::{Rng, point_on_triangle};
use super::{LightModel, SURFACE_OFFSET, Surface};

/// Points a panel group's windows are sampled at, in all.
const WINDOW_SAMPLES: usize = 4096;

/// Points on a panel group's windows: each stands for an equal part of
/// their area.
#[derive(Debug, Clone, Default)]
pub(super) struct WindowSamples {
    pub(super) points: Vec<DVec3>,
    /// The scene window (index into [`crate::scene::Scene::windows`]) of each point.
    pub(super) windows: Vec<u32>,
    /// The area each point stands for (m²).
    pub(super) area: f64,
}

/// A window point a sensor sees: which, and how much its radiance counts.
#[derive(Debug, Clone, Copy)]
pub(super) struct SeenSample {
    sample: u32,
    /// cos θₛ cos θₒ ΔA / r², times the glass crossed, over the sensor's points.
    weight: f32,
    /// The data's outgoing cell of the way the light leaves the window toward the sensor.
    cell: u32,
}

/// The sun on one measured panel group: what its windows' points get.
pub(super) struct GroupSun {
    /// Per outgoing cell of the data, Eₙ cos θᵢ (f − τd/π): the radiance
    /// of the windows in that cell (W/sr/m²) beyond the diffuse part, which
    /// the gather rays carry.
    radiance: Vec<f64>,
    /// Per window point, the share of the sun reaching it.
    sunlit: Vec<f32>,
}

/// The sun on every panel group with measured transmission (`None` for
/// the others: their beams carry the sun).
#[derive(Default)]
pub struct MeasuredSun(Vec<Option<GroupSun>>);

impl MeasuredSun {
    /// Whether panel group `group`'s direct sun comes from its data rather than its beams.
    pub(super) fn covers(&self, group: Option<u32>) -> bool {
        group.is_some_and(|g| self.0.get(g as usize).is_some_and(Option::is_some))
    }
}

impl LightModel {
    /// Points on panel group `group`'s windows: per window triangle a
    /// jittered grid in proportion to its area.
    pub(super) fn window_samples(&self, group: usize) -> WindowSamples {
        let triangles: Vec<(u32, [DVec3; 3], f64)> = (self.scene.windows.iter().enumerate())
            .filter(|(_, w)| self.group_of_surface[w.surface as usize] == Some(group as u32))
            .flat_map(|(k, w)| {
                self.scene.surface_triangles(w.surface).iter().map(move |t| {
                    let t = t.vertices.map(|v| v.as_dvec3());
                    (k as u32, t, 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
                })
            })
            .collect();
        let total: f64 = triangles.iter().map(|t| t.2).sum();
        let mut samples = WindowSamples::default();
        let mut rng = Rng::new(5, group as u64);
        for (window, triangle, area) in triangles {
            let side = ((WINDOW_SAMPLES as f64 * area / total).sqrt().round() as usize).max(1);
            for k in 0..side * side {
                let (a, b) = (((k / side) as f64 + rng.next_f64()) / side as f64, ((k % side) as f64 + rng.next_f64()) / side as f64);
                samples.points.push(point_on_triangle(&triangle, a, b));
                samples.windows.push(window);
            }
        }
        samples.area = total / samples.points.len().max(1) as f64;
        samples
    }

    /// The window points of every measured panel group that sensor `index`
    /// sees, per group (empty for the others). An area sensor's points
    /// share the window points out, each every `stride`-th (`stride` = its
    /// point count, up to the window points'), so that a sensor costs what
    /// a point does per sun.
    pub(super) fn seen_samples(&self, index: usize) -> Vec<Vec<SeenSample>> {
        let geometry = &self.sensors[index];
        (0..self.panel_groups.len())
            .map(|group| {
                let Some(data) = self.panel_groups[group].model.measured() else { return Vec::new() };
                let samples = &self.panel_samples[group];
                let frame = self.panel_groups[group].frame;
                let points = &geometry.sun_points;
                let stride = points.len().min(samples.points.len()).max(1);
                let share = samples.area * stride as f64 / points.len() as f64;
                let mut seen = Vec::new();
                for (j, &point) in points.iter().enumerate() {
                    let origin = point + geometry.normal * SURFACE_OFFSET;
                    for sample in (j % stride..samples.points.len()).step_by(stride) {
                        let to_window = samples.points[sample] - origin;
                        let (distance, direction) = (to_window.length(), to_window.normalize());
                        let (cos_sensor, outgoing) = (geometry.normal.dot(direction), frame.to_panel(-direction));
                        if cos_sensor <= 0.0 || outgoing.z <= 0.0 {
                            continue;
                        }
                        let glass = self
                            .reaches_panel(None, origin, direction, group as u32)
                            .filter(|&(at, _)| at.distance(origin) > distance - 1e-3);
                        if let Some((_, transmittance)) = glass {
                            let weight = transmittance * cos_sensor * outgoing.z * share / (distance * distance);
                            let cell = data.outgoing_cell(outgoing).min(data.outgoing_cells().saturating_sub(1)) as u32;
                            seen.push(SeenSample { sample: sample as u32, weight: weight as f32, cell });
                        }
                    }
                }
                seen
            })
            .collect()
    }

    /// Where a ray from `origin` along `direction` meets a window of panel
    /// group `group`, and the glass it crosses on the way; `None` when
    /// something else stops it first. The nearest of the group's window
    /// triangles along the ray, then one bounded traversal for what lies
    /// before it (a closest-hit search per pane cost most of a panel
    /// room's year); among the ray's parallel hits alone when given
    /// ([`super::sun::Shadows`]).
    pub(super) fn reaches_panel(&self, among: Option<&ParallelHits>, origin: DVec3, direction: DVec3, group: u32) -> Option<(DVec3, f64)> {
        let distance = match among {
            Some(hits) => {
                let mut nearest = None::<f64>;
                hits.each_hit(origin, 1e-6, f64::INFINITY, |hit| {
                    if self.group_of_surface[hit.patch as usize] == Some(group) {
                        nearest = Some(nearest.map_or(hit.distance, |d| d.min(hit.distance)));
                    }
                    true
                });
                nearest?
            }
            None => (self.panel_windows[group as usize].iter())
                .filter_map(|triangle| ray_meets_triangle(origin, direction, triangle))
                .filter(|&t| t > 1e-6)
                .min_by(f64::total_cmp)?,
        };
        // What lies within a hair of the pane (its frame, a coplanar glass) does not stop the ray.
        let before = distance * (1.0 - 1e-6) - 1e-5;
        let transmittance = self.through_glass(among, origin, direction, before, |kind| matches!(kind, Surface::Panel(g) if g == group))?;
        Some((origin + direction * distance, transmittance))
    }

    /// The sun on every measured panel group for `beams` (the first is the
    /// sun itself): one row of its data, one shadow ray from each window
    /// point.
    pub fn measured_sun(&self, beams: &[SunBeam]) -> MeasuredSun {
        let Some(sun) = beams.first() else { return MeasuredSun::default() };
        MeasuredSun(
            (0..self.panel_groups.len())
                .map(|g| {
                    let group = &self.panel_groups[g];
                    let incoming = group.frame.to_panel(-sun.to_light);
                    let data = group.model.measured().filter(|_| incoming.z > 0.0)?;
                    let sunlit = self.panel_samples[g]
                        .points
                        .iter()
                        .map(|&p| self.sun_transmittance(p + sun.to_light * SURFACE_OFFSET, sun.to_light) as f32)
                        .collect();
                    let diffuse = group.model.response(incoming).diffuse_transmittance / std::f64::consts::PI;
                    let irradiance = sun.normal_irradiance * incoming.z;
                    let radiance = data.row(incoming).iter().map(|f| irradiance * (f - diffuse)).collect();
                    Some(GroupSun { radiance, sunlit })
                })
                .collect(),
        )
    }

    /// Sensor `index`'s direct sun (W/m²) through measured panel groups, by
    /// the scene window it comes through.
    pub(super) fn sensor_measured_sun(&self, index: usize, sun: &MeasuredSun) -> Vec<(u32, f64)> {
        let mut by_window: Vec<(u32, f64)> = Vec::new();
        if sun.0.iter().all(Option::is_none) {
            return by_window;
        }
        let seen = self.sensors[index].panel_views.get_or_init(|| self.seen_samples(index));
        for (g, (on_group, seen)) in sun.0.iter().zip(seen).enumerate() {
            let Some(on_group) = on_group else { continue };
            let windows = &self.panel_samples[g].windows;
            for s in seen {
                let sunlit = on_group.sunlit[s.sample as usize];
                if sunlit <= 0.0 {
                    continue;
                }
                let e = on_group.radiance.get(s.cell as usize).copied().unwrap_or(0.0) * f64::from(s.weight * sunlit);
                let window = windows[s.sample as usize];
                match by_window.iter_mut().find(|w| w.0 == window) {
                    Some(entry) => entry.1 += e,
                    None => by_window.push((window, e)),
                }
            }
        }
        by_window
    }
}

/// Where the line from `origin` along unit `direction` meets `triangle`
/// (Möller–Trumbore), as a signed distance (negative: behind the origin);
/// `None` when it misses.
fn ray_meets_triangle(origin: DVec3, direction: DVec3, [a, b, c]: &[DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (*b - *a, *c - *a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let to_origin = origin - *a;
    let u = to_origin.dot(p) / det;
    let q = to_origin.cross(e1);
    let v = direction.dot(q) / det;
    ((0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0).then(|| e2.dot(q) / det)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ray meets a triangle ahead of it, at its distance; one beside it
    /// does not, and one behind it only at a negative distance.
    #[test]
    fn rays_meet_triangles_ahead_of_them() {
        let triangle = [DVec3::new(0.0, 0.0, 2.0), DVec3::new(1.0, 0.0, 2.0), DVec3::new(0.0, 1.0, 2.0)];
        let t = ray_meets_triangle(DVec3::new(0.2, 0.2, 0.0), DVec3::Z, &triangle).expect("straight up through it");
        assert!((t - 2.0).abs() < 1e-12, "{t}");
        assert!(ray_meets_triangle(DVec3::new(0.8, 0.8, 0.0), DVec3::Z, &triangle).is_none(), "beside its long edge");
        assert!(ray_meets_triangle(DVec3::new(0.2, 0.2, 0.0), -DVec3::Z, &triangle).is_none_or(|t| t < 0.0), "behind it");
        let slanted = DVec3::new(0.1, 0.1, 1.0).normalize();
        let t = ray_meets_triangle(DVec3::new(0.1, 0.1, 0.0), slanted, &triangle).unwrap();
        assert!((t * slanted.z - 2.0).abs() < 1e-12, "{t}");
    }
}
