//! The gather: from every side of every diffuse patch and from every
//! sensor, cosine-weighted hemisphere rays are followed through glass until
//! they reach a diffuse patch side (a **form factor**: the share of the
//! receiver's view that side fills) or leave the model (a **daylight
//! coefficient**: the share that a sky or ground bin fills, keyed by the
//! window the ray first crossed, see [`SkyKey`]). Both are stored sparse, as
//! `(index, share)` rows of [`Gather`]. Done once per geometry; each
//! receiver has its own seeded generator, so results do not depend on
//! threads.

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec3;

use super::bvh::Tracer;
use super::landings::Landings;
use super::openings::{LEAST_JOINING_SHARE, SPACE_MEMBER, Spaces};
use super::sampling::{self, Rng, cosine_directions, sample_area, stratified_area_points, with_cumulative_areas};
use super::sun::SUN_POINTS_STREAM;
use super::{LightModel, LightSettings, MAX_GLASS_DEPTH, MIN_WEIGHT, SURFACE_OFFSET, Surface, par_map, side_of};
use crate::parallel::par_join;
use crate::scene::{Patch, Scene, Sensor};

/// The memory the gathers may take, MiB: `$HELIODON_MEMORY_MB`, else 8 GiB.
pub fn memory_budget_mib() -> u64 {
    std::env::var("HELIODON_MEMORY_MB").ok().and_then(|v| v.trim().parse::<u64>().ok()).unwrap_or(8192)
}

/// Refuses, before any ray is traced, a precomputation whose gathers could
/// outgrow the memory budget: at most 8 bytes per patch-side ray and 28 per
/// sensor ray (a share, and where the ray landed).
pub(super) fn check_memory(scene: &Scene, settings: &LightSettings) -> Result<(), String> {
    let sides = 2.0 * scene.patches.patches.len() as f64 * settings.rays_per_patch as f64 * 8.0;
    // Only the first `rays_per_sensor` rays' landings are kept; the rest of a
    // sensor's sky rays live while it gathers.
    let sensors = scene.sensors.len() as f64 * settings.rays_per_sensor as f64 * 28.0;
    let (need, budget) = ((sides + sensors) / 1048576.0, memory_budget_mib() as f64);
    if need > budget {
        return Err(format!(
            "{}: {} sensors and {} patches could need {:.1} GiB of light data, more than the {:.1} GiB allowed (HELIODON_MEMORY_MB): use fewer sensors (a wider grid spacing) or a larger patch_size",
            scene.files.scene.display(),
            scene.sensors.len(),
            scene.patches.patches.len(),
            need / 1024.0,
            budget / 1024.0
        ));
    }
    Ok(())
}

/// Sensors closer than this to a surface behind them read as lifted this far.
pub(super) const SENSOR_LIFT: f64 = 0.01;

/// Rays that tell a patch's point inside a solid from a seam a ray
/// slipped through ([`LightModel::is_buried`]).
const BURIED_PROBES: usize = 3;

/// Rays from each sensor that find the patch sides it sees
/// ([`LightModel::probe_sensors`]).
const SEEN_PROBE_RAYS: usize = 256;

/// A sensor that sees a little sky no aimed ray draws (some of its probe
/// rays, at most [`LITTLE_UNAIMED_SKY`] of them) traces this many sets of
/// its hemisphere rays for the sky and form factors: the sky through an
/// opening no window fills (or a window not aimed at) comes by them alone,
/// and deep in a room it is a few of them. (bim2sim's 3 rooms, an L-shaped
/// room open to the outside, overcast: readings' spread over seeds 1.7 →
/// 1.4% with the edges retraced, against rtrace median 1.85 → 1.23%, p90
/// 5.7 → 3.7%; cold `sensors` 1.0 → 1.8 s. Rooms lit through glass keep
/// 1 set.)
const UNAIMED_SKY_SETS: usize = 4;
/// Of a sensor's [`SEEN_PROBE_RAYS`], the most that may reach the sky no
/// aimed ray draws for it to see a little of it: a sensor seeing much of it
/// (outdoors) draws it with little noise already.
const LITTLE_UNAIMED_SKY: usize = SEEN_PROBE_RAYS / 8;

/// What each sensor's probe rays met ([`LightModel::probe_sensors`]).
struct Probes {
    /// Per patch side: the largest share of one sensor's view it fills (of
    /// that sensor's probe rays, the share that met it; 0: no sensor sees it).
    view: Vec<f64>,
    /// Per sensor, for each of its probe rays that reached the sky (not
    /// turned back by glass), the window it crossed first, if any.
    sky_through: Vec<Vec<Option<u32>>>,
}

/// How many bounces a patch side's light is from the sensors, which sets
/// the share of its rays it traces: 0 for a side a sensor sees
/// ([`LightModel::probe_sensors`]), k for one that a side k − 1 bounces
/// away gathers from, [`Sight::FARTHER`] for the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Sight(u8);

impl Sight {
    const SEEN: Sight = Sight(0);
    /// Beyond this many steps the share stops falling.
    const FARTHER: Sight = Sight(3);

    /// The share of its rays a side traces: all when seen, and more where
    /// it fills much of a sensor's `view` ([`rays_for_view`]); else the
    /// `unseen` share once per bounce farther from the sensors (twice that
    /// one bounce away, [`ONE_BOUNCE_FACTOR`]), and no more than the share
    /// `where_it_lies` ([`crate::scene::PatchSizing::ray_share`]); an unseen
    /// side smaller than a finest patch (`wide` < 1) traces that times its
    /// area in finest patches, down to [`SMALLEST_SIDE_SHARE`] of it, but
    /// no less than the farthest sides do.
    fn ray_share(self, where_it_lies: f64, unseen: f64, view: f64, wide: f64) -> f64 {
        match self {
            Sight::SEEN => rays_for_view(view),
            Sight(steps) => {
                let nearer = if steps == 1 { ONE_BOUNCE_FACTOR } else { 1.0 };
                let share = where_it_lies.min((unseen.powi(i32::from(steps)) * nearer).min(1.0));
                let farthest = share.min(unseen.powi(i32::from(Sight::FARTHER.0)));
                (share * wide.clamp(SMALLEST_SIDE_SHARE, 1.0)).max(farthest)
            }
        }
    }

    /// Per patch side: seen where some sensor's `view` holds it, else
    /// farther until a gather nearer names it ([`Sight::mark_named`]).
    fn from_view(view: &[f64]) -> Vec<Sight> {
        view.iter().map(|&share| if share > 0.0 { Sight::SEEN } else { Sight::FARTHER }).collect()
    }

    /// The sides `step` bounces from the sensors.
    fn sides_at(sight: &[Sight], step: u8) -> Vec<usize> {
        (0..sight.len()).filter(|&side| sight[side] == Sight(step)).collect()
    }

    /// Marks the sides that `gather`, of a side `step` bounces from the
    /// sensors, names as a bounce farther, where no nearer gather did.
    fn mark_named(sight: &mut [Sight], step: u8, gather: &Gather) {
        // What the last steps name is farther anyway.
        if step + 1 < Sight::FARTHER.0 {
            for &(next, _) in &gather.form_factors {
                if sight[next as usize] == Sight::FARTHER {
                    sight[next as usize] = Sight(step + 1);
                }
            }
        }
    }
}

/// A side one bounce from the sensors traces this many times the unseen
/// share: its light reaches every reading after one reflection off the
/// seen sides, and its noise with it. (SampleHouse, six seeds: the
/// readings' spread 1.44 → 1.01% under a clear sky, 1.24 → 0.99%
/// overcast, the mean of the six against rtrace p90 over the five real
/// models' 823 sensors 3.59 → 3.28%; cold `sensors` 3-10% longer: FZK-Haus
/// 3.09 → 3.39 s, the furnished floor 5.31 → 5.85 s.)
const ONE_BOUNCE_FACTOR: f64 = 2.0;

/// An unseen side smaller than a finest patch traces its share of the
/// rays in proportion to its area, down to this share of it: its light
/// reaches the readings through the sides that gather it, weighted by its
/// area there, so its noise averages out with that of its neighbours. (A
/// clutter cluster of a few square centimetres traced what a wall's
/// half-metre square did.) FZK-Haus, SampleHouse and the Duplex cold
/// `sensors` 3.33 → 2.96 s, 2.40 → 1.97 s and 4.02 → 3.50 s; the readings'
/// spread over six seeds as before (SampleHouse 1.01 → 1.05% clear, 0.99 →
/// 0.94% overcast, FZK-Haus 1.46% either way); seen sides keep their rays,
/// as a reading takes their noise straight. (Seen sides so reduced too:
/// the spread grew 5-10%.)
const SMALLEST_SIDE_SHARE: f64 = 1.0 / 16.0;

/// Of a sensor's view, the share a side may fill and trace the usual rays
/// (four of a sensor's 256 probe rays).
const USUAL_VIEW_SHARE: f64 = 1.0 / 64.0;
/// The most rays a side a sensor sees traces, in units of the usual.
const MOST_RAYS_SEEN: f64 = 16.0;

