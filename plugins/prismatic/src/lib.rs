//! Prismatic panels for heliodon (thesis figure 1.3): a clear sheet whose
//! outer face is a sawtooth of two facet orientations, its inner face flat.
//! Light from outside meets a facet (in proportion to the facet's projected
//! area), refracts into the sheet with Fresnel losses, and leaves through
//! the inner face or, where it meets it beyond the critical angle, is
//! totally reflected back to the facets, and so on. Each path ends in a
//! specular lobe, transmitted (z > 0) or reflected back outside (z < 0).
//!
//! Scene-file keys (`kind = "panel"`, `panel = "prismatic"`):
//! `facet_angles = [a, b]` (degrees from the panel plane, 0-89; the first
//! facet faces up, toward the sky, the second down), `refractive_index`
//! (default 1.49, acrylic).
//!
//! Written the way any panel plugin is: a [`PanelType`] that builds a
//! [`PanelModel`] from the keys, on the core crate alone; an app registers
//! it with one line (`app.register_panel(Prismatic)` in heliodon's ECS, or
//! `PanelCatalog::with(Prismatic)`).

use std::sync::Arc;

use heliodon_core::glam::DVec3;
use heliodon_core::panel::{
    Key, Lobe, PanelModel, PanelResponse, PanelType, ParameterError, Parameters, fresnel_reflectance, reflect, refract,
};

/// The `prismatic` panel type.
pub struct Prismatic;

impl PanelType for Prismatic {
    fn name(&self) -> &str {
        "prismatic"
    }

    fn keys(&self) -> &[Key] {
        &[FACET_ANGLES, REFRACTIVE_INDEX]
    }

    fn build(&self, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
        let [a, b] = parameters.numbers(&FACET_ANGLES)?;
        if a + b <= 0.0 {
            return Err(ParameterError::new(FACET_ANGLES.name, "at least one facet must be tilted"));
        }
        let index = parameters.number(&REFRACTIVE_INDEX)?;
        Ok(Arc::new(PrismaticModel::new([a, b], index)))
    }
}

const FACET_ANGLES: Key =
    Key::numbers("facet_angles", "tilt from the panel plane of the upward and the downward facet (°)", (0.0, 89.0), &[40.0, 5.0])
        .required();
const REFRACTIVE_INDEX: Key = Key::number("refractive_index", "of the sheet (acrylic 1.49)", (1.0, 3.0), 1.49);

/// Paths are followed through at most this many interactions; what is
/// left then is light guided inside the sheet to its edges (absorbed).
const MAX_DEPTH: u32 = 16;
/// Path weights below this are dropped (and counted as absorbed).
const MIN_WEIGHT: f64 = 1e-6;
/// Lobes closer than this (radians) are merged.
const MERGE_ANGLE: f64 = 0.25 * std::f64::consts::PI / 180.0;
/// Nominal angular width of a lobe (degrees): ideal facets give sharp lobes;
/// real panels blur them by about this much.
const LOBE_WIDTH: f64 = 2.0;

/// A prismatic sheet with its facets.
#[derive(Debug, Clone)]
pub struct PrismaticModel {
    /// Outward unit normals of the two facets (pointing outside, z < 0).
    facets: [DVec3; 2],
    /// Facet lengths per period of the sawtooth (unit peak height).
    lengths: [f64; 2],
    index: f64,
}

impl PrismaticModel {
    /// Facets tilted `angles` degrees from the panel plane, the first facing
    /// up (+y), the second down.
    pub fn new(angles: [f64; 2], index: f64) -> Self {
        let [a, b] = angles.map(f64::to_radians);
        let facets = [DVec3::new(0.0, a.sin(), -a.cos()), DVec3::new(0.0, -b.sin(), -b.cos())];
        // A tooth of unit height: a flat facet (angle 0) has no share of it
        // unless the other is flat too, which `Prismatic::build` refuses.
        let lengths = [a, b].map(|t| if t > 0.0 { 1.0 / t.sin() } else { 0.0 });
        Self { facets, lengths, index }
    }

