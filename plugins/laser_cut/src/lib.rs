//! Laser-cut panels for heliodon (Edmonds): a clear sheet of thickness W cut
//! through by thin parallel slits D apart. Light refracts into the sheet at
//! its outer face; crossing the sheet it drifts W·|tan| across the cuts, so
//! it meets ⌊q⌋ or ⌈q⌉ of them (q = drift / D). At each cut it is totally
//! reflected when it meets it beyond the critical angle (else the Fresnel
//! share of the two faces of the slit is reflected); an odd number of
//! reflections leaves it deflected, mirrored about the cut planes, an even
//! number undeflected. It leaves by the inner face, with Fresnel losses at
//! both faces (what the faces reflect goes back outside, mirrored by the
//! outer face).
//!
//! Scene-file keys (`kind = "panel"`, `panel = "laser_cut"`):
//! `cut_spacing_ratio` (D/W, 0.05-10), `cut_angle` (degrees from
//! perpendicular to the sheet, −60 to 60), `refractive_index` (default 1.49).

use std::sync::Arc;

use heliodon_core::glam::DVec3;
use heliodon_core::panel::{
    Key, Lobe, PanelModel, PanelResponse, PanelType, ParameterError, Parameters, fresnel_reflectance, reflect, refract,
};

/// The `laser_cut` panel type.
pub struct LaserCut;

impl PanelType for LaserCut {
    fn name(&self) -> &str {
        "laser_cut"
    }

    fn keys(&self) -> &[Key] {
        &[CUT_SPACING_RATIO, CUT_ANGLE, REFRACTIVE_INDEX]
    }

    fn build(&self, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
        let ratio = parameters.number(&CUT_SPACING_RATIO)?;
        let angle = parameters.number(&CUT_ANGLE)?;
        let index = parameters.number(&REFRACTIVE_INDEX)?;
        Ok(Arc::new(LaserCutModel { ratio, angle: angle.to_radians(), index }))
    }
}

const CUT_SPACING_RATIO: Key = Key::number("cut_spacing_ratio", "cut spacing over sheet thickness, D/W", (0.05, 10.0), 0.5).required();
const CUT_ANGLE: Key = Key::number("cut_angle", "tilt of the cuts from perpendicular to the sheet (°)", (-60.0, 60.0), 0.0);
const REFRACTIVE_INDEX: Key = Key::number("refractive_index", "of the sheet (acrylic 1.49)", (1.0, 3.0), 1.49);

/// Nominal angular width of a lobe (degrees).
const LOBE_WIDTH: f64 = 3.0;

/// A laser-cut sheet.
#[derive(Debug, Clone)]
pub struct LaserCutModel {
    /// Cut spacing over sheet thickness, D/W.
    ratio: f64,
    /// Tilt of the cuts from perpendicular to the sheet, radians.
    angle: f64,
    index: f64,
}

impl LaserCutModel {
    /// Unit normal of the cut planes (in the profile plane: y up, z in).
    fn cut_normal(&self) -> DVec3 {
        DVec3::new(0.0, self.angle.cos(), -self.angle.sin())
    }

    /// Shares of light inside the sheet along `inside` that leave it
    /// undeflected and deflected by the cuts (they add up to 1).
    fn deflection(&self, inside: DVec3) -> (f64, f64) {
        let normal = self.cut_normal();
        // Per unit thickness; cuts are D apart along the sheet, D·cos(angle)
        // apart along their normal.
        let drift = inside.dot(normal).abs() / inside.z;
        let q = drift / (self.ratio * self.angle.cos());
        let cos_at_cut = inside.dot(normal).abs();
        let p = fresnel_slit(self.index, cos_at_cut);
        // Meeting n cuts, each reflecting with p: odd reflections deflect.
        let odd = |n: f64| 0.5 * (1.0 - (1.0 - 2.0 * p).powf(n));
        let (low, frac) = (q.floor(), q.fract());
        let deflected = (1.0 - frac) * odd(low) + frac * odd(low + 1.0);
        (1.0 - deflected, deflected)
    }
}

/// Share of light reflected by a thin air slit in a sheet of `index`, met
/// at `cos_incidence`: all of it beyond the critical angle, else the two
/// faces' Fresnel reflections with their interreflection (2R / (1 + R)).
fn fresnel_slit(index: f64, cos_incidence: f64) -> f64 {
    let r = fresnel_reflectance(index, 1.0, cos_incidence);
    if r >= 1.0 { 1.0 } else { 2.0 * r / (1.0 + r) }
}