/// The rays a side filling `view` of some sensor's view traces, in units of
/// `rays_per_patch`: view / [`USUAL_VIEW_SHARE`], at least 1 and at most
/// [`MOST_RAYS_SEEN`]. A reading is the sum of its sides' light weighted by
/// the share of its view each fills, so a side's noise reaches it in that
/// share, squared in its variance; for a given number of rays in all, a
/// reading's variance is least with each side's rays in proportion to its
/// share (Neyman's allocation), not its square, which spent them on the few
/// sides filling an eighth of a view or more (a sensor under a roof's
/// slope in SampleHouse's attic saw 95% of one side, whose 256 rays met a
/// sunlit eave outside through a seam once in some seeds and not in
/// others: it read 35, 36, 73, 35 and 38 lx over five seeds). A side's
/// noise also reaches a reading back and forth between it and the sides
/// near it, where a row of form factors estimated by few rays meets itself
/// (the mean of a square is more than the square of the mean): the rooms
/// seen through a few large sides read high. With the share linear (1/8
/// squared before), four real models' 823 referenced sensors in six cases
/// against rtrace, single seeds, median/p90 1.04/4.34 → 0.90/3.66%, the
/// mean of six seeds' p90 3.21 → 2.65%; FZK-Haus's gallery +2.85 → +2.35%
/// clear, +2.32 → +1.74% overcast, ExampleHOM's children's rooms +1.7 →
/// +1.0-1.2%, the 3 rooms' L +1.05 → 0.01%; cold `sensors` 10-21% longer on
/// whole houses (SampleHouse 1.90 → 2.29 s), as before on one office's
/// sensors. A side wider than a finest patch fills more of a view and so
/// traces more: a tall room's ceiling, coarser 2 m above its grid
/// (`PatchSizing`), is as smooth to the sensors as its finest patches
/// were (the furnished floor's readings, three seeds: their spread 0.91%
/// rms with finest patches, 1.21% coarser with the usual rays), while the
/// far ground seen through a window, wide but a sliver of a view, keeps
/// the usual rays.
fn rays_for_view(view: f64) -> f64 {
    (view / USUAL_VIEW_SHARE).clamp(1.0, MOST_RAYS_SEEN)
}

/// Where a receiver's hemisphere light comes from: the **daylight
/// coefficients** (bins of the sky sphere, each through the window it was
/// seen through, see [`SkyKey`]) and the **form factors** (patch sides),
/// each with its share (the shares of all rays sum to at most 1). Shares
/// through glass carry the glass's transmittance.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Gather {
    /// Packed [`SkyKey`]s with their shares, sorted by key.
    pub daylight_coefficients: Vec<(u32, f32)>,
    /// Patch sides ([`side_of`]) with their shares, sorted by side.
    pub form_factors: Vec<(u32, f32)>,
    /// The share of a patch side's sun points inside a solid (under a face
    /// resting on it that cut no patch there: a tile, a skirting board, a
    /// slab through a wall), where no light reaches, so that its sun
    /// (`sun_on_sides`) is the mean over the rest, the part the room sees,
    /// as the shares above are (their rays from such points are left out).
    /// Found where the side's rays met a solid's inside and the sky; 0 for
    /// sensors.
    pub buried: f32,
}

/// A sky or ground bin as a receiver sees it: straight (no window between,
/// `window: None`) or through the first window its ray crossed. Packed into
/// one `u32` as `slot · bin_count + bin`, slot 0 for none and `k + 1` for
/// window `k` of [`Scene::windows`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkyKey {
    /// The first window the ray crossed (index into [`Scene::windows`]), if any.
    pub window: Option<u32>,
    /// Index into the sky sphere's bins ([`SkyPatches::sphere_bin`]).
    pub bin: u32,
}

impl SkyKey {
    pub(super) fn pack(self, bin_count: u32) -> u32 {
        self.window.map_or(0, |w| w + 1) * bin_count + self.bin
    }

    pub(super) fn unpack(key: u32, bin_count: u32) -> Self {
        let slot = key / bin_count;
        Self { window: slot.checked_sub(1), bin: key % bin_count }
    }
}

/// A window that patch sides aim rays at (see `gather_patch_side`).
struct WindowTarget {
    /// Index into [`Scene::windows`].
    window: u32,
    /// Its triangles with their cumulative areas.
    triangles: Vec<([DVec3; 3], f64)>,
    centroid: DVec3,
    normal: DVec3,
    /// m².
    area: f64,
    /// The diagonal of its box, m.
    size: f64,
}

/// A window a patch side aims rays at, with the odds of picking it.
struct Aim {
    /// Index into the targets.
    target: usize,
    odds: f64,
    /// Within the window's size or the patch's ([`WindowTarget::aim`]).
    near: bool,
}

/// What a receiver aims rays at, and how many.
#[derive(Clone, Copy)]
struct Aiming<'a> {
    /// The receiver's normal.
    normal: DVec3,
    aimed: &'a [Aim],
    targets: &'a [WindowTarget],
    /// Rays aimed.
    rays: usize,
    /// Hemisphere rays the receiver's coefficients are counted in.
    hemisphere: usize,
}

/// Where a receiver's aimed rays start.
#[derive(Clone, Copy)]
enum Eyes<'a> {
    /// Points spread by area over a patch side's triangles (with their
    /// cumulative areas), lifted off it.
    Spread { triangles: &'a [([DVec3; 3], f64)], lift: DVec3 },
    /// A sensor's measuring points, taken in turn: a near window's
    /// triangles' solid angles from each are found once, not per ray.
    Fixed(&'a [DVec3]),
}

/// How far in front of a patch side (m) a vertex of a window must lie for
/// the side to aim at it: a wall around its own window sees none of it.
const WINDOW_IN_FRONT: f64 = 1e-4;

impl WindowTarget {
    /// The solid angle each of its triangles fills seen from `eye`.
    fn solid_angles(&self, eye: DVec3) -> impl Iterator<Item = f64> + '_ {
        self.triangles.iter().map(move |t| sampling::solid_angle(eye, &t.0))
    }

    /// A direction from `eye` toward the window and the solid angle its
    /// pdf is one over. From afar, a point drawn on the window by area
    /// (pdf r²/(A cos)); near it, where that weight would swing with 1/r²,
    /// a direction drawn evenly over the solid angle of one of its
    /// triangles, picked by solid angle with `within` (a stratified
    /// uniform number); `seen`: those solid angles, where already found.
    /// `None` where the window fills no solid angle.
    fn aim(&self, eye: DVec3, near: bool, within: f64, seen: Option<&[f64]>, rng: &mut Rng) -> Option<(DVec3, f64)> {
        if !near {
            let to = sample_area(&self.triangles, rng) - eye;
            let r2 = to.length_squared();
            let dir = to / r2.sqrt();
            return Some((dir, self.area * self.normal.dot(dir).abs() / r2));
        }
        let found: Vec<f64>;
        let solid_angles = match seen {
            Some(seen) => seen,
            None => {
                found = self.solid_angles(eye).collect();
                &found
            }
        };
        let total: f64 = solid_angles.iter().sum();
        if total <= 0.0 {
            return None;
        }
        let mut pick = within * total;
        let (index, share) = solid_angles
            .iter()
            .enumerate()
            .find(|&(_, &omega)| {
                pick -= omega;
                pick <= 0.0 && omega > 0.0
            })
            .map_or((solid_angles.len() - 1, 1.0), |(i, &omega)| (i, ((pick + omega) / omega).clamp(0.0, 1.0)));
        Some((sampling::direction_in_triangle(eye, &self.triangles[index].0, share, rng.next_f64()), total))
    }
}

/// What a followed ray met on its way to the sky.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Way {
    /// The first window it crossed.
    window: Option<u32>,
    /// Whether glass turned it back on the way: a path the aimed rays
    /// cannot draw, left to the hemisphere rays.
    reflected: bool,
}

impl Way {
    const START: Self = Self { window: None, reflected: false };
}

/// A ray that reached a diffuse patch side.
#[derive(Debug, Clone, Copy, PartialEq)]
struct SideHit {
    side: u32,
    weight: f64,
    point: DVec3,
    /// Whether the ray crossed a window on its way.
    through_window: bool,
}

/// The sides `hits` (of `rays` rays) met crossing no window, each once,
/// where they are at least [`LEAST_JOINING_SHARE`] of the rays: what joins
/// a side to its space ([`Spaces`]).
fn unglazed_sides(hits: &[SideHit], rays: usize) -> Vec<u32> {
    let mut sides: Vec<u32> = hits.iter().filter(|h| !h.through_window).map(|h| h.side).collect();
    sides.sort_unstable();
    let least = (LEAST_JOINING_SHARE * rays as f64).ceil() as usize;
    sides.chunk_by(|a, b| a == b).filter(|run| run.len() >= least).map(|run| run[0]).collect()
}

