//! Direct sun and panel beams, by shadow rays: the sun through glass
//! (Radiance's transmittance at each pane's angle, every pane crossed), and
//! each panel lobe as a fake sun ([`SunBeam`]) whose light must leave
//! through a window of its panel group that the real sun reaches. Evaluated
//! per relight, never cached: the sun moves.

use glam::DVec3;

use super::bvh::ParallelHits;
use super::measured::MeasuredSun;
use super::openings::{OpeningsAlong, WayIn};
use super::panels::{self, SunBeam};
use super::sampling::{Rng, sample_area, stratified_area_points};
use super::{LightModel, SURFACE_OFFSET, Surface, par_map};
use crate::sky::SunSource;

/// The sun's beams on every patch side, and where they may land.
pub(super) struct SidesSun {
    /// Beam irradiance (W/m²) of each side, averaged over its sun samples.
    pub(super) irradiance: Vec<f64>,
    /// How beams may reach each side ([`super::openings`]).
    pub(super) reach: SidesReach,
}

/// How beams may reach each patch side, with a dense mark of the sides
/// they reach at all: each sensor's first bounce walks its landings' sides
/// (hundreds an hour), and most are dark.
pub(super) struct SidesReach {
    reach: Vec<Reach>,
    reached: Vec<bool>,
}

impl SidesReach {
    fn new(reach: Vec<Reach>) -> Self {
        let reached = reach.iter().map(|r| *r != Reach::None).collect();
        Self { reach, reached }
    }

    /// How beams may reach `side`; `None` when not at all.
    fn get(&self, side: usize) -> Option<&Reach> {
        self.reached[side].then(|| &self.reach[side])
    }
}

/// How the beams may reach a patch side.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Reach {
    /// Not at all: facing away, or enclosed with no window toward a beam.
    None,
    /// From anywhere: the side sees the open sky.
    Open(Shadows),
    /// Only by these windows.
    Through(Vec<WayIn>, Shadows),
}

/// Per beam, the triangles its rays may meet on their way from anywhere on
/// a side ([`Tracer::parallel_hits`]): a beam's rays from a side are
/// parallel, so they test those alone instead of each traversing the BVH.
/// `None` for a beam the side faces away from or whose rays may meet more
/// than [`SHADOW_CANDIDATES`]; empty: none kept.
///
/// [`Tracer::parallel_hits`]: super::bvh::Tracer::parallel_hits
pub(super) type Shadows = Box<[Option<ParallelHits>]>;

/// Beam `b`'s parallel hits in `shadows`, where kept.
fn beam_shadows(shadows: &Shadows, b: usize) -> Option<&ParallelHits> {
    shadows.get(b).and_then(Option::as_ref)
}

/// The beams the sensors' direct sun follows (those measured data does not
/// cover) and their ways in ([`LightModel::sensors_sun`]).
pub(super) struct SensorsSun<'a> {
    beams: Vec<SunBeam>,
    along: OpeningsAlong<'a>,
    measured: &'a MeasuredSun,
}

/// The random stream of a patch side's sun points (`sun_on_sides`),
/// which the gather also draws to find those inside a solid.
pub(super) const SUN_POINTS_STREAM: u64 = 3;

/// The fewest rays along a beam (sun samples, and the sensors' landings
/// where their first bounce reads the side) for which a side finds its
/// [`Shadows`]: the traversal costs about as much as a dozen rays, the sun
/// path gives sides few sensors care for 8 samples, and many sides catch a
/// few of the sensors' rays. On AC20-Institute-Var-2 with one office's
/// sensors, finding them for every side made a year's sun path a third of
/// the study.
const SHADOWS_FROM_RAYS: usize = 16;

/// The most corners of a patch [`LightModel::sun_reaches_some_point`] asks.
const PROBED_CORNERS: usize = 8;
/// The points spread over a patch it asks besides.
const PROBED_POINTS: usize = 16;

/// The most triangles a beam's rays from a side test one by one (three
/// dot products each, where a traversal of the BVH costs a ray about as
/// much as fifty). (ExampleHOM's cold year, whose open rooms' landings meet
/// many triangles along the beam: 44.5 s at 32, 36.5 s at 64, 35.2 s at
/// 128; FZK-Haus's office 4.56 s at 32 and 64, 4.78 s at 128; hourly values
/// identical.)
const SHADOW_CANDIDATES: usize = 64;

