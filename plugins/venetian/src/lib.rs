//! Venetian blinds for heliodon: slats across the window, mirrored or
//! diffuse. Light is traced through one period of the slat array in the
//! profile plane (slats are long, so a ray's component along them never
//! changes): a beam spread evenly over the period enters from outside, and
//! each ray passes between the slats or meets them, where a share is
//! reflected specularly (and traced on), a share diffusely and the rest
//! absorbed. Specular paths end in lobes: the direct pass and even bounces
//! keep the incoming direction, odd bounces leave mirrored about the slats.
//! Light from the room meets the slats as light from outside meets slats
//! tilted the other way (the window's plane mirrors the profile), and under
//! light from the whole hemisphere those return what the slats themselves
//! do (mirroring up and down turns the tilt over too): the back reflectance
//! is the share of diffuse light from outside the slats send back.
//!
//! Scene-file keys (`kind = "panel"`, `panel = "venetian"`): `slat_width`
//! and `slat_spacing` (m), `tilt` (degrees, −89 to 89; positive turns a
//! slat's outer edge down), `specular` and `diffuse` reflectances (their
//! sum at most 1).

use std::sync::Arc;

use heliodon_core::glam::DVec3;
use heliodon_core::panel::{Key, Lobe, PanelModel, PanelResponse, PanelType, ParameterError, Parameters, reflect};

/// The `venetian` panel type.
pub struct Venetian;

impl PanelType for Venetian {
    fn name(&self) -> &str {
        "venetian"
    }

    fn keys(&self) -> &[Key] {
        &[SLAT_WIDTH, SLAT_SPACING, TILT, SPECULAR, DIFFUSE]
    }

    fn build(&self, parameters: &Parameters) -> Result<Arc<dyn PanelModel>, ParameterError> {
        let width = parameters.number(&SLAT_WIDTH)?;
        let spacing = parameters.number(&SLAT_SPACING)?;
        let tilt = parameters.number(&TILT)?;
        let specular = parameters.number(&SPECULAR)?;
        let diffuse = parameters.number(&DIFFUSE)?;
        if specular + diffuse > 1.0 {
            return Err(ParameterError::new(DIFFUSE.name, format!("specular + diffuse = {} is more than 1", specular + diffuse)));
        }
        Ok(Arc::new(VenetianModel::new(width, spacing, tilt.to_radians(), specular, diffuse)))
    }
}

const SLAT_WIDTH: Key = Key::number("slat_width", "slat depth across the window (m)", (1e-3, 1.0), 0.025).required();
const SLAT_SPACING: Key = Key::number("slat_spacing", "vertical distance between slats (m)", (1e-3, 1.0), 0.0225).required();
const TILT: Key = Key::number("tilt", "slat tilt from horizontal (°)", (-89.0, 89.0), 0.0);
const SPECULAR: Key = Key::number("specular", "mirror reflectance of the slats", (0.0, 1.0), 0.9).required();
const DIFFUSE: Key = Key::number("diffuse", "diffuse reflectance of the slats", (0.0, 1.0), 0.05).required();

/// Rays traced through one period (evenly spaced: shares come in steps of 1/128).
const RAYS: usize = 128;
/// Bounces followed per ray; what is left is counted absorbed.
const MAX_BOUNCES: usize = 32;
/// Nominal angular width of a lobe (degrees): slats are never perfect mirrors.
const LOBE_WIDTH: f64 = 2.0;

/// Blinds with their slats.
#[derive(Debug, Clone)]
pub struct VenetianModel {
    width: f64,
    spacing: f64,
    /// Radians; positive turns the outer edge down.
    tilt: f64,
    specular: f64,
    diffuse: f64,
    /// Share of the room's diffuse light sent back into it.
    back_reflectance: f64,
}

/// Directions per axis of the hemisphere the back reflectance is averaged over.
const HEMISPHERE_STEPS: usize = 24;

impl VenetianModel {
    fn new(width: f64, spacing: f64, tilt: f64, specular: f64, diffuse: f64) -> Self {
        let mut model = Self { width, spacing, tilt, specular, diffuse, back_reflectance: 0.0 };
        model.back_reflectance = model.hemispherical_reflectance();
        model
    }

    /// What the slats send back out of light arriving evenly (diffusely)
    /// from outside: the mean reflected share over directions of equal
    /// projected solid angle (sin²θ and φ in even steps).
    fn hemispherical_reflectance(&self) -> f64 {
        let n = HEMISPHERE_STEPS;
        let total: f64 = (0..n * 2 * n)
            .map(|k| {
                let (sin, phi) =
                    ((((k / (2 * n)) as f64 + 0.5) / n as f64).sqrt(), std::f64::consts::PI * ((k % (2 * n)) as f64 + 0.5) / n as f64);
                let r = self.response(DVec3::new(sin * phi.cos(), sin * phi.sin(), (1.0 - sin * sin).sqrt()));
                r.diffuse_reflectance + r.lobes.iter().filter(|l| l.direction.z < 0.0).map(|l| l.share).sum::<f64>()
            })
            .sum();
        total / (2 * n * n) as f64
    }