impl Gather {
    /// The share of the side's area the room sees (see [`Self::buried`]).
    pub fn visible(&self) -> f64 {
        1.0 - f64::from(self.buried)
    }

    fn from_raw(mut coefficients: Vec<(u32, f64)>, hits: &[SideHit], rays: usize) -> Self {
        let mut sides: Vec<(u32, f64)> = hits.iter().map(|h| (h.side, h.weight)).collect();
        let merge = |v: &mut Vec<(u32, f64)>| -> Vec<(u32, f32)> {
            v.sort_by_key(|e| e.0);
            let mut out: Vec<(u32, f32)> = Vec::new();
            for &(i, w) in v.iter() {
                match out.last_mut() {
                    Some(last) if last.0 == i => last.1 += (w / rays as f64) as f32,
                    _ => out.push((i, (w / rays as f64) as f32)),
                }
            }
            out
        };
        Self { daylight_coefficients: merge(&mut coefficients), form_factors: merge(&mut sides), buried: 0.0 }
    }
}

/// What a sensor sees, gathered once.
#[derive(Clone)]
pub(super) struct SensorGeometry {
    /// Points whose direct sun is averaged.
    pub(super) sun_points: Vec<DVec3>,
    pub(super) normal: DVec3,
    pub(super) gather: Gather,
    /// Where the sensor's first rays meet patch sides the sun may reach,
    /// with their shares: the sun's first bounce is evaluated at these
    /// points, not averaged over patches (a sun patch right beside a sensor
    /// is what patch averages get wrong).
    pub(super) landings: Landings,
    /// The panels' window points it sees, per panel group, found on first use.
    pub(super) panel_views: std::sync::OnceLock<Vec<Vec<super::measured::SeenSample>>>,
}

/// Equal where traced alike (the panels' window points, found on first
/// use, aside): what the cache holds.
impl PartialEq for SensorGeometry {
    fn eq(&self, other: &Self) -> bool {
        self.sun_points == other.sun_points && self.normal == other.normal && self.gather == other.gather && self.landings == other.landings
    }
}

impl SensorGeometry {
    pub(super) fn new(gather: Gather, sun_points: Vec<DVec3>, normal: DVec3, landings: Landings) -> Self {
        Self { sun_points, normal, gather, landings, panel_views: std::sync::OnceLock::new() }
    }
}

impl LightModel {
    /// Traces everything that does not depend on the sun and sky.
    pub fn precompute(scene: Arc<Scene>, settings: LightSettings) -> Result<Self, String> {
        Self::precompute_with_progress(scene, settings, &|_| {})
    }

    /// [`Self::precompute`], reporting the fraction done (0-1) now and then.
    pub fn precompute_with_progress(scene: Arc<Scene>, settings: LightSettings, progress: &(dyn Fn(f64) + Sync)) -> Result<Self, String> {
        settings.check()?;
        Self::traced(scene, settings, None, progress)
    }