impl LightModel {
    /// The beams' irradiance at `point` of a side they `reach`: every beam
    /// on an open side; on an enclosed one only the beams whose ray may
    /// pass one of their windows (the others are blocked: not traced).
    fn reaching_irradiance(&self, reach: &Reach, point: DVec3, normal: DVec3, beams: &[SunBeam]) -> f64 {
        let origin = point + normal * SURFACE_OFFSET;
        match reach {
            Reach::None => 0.0,
            Reach::Open(shadows) => {
                beams.iter().enumerate().map(|(b, beam)| self.beam_irradiance(origin, normal, beam, beam_shadows(shadows, b))).sum()
            }
            Reach::Through(ways, shadows) => self
                .openings
                .beams_reaching(point, ways)
                .map(|b| self.beam_irradiance(origin, normal, &beams[b], beam_shadows(shadows, b)))
                .sum(),
        }
    }
}

impl LightModel {
    /// Direct sun irradiance (W/m²) at `point` on a surface side with
    /// `normal`: shadow rays through glass toward the sun, and through panel
    /// windows along their lobes. For many points, get the beams once
    /// ([`Self::sun_beams`]) and use [`Self::beams_irradiance`].
    pub fn sun_irradiance(&self, point: DVec3, normal: DVec3, sun: &SunSource) -> f64 {
        self.beams_irradiance(point, normal, &self.sun_beams(sun))
    }

    /// How much of the sun reaches `point` (through glass; 0 when blocked).
    pub(super) fn sun_transmittance(&self, point: DVec3, sun: DVec3) -> f64 {
        self.through_glass(None, point, sun, f64::INFINITY, |_| false).unwrap_or(0.0)
    }

    /// The product of the glass a ray crosses before `t_max`; `None` when
    /// anything else stops it first, but what `passes` lets through. The
    /// product does not depend on the order of the panes, so one traversal
    /// visits them all and stops at the first stop; with the ray's parallel
    /// hits (`among`, [`Shadows`]) it tests those alone.
    pub(super) fn through_glass(
        &self,
        among: Option<&ParallelHits>,
        origin: DVec3,
        direction: DVec3,
        t_max: f64,
        passes: impl Fn(Surface) -> bool,
    ) -> Option<f64> {
        let mut transmittance = Some(1.0);
        // Glass surfaces crossed, by distance: a ray through the edge between
        // two triangles of one surface meets it twice.
        // (A few at most: kept on the stack, shadow rays are many.)
        let mut crossed = [(u32::MAX, 0.0); 16];
        let mut count = 0;
        let visit = |hit: super::bvh::Hit| {
            let (surface, normal) = (hit.patch, self.scene.surfaces[hit.patch as usize].normal);
            match self.surface_kind(surface) {
                Surface::Glass(glass) => {
                    if !crossed[..count].iter().any(|&(s, d)| s == surface && (d - hit.distance).abs() < 1e-5) {
                        crossed[count.min(15)] = (surface, hit.distance);
                        count = (count + 1).min(16);
                        transmittance = transmittance.map(|t| t * glass_transmittance(glass, direction.dot(normal.as_dvec3())));
                    }
                    true
                }
                kind if passes(kind) => true,
                // Through a panel the sun arrives only along its lobes.
                Surface::Diffuse(_) | Surface::Panel(_) => {
                    transmittance = None;
                    false
                }
            }
        };
        match among {
            Some(hits) => hits.each_hit(origin, 1e-6, t_max, visit),
            None => self.shadow_tracer.each_hit(origin, direction, 1e-6, t_max, visit),
        }
        transmittance
    }

    /// How much of a panel lobe's light reaches `point` from `to_light`:
    /// the ray must leave through a window of the lobe's panel group (glass
    /// on the way counts), and from there the real sun (`window_sun`; `None`:
    /// the windows taken as sunlit) must reach it. `among`: the lobe's
    /// parallel hits from around `point`, when kept ([`Shadows`]).
    fn lobe_transmittance(
        &self,
        point: DVec3,
        to_light: DVec3,
        group: u32,
        window_sun: Option<DVec3>,
        among: Option<&ParallelHits>,
    ) -> f64 {
        self.reaches_panel(among, point, to_light, group).map_or(0.0, |(at, transmittance)| {
            transmittance * window_sun.map_or(1.0, |sun| self.sun_transmittance(at + sun * SURFACE_OFFSET, sun))
        })
    }

    /// The beams of direct sunlight for a sun: itself and its panel lobes.
    pub fn sun_beams(&self, sun: &SunSource) -> Vec<SunBeam> {
        if sun.direction.z <= 0.0 {
            return Vec::new();
        }
        panels::sun_beams(&self.panel_groups, sun)
    }