    /// Unit vector along a slat from its outer to its inner edge, and the
    /// slat's normal, in the profile plane (y up, z into the room).
    fn slat_axes(&self) -> (DVec3, DVec3) {
        let along = DVec3::new(0.0, self.tilt.sin(), self.tilt.cos());
        (along, DVec3::new(0.0, along.z, -along.y))
    }

    /// How far a ray from `origin` along `direction` goes before it meets
    /// a slat, if it does.
    fn first_hit(&self, origin: DVec3, direction: DVec3) -> Option<f64> {
        let (along, normal) = self.slat_axes();
        let half = self.width / 2.0;
        let depth = half * along.z.abs() + 1e-9;
        // The ray crosses the slat band |z| ≤ depth between these distances.
        let (t0, t1) = if direction.z.abs() < 1e-12 {
            (0.0, f64::INFINITY)
        } else {
            let (a, b) = ((-depth - origin.z) / direction.z, (depth - origin.z) / direction.z);
            (a.min(b).max(0.0), a.max(b))
        };
        if t1 <= t0 {
            return None;
        }
        let (y0, y1) = (origin.y + direction.y * t0, origin.y + direction.y * t1.min(1e3));
        let reach = half * along.y.abs() + 1e-9;
        let denominator = direction.dot(normal);
        if denominator.abs() < 1e-12 {
            return None;
        }
        let hit = |k: i64| {
            let centre = DVec3::new(0.0, k as f64 * self.spacing, 0.0);
            let t = (centre - origin).dot(normal) / denominator;
            let along_slat = (origin + direction * t - centre).dot(along);
            (t > 1e-9 && along_slat.abs() <= half).then_some(t)
        };
        // Slats in the order the ray passes them; the first hit, checked
        // against the next slat (tilted slats overlap in height), is the nearest.
        let step: i64 = if direction.y >= 0.0 { 1 } else { -1 };
        let first = ((y0 - step as f64 * reach) / self.spacing).floor() as i64 - step;
        let last = ((y1 + step as f64 * reach) / self.spacing).floor() as i64 + 2 * step;
        let mut k = first;
        while (last - k) * step >= 0 {
            if let Some(t) = hit(k) {
                return Some(hit(k + step).map_or(t, |u| t.min(u)));
            }
            k += step;
        }
        None
    }
}

impl PanelModel for VenetianModel {
    fn response(&self, incoming: DVec3) -> PanelResponse {
        let incoming = incoming.normalize();
        let mut response = PanelResponse::default();
        if incoming.z <= 0.0 {
            return response;
        }
        let (along, normal) = self.slat_axes();
        let start_z = -(self.width / 2.0) * along.z.abs() - 1e-6;
        let weight = 1.0 / RAYS as f64;
        let add_lobe = |direction: DVec3, share: f64, response: &mut PanelResponse| match response
            .lobes
            .iter_mut()
            .find(|l| l.direction.angle_between(direction) < 1e-6)
        {
            Some(lobe) => lobe.share += share,
            None => response.lobes.push(Lobe { direction, share, width: LOBE_WIDTH }),
        };
        for k in 0..RAYS {
            let mut origin = DVec3::new(0.0, (k as f64 + 0.5) / RAYS as f64 * self.spacing, start_z);
            let mut direction = incoming;
            let mut w = weight;
            let mut bounces = 0;
            loop {
                match self.first_hit(origin, direction) {
                    None => {
                        add_lobe(direction, w, &mut response);
                        break;
                    }
                    Some(t) => {
                        // Diffuse light off a slat goes either way about equally.
                        response.diffuse_transmittance += 0.5 * w * self.diffuse;
                        response.diffuse_reflectance += 0.5 * w * self.diffuse;
                        response.absorbed += w * (1.0 - self.specular - self.diffuse);
                        w *= self.specular;
                        bounces += 1;
                        if bounces >= MAX_BOUNCES || w < 1e-9 {
                            response.absorbed += w;
                            break;
                        }
                        origin += direction * t;
                        direction = reflect(direction, normal);
                    }
                }
            }
        }
        response.lobes.sort_by(|a, b| b.share.total_cmp(&a.share));
        response
    }

