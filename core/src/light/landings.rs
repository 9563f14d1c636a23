//! Where a sensor's first rays land: the points the sun's first bounce is
//! evaluated at for that sensor ([`super::sun`]), kept per sensor from the
//! gather to every relight and in the light cache.
//!
//! They are most of a sensor's memory and of a large model's cache file (a
//! few thousand per sensor), so they are kept small: a run per patch side,
//! the landings' shares run-length coded (most are one ray's, 1/rays: as
//! a float each, they were 148 MB of Revit's Office_A's 10,244 sensors), each
//! point in 16 bits per axis of its patch's box ([`PatchBox`]). The point is stored so as soon as the ray
//! lands, so a fresh gather and a cached one use the very same points.

use glam::{DVec3, Vec3};

/// A patch's bounding box, where its landings are stored in 16 bits per axis
/// (a 4 m patch to 0.06 mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PatchBox {
    lo: Vec3,
    /// One step of the 16-bit grid per axis (zero along a flat axis).
    step: Vec3,
}

impl PatchBox {
    const STEPS: f32 = u16::MAX as f32;

    /// The box around `triangles`.
    pub(super) fn around(triangles: &[[Vec3; 3]]) -> Self {
        let (lo, hi) = triangles.iter().flatten().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        Self { lo, step: (hi - lo) / Self::STEPS }
    }

    /// `point` (in the box) on the grid.
    fn grid(&self, point: DVec3) -> [u16; 3] {
        let relative = (point.as_vec3() - self.lo) / self.step;
        let axis = |r: f32, step: f32| if step > 0.0 { r.round().clamp(0.0, Self::STEPS) as u16 } else { 0 };
        [axis(relative.x, self.step.x), axis(relative.y, self.step.y), axis(relative.z, self.step.z)]
    }

    /// The box's corners, grown by the most a landing is lifted off its
    /// patch ([`Self::point`]): every landing lies within.
    pub(super) fn bounds(&self) -> (DVec3, DVec3) {
        let lift = 0.5 * self.step.length();
        let hi = self.lo + self.step * Self::STEPS;
        ((self.lo - lift).as_dvec3(), (hi + lift).as_dvec3())
    }

    /// A grid point, lifted off the patch's side along `normal` by as much as
    /// the grid may have moved it (half a step's diagonal) so it never falls
    /// behind the surface (a shadow ray from there would meet the patch).
    pub(super) fn point(&self, grid: [u16; 3], normal: DVec3) -> DVec3 {
        let on_grid = self.lo + Vec3::from_array(grid.map(f32::from)) * self.step;
        on_grid.as_dvec3() + normal * f64::from(0.5 * self.step.length())
    }
}

/// A run of landings: its side and where its landings end.
pub(super) type Run = (u32, u32);

/// Landings in a row with one share: how many, and the share.
pub(super) type Repeat = (u32, f32);

/// A sensor's landings on patch sides, a run per side in side order.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Landings {
    runs: Vec<Run>,
    /// Each landing's share of the sensor's irradiance (the ray's weight
    /// over the rays traced), in landing order as repeats.
    shares: Vec<Repeat>,
    /// Each landing's point on its side's [`PatchBox`] grid.
    points: Vec<[u16; 3]>,
}

impl Landings {
    /// `(side, share, point)` landings, stored on the grids of `boxes`
    /// (per patch; a side's patch is `side / 2`).
    pub(super) fn new(mut landings: Vec<(u32, f32, DVec3)>, boxes: &[PatchBox]) -> Self {
        landings.sort_by_key(|l| l.0);
        let mut runs: Vec<Run> = Vec::new();
        for (k, &(side, _, _)) in landings.iter().enumerate() {
            match runs.last_mut() {
                Some(run) if run.0 == side => run.1 = k as u32 + 1,
                _ => runs.push((side, k as u32 + 1)),
            }
        }
        let mut shares: Vec<Repeat> = Vec::new();
        for &(_, share, _) in &landings {
            match shares.last_mut() {
                Some((count, value)) if value.to_bits() == share.to_bits() => *count += 1,
                _ => shares.push((1, share)),
            }
        }
        let points = landings.iter().map(|&(side, _, point)| boxes[side as usize / 2].grid(point)).collect();
        Self { runs, shares, points }
    }

