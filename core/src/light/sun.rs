//! Direct sun and panel beams, by shadow rays: the sun through glass
//! (Radiance's transmittance at each pane's angle, every pane crossed), and
//! each panel lobe as a fake sun ([`SunBeam`]) whose light must leave
//! through a window of its panel group that the real sun reaches. Evaluated
//! per relight, never cached: the sun moves.

use glam::DVec3;

use super::panels::{self, SunBeam};
use super::{LightModel, MAX_GLASS_DEPTH, SURFACE_OFFSET, Surface};
use crate::sky::SunSource;

impl LightModel {
    /// Direct sun irradiance (W/m²) at `point` on a surface side with
    /// `normal`: shadow rays through glass toward the sun, and through panel
    /// windows along their lobes. For many points, get the beams once
    /// ([`Self::sun_beams`]) and use [`Self::beams_irradiance`].
    pub fn sun_irradiance(&self, point: DVec3, normal: DVec3, sun: &SunSource) -> f64 {
        self.beams_irradiance(point, normal, &self.sun_beams(sun))
    }

    /// How much of the sun reaches `point` (through glass; 0 when blocked).
    /// The product of the glass crossed does not depend on their order, so
    /// one traversal visits them all and stops at the first opaque surface.
    fn sun_transmittance(&self, point: DVec3, sun: DVec3) -> f64 {
        let mut transmittance = 1.0;
        // Glass surfaces crossed, by distance: a ray through the edge between
        // two triangles of one surface meets it twice.
        let mut crossed: Vec<(u32, f64)> = Vec::new();
        self.tracer.each_hit(point, sun, 1e-6, |hit| {
            let patch = &self.scene.patches.patches[hit.patch as usize];
            match self.surface_of_patch(hit.patch) {
                // Through a panel the sun arrives only along its lobes.
                Surface::Diffuse(_) | Surface::Panel(_) => {
                    transmittance = 0.0;
                    false
                }
                Surface::Glass(glass) => {
                    if !crossed.iter().any(|&(s, d)| s == patch.surface && (d - hit.distance).abs() < 1e-5) {
                        crossed.push((patch.surface, hit.distance));
                        transmittance *= glass.at(sun.dot(patch.normal.as_dvec3())).0;
                    }
                    true
                }
            }
        });
        transmittance
    }

    /// How much of a panel lobe's light reaches `point` from `to_light`:
    /// the ray must leave through a window of the lobe's panel group (glass
    /// on the way counts), and from there the real sun must reach it.
    fn lobe_transmittance(&self, point: DVec3, to_light: DVec3, group: u32, sun: DVec3) -> f64 {
        let (mut origin, mut transmittance) = (point, 1.0);
        for _ in 0..=MAX_GLASS_DEPTH {
            let Some(hit) = self.tracer.closest(origin, to_light, 1e-6) else { return 0.0 };
            let at = origin + to_light * hit.distance;
            match self.surface_of_patch(hit.patch) {
                Surface::Panel(g) if g == group => return transmittance * self.sun_transmittance(at + sun * SURFACE_OFFSET, sun),
                Surface::Glass(glass) => transmittance *= glass.at(to_light.dot(self.patch_normal(hit.patch))).0,
                _ => return 0.0,
            }
            origin = at + to_light * SURFACE_OFFSET;
        }
        0.0
    }

    /// The beams of direct sunlight for a sun: itself and its panel lobes.
    pub fn sun_beams(&self, sun: &SunSource) -> Vec<SunBeam> {
        if sun.direction.z <= 0.0 {
            return Vec::new();
        }
        panels::sun_beams(&self.panel_groups, sun)
    }

    /// Direct sun irradiance (W/m²) from all `beams` at `point` on a surface
    /// side with `normal`.
    pub fn beams_irradiance(&self, point: DVec3, normal: DVec3, beams: &[SunBeam]) -> f64 {
        let sun = beams.first().map_or(DVec3::Z, |b| b.to_light);
        let origin = point + normal * SURFACE_OFFSET;
        beams
            .iter()
            .map(|beam| {
                let cos = normal.dot(beam.to_light);
                if cos <= 0.0 {
                    return 0.0;
                }
                let reach = match beam.panel_group {
                    None => self.sun_transmittance(origin, beam.to_light),
                    Some(group) => self.lobe_transmittance(origin, beam.to_light, group, sun),
                };
                beam.normal_irradiance * cos * reach
            })
            .sum()
    }
}
