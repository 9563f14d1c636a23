//! Deterministic sampling: a small counter-based generator seeded per
//! receiver (so results do not depend on thread count or order), stratified
//! cosine-weighted hemisphere directions, and points on triangles.

use glam::DVec3;

/// SplitMix64: tiny, fast and good enough for stratified jitter.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator for receiver `index` of kind `stream` (patches, sensors, ...).
    pub fn new(stream: u64, index: u64) -> Self {
        Self(stream.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03) ^ 0x5851_F42D_4C95_7F2D)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// An orthonormal frame around a unit normal.
pub fn frame(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let u = n.cross(helper).normalize();
    (u, n.cross(u))
}

/// `count` cosine-weighted directions about `n`, stratified on a grid of
/// about √count × √count cells (the remainder jittered at random).
pub fn cosine_directions(n: DVec3, count: usize, rng: &mut Rng) -> Vec<DVec3> {
    let (u, v) = frame(n);
    let side = (count as f64).sqrt().floor().max(1.0) as usize;
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let (a, b) = if k < side * side {
            (((k / side) as f64 + rng.next_f64()) / side as f64, ((k % side) as f64 + rng.next_f64()) / side as f64)
        } else {
            (rng.next_f64(), rng.next_f64())
        };
        // Malley: uniform on the disc, lifted to the hemisphere.
        let r = a.sqrt();
        let phi = 2.0 * std::f64::consts::PI * b;
        let (x, y) = (r * phi.cos(), r * phi.sin());
        out.push(u * x + v * y + n * (1.0 - a).max(0.0).sqrt());
    }
    out
}

/// A uniformly distributed point on a triangle from two uniform numbers.
pub fn point_on_triangle(t: &[DVec3; 3], a: f64, b: f64) -> DVec3 {
    let s = a.sqrt();
    t[0] * (1.0 - s) + t[1] * (s * (1.0 - b)) + t[2] * (s * b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_directions_are_unit_and_cosine_weighted() {
        let mut rng = Rng::new(1, 2);
        let dirs = cosine_directions(DVec3::Z, 4096, &mut rng);
        assert!(dirs.iter().all(|d| (d.length() - 1.0).abs() < 1e-9 && d.z >= 0.0));
        // E[cos θ] under cosine weighting is 2/3.
        let mean = dirs.iter().map(|d| d.z).sum::<f64>() / dirs.len() as f64;
        assert!((mean - 2.0 / 3.0).abs() < 2e-3, "{mean}");
    }

    #[test]
    fn generators_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..4).map(|_| Rng::new(3, 9).next_u64()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        assert_ne!(Rng::new(3, 9).next_u64(), Rng::new(3, 10).next_u64());
    }
}