    /// The runs: each side with its landings' shares and grid points.
    pub(super) fn by_side(&self) -> impl Iterator<Item = (u32, Shares<'_>, &[[u16; 3]])> {
        let mut next = Shares { repeats: &self.shares, used: 0, left: 0 };
        let mut start = 0;
        self.runs.iter().map(move |&(side, end)| {
            let run = Shares { left: end - start, ..next.clone() };
            next.advance(end - start);
            let points = &self.points[start as usize..end as usize];
            start = end;
            (side, run, points)
        })
    }

    /// Whether every side named is below `sides`.
    pub(super) fn fits(&self, sides: u32) -> bool {
        self.runs.iter().all(|r| r.0 < sides)
    }

    /// Its runs (each side and where its landings end), shares (repeats)
    /// and grid points, as the cache stores them.
    pub(super) fn parts(&self) -> (&[Run], &[Repeat], &[[u16; 3]]) {
        (&self.runs, &self.shares, &self.points)
    }

    /// Landings from their parts; `None` unless the runs go up by side and
    /// end, the last at the shares' (no repeat empty) and points' count.
    pub(super) fn from_parts(runs: Vec<Run>, shares: Vec<Repeat>, points: Vec<[u16; 3]>) -> Option<Self> {
        let ordered = runs.windows(2).all(|w| w[0].0 < w[1].0 && w[0].1 < w[1].1) && runs.first().is_none_or(|r| r.1 > 0);
        let shared = shares.iter().try_fold(0usize, |sum, &(count, _)| (count > 0).then(|| sum + count as usize));
        let complete = runs.last().map_or(0, |r| r.1 as usize) == points.len() && shared == Some(points.len());
        (ordered && complete).then_some(Self { runs, shares, points })
    }
}

/// The shares of a run of landings, one by one off the repeats.
#[derive(Debug, Clone)]
pub(super) struct Shares<'a> {
    /// The repeats from the one holding the next share.
    repeats: &'a [Repeat],
    /// How many of the first repeat's are behind.
    used: u32,
    /// How many shares are left in the run.
    left: u32,
}

impl Shares<'_> {
    /// Moves on by `n` shares.
    fn advance(&mut self, mut n: u32) {
        while let Some(&(count, _)) = self.repeats.first() {
            if self.used + n < count {
                self.used += n;
                return;
            }
            n -= count - self.used;
            (self.repeats, self.used) = (&self.repeats[1..], 0);
        }
    }
}

impl Iterator for Shares<'_> {
    type Item = f32;

    fn next(&mut self) -> Option<f32> {
        let &(_, share) = self.repeats.first().filter(|_| self.left > 0)?;
        self.left -= 1;
        self.advance(1);
        Some(share)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left as usize, Some(self.left as usize))
    }
}

impl ExactSizeIterator for Shares<'_> {}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tilted 5 m patch: a landing comes back within the grid's step, on
    /// the sunny side of the surface, never behind it.
    #[test]
    fn a_landing_comes_back_where_it_was_never_behind_its_surface() {
        let (a, b, c) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 0.0, 1.0), Vec3::new(0.0, 4.0, 3.0));
        let boxes = [PatchBox::around(&[[a, b, c]])];
        let normal = (b - a).cross(c - a).normalize().as_dvec3();
        let on_it = |u: f64, v: f64| a.as_dvec3() + (b - a).as_dvec3() * u + (c - a).as_dvec3() * v;
        let points: Vec<DVec3> = (0..50).map(|k| on_it(0.009 * k as f64, 0.011 * k as f64)).collect();
        let landings = Landings::new(points.iter().map(|&p| (0, 0.25, p)).collect(), &boxes);
        let (_, shares, grid) = landings.by_side().next().unwrap();
        assert_eq!(shares.len(), 50);
        for (&point, &q) in points.iter().zip(grid) {
            let back = boxes[0].point(q, normal);
            let above = (back - point).dot(normal);
            assert!(above > 0.0 && above < 2e-4, "{above}");
            assert!((back - point).length() < 2e-4);
        }
    }
}