    fn back_reflectance(&self) -> f64 {
        self.back_reflectance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(width: f64, spacing: f64, tilt: f64, specular: f64, diffuse: f64) -> VenetianModel {
        VenetianModel::new(width, spacing, f64::to_radians(tilt), specular, diffuse)
    }

    fn from_above(altitude: f64) -> DVec3 {
        DVec3::new(0.0, -altitude.to_radians().sin(), altitude.to_radians().cos())
    }

    /// Slats return the room's light as their geometry says: closed
    /// mirror slats send most of it back (over half; interreflection between
    /// the overlapping slats absorbs some); thin open slats little; and
    /// slats tilted either way alike (the geometry's mirror in y).
    #[test]
    fn slats_return_the_rooms_light_as_their_geometry_says() {
        let closed = model(0.025, 0.0225, 80.0, 0.9, 0.05);
        assert!(closed.back_reflectance > 0.5, "{}", closed.back_reflectance);
        let open = model(0.002, 0.05, 0.0, 0.9, 0.05);
        assert!(open.back_reflectance < 0.05, "{}", open.back_reflectance);
        let (up, down) = (model(0.025, 0.0225, 30.0, 0.9, 0.05), model(0.025, 0.0225, -30.0, 0.9, 0.05));
        assert!((up.back_reflectance - down.back_reflectance).abs() < 1e-3, "{} vs {}", up.back_reflectance, down.back_reflectance);
        assert!(up.back_reflectance > open.back_reflectance && up.back_reflectance < closed.back_reflectance);
    }

    #[test]
    fn horizontal_slats_pass_and_mirror_as_worked_by_hand() {
        // Slats 25 mm wide every 22.5 mm, horizontal; sun 30° high. A ray
        // falls w·tan 30° = 14.43 mm across a slat's depth, so 14.43/22.5 =
        // 64.2% of the beam meets a slat top and 35.8% passes straight.
        let blinds = model(0.025, 0.0225, 0.0, 0.9, 0.0);
        let response = blinds.response(from_above(30.0));
        let straight: f64 = response.lobes.iter().filter(|l| l.direction.angle_between(from_above(30.0)) < 1e-6).map(|l| l.share).sum();
        let mirrored = from_above(30.0) * DVec3::new(1.0, -1.0, 1.0);
        let up: f64 = response.lobes.iter().filter(|l| l.direction.angle_between(mirrored) < 1e-6).map(|l| l.share).sum();
        let hit = 0.025 * 30f64.to_radians().tan() / 0.0225;
        assert!((straight - (1.0 - hit)).abs() < 0.01, "straight {straight}");
        // Mirrored once, upward to the ceiling: 90% of what met a slat.
        assert!((up - 0.9 * hit).abs() < 0.01, "up {up}");
        assert!((response.absorbed - 0.1 * hit).abs() < 0.01);
    }

    #[test]
    fn closed_slats_block_and_energy_is_conserved() {
        let closed = model(0.025, 0.0225, 80.0, 0.9, 0.05);
        assert!(closed.response(from_above(10.0)).transmitted() < 0.3);
        for (tilt, specular, diffuse) in [(0.0, 0.9, 0.05), (30.0, 0.5, 0.4), (-45.0, 0.0, 0.8), (70.0, 0.95, 0.0)] {
            let blinds = model(0.025, 0.0225, tilt, specular, diffuse);
            for altitude in [0.0, 20.0, 45.0, 70.0] {
                for azimuth in [0.0, 50.0] {
                    let d = from_above(altitude) + DVec3::X * f64::to_radians(azimuth).tan();
                    let r = blinds.response(d.normalize());
                    let total = r.total() + r.absorbed;
                    assert!((total - 1.0).abs() < 0.01, "tilt {tilt} alt {altitude} az {azimuth}: {total}");
                }
            }
        }
    }

    #[test]
    fn keys_are_checked() {
        assert_eq!(heliodon_core::panel::check_keys(Venetian.keys()), Ok(()));
        let build = |text: &str| Venetian.build(&Parameters::from_toml(text, "").unwrap());
        let ok = "slat_width = 0.025\nslat_spacing = 0.0225\ntilt = 30.0\nspecular = 0.9\ndiffuse = 0.05";
        assert!(build(ok).is_ok());
        assert!(Venetian.build(&Parameters::new(heliodon_core::panel::default_values(Venetian.keys()), "")).is_ok());
        assert_eq!(build(&ok.replace("diffuse = 0.05", "diffuse = 0.5")).unwrap_err().key, "diffuse");
        assert_eq!(build(&ok.replace("tilt = 30.0", "tilt = 95.0")).unwrap_err().key, "tilt");
        assert_eq!(build("tilt = 1.0").unwrap_err().key, "slat_width");
    }
}