impl PanelModel for LaserCutModel {
    fn response(&self, incoming: DVec3) -> PanelResponse {
        let incoming = incoming.normalize();
        let mut response = PanelResponse::default();
        if incoming.z <= 0.0 {
            return response;
        }
        let outer = fresnel_reflectance(1.0, self.index, incoming.z);
        let mirror = reflect(incoming, DVec3::Z);
        let Some(inside) = refract(incoming, DVec3::Z, 1.0, self.index) else { return response };
        let (straight, deflected) = self.deflection(inside);
        let mut reflected = outer;
        for (share, direction) in [(straight, inside), (deflected, reflect(inside, self.cut_normal()))] {
            let share = share * (1.0 - outer);
            if share <= 0.0 {
                continue;
            }
            match refract(direction, DVec3::Z, self.index, 1.0) {
                Some(out) if direction.z > 0.0 => {
                    let inner = fresnel_reflectance(self.index, 1.0, direction.z);
                    response.lobes.push(Lobe { direction: out, share: share * (1.0 - inner), width: LOBE_WIDTH });
                    reflected += share * inner;
                }
                // Turned back or trapped by the inner face: back outside.
                _ => reflected += share,
            }
        }
        response.lobes.push(Lobe { direction: mirror, share: reflected, width: LOBE_WIDTH });
        response.lobes.retain(|l| l.share > 0.0);
        response.lobes.sort_by(|a, b| b.share.total_cmp(&a.share));
        response
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from_above(altitude: f64) -> DVec3 {
        DVec3::new(0.0, -altitude.to_radians().sin(), altitude.to_radians().cos())
    }

    #[test]
    fn a_high_sun_is_deflected_upward_by_total_internal_reflection() {
        // D/W = 0.5, cuts perpendicular. Sun 60° high: inside the sheet
        // (n = 1.49) the ray is 35.6° from the normal, so it drifts
        // tan 35.6° = 0.716 W across the cuts: q = 1.43; it meets the cuts
        // at 54.4° incidence, beyond the critical angle (42.2°), so each cut
        // it meets reflects it: 43% meet two (undeflected), 57% one.
        let panel = LaserCutModel { ratio: 0.5, angle: 0.0, index: 1.49 };
        let inside = 60f64.to_radians().sin() / 1.49;
        let q = inside.asin().tan() / 0.5;
        assert!((q - 1.433).abs() < 0.01, "{q}");
        let response = panel.response(from_above(60.0));
        let up: f64 = response.lobes.iter().filter(|l| l.direction.z > 0.0 && l.direction.y > 0.0).map(|l| l.share).sum();
        let down: f64 = response.lobes.iter().filter(|l| l.direction.z > 0.0 && l.direction.y < 0.0).map(|l| l.share).sum();
        let faces =
            (1.0 - fresnel_reflectance(1.0, 1.49, 60f64.to_radians().cos())) * (1.0 - fresnel_reflectance(1.49, 1.0, inside.asin().cos()));
        assert!((up - (2.0 - q) * faces).abs() < 0.01, "deflected up {up}");
        assert!((down - (q - 1.0) * faces).abs() < 0.01, "undeflected {down}");
        // The deflected lobe leaves mirrored: 60° up into the room.
        let lobe = response.lobes.iter().find(|l| l.direction.y > 0.0 && l.direction.z > 0.0).unwrap();
        assert!((lobe.direction.y.asin().to_degrees() - 60.0).abs() < 1e-6);
    }

    #[test]
    fn low_sun_passes_and_energy_is_conserved() {
        let panel = LaserCutModel { ratio: 0.5, angle: 0.0, index: 1.49 };
        // Straight on, nothing crosses a cut.
        let r = panel.response(DVec3::Z);
        assert!(r.lobes.iter().all(|l| l.direction.y.abs() < 1e-9));
        for (ratio, angle) in [(0.5, 0.0), (0.2, 10.0), (2.0, -20.0)] {
            let panel = LaserCutModel { ratio, angle: f64::to_radians(angle), index: 1.49 };
            for altitude in [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 89.0] {
                for azimuth in [0.0, 40.0] {
                    let d = (from_above(altitude) + DVec3::X * f64::to_radians(azimuth).tan()).normalize();
                    let r = panel.response(d);
                    let total = r.total() + r.absorbed;
                    assert!((total - 1.0).abs() < 1e-9, "D/W {ratio} angle {angle} alt {altitude}: {total}");
                }
            }
        }
    }

    #[test]
    fn keys_are_checked() {
        assert_eq!(heliodon_core::panel::check_keys(LaserCut.keys()), Ok(()));
        let build = |text: &str| LaserCut.build(&Parameters::from_toml(text, "").unwrap());
        assert!(build("cut_spacing_ratio = 0.5").is_ok());
        assert!(LaserCut.build(&Parameters::new(heliodon_core::panel::default_values(LaserCut.keys()), "")).is_ok());
        assert_eq!(build("").unwrap_err().key, "cut_spacing_ratio");
        assert_eq!(build("cut_spacing_ratio = 0.5\ncut_angle = 80.0").unwrap_err().key, "cut_angle");
    }
}
