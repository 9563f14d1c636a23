//! Radiance's `glass` material (rt/glass.c): a thin pane of index 1.52 whose
//! transmission and reflection depend on the angle of incidence, with the
//! internal reflections between its two faces summed.

/// Refractive index of clear glazing.
const INDEX: f64 = 1.52;

/// A glass pane, from its transmittance at normal incidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glass {
    /// Radiance's transmissivity tn (what its `glass` takes).
    pub transmissivity: f64,
}

impl Glass {
    /// Glass of visible transmittance `transmittance` at normal incidence
    /// (Radiance's conversion to transmissivity, n = 1.52).
    pub fn from_transmittance(transmittance: f64) -> Self {
        let t = transmittance.clamp(1e-9, 1.0);
        let tn = ((0.840_252_843_5 + 0.007_252_223_9 * t * t).sqrt() - 0.916_653_066_1) / 0.003_626_111_9 / t;
        Self { transmissivity: tn.max(1e-15) }
    }

    /// (transmittance, reflectance) for a ray meeting the pane at `cos_incidence` (either side).
    pub fn at(&self, cos_incidence: f64) -> (f64, f64) {
        let c1 = cos_incidence.abs().max(1e-6);
        let c2 = ((1.0 - 1.0 / (INDEX * INDEX)) + c1 * c1 / (INDEX * INDEX)).sqrt();
        let d = self.transmissivity.powf(1.0 / c2);
        let r1e = ((c1 - INDEX * c2) / (c1 + INDEX * c2)).powi(2);
        let r1m = ((1.0 / c1 - INDEX / c2) / (1.0 / c1 + INDEX / c2)).powi(2);
        let transmit = |r: f64| 0.5 * (1.0 - r) * (1.0 - r) * d / (1.0 - r * r * d * d);
        let reflect = |r: f64| 0.5 * r * (1.0 + (1.0 - 2.0 * r) * d * d) / (1.0 - r * r * d * d);
        (transmit(r1e) + transmit(r1m), reflect(r1e) + reflect(r1m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_gives_back_the_transmittance() {
        for t in [0.6, 0.7, 0.88] {
            let glass = Glass::from_transmittance(t);
            assert!((glass.at(1.0).0 - t).abs() < 1e-4, "{t}: {:?}", glass.at(1.0));
        }
        // Radiance: "The transmissivity of standard 88% transmittance glass is 0.96".
        assert!((Glass::from_transmittance(0.88).transmissivity - 0.96).abs() < 0.002);
        // About 8% reflected at normal incidence (the contract).
        let (_, r) = Glass::from_transmittance(0.88).at(1.0);
        assert!((r - 0.08).abs() < 0.005, "{r}");
    }

    #[test]
    fn grazing_light_is_reflected() {
        let glass = Glass::from_transmittance(0.88);
        let (t60, _) = glass.at(60f64.to_radians().cos());
        let (t85, r85) = glass.at(85f64.to_radians().cos());
        assert!(t60 < 0.88 && t85 < t60 && r85 > 0.5);
    }
}