    /// Everything traced anew (beside `beside`, as [`Self::gathered`] says).
    /// The model (its shadow tracer, windows, openings) and the sides inside
    /// solids are made beside the patches' tracer, which the gathers need
    /// first (where no model beside lends it): built on first use, it held
    /// up every thread (the furnished floor with one office's sensors, cold
    /// `sensors`: 2.00 → 1.90 s).
    pub(super) fn traced(
        scene: Arc<Scene>,
        settings: LightSettings,
        beside: Option<&LightModel>,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<Self, String> {
        check_memory(&scene, &settings)?;
        let lent = beside.is_some_and(|b| Arc::ptr_eq(&b.scene, &scene) && b.tracer.get().is_some());
        let ((empty, mut dark), tracer) = par_join(
            settings.threads,
            || (Self::empty(scene.clone(), settings, beside, None), super::solids::dark_sides(&scene)),
            || (!lent).then(|| Arc::new(Tracer::new(&scene.patches))),
        );
        if let Some(tracer) = tracer {
            let _ = empty.tracer.set(tracer);
        }
        super::solids::slot_sides(&empty, &mut dark);
        Ok(empty.gathered(&dark, beside, progress))
    }

    /// This model, made by [`Self::empty`], with every patch side's and
    /// sensor's gather; the sides `dark` inside solids ([`super::solids`])
    /// gather nothing. Beside a model of the same scene and settings but
    /// for the share of rays of the sides no sensor sees (the viewer's
    /// model for display beside the settings' own), a side whose rays are
    /// the same is that model's, shared, not traced again, and so are the
    /// sensors where no side traced again changes whether the sun may
    /// reach it (their landings keep such sides only): each is what a
    /// trace would give, bit for bit. The rays that cross no window join
    /// the sides into spaces, and a space with an opening to the sky makes
    /// its sides open to the sun ([`Spaces`]).
    pub(super) fn gathered(mut self, dark: &[bool], beside: Option<&LightModel>, progress: &(dyn Fn(f64) + Sync)) -> Self {
        let model = &mut self;
        let patches = &model.scene.patches.patches;
        let total = patches.len() * 2 + model.scene.sensors.len();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let tick = || {
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            if n.is_multiple_of(64) || n == total {
                progress(n as f64 / total as f64);
            }
        };
        let targets = model.window_targets();
        // A model beside that gathered nothing (`unlit`) lends its tracers only.
        let beside = beside.filter(|b| {
            Arc::ptr_eq(&b.scene, &model.scene)
                && b.side_gathers.len() == patches.len() * 2
                && LightSettings { unseen_ray_share: model.settings.unseen_ray_share, ..b.settings } == model.settings
        });
        // What a sensor sees straight gets all its rays: its noise would
        // show. The sides those see are found by their own gathers, traced
        // first; each step farther from the sensors takes the unseen share
        // of the rays again.
        let probes = model.probe_sensors();
        let view = &probes.view;
        let share = |settings: &LightSettings, side: usize, sight: &[Sight]| {
            let unseen_share = if model.scene.sensors.is_empty() { 1.0 } else { settings.unseen_ray_share };
            let wide = f64::from(model.scene.patches.patches[side / 2].area / model.scene.patch_sizing.finest.powi(2));
            (!dark[side]).then(|| sight[side].ray_share(model.ray_shares[side / 2], unseen_share, view[side], wide))
        };
        let nothing = Arc::new(Gather::default());
        // Each side's gather, whether it was traced here, and the sides its
        // rays met crossing no window (none where `beside`'s is shared).
        let gather_side = |side: usize, sight: &[Sight]| {
            let own = share(&model.settings, side, sight);
            let gather = match (own, beside) {
                (_, Some(b)) if share(&b.settings, side, sight) == own => (b.side_gathers[side].clone(), false, Vec::new()),
                (None, _) => (nothing.clone(), false, Vec::new()),
                (Some(own), beside) => {
                    let (traced, unglazed) = model.gather_patch_side(side, &targets, own, dark);
                    match beside.map(|b| &b.side_gathers[side]) {
                        // Glass gathers nothing, whatever its rays.
                        Some(theirs) if **theirs == traced => (theirs.clone(), true, unglazed),
                        _ => (Arc::new(traced), true, unglazed),
                    }
                }
            };
            tick();
            gather
        };
        // Step by step: the sides a step away, gathered, name those one more.
        let mut sight = Sight::from_view(view);
        let mut gathers = vec![(nothing.clone(), false); patches.len() * 2];
        let mut spaces = Spaces::new(gathers.len());
        let mut own_sky = vec![false; gathers.len()];
        let finest = model.scene.patch_sizing.finest;
        let joins = |side: usize| patches[side / 2].area >= SPACE_MEMBER * finest * finest;
        for step in 0..=Sight::FARTHER.0 {
            let these = Sight::sides_at(&sight, step);
            let traced = par_map(model.settings.threads, these.len(), |k| gather_side(these[k], &sight));
            for (side, (gather, fresh, unglazed)) in these.into_iter().zip(traced) {
                Sight::mark_named(&mut sight, step, &gather);
                let sees_sky = model.sees_open_sky(&gather);
                if joins(side) {
                    // A side shared with `beside` brings no rays: an open space
                    // of `beside`'s it was in stays open.
                    let was_open = !fresh && !sees_sky && beside.is_some_and(|b| b.open_sides[side]);
                    let opening = if was_open { f64::INFINITY } else { model.sky_opening(side, &gather) };
                    let members: Vec<u32> = unglazed.into_iter().filter(|&other| joins(other as usize)).collect();
                    spaces.join(side as u32, opening, &members);
                }
                own_sky[side] = sees_sky;
                gathers[side] = (gather, fresh);
            }
        }
        // Open: a side whose own rays saw the open sky, or one in an open space.
        model.open_sides = spaces.open_sides().into_iter().zip(own_sky).map(|(space, own)| space || own).collect();
        let traced: Vec<bool>;
        (model.side_gathers, traced) = gathers.into_iter().unzip();
        let same_sunlit_sides = |b: &LightModel| {
            b.open_sides == model.open_sides
                && (0..traced.len() as u32).all(|side| !traced[side as usize] || model.may_be_sunlit(side) == b.may_be_sunlit(side))
        };
        if let Some(b) = beside.filter(|b| same_sunlit_sides(b)) {
            (model.sensors, model.open_sensors, model.sensors_of) = (b.sensors.clone(), b.open_sensors.clone(), b.cache_key.get().copied());
        } else {
            let sensors = model.scene.sensors.clone();
            let traced = par_map(model.settings.threads, sensors.len(), |i| {
                let (geometry, unglazed) = model.sensor_geometry(i, &sensors[i], &targets, &probes.sky_through[i]);
                tick();
                let open = model.sees_open_sky(&geometry.gather) || unglazed.iter().any(|&side| model.open_sides[side as usize]);
                (geometry, open)
            });
            let geometries;
            (geometries, model.open_sensors) = traced.into_iter().unzip();
            model.sensors = Arc::new(geometries);
        }
        self
    }

    /// Follows a ray through glass, adding the sky bin it leaves by to
    /// `coefficients` where `keep_sky` takes its way, or the patch side it
    /// reaches to `hits`.
    #[allow(clippy::too_many_arguments)]
    fn follow(
        &self,
        origin: DVec3,
        dir: DVec3,
        weight: f64,
        depth: u32,
        way: Way,
        keep_sky: &dyn Fn(Way) -> bool,
        coefficients: &mut Vec<(u32, f64)>,
        hits: &mut Vec<SideHit>,
    ) {
        let Way { window, reflected } = way;
        match self.tracer().closest(origin, dir, 1e-6) {
            None if keep_sky(way) => {
                coefficients.push((SkyKey { window, bin: self.sky_bins.sphere_bin(dir) as u32 }.pack(self.bin_count()), weight))
            }
            None => {}
            Some(hit) => {
                let normal = self.patch_normal(hit.patch);
                let cos = dir.dot(normal);
                let point = origin + dir * hit.distance;
                let crossed = Way {
                    window: window.or(self.window_of_surface[self.scene.patches.patches[hit.patch as usize].surface as usize]),
                    reflected,
                };
                match self.surface_of_patch(hit.patch) {
                    Surface::Diffuse(_) => {
                        hits.push(SideHit { side: side_of(hit.patch, cos > 0.0), weight, point, through_window: window.is_some() })
                    }
                    Surface::Panel(group) if depth < MAX_GLASS_DEPTH => {
                        let side = side_of(hit.patch, cos > 0.0);
                        if self.panel_room_side(hit.patch, group) == Some(side) {
                            // From the room the ray meets the panel's room side
                            // (what it reflects back) and the panel's light along
                            // the ray, made at relight from the sky its windows
                            // see; what lies beyond is not seen through a panel.
                            hits.push(SideHit { side, weight, point, through_window: window.is_some() });
                            let window = self.window_of_surface[self.scene.patches.patches[hit.patch as usize].surface as usize];
                            if keep_sky(Way { window, reflected }) {
                                let key = SkyKey { window, bin: self.sky_bins.sphere_bin(dir) as u32 };
                                coefficients.push((key.pack(self.bin_count()), weight));
                            }
                        } else {
                            self.follow(point + dir * SURFACE_OFFSET, dir, weight, depth + 1, crossed, keep_sky, coefficients, hits)
                        }
                    }
                    Surface::Glass(glass) if depth < MAX_GLASS_DEPTH => {
                        let (t, r) = glass.at(cos);
                        if weight * t > MIN_WEIGHT {
                            self.follow(point + dir * SURFACE_OFFSET, dir, weight * t, depth + 1, crossed, keep_sky, coefficients, hits);
                        }
                        if weight * r > MIN_WEIGHT {
                            let turned = dir - 2.0 * cos * normal;
                            let way = Way { window, reflected: true };
                            self.follow(point + turned * SURFACE_OFFSET, turned, weight * r, depth + 1, way, keep_sky, coefficients, hits);
                        }
                    }
                    _ => {}
                }
            }
        }
    }

    /// One patch side's gather: cosine-weighted rays from points spread over
    /// the patch, each receiver with its own seeded generator. Diffuse
    /// sides and panels' room sides gather (whatever the panel's back
    /// reflectance: a sweep may change it), glass and panels' outer sides
    /// do not.
    ///
    /// The sky through the windows the side sees comes from rays aimed at
    /// them instead ([`LightSettings::window_rays_per_patch`]), each ray
    /// weighted by cos·Ω/(π P) for the solid angle Ω its direction was
    /// drawn from and the odds P of its window ([`WindowTarget::aim`]).
    /// The hemisphere rays keep the sky only where no aimed ray could have
    /// drawn its path (through a window not aimed at, or after glass
    /// turned it back), so every path to the sky is counted once.
    /// Also returns the sides its rays met crossing no window.
    fn gather_patch_side(&self, side: usize, targets: &[WindowTarget], share: f64, dark: &[bool]) -> (Gather, Vec<u32>) {
        let patch_index = side / 2;
        let gathers = match self.surface_of_patch(patch_index as u32) {
            Surface::Diffuse(_) => true,
            Surface::Panel(group) => self.panel_room_side(patch_index as u32, group) == Some(side as u32),
            Surface::Glass(_) => false,
        };
        if !gathers {
            return (Gather::default(), Vec::new());
        }
        let patch = &self.scene.patches.patches[patch_index];
        let normal = patch.normal.as_dvec3() * if side % 2 == 1 { -1.0 } else { 1.0 };
        let triangles = self.patch_triangles(patch_index);
        let reach = f64::from(patch.area).sqrt() * std::f64::consts::SQRT_2;
        let rays = |full: usize| (full as f64 * share).ceil() as usize;
        let window_rays = rays(self.settings.window_rays_per_patch);
        let aimed = self.windows_to_aim_at(patch.centroid.as_dvec3(), reach, normal, window_rays, targets);
        let aimed_window = |w: u32| aimed.iter().any(|a| targets[a.target].window == w);
        let mut rng = Rng::seeded(1, self.settings.seed, side as u64);
        let hemisphere = rays(self.settings.rays_per_patch);
        let directions = cosine_directions(normal, hemisphere, &mut rng);
        let (mut coefficients, mut hits) = (Vec::new(), Vec::new());
        // The sky straight through an aimed-at window is the aimed rays'.
        let not_aimed = |way: Way| way.reflected || !way.window.is_some_and(aimed_window);
        // Rays from points inside a solid (under a face resting on the
        // patch that cut it nowhere) are left out: each estimate below is
        // the mean over the part of the side the room sees.
        let mut probe_rng = Rng::seeded(6, self.settings.seed, side as u64);
        let mut from_inside = |point: DVec3, first: Option<&SideHit>| {
            first.is_some_and(|hit| dark[hit.side as usize]) && self.is_buried(point, normal, dark, &mut probe_rng)
        };
        let mut buried = 0;
        for dir in directions {
            let point = sample_area(&triangles, &mut rng) + normal * SURFACE_OFFSET;
            let before = (coefficients.len(), hits.len());
            self.follow(point, dir, 1.0, 0, Way::START, &not_aimed, &mut coefficients, &mut hits);
            if from_inside(point, hits.get(before.1)) {
                coefficients.truncate(before.0);
                hits.truncate(before.1);
                buried += 1;
            }
        }
        let seen_rays = if buried < hemisphere { hemisphere - buried } else { hemisphere };
        let aimed_from = coefficients.len();
        let aiming = Aiming { normal, aimed: &aimed, targets, rays: window_rays, hemisphere };
        let eyes = Eyes::Spread { triangles: &triangles, lift: normal * SURFACE_OFFSET };
        let aimed_inside = self.aim_at_windows(&aiming, &mut rng, eyes, &mut coefficients, &mut from_inside);
        if buried > 0 || aimed_inside > 0 {
            // The aimed rays' weights are in the units of all hemisphere rays.
            let outside = window_rays.saturating_sub(aimed_inside).max(1);
            let scale = seen_rays as f64 / hemisphere as f64 * window_rays as f64 / outside as f64;
            coefficients[aimed_from..].iter_mut().for_each(|(_, weight)| *weight *= scale);
        }
        // A side none of whose rays found the sky sees no sun either.
        let sees_sky = !coefficients.is_empty();
        let sun_points_buried =
            if buried > 0 && sees_sky { self.sun_points_buried(side, &triangles, normal, dark, &mut probe_rng) } else { 0.0 };
        let gather = Gather { buried: sun_points_buried, ..Gather::from_raw(coefficients, &hits, seen_rays) };
        (gather, unglazed_sides(&hits, hemisphere))
    }

    /// Whether a point whose ray met a side inside a solid (`dark`) lies in
    /// that solid: [`BURIED_PROBES`] more rays from it meet such sides too.
    /// A ray that slipped through a seam between two faces into a wall has
    /// open air behind it, and is kept.
    fn is_buried(&self, point: DVec3, normal: DVec3, dark: &[bool], rng: &mut Rng) -> bool {
        cosine_directions(normal, BURIED_PROBES, rng).into_iter().all(|dir| self.meets_dark_side(point, dir, dark))
    }

    /// Whether the ray from `point` along `dir` first meets a side inside a solid.
    fn meets_dark_side(&self, point: DVec3, dir: DVec3, dark: &[bool]) -> bool {
        self.tracer()
            .closest(point, dir, 1e-6)
            .is_some_and(|hit| dark[side_of(hit.patch, dir.dot(self.patch_normal(hit.patch)) > 0.0) as usize])
    }

    /// The share of `side`'s sun points (the ones `sun_on_sides` draws from
    /// its `triangles`) inside a solid, so its sun is their mean over the
    /// others ([`Gather::buried`]); 0 where all are.
    fn sun_points_buried(&self, side: usize, triangles: &[([DVec3; 3], f64)], normal: DVec3, dark: &[bool], rng: &mut Rng) -> f32 {
        let n = self.sun_samples(side);
        let mut points_rng = Rng::seeded(SUN_POINTS_STREAM, self.settings.seed, side as u64);
        let inside = stratified_area_points(triangles, n, &mut points_rng)
            .map(|point| point + normal * SURFACE_OFFSET)
            .filter(|&origin| self.meets_dark_side(origin, normal, dark) && self.is_buried(origin, normal, dark, rng))
            .count();
        if inside < n { (inside as f64 / n as f64) as f32 } else { 0.0 }
    }

    /// Traces `aiming.rays` rays aimed at its windows from `eyes`, adding
    /// the sky straight through each window to `coefficients`: stratified
    /// over the windows by their odds, and within a near window by the rest
    /// of the stratum; each ray weighted
    /// by cos·Ω/(π P) for the solid angle Ω its direction was drawn from
    /// and the odds P of its window, in units of the receiver's
    /// `aiming.hemisphere` hemisphere rays.
    /// Rays from an eye that `from_inside` finds inside a solid (given the
    /// first side the ray met) add nothing; returns how many there were.
    fn aim_at_windows(
        &self,
        aiming: &Aiming,
        rng: &mut Rng,
        eyes: Eyes,
        coefficients: &mut Vec<(u32, f64)>,
        from_inside: &mut dyn FnMut(DVec3, Option<&SideHit>) -> bool,
    ) -> usize {
        let Aiming { normal, aimed, targets, rays, hemisphere } = *aiming;
        let odds_total: f64 = aimed.iter().map(|a| a.odds).sum();
        let mut ignored = Vec::new();
        let mut inside = 0;
        // Per fixed eye and near window, its triangles' solid angles.
        let mut seen: HashMap<(usize, usize), Vec<f64>> = HashMap::new();
        for j in (0..rays).filter(|_| !aimed.is_empty()) {
            let mut pick = (j as f64 + rng.next_f64()) / rays as f64 * odds_total;
            let aim = aimed
                .iter()
                .find(|a| {
                    pick -= a.odds;
                    pick <= 0.0
                })
                .unwrap_or(aimed.last().expect("aimed is not empty"));
            let within = ((pick + aim.odds) / aim.odds).clamp(0.0, 1.0);
            let target = &targets[aim.target];
            let (point, eye) = match eyes {
                Eyes::Spread { triangles, lift } => (sample_area(triangles, rng) + lift, None),
                Eyes::Fixed(points) => (points[j % points.len()], Some(j % points.len())),
            };
            let angles = eye
                .filter(|_| aim.near)
                .map(|eye| &seen.entry((eye, aim.target)).or_insert_with(|| target.solid_angles(point).collect())[..]);
            let Some((dir, solid_angle)) = target.aim(point, aim.near, within, angles, rng) else { continue };
            let cos_here = normal.dot(dir);
            if cos_here <= 0.0 {
                continue;
            }
            let weight = cos_here * solid_angle / (std::f64::consts::PI * aim.odds / odds_total) * hemisphere as f64 / rays as f64;
            let straight_through = |way: Way| !way.reflected && way.window == Some(target.window);
            let before = coefficients.len();
            self.follow(point, dir, weight, 0, Way::START, &straight_through, coefficients, &mut ignored);
            if from_inside(point, ignored.first()) {
                coefficients.truncate(before);
                inside += 1;
            }
            ignored.clear();
        }
        inside
    }

    /// The windows a receiver (a patch side, a sensor) at `centre`, `reach`
    /// across, facing `normal`, sees, with the odds of aiming a ray at
    /// each: seen from afar by their solid angle from the centre, near
    /// ones by the solid angle of their triangles, the largest from the
    /// centre and the receiver's four corners (a window beside a patch's
    /// edge may fill a large part of the sky there and little or none of
    /// it from the middle: a ray from there, at the middle's odds, weighed
    /// so much that IfcOpenHouse's interreflected light under an overcast
    /// sky spread 7% over seeds), times the cosine there (at least 0.1:
    /// the odds only spread the rays, and a window seen at a grazing angle
    /// must keep some). None where no `rays` are aimed.
    fn windows_to_aim_at(&self, centre: DVec3, reach: f64, normal: DVec3, rays: usize, targets: &[WindowTarget]) -> Vec<Aim> {
        let mut aimed = Vec::new();
        if rays == 0 {
            return aimed;
        }
        let (u, v) = sampling::frame(normal);
        let corner = 0.5 * reach * std::f64::consts::FRAC_1_SQRT_2;
        let all = [centre, centre + corner * (u + v), centre + corner * (u - v), centre - corner * (u + v), centre - corner * (u - v)];
        // A point sensor has no corners: its centre alone.
        let corners = if reach > 0.0 { &all[..] } else { &all[..1] };
        for (k, target) in targets.iter().enumerate() {
            // Seen from some point of the side: a vertex in front of its plane.
            if !target.triangles.iter().flat_map(|t| t.0).any(|v| normal.dot(v - centre) > WINDOW_IN_FRONT) {
                continue;
            }
            let to = target.centroid - centre;
            let distance = to.length();
            let cos_here = (normal.dot(to) / distance.max(f64::EPSILON)).max(0.1);
            let near = distance <= target.size.max(reach);
            let solid_angle = if near {
                corners.iter().map(|&p| target.solid_angles(p).sum::<f64>()).fold(0.0, f64::max)
            } else {
                target.area * target.normal.dot(to / distance).abs().max(0.1) / (distance * distance)
            };
            if solid_angle > 0.0 {
                aimed.push(Aim { target: k, odds: solid_angle * cos_here, near });
            }
        }
        aimed
    }

    /// The windows as targets of aimed rays.
    fn window_targets(&self) -> Vec<WindowTarget> {
        let scene = &self.scene;
        scene
            .windows
            .iter()
            .enumerate()
            .map(|(k, window)| {
                let triangles = scene.surface_triangles(window.surface);
                let (lo, hi) = crate::scene::bounds(triangles);
                WindowTarget {
                    window: k as u32,
                    triangles: with_cumulative_areas(triangles.iter().map(|t| t.vertices)),
                    centroid: window.centroid.as_dvec3(),
                    normal: window.normal.as_dvec3(),
                    area: f64::from(window.area),
                    size: f64::from((hi - lo).length()),
                }
            })
            .collect()
    }

    /// Whether the sun may light patch side `side`: not a diffuse side
    /// whose gather met no sky at all.
    fn may_be_sunlit(&self, side: u32) -> bool {
        !matches!(self.surface_of_patch(side / 2), Surface::Diffuse(_))
            || !self.side_gathers[side as usize].daylight_coefficients.is_empty()
    }

    /// A patch's render triangles with their cumulative areas.
    pub(super) fn patch_triangles(&self, patch: usize) -> Vec<([DVec3; 3], f64)> {
        with_cumulative_areas(self.scene.patches.triangles[self.scene.patches.patches[patch].triangle_indices()].iter().copied())
    }

    /// What each sensor sees, by a few rays from each
    /// ([`SEEN_PROBE_RAYS`], drawn apart from its gather's and the sides',
    /// so that how many rays a gather draws does not hang on them): the
    /// sides it meets, straight or through glass, with the share of its view
    /// each fills, and the sky.
    fn probe_sensors(&self) -> Probes {
        let probes = par_map(self.settings.threads, self.scene.sensors.len(), |i| {
            let sensor = &self.scene.sensors[i];
            let mut rng = Rng::new(3, i as u64);
            let (mut coefficients, mut hits) = (Vec::new(), Vec::new());
            let not_reflected = |way: Way| !way.reflected;
            for point in place_sensor(self.tracer(), &self.scene.patches.patches, sensor, 1) {
                for dir in cosine_directions(sensor.normal.as_dvec3(), SEEN_PROBE_RAYS, &mut rng) {
                    self.follow(point, dir, 1.0, 0, Way::START, &not_reflected, &mut coefficients, &mut hits);
                }
            }
            let sky_through = coefficients.iter().map(|&(key, _)| SkyKey::unpack(key, self.bin_count()).window).collect();
            let mut shares: HashMap<u32, f64> = HashMap::new();
            for hit in hits {
                *shares.entry(hit.side).or_default() += hit.weight / SEEN_PROBE_RAYS as f64;
            }
            (shares, sky_through)
        });
        let mut view = vec![0.0; self.scene.patches.patches.len() * 2];
        let mut sky_through = Vec::with_capacity(probes.len());
        for (shares, sky) in probes {
            for (side, share) in shares {
                view[side as usize] = f64::max(view[side as usize], share);
            }
            sky_through.push(sky);
        }
        Probes { view, sky_through }
    }

    /// A sensor's gather, its sun points and where its rays land. As a
    /// patch side's, the sky through the windows it sees comes from rays
    /// aimed at them ([`LightSettings::window_rays_per_sensor`]), the rest
    /// from its hemisphere rays.
    /// Also returns the sides its rays met crossing no window.
    /// `probe_sky`: the windows its probe rays reached the sky through
    /// ([`Probes::sky_through`]).
    fn sensor_geometry(
        &self,
        index: usize,
        sensor: &Sensor,
        targets: &[WindowTarget],
        probe_sky: &[Option<u32>],
    ) -> (SensorGeometry, Vec<u32>) {
        let normal = sensor.normal.as_dvec3();
        let points = place_sensor(self.tracer(), &self.scene.patches.patches, sensor, 4);
        let sun_points = match sensor.size {
            Some(_) => place_sensor(self.tracer(), &self.scene.patches.patches, sensor, self.settings.area_sensor_sun_grid),
            None => points.clone(),
        };
        let centre = points.iter().sum::<DVec3>() / points.len() as f64;
        let reach = f64::from(sensor.size.unwrap_or(0.0)) * std::f64::consts::SQRT_2;
        let aimed = self.windows_to_aim_at(centre, reach, normal, self.settings.window_rays_per_sensor, targets);
        let aimed_window = |w: u32| aimed.iter().any(|a| targets[a.target].window == w);
        let not_aimed = |way: Way| way.reflected || !way.window.is_some_and(aimed_window);
        let unaimed_sky = probe_sky.iter().filter(|&&window| !window.is_some_and(aimed_window)).count();
        let sky_sets = if (1..=LITTLE_UNAIMED_SKY).contains(&unaimed_sky) { UNAIMED_SKY_SETS } else { 1 };
        let mut rng = Rng::seeded(2, self.settings.seed, index as u64);
        let per_point = self.settings.rays_per_sensor.div_ceil(points.len());
        let more_per_point = self.settings.sky_rays_per_sensor.saturating_sub(self.settings.rays_per_sensor).div_ceil(points.len());
        let (mut coefficients, mut hits, mut strata) = (Vec::new(), Vec::new(), Vec::new());
        let mut trace = |count: usize, coefficients: &mut Vec<(u32, f64)>, hits: &mut Vec<SideHit>, rng: &mut Rng| {
            let side = sampling::strata_side(count);
            for &point in &points {
                let first = strata.len();
                for (k, dir) in cosine_directions(normal, count, rng).into_iter().enumerate() {
                    let (c0, h0) = (coefficients.len(), hits.len());
                    self.follow(point, dir, 1.0, 0, Way::START, &not_aimed, coefficients, hits);
                    let sky = coefficients[c0..].iter().map(|c| c.1).sum::<f64>() >= 0.5;
                    let cell = (k < side * side).then_some((k / side, k % side));
                    strata.push(StratumRay { point, first, side, cell, sky, coefficients: c0..coefficients.len(), hits: h0..hits.len() });
                }
            }
            count * points.len()
        };
        // The first rays' landings keep the sun's first bounce; more rays,
        // a second stratified set (and, for `sky_sets`, more sets of both
        // sizes), refine the sky and form factors. Only
        // landings on sides the sun may reach are kept: a diffuse side none
        // of whose rays (those aimed at the windows it faces included) saw
        // the sky is dark to the sun (as `openings` has it), and the landings
        // are most of a sensor's memory (none in a windowless room).
        let bounce_rays = trace(per_point, &mut coefficients, &mut hits, &mut rng);
        let bounce =
            hits.iter().filter(|h| self.may_be_sunlit(h.side)).map(|h| (h.side, (h.weight / bounce_rays as f64) as f32, h.point)).collect();
        let landings = Landings::new(bounce, &self.patch_boxes);
        let mut rays = bounce_rays + trace(more_per_point, &mut coefficients, &mut hits, &mut rng);
        for _ in 1..sky_sets {
            rays +=
                trace(per_point, &mut coefficients, &mut hits, &mut rng) + trace(more_per_point, &mut coefficients, &mut hits, &mut rng);
        }
        let unglazed = unglazed_sides(&hits, rays);
        self.retrace_sky_edges(&strata, normal, &not_aimed, &mut rng, &mut coefficients, &mut hits);
        let aiming = Aiming { normal, aimed: &aimed, targets, rays: self.settings.window_rays_per_sensor, hemisphere: rays };
        self.aim_at_windows(&aiming, &mut rng, Eyes::Fixed(&points), &mut coefficients, &mut |_, _| false);
        (SensorGeometry::new(Gather::from_raw(coefficients, &hits, rays), sun_points, normal, landings), unglazed)
    }

    /// Traces again, with [`SKY_EDGE_RAYS`] rays each, the hemisphere
    /// strata on the edge of the sky a receiver's hemisphere rays keep
    /// (those whose neighbours' rays disagree on reaching it: the
    /// outline of an opening no window fills, a skyline), their one ray's
    /// part dropped. Unbiased, as which strata are traced again does not
    /// hang on their own rays and the rays that replace them are new; the
    /// edges are where the sky's share of the rays is noisy.
    fn retrace_sky_edges(
        &self,
        strata: &[StratumRay],
        normal: DVec3,
        keep_sky: &dyn Fn(Way) -> bool,
        rng: &mut Rng,
        coefficients: &mut Vec<(u32, f64)>,
        hits: &mut Vec<SideHit>,
    ) {
        let edges: Vec<&StratumRay> = strata.iter().filter(|ray| ray.is_on_sky_edge(strata)).collect();
        if edges.is_empty() {
            return;
        }
        let (mut dropped_coefficients, mut dropped_hits) = (vec![false; coefficients.len()], vec![false; hits.len()]);
        for ray in &edges {
            dropped_coefficients[ray.coefficients.clone()].fill(true);
            dropped_hits[ray.hits.clone()].fill(true);
        }
        let mut dropped = dropped_coefficients.into_iter();
        coefficients.retain(|_| !dropped.next().unwrap_or(false));
        let mut dropped = dropped_hits.into_iter();
        hits.retain(|_| !dropped.next().unwrap_or(false));
        let weight = 1.0 / SKY_EDGE_RAYS as f64;
        for ray in edges {
            let cell = ray.cell.expect("only strata of the grid are on an edge");
            for dir in sampling::cosine_directions_in(normal, cell, ray.side, SKY_EDGE_RAYS, rng) {
                self.follow(ray.point, dir, weight, 0, Way::START, keep_sky, coefficients, hits);
            }
        }
    }
}

/// The rays that trace again a hemisphere stratum on the sky's edge
/// ([`LightModel::retrace_sky_edges`]). (FZK-Haus's office with its panes
/// taken out, overcast: the readings' spread over four seeds 0.98 → 0.58%,
/// no time measurable; a sensor under a hole in a ceiling reads the hole's
/// view factor within 0.33% on six seeds, 1.6% before. Rooms lit through
/// glass read as before: their sky is drawn by aimed rays.)
const SKY_EDGE_RAYS: usize = 16;

/// One of a sensor's hemisphere rays: its stratum and what it added.
struct StratumRay {
    point: DVec3,
    /// Where its point's rays begin in the list of strata.
    first: usize,
    /// The side of its point's grid of strata.
    side: usize,
    /// Its cell of that grid (none for the random rays past the grid).
    cell: Option<(usize, usize)>,
    /// Whether it reached the sky (half its weight or more).
    sky: bool,
    coefficients: std::ops::Range<usize>,
    hits: std::ops::Range<usize>,
}

impl StratumRay {
    /// Whether its neighbours' rays (round the hemisphere in azimuth,
    /// within it in radius) disagree on reaching the sky: the sky's edge
    /// passes by. Its own ray has no say, so that the rays kept are as
    /// likely to have reached the sky as any (asked of its own ray too, a
    /// stratum the edge crosses would be kept only where its ray agreed
    /// with its neighbours, and bias it their way: the 3 rooms' direct
    /// sky 4.8% low).
    fn is_on_sky_edge(&self, strata: &[StratumRay]) -> bool {
        let Some((i, j)) = self.cell else { return false };
        let side = self.side;
        let around = [(i.wrapping_sub(1), j), (i + 1, j), (i, (j + side - 1) % side), (i, (j + 1) % side)];
        let mut skies = around.into_iter().filter(|&(i, _)| i < side).map(|(i, j)| strata[self.first + i * side + j].sky);
        let first = skies.next();
        skies.any(|sky| Some(sky) != first)
    }
}

/// Where a sensor measures: its position, or an n × n grid of cell centres
/// over its square, lifted off a surface it lies on.
fn place_sensor(tracer: &Tracer, patches: &[Patch], sensor: &Sensor, n: usize) -> Vec<DVec3> {
    let normal = sensor.normal.as_dvec3();
    let [u, v] = sensor.axes.map(|a| a.as_dvec3());
    let mut centre = sensor.position.as_dvec3();
    // Probe beside the point too, in case a ray down a shared edge slips between triangles.
    let probes = [DVec3::ZERO, u * 1e-4, v * 1e-4, -(u + v) * 1e-4];
    // A surface it faces closer than the lift, front on (a sensor 5 mm under
    // a ceiling, facing it), bounds the lift to half the way there: probed
    // from beyond that surface, the sensor was lifted through it into the
    // solid behind and read 0 lx. One met from behind is the one it lies
    // in (a desk top 5 mm over a grid): it is lifted out of that.
    let ahead = probes
        .iter()
        .filter_map(|&o| tracer.closest(centre + o, normal, 1e-6))
        .filter(|hit| patches[hit.patch as usize].normal.as_dvec3().dot(normal) < 0.0)
        .map(|hit| hit.distance)
        .fold(f64::INFINITY, f64::min);
    let lift = SENSOR_LIFT.min(0.5 * ahead);
    // Lying on a surface (within the lift, facing away from it): lift it.
    let gap = probes
        .iter()
        .filter_map(|&o| tracer.closest(centre + o + normal * lift, -normal, 0.0))
        .map(|hit| hit.distance - lift)
        .fold(f64::INFINITY, f64::min);
    if gap <= lift * 0.01 {
        centre += normal * (lift - gap.max(-lift)).max(0.0);
    }
    let Some(size) = sensor.size else { return vec![centre] };
    let size = f64::from(size);
    (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            centre + u * size * ((i + 0.5) / n as f64 - 0.5) + v * size * ((j + 0.5) / n as f64 - 0.5)
        })
        .collect()
}