    /// Shares of the flux travelling along `direction` that meet each facet
    /// from the side its normal points to (`inside`: from within the sheet,
    /// where the normals point the other way).
    fn facet_shares(&self, direction: DVec3, inside: bool) -> [f64; 2] {
        let sign = if inside { 1.0 } else { -1.0 };
        let projected = [0, 1].map(|i| self.lengths[i] * (sign * direction.dot(self.facets[i])).max(0.0));
        let total = projected[0] + projected[1];
        if total <= 0.0 { [0.0; 2] } else { projected.map(|p| p / total) }
    }

    /// Follows light of `weight` inside the sheet along `direction`; what
    /// no path carries out is added to `absorbed`.
    fn inside(&self, direction: DVec3, weight: f64, depth: u32, out: &mut Vec<Lobe>, absorbed: &mut f64) {
        if weight < MIN_WEIGHT || depth >= MAX_DEPTH {
            *absorbed += weight;
            return;
        }
        if direction.z > 0.0 {
            // The flat inner face: out into the room, or back by reflection.
            let r = fresnel_reflectance(self.index, 1.0, direction.z);
            if let Some(exit) = refract(direction, DVec3::Z, self.index, 1.0) {
                push(out, exit, weight * (1.0 - r));
            }
            self.inside(reflect(direction, DVec3::Z), weight * r, depth + 1, out, absorbed);
        } else {
            // Back at the sawtooth: out through a facet, or reflected.
            let shares = self.facet_shares(direction, true);
            if shares == [0.0; 2] {
                *absorbed += weight;
            }
            for (i, share) in shares.into_iter().enumerate() {
                let normal = self.facets[i];
                let r = fresnel_reflectance(self.index, 1.0, direction.dot(normal));
                if let Some(exit) = refract(direction, normal, self.index, 1.0) {
                    push(out, exit, weight * share * (1.0 - r));
                }
                self.inside(reflect(direction, normal), weight * share * r, depth + 1, out, absorbed);
            }
        }
    }
}

/// Adds a lobe, merging it with one already leaving the same way.
fn push(out: &mut Vec<Lobe>, direction: DVec3, share: f64) {
    if share <= 0.0 {
        return;
    }
    match out.iter_mut().find(|l| l.direction.angle_between(direction) < MERGE_ANGLE) {
        Some(lobe) => lobe.share += share,
        None => out.push(Lobe { direction, share, width: LOBE_WIDTH }),
    }
}