    /// Shadow rays toward the sun from a patch side: its share of
    /// `sun_samples_per_patch` by where it lies, as its gather's rays
    /// ([`crate::scene::PatchSizing::ray_share`]). The sun on a side far
    /// from the sensors reaches them only through bounces that average many
    /// sides: AC20-Institute-Var-2 with one office's sensors relights
    /// 70 ms sooner (2 cores), its readings within 0.04%.
    pub(super) fn sun_samples(&self, side: usize) -> usize {
        let full = self.settings.sun_samples_per_patch;
        ((full as f64 * self.ray_shares[side / 2]).ceil() as usize).clamp(1, full)
    }

    /// The beams on every diffuse patch side: shadow rays from `samples(side)`
    /// stratified seeded points of each side (0: not traced) that faces a beam and
    /// that a beam may reach (`threads` as [`par_map`]). With
    /// `for_first_bounce` (the sensors' first bounce will read the reach),
    /// it keeps its [`Shadows`] on the sides where sensors' rays land and
    /// drops the others': a relight of a large model holds them for a few
    /// sides, not all.
    pub(super) fn sun_on_sides(
        &self,
        beams: &[SunBeam],
        samples: &(dyn Fn(usize) -> usize + Sync),
        for_first_bounce: bool,
        threads: Option<usize>,
    ) -> SidesSun {
        let patches = &self.scene.patches.patches;
        let landed = if for_first_bounce { self.landings_on_sides() } else { &[] };
        let along = self.openings.along(beams);
        let sides: Vec<(f64, Reach)> = par_map(threads, patches.len() * 2, |side| {
            let n = samples(side);
            let landings = landed.get(side).map_or(0, |&l| l as usize);
            let keep = landings > 0;
            let reach = if n == 0 { Reach::None } else { self.side_reach(side, beams, &along, n + landings >= SHADOWS_FROM_RAYS) };
            if reach == Reach::None {
                return (0.0, reach);
            }
            let triangles = self.patch_triangles(side / 2);
            let mut rng = Rng::seeded(SUN_POINTS_STREAM, self.settings.seed, side as u64);
            let normal = self.side_normal(side as u32);
            let total: f64 =
                stratified_area_points(&triangles, n, &mut rng).map(|point| self.reaching_irradiance(&reach, point, normal, beams)).sum();
            let reach = match reach {
                _ if keep => reach,
                Reach::Open(_) => Reach::Open(Shadows::default()),
                Reach::Through(ways, _) => Reach::Through(ways, Shadows::default()),
                Reach::None => Reach::None,
            };
            // The mean over the part of the side the room sees
            // (`Gather::buried`, found on the `sun_samples` points: exact
            // for those, an estimate for the sun path's other counts).
            (total / n as f64 / self.side_gathers[side].visible(), reach)
        });
        let (irradiance, reach) = sides.into_iter().unzip();
        SidesSun { irradiance, reach: SidesReach::new(reach) }
    }

    /// How beams may reach the sides where sensors' rays land (none
    /// elsewhere), without tracing: for the sensors' first bounce.
    pub(super) fn sides_reach(&self, beams: &[SunBeam], threads: Option<usize>) -> SidesReach {
        let (landed, along) = (self.landings_on_sides(), self.openings.along(beams));
        SidesReach::new(par_map(threads, self.side_gathers.len(), |side| match landed[side] as usize {
            0 => Reach::None,
            landings => self.side_reach(side, beams, &along, landings >= SHADOWS_FROM_RAYS),
        }))
    }

    /// How `beams` (seen `along` them) may reach `side`, with its
    /// [`Shadows`] when `shadows`.
    fn side_reach(&self, side: usize, beams: &[SunBeam], along: &OpeningsAlong, shadows: bool) -> Reach {
        if beams.is_empty() || self.side_reflectance(side).is_none() {
            return Reach::None;
        }
        let normal = self.side_normal(side as u32);
        // A side open only by its space, with many points to trace, first
        // asks a few whether the sun comes in at all.
        let open_here = || !shadows || self.sees_open_sky(&self.side_gathers[side]) || self.sun_reaches_some_point(side, normal, beams);
        if !beams.iter().any(|b| normal.dot(b.to_light) > 0.0) {
            Reach::None
        } else if self.side_is_open(side) && open_here() {
            Reach::Open(self.side_shadows(side, normal, beams, shadows))
        } else {
            match along.ways_in(side / 2) {
                ways if ways.is_empty() => Reach::None,
                ways => Reach::Through(ways, self.side_shadows(side, normal, beams, shadows)),
            }
        }
    }