/// Every sensor's measuring points as [`LightModel`] places them (area
/// sensors: a 4 × 4 grid), for exporting them.
pub fn sensor_points(scene: &Scene) -> Vec<Vec<DVec3>> {
    let tracer = Tracer::new(&scene.patches);
    scene.sensors.iter().map(|s| place_sensor(&tracer, &scene.patches.patches, s, 4)).collect()
}

#[cfg(test)]
mod tests {
    use std::fmt::Write as _;

    use super::*;

    /// Appends an OBJ quad of `material`, moved `x0` along x.
    fn quad(obj: &mut String, material: &str, x0: f64, corners: [[f64; 3]; 4]) {
        let _ = writeln!(obj, "usemtl {material}");
        for [x, y, z] in corners {
            let _ = writeln!(obj, "v {} {y} {z}", x0 + x);
        }
        let _ = writeln!(obj, "f -4 -3 -2 -1");
    }

    /// The faces of a 4 × 4 × 3 m box from `x0`, wound inward, but those
    /// named in `open` (floor, ceiling, north, west, south, east): OBJ quads.
    fn box_but(obj: &mut String, x0: f64, open: &[&str]) {
        let faces = [
            ("floor", [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 4.0, 0.0], [0.0, 4.0, 0.0]]),
            ("ceiling", [[0.0, 0.0, 3.0], [0.0, 4.0, 3.0], [4.0, 4.0, 3.0], [4.0, 0.0, 3.0]]),
            ("north", [[0.0, 4.0, 0.0], [4.0, 4.0, 0.0], [4.0, 4.0, 3.0], [0.0, 4.0, 3.0]]),
            ("west", [[0.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 4.0, 3.0], [0.0, 0.0, 3.0]]),
            ("south", [[0.0, 0.0, 0.0], [0.0, 0.0, 3.0], [4.0, 0.0, 3.0], [4.0, 0.0, 0.0]]),
            ("east", [[4.0, 0.0, 0.0], [4.0, 0.0, 3.0], [4.0, 4.0, 3.0], [4.0, 4.0, 0.0]]),
        ];
        for (_, corners) in faces.into_iter().filter(|(name, _)| !open.contains(name)) {
            quad(obj, "wall", x0, corners);
        }
    }

    /// A 4 × 4 × 3 m room from `x0`, its faces wound inward, its south wall
    /// glazed from 1 to 3 m across and 1 to 2 m up: OBJ quads.
    fn room(obj: &mut String, x0: f64) {
        box_but(obj, x0, &["south"]);
        for (xa, xb, za, zb) in [(0.0, 4.0, 0.0, 1.0), (0.0, 4.0, 2.0, 3.0), (0.0, 1.0, 1.0, 2.0), (3.0, 4.0, 1.0, 2.0)] {
            quad(obj, "wall", x0, [[xa, 0.0, za], [xa, 0.0, zb], [xb, 0.0, zb], [xb, 0.0, za]]);
        }
        quad(obj, "glass", x0, [[1.0, 0.0, 1.0], [1.0, 0.0, 2.0], [3.0, 0.0, 2.0], [3.0, 0.0, 1.0]]);
    }

    /// A sensor facing up, 0.8 m above the middle of the floor of the room
    /// at the origin.
    const DESK: &str = "[[sensors]]\nname = \"desk\"\nposition = [2.0, 2.0, 0.8]\nnormal = [0.0, 0.0, 1.0]\n";

    /// The scene of `obj` (grey walls, clear glass) at 45° N, with `more`
    /// (sensors) appended to its file, shared.
    fn scene_of(name: &str, obj: &str, more: &str) -> Arc<Scene> {
        Arc::new(super::super::test_scene::scene_of(name, obj, more))
    }

    /// A room with a doorway and no window, and beside it a room closed but
    /// for its window: the sun through the doorway lights the floor of the
    /// first even where a side's own few rays missed the doorway (each side
    /// joins the doorway's space), and the second room stays enclosed.
    #[test]
    fn the_sun_through_a_doorway_reaches_the_sides_whose_own_rays_missed_it() {
        // 4 × 4 × 3 m, wound inward; the east wall has a doorway 1 m wide
        // (y 1.5–2.5) and 2 m high.
        let mut obj = String::new();
        box_but(&mut obj, 0.0, &["east"]);
        for (ya, yb, za, zb) in [(0.0, 1.5, 0.0, 3.0), (2.5, 4.0, 0.0, 3.0), (1.5, 2.5, 2.0, 3.0)] {
            quad(&mut obj, "wall", 0.0, [[4.0, ya, za], [4.0, ya, zb], [4.0, yb, zb], [4.0, yb, za]]);
        }
        room(&mut obj, -6.0);
        let scene = scene_of("doorway", &obj, "");
        // Few rays: a floor side sees the doorway in about one ray of twenty.
        // Many sun samples: the sun patch's edges cross the sides, and at
        // the default's share here (19-31 points a side) where they fall
        // moves the floor's sum by about 4%.
        let settings =
            LightSettings { rays_per_patch: 24, window_rays_per_patch: 8, sun_samples_per_patch: 1024, ..LightSettings::default() };
        let model = LightModel::precompute(scene.clone(), settings).unwrap();
        // The sun from the east, 30° up: all it sends through the doorway
        // lands on the floor, between x = 0.54 and 4 m.
        let to_sun = DVec3::new(30f64.to_radians().cos(), 0.0, 30f64.to_radians().sin());
        let beams = model.sun_beams(&crate::sky::SunSource::unit(to_sun));
        let on_sides = model.sun_on_sides(&beams, &|side| model.sun_samples(side), false, None);
        let inward_floor = |x: std::ops::Range<f32>| {
            (scene.patches.patches.iter().enumerate()).filter(move |(_, p)| x.contains(&p.centroid.x) && p.centroid.z < 0.1).map(
                |(p, patch)| {
                    let side = side_of(p as u32, patch.normal.z < 0.0) as usize;
                    (side, f64::from(patch.area))
                },
            )
        };
        let on_floor: f64 = inward_floor(0.0..4.0).map(|(side, area)| on_sides.irradiance[side] * area).sum();
        let through_doorway = beams[0].normal_irradiance * 2.0 * to_sun.x;
        let missed = inward_floor(0.0..4.0).filter(|&(side, _)| !model.sees_open_sky(model.side_gather(side))).count();
        assert!(missed > 10, "the test needs floor sides whose own rays missed the doorway: {missed}");
        assert!((on_floor / through_doorway - 1.0).abs() < 0.03, "{on_floor} W on the floor, {through_doorway} W through the doorway");
        assert!(inward_floor(-6.0..-2.0).all(|(side, _)| !model.side_is_open(side)), "the room closed but for its window is enclosed");
    }

    /// A room lit only through a hole in its ceiling, 1 m square, 2.2 m
    /// above a sensor below its middle: the share of the sensor's view
    /// that is open sky is the hole's view factor (a differential area
    /// under a parallel rectangle, in closed form), within half a percent
    /// on every seed. No aimed ray draws it: it comes by hemisphere rays,
    /// more sets of them as the sensor sees a little open sky, and again
    /// along the hole's outline (4,096 rays alone: up to 1.6% off).
    #[test]
    fn the_open_sky_through_a_hole_fills_its_view_factor_of_the_sensors_view() {
        let mut obj = String::new();
        box_but(&mut obj, 0.0, &["ceiling"]);
        // The ceiling round the hole (x, y 1.5–2.5).
        for (xa, xb, ya, yb) in [(0.0, 4.0, 0.0, 1.5), (0.0, 4.0, 2.5, 4.0), (0.0, 1.5, 1.5, 2.5), (2.5, 4.0, 1.5, 2.5)] {
            quad(&mut obj, "wall", 0.0, [[xa, ya, 3.0], [xa, yb, 3.0], [xb, yb, 3.0], [xb, ya, 3.0]]);
        }
        let scene = scene_of("hole", &obj, DESK);
        // A corner of the hole: sides a and b over the height, in units of it.
        let corner = |a: f64, b: f64| {
            let (p, q) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
            (a / p * (b / p).atan() + b / q * (a / q).atan()) / (2.0 * std::f64::consts::PI)
        };
        let view_factor = 4.0 * corner(0.5 / 2.2, 0.5 / 2.2);
        let shares: Vec<f64> = (0..6)
            .map(|seed| {
                let settings = LightSettings { rays_per_patch: 16, window_rays_per_patch: 4, seed, ..LightSettings::default() };
                let model = LightModel::precompute(scene.clone(), settings).unwrap();
                let open = |&&(key, _): &&(u32, f32)| SkyKey::unpack(key, model.bin_count()).window.is_none();
                model.sensor_gather(0).daylight_coefficients.iter().filter(open).map(|&(_, share)| f64::from(share)).sum()
            })
            .collect();
        for share in &shares {
            assert!((share / view_factor - 1.0).abs() < 0.005, "open sky {shares:?} of the view, the hole's view factor {view_factor}");
        }
    }

    /// A sensor lying on the floor (or a few millimetres under it, as
    /// rounding leaves a grid on a desk) is lifted off it; one a few
    /// millimetres under the ceiling, facing it, stays in the room and sees
    /// the ceiling: probed from beyond the ceiling, it was lifted through
    /// it and read 0 lx.
    #[test]
    fn a_sensor_is_lifted_off_the_floor_it_lies_on_not_through_the_ceiling_it_faces() {
        let mut obj = String::new();
        room(&mut obj, 0.0);
        let sensors = [("on_floor", 0.0), ("in_floor", -0.005), ("under_ceiling", 2.995), ("near_ceiling", 2.98)]
            .map(|(name, z)| format!("[[sensors]]\nname = \"{name}\"\nposition = [2.0, 2.0, {z}]\nnormal = [0.0, 0.0, 1.0]\n"))
            .concat();
        let scene = scene_of("lift", &obj, &sensors);
        let heights: Vec<f64> = sensor_points(&scene).iter().map(|points| points[0].z).collect();
        assert!((heights[0] - SENSOR_LIFT).abs() < 1e-6 && (heights[1] - SENSOR_LIFT).abs() < 1e-6, "lifted off the floor: {heights:?}");
        assert!((heights[2] - 2.995).abs() < 1e-6 && (heights[3] - 2.98).abs() < 1e-6, "left under the ceiling: {heights:?}");
        let settings = LightSettings { rays_per_patch: 16, window_rays_per_patch: 4, ..LightSettings::default() };
        let model = LightModel::precompute(scene.clone(), settings).unwrap();
        for sensor in [2, 3] {
            let ceiling: f64 = model
                .sensor_gather(sensor)
                .form_factors
                .iter()
                .filter(|&&(side, _)| scene.patches.patches[side as usize / 2].centroid.z > 2.99)
                .map(|&(_, share)| f64::from(share))
                .sum();
            assert!(ceiling > 0.9, "sensor {sensor} sees the ceiling as {ceiling} of its view");
        }
    }

    /// Two rooms side by side, each with its window, the sensor in the
    /// first: a sensor facing up sees the ceiling, not the floor, which the
    /// ceiling sees; the second room is lit only through its own window,
    /// so its light is farther. The rays each traces follow: a gather names
    /// no more sides than it traced rays.
    #[test]
    fn sides_trace_fewer_rays_the_farther_their_light_is_from_the_sensors() {
        let mut obj = String::new();
        room(&mut obj, 0.0);
        room(&mut obj, 5.0);
        let scene = scene_of("sight", &obj, DESK);
        let settings = LightSettings { rays_per_patch: 64, window_rays_per_patch: 16, ..LightSettings::default() };
        let model = LightModel::precompute(scene.clone(), settings).unwrap();
        // Each side's steps from the sensors, as the gathers found them.
        let mut sight = Sight::from_view(&model.probe_sensors().view);
        for step in 0..Sight::FARTHER.0 {
            for side in Sight::sides_at(&sight, step) {
                Sight::mark_named(&mut sight, step, model.side_gather(side));
            }
        }
        // The inward sides of the faces with their middles in `place`,
        // facing `up`: their sight and how many sides each gather names.
        let sides = |place: &dyn Fn(glam::Vec3) -> bool, up: f32| {
            let patches = scene.patches.patches.iter().enumerate().filter(|(_, p)| place(p.centroid) && p.normal.z * up > 0.5);
            let sides: Vec<usize> = patches.map(|(p, patch)| side_of(p as u32, patch.normal.z * up < 0.0) as usize).collect();
            assert!(!sides.is_empty());
            sides.into_iter().map(|side| (sight[side], model.side_gather(side).form_factors.len())).collect::<Vec<_>>()
        };
        // The probes from the sensor may miss a corner patch of the ceiling;
        // the ceiling's middle, over the sensor, is seen.
        let ceiling = sides(&|c| (c.x - 2.0).abs() < 1.0 && (c.y - 2.0).abs() < 1.0 && c.z > 2.9, -1.0);
        let floor = sides(&|c| c.x < 4.0 && c.z < 0.1, 1.0);
        let other_floor = sides(&|c| c.x > 5.0 && c.z < 0.1, 1.0);
        assert!(ceiling.iter().all(|&(s, named)| s == Sight::SEEN && named > 16), "{ceiling:?}");
        // One bounce away: half of the 64 rays (`ONE_BOUNCE_FACTOR` times a quarter).
        assert!(floor.iter().all(|&(s, named)| s == Sight(1) && named <= 32), "{floor:?}");
        assert!(other_floor.iter().all(|&(s, named)| s == Sight::FARTHER && named <= 1), "{other_floor:?}");
        assert_eq!(Sight::SEEN.ray_share(0.5, 0.25, 0.01, 0.3), 1.0, "a seen side keeps its rays wherever it lies");
        assert_eq!(
            [1, 2, 3].map(|steps| Sight(steps).ray_share(1.0, 0.25, 0.0, 4.0)),
            [0.5, 0.0625, 0.015625],
            "twice the share one bounce away"
        );
        assert_eq!(Sight(2).ray_share(0.03, 0.25, 0.0, 1.0), 0.03, "no more than where it lies allows");
        assert_eq!(
            [Sight(1), Sight::FARTHER].map(|sight| sight.ray_share(1.0, 1.0, 0.0, 1.0)),
            [1.0; 2],
            "a picture keeps every side's rays"
        );
        assert_eq!(Sight(1).ray_share(1.0, 1.0, 0.0, 0.01), 1.0, "a picture keeps a small side's rays too");
        assert_eq!(
            [0.5, 0.01].map(|wide| Sight(1).ray_share(1.0, 0.25, 0.0, wide)),
            [0.25, 1.0 / 32.0],
            "a small unseen side traces fewer, down to a sixteenth"
        );
        assert_eq!(Sight(3).ray_share(1.0, 0.25, 0.0, 0.01), 1.0 / 64.0, "but no fewer than the farthest sides");
        assert_eq!(Sight::SEEN.ray_share(1.0, 0.25, 0.0, 0.01), 1.0, "and a seen one keeps them");
        assert_eq!(
            [0.01, 1.0 / 32.0, 0.125, 0.25, 0.95].map(|view| Sight::SEEN.ray_share(1.0, 0.25, view, 1.0)),
            [1.0, 2.0, 8.0, 16.0, 16.0],
            "more where it fills a view, in proportion"
        );
        assert_eq!(Sight::SEEN.ray_share(1.0, 0.25, 0.001, 64.0), 1.0, "a wide side a sliver of the view keeps the usual rays");
    }
}