impl PanelModel for PrismaticModel {
    fn response(&self, incoming: DVec3) -> PanelResponse {
        let incoming = incoming.normalize();
        let (mut lobes, mut absorbed) = (Vec::new(), 0.0);
        if incoming.z > 0.0 {
            for (i, share) in self.facet_shares(incoming, false).into_iter().enumerate() {
                let normal = self.facets[i];
                let r = fresnel_reflectance(1.0, self.index, incoming.dot(normal));
                push(&mut lobes, reflect(incoming, normal), share * r);
                if let Some(inside) = refract(incoming, normal, 1.0, self.index) {
                    self.inside(inside, share * (1.0 - r), 0, &mut lobes, &mut absorbed);
                }
            }
        }
        lobes.sort_by(|a, b| b.share.total_cmp(&a.share));
        PanelResponse { lobes, diffuse_transmittance: 0.0, diffuse_reflectance: 0.0, absorbed }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Angle from the normal, signed toward +y, of a direction in the y-z plane.
    fn signed_angle(d: DVec3) -> f64 {
        d.y.atan2(d.z.abs()).to_degrees()
    }

    /// Snell's law worked with angles alone, in the profile plane (angles
    /// from the panel normal, positive toward up): light at `phi` meets the
    /// facet whose inward normal is at `normal` (−a for the up-facing facet
    /// of angle a, +b for the down-facing one), enters at t = asin(sin(phi −
    /// normal) / n), crosses the sheet at normal + t, and leaves the flat
    /// face at asin(n · sin(normal + t)), unless that is beyond the critical
    /// angle.
    fn worked_exit_angle(phi: f64, normal: f64, n: f64) -> Option<f64> {
        let t = ((phi - normal).to_radians().sin() / n).asin().to_degrees();
        let inside = normal + t;
        let s = n * inside.to_radians().sin();
        (s.abs() < 1.0).then(|| s.asin().to_degrees())
    }

    fn transmitted_angles(model: &PrismaticModel, phi: f64) -> Vec<f64> {
        let incoming = DVec3::new(0.0, phi.to_radians().sin(), phi.to_radians().cos());
        model.response(incoming).lobes.iter().filter(|l| l.direction.z > 0.0).map(|l| signed_angle(l.direction)).collect()
    }

    #[test]
    fn lobes_follow_snell_and_total_internal_reflection() {
        let n = 1.49;
        let model = PrismaticModel::new([40.0, 5.0], n);
        // Straight on: the 40° facet bends light down by 21.81°, the 5° one
        // up by 2.45° (worked on paper, and by the angle formula).
        assert!((worked_exit_angle(0.0, -40.0, n).unwrap() + 21.81).abs() < 0.01);
        assert!((worked_exit_angle(0.0, 5.0, n).unwrap() - 2.45).abs() < 0.01);
        let straight = transmitted_angles(&model, 0.0);
        for expected in [-21.81, 2.45] {
            assert!(straight.iter().any(|a| (a - expected).abs() < 0.01), "{expected}° not in {straight:?}");
        }
        // From 50° above: through the 40° facet the light crosses the sheet
        // at −46.69°, beyond the critical angle asin(1/1.49) = 42.16°: it is
        // totally reflected, no lobe leaves that way. Through the 5° facet
        // it crosses at −28.35° and leaves at −45.03°.
        assert!(worked_exit_angle(-50.0, -40.0, n).is_none());
        let expected = worked_exit_angle(-50.0, 5.0, n).unwrap();
        assert!((expected + 45.03).abs() < 0.01, "{expected}");
        let steep = transmitted_angles(&model, -50.0);
        assert!(steep.iter().any(|a| (a - expected).abs() < 0.01), "{expected}° not in {steep:?}");
        // Just below the limit, from 40° above, the 40° facet's light does leave directly.
        let shallow = worked_exit_angle(-40.0, -40.0, n).unwrap();
        assert!(transmitted_angles(&model, -40.0).iter().any(|a| (a - shallow).abs() < 0.01), "{shallow}");
    }

    #[test]
    fn energy_is_conserved() {
        for facets in [[40.0, 5.0], [30.0, 30.0], [60.0, 10.0], [80.0, 80.0]] {
            let model = PrismaticModel::new(facets, 1.49);
            for altitude in [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0] {
                for azimuth in [-60.0, 0.0, 45.0] {
                    let (a, z): (f64, f64) = (f64::to_radians(altitude), f64::to_radians(azimuth));
                    // Light from above the panel's horizon, coming down at it.
                    let incoming = DVec3::new(a.cos() * z.sin(), -a.sin(), a.cos() * z.cos()).normalize();
                    let response = model.response(incoming);
                    // Every path is accounted for: out as lobes, or absorbed
                    // (guided to the edges); the guided part stays small.
                    let total = response.total() + response.absorbed;
                    assert!((total - 1.0).abs() < 0.01, "{facets:?} alt {altitude} az {azimuth}: {total}");
                    assert!(response.absorbed < 0.05, "{facets:?} alt {altitude} az {azimuth}: absorbed {}", response.absorbed);
                }
            }
        }
    }

    #[test]
    fn keys_are_checked() {
        assert_eq!(heliodon_core::panel::check_keys(Prismatic.keys()), Ok(()));
        let build = |text: &str| Prismatic.build(&Parameters::from_toml(text, "").unwrap());
        assert!(build("facet_angles = [40.0, 5.0]").is_ok());
        assert!(Prismatic.build(&Parameters::new(heliodon_core::panel::default_values(Prismatic.keys()), "")).is_ok());
        assert_eq!(build("").unwrap_err().key, "facet_angles");
        assert_eq!(build("facet_angles = [40.0, 95.0]").unwrap_err().key, "facet_angles");
        assert_eq!(build("facet_angles = [40.0, 5.0]\nrefractive_index = 0.5").unwrap_err().key, "refractive_index");
    }
}