    /// Whether the sun itself reaches a few points of `side`'s patch: its
    /// corners (pulled a tenth toward its middle), its middle and
    /// [`PROBED_POINTS`] spread over it. A side open only by its space takes
    /// the sun through an opening a doorway wide, whose sun patch on it
    /// covers some of them; the landings and samples of a side the sun
    /// misses are not traced hour by hour. ExampleHOM's year: 66 → 37 s
    /// (before the spaces 28 s), its readings at an instant 0.05% lower on
    /// average (at most 0.55%); with the corners and middle alone 32 s and
    /// 0.3% lower (at most 4%).
    fn sun_reaches_some_point(&self, side: usize, normal: DVec3, beams: &[SunBeam]) -> bool {
        let patch = &self.scene.patches.patches[side / 2];
        let middle = patch.centroid.as_dvec3();
        let mut corners: Vec<DVec3> = Vec::new();
        let vertices = self.scene.patches.triangles[patch.triangle_indices()].iter().flatten();
        for vertex in vertices.map(|v| v.as_dvec3()) {
            if corners.len() == PROBED_CORNERS {
                break;
            }
            if !corners.iter().any(|c| c.distance_squared(vertex) < 1e-8) {
                corners.push(vertex);
            }
        }
        // The spread points are drawn only if no corner nor the middle sees the sun.
        let triangles = std::cell::OnceCell::new();
        let mut rng = Rng::seeded(5, self.settings.seed, side as u64);
        let spread = std::iter::repeat_with(|| sample_area(triangles.get_or_init(|| self.patch_triangles(side / 2)), &mut rng));
        let probes = corners.into_iter().map(|c| c + (middle - c) * 0.1).chain(std::iter::once(middle)).chain(spread.take(PROBED_POINTS));
        let sun: Vec<&SunBeam> = beams.iter().filter(|b| b.panel_group.is_none() && normal.dot(b.to_light) > 0.0).collect();
        probes.map(|p| p + normal * SURFACE_OFFSET).any(|p| sun.iter().any(|beam| self.beam_irradiance(p, normal, beam, None) > 0.0))
    }

    /// The triangles each beam's rays from `side` may meet ([`Shadows`]);
    /// none kept unless `wanted`.
    fn side_shadows(&self, side: usize, normal: DVec3, beams: &[SunBeam], wanted: bool) -> Shadows {
        if !wanted {
            return Shadows::default();
        }
        // Rays leave a side's points (its landings among them) lifted by the offset.
        let (lo, hi) = self.patch_boxes[side / 2].bounds();
        let (lo, hi) = (lo - DVec3::splat(SURFACE_OFFSET), hi + DVec3::splat(SURFACE_OFFSET));
        let faced = |beam: &SunBeam| normal.dot(beam.to_light) > 0.0;
        let shadows = |beam: &SunBeam| self.shadow_tracer.parallel_hits(lo, hi, beam.to_light, SHADOW_CANDIDATES);
        beams.iter().map(|beam| if faced(beam) { shadows(beam) } else { None }).collect()
    }

    /// The sensors' direct sun from `beams`, made once for all of them:
    /// through panels with measured transmission their data (`measured`,
    /// [`Self::measured_sun`] of the same beams) in place of their beams.
    pub(super) fn sensors_sun<'a>(&'a self, beams: &[SunBeam], measured: &'a MeasuredSun) -> SensorsSun<'a> {
        let beams: Vec<SunBeam> = beams.iter().filter(|b| !measured.covers(b.panel_group)).copied().collect();
        SensorsSun { along: self.openings.along(&beams), beams, measured }
    }

    /// Sensor `index`'s direct sun (W/m², averaged over its sun points).
    /// An enclosed sensor (neither its rays nor the sides they met with no
    /// window between are open to the sky) is traced only along beams that
    /// may pass a window, as sides are.
    pub(super) fn sensor_direct_sun(&self, index: usize, sun: &SensorsSun) -> f64 {
        let through_data: f64 = self.sensor_measured_sun(index, sun.measured).iter().map(|w| w.1).sum();
        let beams = &sun.beams[..];
        let geometry = &self.sensors[index];
        let reach = if self.open_sensors[index] || beams.is_empty() {
            Reach::Open(Shadows::default())
        } else {
            let centre = geometry.sun_points.iter().sum::<DVec3>() / geometry.sun_points.len() as f64;
            let radius = geometry.sun_points.iter().map(|p| p.distance(centre)).fold(0.0, f64::max);
            Reach::Through(sun.along.ways_into_sphere(centre, radius), Shadows::default())
        };
        let total: f64 = geometry.sun_points.iter().map(|&p| self.reaching_irradiance(&reach, p, geometry.normal, beams)).sum();
        total / geometry.sun_points.len() as f64 + through_data
    }

