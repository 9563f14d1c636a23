//! Where a sensor's first rays land: the points the sun's first bounce is
//! evaluated at for that sensor ([`super::sun`]), kept per sensor from the
//! gather to every relight and in the light cache.
//!
//! They are most of a sensor's memory and of a large model's cache file (a
//! few thousand per sensor), so they are kept small: a run per patch side,
//! the landings' shares run-length coded (most are one ray's, 1/rays: as
//! a float each, they were 148 MB of Revit's Office_A's 10,244 sensors), each
//! point in 16 bits per axis of its patch's box ([`PatchBox`]), the axes a
//! run's points share (on a patch square to an axis, as most of a
//! building's are, one of the three) held once for the run. The point is
//! stored so as soon as the ray lands, so a fresh gather and a cached one
//! use the very same points.

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
    pub(super) fn grid(&self, point: DVec3) -> [u16; 3] {
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
    /// Per run, the grid coordinates its points share ([`RunPoints`]).
    run_points: Vec<RunPoints>,
    /// Each landing's other coordinates on its side's [`PatchBox`] grid,
    /// in landing order, ascending axes.
    coords: Vec<u16>,
}

/// What a run's points share: the axes (bit k for axis k) whose coordinate
/// is the same for all of them, and those coordinates (0 on the others).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct RunPoints {
    pub(super) shared: u8,
    pub(super) first: [u16; 3],
}

impl RunPoints {
    /// What `points` share.
    fn of(points: &[[u16; 3]]) -> Self {
        let mut run = Self::default();
        for axis in 0..3 {
            if points.iter().all(|p| p[axis] == points[0][axis]) {
                run.shared |= 1 << axis;
                run.first[axis] = points[0][axis];
            }
        }
        run
    }

    /// The axes a point holds on its own, ascending.
    pub(super) fn own_axes(self) -> impl Iterator<Item = usize> {
        (0..3).filter(move |&axis| self.shared & (1 << axis) == 0)
    }
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
        let points: Vec<[u16; 3]> = landings.iter().map(|&(side, _, point)| boxes[side as usize / 2].grid(point)).collect();
        let (mut run_points, mut coords, mut start) = (Vec::with_capacity(runs.len()), Vec::new(), 0);
        for &(_, end) in &runs {
            let run = RunPoints::of(&points[start..end as usize]);
            for point in &points[start..end as usize] {
                coords.extend(run.own_axes().map(|axis| point[axis]));
            }
            run_points.push(run);
            start = end as usize;
        }
        Self { runs, shares, run_points, coords }
    }

    /// The runs: each side with its landings' shares and grid points.
    pub(super) fn by_side(&self) -> impl Iterator<Item = (u32, Shares<'_>, Points<'_>)> {
        let mut next = Shares { repeats: &self.shares, used: 0, left: 0 };
        let lengths =
            std::iter::once(0).chain(self.runs.iter().map(|r| r.1)).zip(&self.runs).map(|(start, &(side, end))| (side, end - start));
        lengths.zip(self.run_coordinates()).map(move |((side, length), (run, coords))| {
            let shares = Shares { left: length, ..next.clone() };
            next.advance(length);
            (side, shares, Points { run, coords, left: length })
        })
    }

    /// Per run, what its points share and their own coordinates (as the
    /// cache stores them).
    pub(super) fn run_coordinates(&self) -> impl Iterator<Item = (RunPoints, &[u16])> {
        let mut rest = &self.coords[..];
        let starts = std::iter::once(0).chain(self.runs.iter().map(|r| r.1));
        starts.zip(&self.runs).zip(&self.run_points).map(move |((start, &(_, end)), &run)| {
            let (own, after) = rest.split_at((end - start) as usize * run.own_axes().count());
            rest = after;
            (run, own)
        })
    }

    /// Whether every side named is below `sides`.
    pub(super) fn fits(&self, sides: u32) -> bool {
        self.runs.iter().all(|r| r.0 < sides)
    }

    /// Its runs (each side and where its landings end) and shares
    /// (repeats), as the cache stores them; the points are
    /// [`Self::run_coordinates`].
    pub(super) fn parts(&self) -> (&[Run], &[Repeat]) {
        (&self.runs, &self.shares)
    }

    /// Landings from their parts; `None` unless the runs go up by side and
    /// end, the last at the shares' count (no repeat empty), and the
    /// coordinates are those the runs' points hold on their own.
    pub(super) fn from_parts(runs: Vec<Run>, shares: Vec<Repeat>, run_points: Vec<RunPoints>, coords: Vec<u16>) -> Option<Self> {
        let ordered = runs.windows(2).all(|w| w[0].0 < w[1].0 && w[0].1 < w[1].1) && runs.first().is_none_or(|r| r.1 > 0);
        let total = runs.last().map_or(0, |r| r.1 as usize);
        let shared = shares.iter().try_fold(0usize, |sum, &(count, _)| (count > 0).then(|| sum + count as usize));
        let starts = std::iter::once(0).chain(runs.iter().map(|r| r.1));
        let own: usize =
            starts.zip(&runs).zip(&run_points).map(|((start, &(_, end)), run)| (end - start) as usize * run.own_axes().count()).sum();
        let complete = shared == Some(total) && run_points.len() == runs.len() && own == coords.len();
        (ordered && complete && run_points.iter().all(|r| r.shared < 8)).then_some(Self { runs, shares, run_points, coords })
    }
}

/// The grid points of a run of landings, one by one off what the run's
/// points share and their own coordinates.
#[derive(Debug, Clone)]
pub(super) struct Points<'a> {
    run: RunPoints,
    coords: &'a [u16],
    /// How many points are left in the run.
    left: u32,
}

impl Iterator for Points<'_> {
    type Item = [u16; 3];

    fn next(&mut self) -> Option<[u16; 3]> {
        self.left = self.left.checked_sub(1)?;
        let mut point = self.run.first;
        let (these, rest) = self.coords.split_at_checked(self.run.own_axes().count())?;
        self.run.own_axes().zip(these).for_each(|(axis, &c)| point[axis] = c);
        self.coords = rest;
        Some(point)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left as usize, Some(self.left as usize))
    }
}

impl ExactSizeIterator for Points<'_> {}

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
        assert_eq!((shares.len(), grid.len()), (50, 50));
        for (&point, q) in points.iter().zip(grid) {
            let back = boxes[0].point(q, normal);
            let above = (back - point).dot(normal);
            assert!(above > 0.0 && above < 2e-4, "{above}");
            assert!((back - point).length() < 2e-4);
        }
    }
}