    /// The first bounce of the beams off the sides sensor `index`'s rays
    /// meet (RGB W/m², evaluated where each ray lands), given how beams
    /// `reach` each side.
    pub(super) fn sensor_sun_bounce(&self, index: usize, beams: &[SunBeam], reach: &SidesReach) -> [f64; 3] {
        let geometry = &self.sensors[index];
        let mut bounce = [0.0; 3];
        for (side, shares, points) in geometry.landings.by_side() {
            let Some(reach) = reach.get(side as usize) else { continue };
            let Some(rho) = self.side_reflectance(side as usize) else { continue };
            let (normal, patch_box) = (self.side_normal(side), &self.patch_boxes[side as usize / 2]);
            for (share, grid) in shares.zip(points) {
                let point = patch_box.point(grid, normal);
                let e = self.reaching_irradiance(reach, point, normal, beams);
                if e > 0.0 {
                    for (b, r) in bounce.iter_mut().zip(rho) {
                        *b += f64::from(share) * r * e;
                    }
                }
            }
        }
        bounce
    }

    /// Direct sun irradiance (W/m²) from all `beams` at `point` on a surface
    /// side with `normal`.
    pub fn beams_irradiance(&self, point: DVec3, normal: DVec3, beams: &[SunBeam]) -> f64 {
        self.reaching_irradiance(&Reach::Open(Shadows::default()), point, normal, beams)
    }

    /// One beam's irradiance at `origin` (already off its surface); the
    /// sun's own beam tests only the triangles `among` when given ([`Shadows`]).
    fn beam_irradiance(&self, origin: DVec3, normal: DVec3, beam: &SunBeam, among: Option<&ParallelHits>) -> f64 {
        let cos = normal.dot(beam.to_light);
        if cos <= 0.0 {
            return 0.0;
        }
        let reach = match beam.panel_group {
            None => self.through_glass(among, origin, beam.to_light, f64::INFINITY, |_| false).unwrap_or(0.0),
            Some(group) => self.lobe_transmittance(origin, beam.to_light, group, beam.window_sun, among),
        };
        beam.normal_irradiance * cos * reach
    }

    /// Sensor `index`'s direct sun (W/m², averaged over its sun points) by
    /// the window it comes through last (index into [`Scene::windows`];
    /// `None`: straight from the sky).
    ///
    /// [`Scene::windows`]: crate::scene::Scene::windows
    pub fn sensor_sun_by_window(&self, index: usize, beams: &[SunBeam], measured: &MeasuredSun) -> Vec<(Option<u32>, f64)> {
        let geometry = &self.sensors[index];
        let mut by_window: Vec<(Option<u32>, f64)> =
            self.sensor_measured_sun(index, measured).into_iter().map(|(window, e)| (Some(window), e)).collect();
        let share = 1.0 / geometry.sun_points.len() as f64;
        for &point in &geometry.sun_points {
            let origin = point + geometry.normal * SURFACE_OFFSET;
            for beam in beams.iter().filter(|b| !measured.covers(b.panel_group)) {
                let e = self.beam_irradiance(origin, geometry.normal, beam, None);
                if e > 0.0 {
                    let hit = self.shadow_tracer.closest(origin, beam.to_light, 1e-6);
                    let window = hit.and_then(|h| self.window_of_surface[h.patch as usize]);
                    match by_window.iter_mut().find(|w| w.0 == window) {
                        Some(entry) => entry.1 += e * share,
                        None => by_window.push((window, e * share)),
                    }
                }
            }
        }
        by_window
    }
}

/// [`super::glass::Glass::at`]'s transmittance, remembered per thread for
/// the last few panes and angles: one hour's shadow rays cross the same
/// panes at the same angle thousands of times (the power in it is most of
/// a shadow ray's own arithmetic).
fn glass_transmittance(glass: super::glass::Glass, cos: f64) -> f64 {
    thread_local! {
        static LAST: std::cell::Cell<[(u64, u64, f64); 4]> = const { std::cell::Cell::new([(u64::MAX, u64::MAX, 0.0); 4]) };
    }
    let key = (glass.transmissivity.to_bits(), cos.to_bits());
    LAST.with(|last| {
        let mut entries = last.get();
        if let Some(&(_, _, t)) = entries.iter().find(|e| (e.0, e.1) == key) {
            return t;
        }
        let t = glass.at(cos).0;
        entries.rotate_right(1);
        entries[0] = (key.0, key.1, t);
        last.set(entries);
        t
    })
}
