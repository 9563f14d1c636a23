//! The light engine: the light factored as the thesis does (chapter 3).
//!
//! - Precomputation, once per geometry ([`LightModel::precompute`]): from
//!   every side of every diffuse patch and from every sensor, cosine-weighted
//!   hemisphere rays are followed through glass (Radiance's `glass`:
//!   transmitted and reflected) until they reach a diffuse patch (a form
//!   factor) or leave the model (a daylight coefficient to a sky or ground
//!   bin, Reinhart MF:n above the horizon and its mirror below).
//! - Relighting, per sun and sky ([`LightModel::solve`]): direct sun by shadow
//!   rays through the windows, direct sky as a sparse product of coefficients
//!   and bin radiances, and indirect light by Jacobi iterations over the form
//!   factors, three channels per patch side (sun, sky, indirect, RGB),
//!   warm-started from a previous solution. Sensors gather through their own
//!   rays, never from the nearest patch.
//!
//! Results are deterministic: every receiver has its own seeded generator.
//! Plain Rust, no Bevy types.

mod bvh;
pub mod cache;
mod glass;
pub mod panels;
mod sampling;

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;

pub use glass::Glass;
pub use panels::{PanelFrame, SunBeam};

use crate::scene::{MaterialKind, Scene, Sensor};
use crate::sky::{LUMINOUS_EFFICACY, Sky, SkyPatches};
use bvh::Tracer;
use sampling::{Rng, cosine_directions, point_on_triangle};

/// Knobs of the simulation; the defaults reach the accuracy targets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSettings {
    /// Hemisphere rays from each side of each patch (form factors, sky coefficients).
    pub rays_per_patch: usize,
    /// Hemisphere rays from each sensor point.
    pub rays_per_sensor: usize,
    /// Shadow rays toward the sun per patch.
    pub sun_samples_per_patch: usize,
    /// Points per side of an area sensor's grid for the direct sun (sky and
    /// indirect use a 4 × 4 grid).
    pub area_sensor_sun_grid: usize,
    /// Reinhart MF:n of the sky bins.
    pub sky_subdivision: u32,
    /// Jacobi iterations at most.
    pub max_iterations: usize,
    /// Stop when no patch side's indirect irradiance changes by more than
    /// this fraction of its own irradiance in an iteration.
    pub tolerance: f64,
    /// Worker threads; `None` for all cores. Results do not depend on it.
    pub threads: Option<usize>,
}

impl Default for LightSettings {
    fn default() -> Self {
        Self {
            rays_per_patch: 256,
            rays_per_sensor: 4096,
            sun_samples_per_patch: 16,
            area_sensor_sun_grid: 32,
            sky_subdivision: 4,
            max_iterations: 200,
            tolerance: 1e-4,
            threads: None,
        }
    }
}

impl LightSettings {
    /// One line naming the first setting that cannot work.
    pub fn check(&self) -> Result<(), String> {
        let positive = [
            (self.rays_per_patch, "rays_per_patch"),
            (self.rays_per_sensor, "rays_per_sensor"),
            (self.sun_samples_per_patch, "sun_samples_per_patch"),
            (self.area_sensor_sun_grid, "area_sensor_sun_grid"),
            (self.max_iterations, "max_iterations"),
        ];
        if let Some((_, name)) = positive.iter().find(|(v, _)| *v == 0) {
            return Err(format!("lighting setting {name} must be at least 1"));
        }
        if self.sky_subdivision == 0 || self.sky_subdivision > 16 {
            return Err(format!("sky subdivision MF:{} is outside 1-16", self.sky_subdivision));
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(format!("tolerance {} must lie in (0, 1)", self.tolerance));
        }
        Ok(())
    }
}

/// Offset of ray origins off their surface, metres.
const SURFACE_OFFSET: f64 = 1e-4;
/// Glass interactions followed along one ray.
const MAX_GLASS_DEPTH: u32 = 4;
/// Branches carrying less than this share of a ray are dropped.
const MIN_WEIGHT: f64 = 1e-4;
/// Sensors closer than this to a surface behind them read as lifted this far.
const SENSOR_LIFT: f64 = 0.01;

/// Where a receiver's hemisphere light comes from: bins of the sky sphere,
/// each through the window it was seen through (see [`SkyKey`]), and patch
/// sides, each with its share (the shares of all rays sum to at most 1).
/// Shares through glass carry the glass's transmittance.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Gather {
    /// Packed [`SkyKey`]s with their shares, sorted by key.
    pub bins: Vec<(u32, f32)>,
    pub sides: Vec<(u32, f32)>,
}

/// A sky or ground bin as a receiver sees it: straight (no window between,
/// `window: None`) or through the first window its ray crossed. Packed into
/// one `u32` as `slot · bin_count + bin`, slot 0 for none and `k + 1` for
/// window `k` of [`Scene::windows`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkyKey {
    pub window: Option<u32>,
    /// Index into the sky sphere's bins ([`SkyPatches::sphere_bin`]).
    pub bin: u32,
}

impl SkyKey {
    fn pack(self, bin_count: u32) -> u32 {
        self.window.map_or(0, |w| w + 1) * bin_count + self.bin
    }

    fn unpack(key: u32, bin_count: u32) -> Self {
        let slot = key / bin_count;
        Self { window: slot.checked_sub(1), bin: key % bin_count }
    }
}

/// A ray that reached a diffuse patch side.
#[derive(Debug, Clone, Copy, PartialEq)]
struct SideHit {
    side: u32,
    weight: f64,
    point: DVec3,
}

impl Gather {
    fn from_raw(mut bins: Vec<(u32, f64)>, sides: &[SideHit], rays: usize) -> Self {
        let mut sides: Vec<(u32, f64)> = sides.iter().map(|h| (h.side, h.weight)).collect();
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
        Self { bins: merge(&mut bins), sides: merge(&mut sides) }
    }
}

/// A patch side: index `2·patch` for the side its normal points to, `2·patch + 1` for the other.
pub fn side_of(patch: u32, back: bool) -> u32 {
    2 * patch + u32::from(back)
}

/// What a material does to a ray that meets it.
#[derive(Debug, Clone, Copy)]
enum Surface {
    Diffuse([f64; 3]),
    Glass(Glass),
    /// A panel window of this group: rays pass on (what they see beyond is
    /// turned into the panel's light at relight time, see
    /// `PanelGroup::radiance_through`); the sun passes only along its lobes.
    Panel(u32),
}

/// Precomputed light transport for one scene.
pub struct LightModel {
    pub scene: Arc<Scene>,
    pub settings: LightSettings,
    pub bins: SkyPatches,
    tracer: Tracer,
    surfaces: Vec<Surface>,
    /// Per scene surface: its index in [`Scene::windows`], if it is one.
    window_of_surface: Vec<Option<u32>>,
    /// Panel windows by material and orientation, and each surface's group.
    panel_groups: Vec<panels::PanelGroup>,
    group_of_surface: Vec<Option<u32>>,
    /// Per patch side (2 per patch; empty for glass and panels).
    side_gathers: Vec<Gather>,
    sensors: Vec<SensorGeometry>,
}

struct SensorGeometry {
    /// Points whose direct sun is averaged.
    sun_points: Vec<DVec3>,
    normal: DVec3,
    gather: Gather,
    /// Where the sensor's rays meet patches, with their shares: the sun's
    /// first bounce is evaluated at these points, not averaged over patches
    /// (a sun patch right beside a sensor is what patch averages get wrong).
    hits: Vec<(u32, f32, [f32; 3])>,
}

/// Irradiance (W/m²) on a patch side or sensor, by channel.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Channels {
    /// All direct sunlight: straight, along panel lobes, and transmitted
    /// diffusely by panels.
    pub sun: f64,
    /// The part of `sun` that panels transmit diffusely (the renderer draws
    /// it with the patches, not with the sun pass).
    pub sun_diffuse: f64,
    /// Sky and ground glow.
    pub sky: f64,
    /// Interreflected, RGB.
    pub indirect: [f64; 3],
}

impl Channels {
    /// Photometric indirect irradiance (Radiance's RGB weights).
    pub fn indirect_luminous(&self) -> f64 {
        let [r, g, b] = self.indirect;
        0.265 * r + 0.670 * g + 0.065 * b
    }
}

/// A sensor's reading in lux.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorReading {
    pub name: String,
    pub total: f64,
    pub direct_sun: f64,
    pub direct_sky: f64,
    pub indirect: f64,
}

/// The light for one sun and sky.
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    /// Per patch side (see [`side_of`]).
    pub sides: Vec<Channels>,
    pub sensors: Vec<SensorReading>,
    /// Jacobi iterations used.
    pub iterations: usize,
    /// The last iteration's largest change of a patch side's indirect light,
    /// relative to its irradiance (infinite before the first).
    pub residual: f64,
}

/// Maps `f` over `0..count` on `threads` threads (all cores when `None`);
/// the result does not depend on how the work is split.
pub(crate) fn par_map<T: Send>(threads: Option<usize>, count: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let available = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = threads.unwrap_or(available).max(1).min(count.max(1));
    let chunk = count.div_ceil(threads).max(1);
    let f = &f;
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..count)
            .step_by(chunk)
            .map(|start| scope.spawn(move || (start..(start + chunk).min(count)).map(f).collect::<Vec<T>>()))
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("light worker panicked")).collect()
    })
}

impl LightModel {
    /// Traces everything that does not depend on the sun and sky.
    pub fn precompute(scene: Arc<Scene>, settings: LightSettings) -> Result<Self, String> {
        Self::precompute_with_progress(scene, settings, &|_| {})
    }

    /// [`Self::precompute`], reporting the fraction done (0-1) now and then.
    pub fn precompute_with_progress(scene: Arc<Scene>, settings: LightSettings, progress: &(dyn Fn(f64) + Sync)) -> Result<Self, String> {
        settings.check()?;
        let mut model = Self::empty(scene, settings);
        let patches = &model.scene.patches.patches;
        let total = patches.len() * 2 + model.scene.sensors.len();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let tick = || {
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            if n.is_multiple_of(64) || n == total {
                progress(n as f64 / total as f64);
            }
        };
        model.side_gathers = par_map(model.settings.threads, patches.len() * 2, |side| {
            let gather = model.gather_patch_side(side);
            tick();
            gather
        });
        let sensors = model.scene.sensors.clone();
        model.sensors = par_map(model.settings.threads, sensors.len(), |i| {
            let geometry = model.sensor_geometry(i, &sensors[i]);
            tick();
            geometry
        });
        Ok(model)
    }

    /// The model with its tracer and materials but nothing gathered: enough
    /// for ray queries ([`Self::trace`], [`Self::sun_irradiance`]), not for
    /// lighting.
    pub fn unlit(scene: Arc<Scene>) -> Self {
        Self::empty(scene, LightSettings::default())
    }

    /// The first patch a ray meets and its distance.
    pub fn trace(&self, origin: DVec3, direction: DVec3) -> Option<(u32, f64)> {
        self.tracer.closest(origin, direction, 1e-6).map(|hit| (hit.patch, hit.distance))
    }

    /// Direct sun irradiance (W/m²) at `point` on a surface side with
    /// `normal`: shadow rays through glass toward the sun, and through panel
    /// windows along their lobes. For many points, get the beams once
    /// ([`Self::sun_beams`]) and use [`Self::beams_irradiance`].
    pub fn sun_irradiance(&self, point: DVec3, normal: DVec3, sun: &crate::sky::SunSource) -> f64 {
        self.beams_irradiance(point, normal, &self.sun_beams(sun))
    }

    /// The model with its tracer and materials but nothing gathered yet.
    fn empty(scene: Arc<Scene>, settings: LightSettings) -> Self {
        let tracer = Tracer::new(&scene.patches);
        let surfaces = scene
            .materials
            .iter()
            .map(|m| match &m.kind {
                MaterialKind::Diffuse { reflectance } => Surface::Diffuse(reflectance.0.map(f64::from)),
                MaterialKind::Glass { transmittance } => Surface::Glass(Glass::from_transmittance(f64::from(*transmittance))),
                // The group is the surface's: see `surface_of_patch`.
                MaterialKind::Panel { .. } => Surface::Panel(u32::MAX),
            })
            .collect();
        let (panel_groups, group_of_surface) = panels::panel_groups(&scene, &tracer);
        let mut window_of_surface = vec![None; scene.surfaces.len()];
        for (k, window) in scene.windows.iter().enumerate() {
            window_of_surface[window.surface as usize] = Some(k as u32);
        }
        Self {
            bins: SkyPatches::reinhart(settings.sky_subdivision),
            window_of_surface,
            panel_groups,
            group_of_surface,
            scene,
            settings,
            tracer,
            surfaces,
            side_gathers: Vec::new(),
            sensors: Vec::new(),
        }
    }

    /// The gathered data, for the cache.
    fn payload(&self) -> Vec<u8> {
        let mut w = cache::Writer::default();
        w.u32(self.side_gathers.len() as u32);
        self.side_gathers.iter().for_each(|g| w.gather(g));
        w.u32(self.sensors.len() as u32);
        self.sensors.iter().for_each(|s| s.write(&mut w));
        w.0
    }

    /// The model from cached data; `None` when it does not fit the scene.
    fn from_payload(scene: Arc<Scene>, settings: LightSettings, payload: &[u8]) -> Option<Self> {
        let mut r = cache::Reader(payload);
        let sides = r.u32()? as usize;
        if sides != scene.patches.patches.len() * 2 {
            return None;
        }
        let side_gathers = (0..sides).map(|_| r.gather()).collect::<Option<Vec<_>>>()?;
        let sensor_count = r.u32()? as usize;
        if sensor_count != scene.sensors.len() {
            return None;
        }
        let sensors = (0..sensor_count).map(|_| SensorGeometry::read(&mut r)).collect::<Option<Vec<_>>>()?;
        let bins = (scene.windows.len() as u32 + 1) * 2 * SkyPatches::reinhart(settings.sky_subdivision).len() as u32;
        let patch_sides = sides as u32;
        let fits = |g: &Gather| g.bins.iter().all(|b| b.0 < bins) && g.sides.iter().all(|s| s.0 < patch_sides);
        let hits_fit = |s: &SensorGeometry| s.hits.iter().all(|h| h.0 < patch_sides);
        if !r.is_empty() || !side_gathers.iter().all(fits) || !sensors.iter().all(|s| fits(&s.gather) && hits_fit(s)) {
            return None;
        }
        let mut model = Self::empty(scene, settings);
        model.side_gathers = side_gathers;
        model.sensors = sensors;
        Some(model)
    }

    fn surface_of_patch(&self, patch: u32) -> Surface {
        let patch = &self.scene.patches.patches[patch as usize];
        match self.group_of_surface[patch.surface as usize] {
            Some(group) => Surface::Panel(group),
            None => self.surfaces[patch.material as usize],
        }
    }

    fn patch_normal(&self, patch: u32) -> DVec3 {
        self.scene.patches.patches[patch as usize].normal.as_dvec3()
    }

    /// Bins of the sky sphere (sky above the horizon, ground below).
    fn bin_count(&self) -> u32 {
        2 * self.bins.len() as u32
    }

    /// Follows a ray through glass, adding what it reaches to `bins`/`sides`;
    /// `window` is the first window it crossed.
    #[allow(clippy::too_many_arguments)]
    fn follow(&self, origin: DVec3, dir: DVec3, weight: f64, depth: u32, window: Option<u32>, bins: &mut Vec<(u32, f64)>, sides: &mut Vec<SideHit>) {
        match self.tracer.closest(origin, dir, 1e-6) {
            None => bins.push((SkyKey { window, bin: self.bins.sphere_bin(dir) as u32 }.pack(self.bin_count()), weight)),
            Some(hit) => {
                let normal = self.patch_normal(hit.patch);
                let cos = dir.dot(normal);
                let point = origin + dir * hit.distance;
                let crossed = window.or(self.window_of_surface[self.scene.patches.patches[hit.patch as usize].surface as usize]);
                match self.surface_of_patch(hit.patch) {
                    Surface::Diffuse(_) => sides.push(SideHit { side: side_of(hit.patch, cos > 0.0), weight, point }),
                    Surface::Panel(_) if depth < MAX_GLASS_DEPTH => {
                        self.follow(point + dir * SURFACE_OFFSET, dir, weight, depth + 1, crossed, bins, sides)
                    }
                    Surface::Glass(glass) if depth < MAX_GLASS_DEPTH => {
                        let (t, r) = glass.at(cos);
                        if weight * t > MIN_WEIGHT {
                            self.follow(point + dir * SURFACE_OFFSET, dir, weight * t, depth + 1, crossed, bins, sides);
                        }
                        if weight * r > MIN_WEIGHT {
                            let reflected = dir - 2.0 * cos * normal;
                            self.follow(point + reflected * SURFACE_OFFSET, reflected, weight * r, depth + 1, window, bins, sides);
                        }
                    }
                    _ => {}
                }
            }
        }
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
    pub fn sun_beams(&self, sun: &crate::sky::SunSource) -> Vec<SunBeam> {
        if sun.direction.z <= 0.0 {
            return Vec::new();
        }
        panels::sun_beams(&self.panel_groups, sun)
    }

    /// Which panel group a surface's windows belong to.
    pub fn panel_group_of_surface(&self, surface: u32) -> Option<u32> {
        self.group_of_surface[surface as usize]
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

    fn gather_patch_side(&self, side: usize) -> Gather {
        let patch_index = side / 2;
        let patch = &self.scene.patches.patches[patch_index];
        if !matches!(self.surfaces[patch.material as usize], Surface::Diffuse(_)) {
            return Gather::default();
        }
        let normal = patch.normal.as_dvec3() * if side % 2 == 1 { -1.0 } else { 1.0 };
        let triangles = self.patch_triangles(patch_index);
        let mut rng = Rng::new(1, side as u64);
        let directions = cosine_directions(normal, self.settings.rays_per_patch, &mut rng);
        let (mut bins, mut sides) = (Vec::new(), Vec::new());
        for dir in directions {
            let point = sample_area(&triangles, &mut rng) + normal * SURFACE_OFFSET;
            self.follow(point, dir, 1.0, 0, None, &mut bins, &mut sides);
        }
        Gather::from_raw(bins, &sides, self.settings.rays_per_patch)
    }

    /// A patch's render triangles with their cumulative areas.
    fn patch_triangles(&self, patch: usize) -> Vec<([DVec3; 3], f64)> {
        let range = self.scene.patches.patches[patch].triangles.clone();
        let mut total = 0.0;
        self.scene.patches.triangles[range.start as usize..range.end as usize]
            .iter()
            .map(|t| {
                let t = t.map(|v| v.as_dvec3());
                total += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                (t, total)
            })
            .collect()
    }

    fn sensor_geometry(&self, index: usize, sensor: &Sensor) -> SensorGeometry {
        let normal = sensor.normal.as_dvec3();
        let points = place_sensor(&self.tracer, sensor, 4);
        let sun_points = match sensor.size {
            Some(_) => place_sensor(&self.tracer, sensor, self.settings.area_sensor_sun_grid),
            None => points.clone(),
        };
        let mut rng = Rng::new(2, index as u64);
        let per_point = self.settings.rays_per_sensor.div_ceil(points.len());
        let (mut bins, mut sides) = (Vec::new(), Vec::new());
        for &point in &points {
            for dir in cosine_directions(normal, per_point, &mut rng) {
                self.follow(point, dir, 1.0, 0, None, &mut bins, &mut sides);
            }
        }
        let rays = per_point * points.len();
        let hits = sides.iter().map(|h| (h.side, (h.weight / rays as f64) as f32, h.point.as_vec3().to_array())).collect();
        SensorGeometry { gather: Gather::from_raw(bins, &sides, rays), sun_points, normal, hits }
    }

    /// The light for a sky (and its sun), iterated to convergence. `warm` is
    /// an earlier solution of the same model to start from.
    pub fn solve(&self, sky: &Sky, warm: Option<&Lighting>) -> Lighting {
        let mut relight = self.relight(sky, warm);
        while !relight.step() {}
        relight.lighting()
    }

    /// Starts relighting for a sky: the direct light (sun and sky on every
    /// patch side and sensor) is computed now; [`Relight::step`] then iterates
    /// the interreflection, and [`Relight::lighting`] reads the state at any time.
    pub fn relight(&self, sky: &Sky, warm: Option<&Lighting>) -> Relight<'_> {
        let patches = &self.scene.patches.patches;
        let sun = sky.sun.filter(|s| s.direction.z > 0.0);
        let seen = self.key_radiance(sky);
        let sky_irradiance = |g: &Gather| PI * g.bins.iter().map(|&(k, w)| f64::from(w) * seen.of(k)).sum::<f64>();
        // Sunlight that panels transmit diffusely, seen through them.
        let panel_sun = |g: &Gather| PI * g.bins.iter().map(|&(k, w)| f64::from(w) * seen.sun_of(k)).sum::<f64>();
        let beams = sun.map(|s| self.sun_beams(&s)).unwrap_or_default();
        let direct: Vec<Channels> = par_map(self.settings.threads, patches.len() * 2, |side| {
            let gather = &self.side_gathers[side];
            let patch = &patches[side / 2];
            if !matches!(self.surfaces[patch.material as usize], Surface::Diffuse(_)) {
                return Channels::default();
            }
            let normal = patch.normal.as_dvec3() * if side % 2 == 1 { -1.0 } else { 1.0 };
            let diffuse_sun = panel_sun(gather);
            let mut channels = Channels { sky: sky_irradiance(gather), sun: diffuse_sun, sun_diffuse: diffuse_sun, ..Default::default() };
            if beams.iter().any(|b| normal.dot(b.to_light) > 0.0) {
                let triangles = self.patch_triangles(side / 2);
                let mut rng = Rng::new(3, side as u64);
                let n = self.settings.sun_samples_per_patch;
                let total: f64 = (0..n).map(|_| self.beams_irradiance(sample_area(&triangles, &mut rng), normal, &beams)).sum();
                channels.sun += total / n as f64;
            }
            channels
        });
        let reflectance: Vec<[f64; 3]> = (0..patches.len() * 2)
            .map(|side| match self.surfaces[patches[side / 2].material as usize] {
                Surface::Diffuse(rho) => rho,
                _ => [0.0; 3],
            })
            .collect();
        // Each sensor's direct light and the first bounce of sun where its rays land.
        let sensors: Vec<SensorDirect> = par_map(self.settings.threads, self.sensors.len(), |i| {
            let geometry = &self.sensors[i];
            let mut out = SensorDirect { sky: sky_irradiance(&geometry.gather), sun: panel_sun(&geometry.gather), ..Default::default() };
            if beams.is_empty() {
                return out;
            }
            let total: f64 = geometry.sun_points.iter().map(|&p| self.beams_irradiance(p, geometry.normal, &beams)).sum();
            out.sun += total / geometry.sun_points.len() as f64;
            for &(j, w, point) in &geometry.hits {
                let side_normal = self.patch_normal(j / 2) * if j % 2 == 1 { -1.0 } else { 1.0 };
                if beams.iter().any(|b| side_normal.dot(b.to_light) > 0.0) {
                    let e = self.beams_irradiance(glam::Vec3::from_array(point).as_dvec3(), side_normal, &beams);
                    for (bounce, rho) in out.sun_bounce.iter_mut().zip(reflectance[j as usize]) {
                        *bounce += f64::from(w) * rho * e;
                    }
                }
            }
            out
        });
        let indirect = match warm {
            Some(w) if w.sides.len() == direct.len() => {
                // Scaled by how much the direct light changed: close when the
                // sun moves a little, and dark at once when the light is gone
                // (unscaled, a day's light would fade over every iteration
                // the budget allows and leave a glow in the night).
                let before: f64 = w.sides.iter().map(|c| c.sun + c.sky).sum();
                let now: f64 = direct.iter().map(|c| c.sun + c.sky).sum();
                let scale = if before > 0.0 { now / before } else { 0.0 };
                w.sides.iter().map(|c| c.indirect.map(|e| e * scale)).collect()
            }
            _ => vec![[0.0; 3]; direct.len()],
        };
        let mean_direct = direct.iter().map(|c| c.sun + c.sky).sum::<f64>() / direct.len().max(1) as f64;
        Relight {
            model: self,
            floor: 1e-3 * mean_direct.max(1e-12),
            direct,
            reflectance,
            indirect,
            sensors,
            iterations: 0,
            residual: f64::INFINITY,
            converged: false,
        }
    }

}

/// Radiance behind gather keys ([`SkyKey`]) for one sky.
struct KeyRadiance {
    bin_count: u32,
    /// Per sphere bin.
    bins: Vec<f64>,
    /// Per panel group, per sphere bin: sky and ground seen through its windows.
    panels: Vec<Vec<f64>>,
    /// Per panel group: its diffusely transmitted sunlight's radiance.
    panel_sun: Vec<f64>,
    /// Per scene window: its panel group.
    window_panel: Vec<Option<u32>>,
}

impl KeyRadiance {
    /// Sky and ground radiance behind `key`.
    fn of(&self, key: u32) -> f64 {
        let key = SkyKey::unpack(key, self.bin_count);
        match key.window.and_then(|w| self.window_panel[w as usize]) {
            Some(group) => self.panels[group as usize][key.bin as usize],
            None => self.bins[key.bin as usize],
        }
    }

    /// Diffusely transmitted sunlight behind `key` (through panels only).
    fn sun_of(&self, key: u32) -> f64 {
        let key = SkyKey::unpack(key, self.bin_count);
        key.window.and_then(|w| self.window_panel[w as usize]).map_or(0.0, |group| self.panel_sun[group as usize])
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct SensorDirect {
    sun: f64,
    sky: f64,
    /// RGB irradiance from the sun's first reflection off patches.
    sun_bounce: [f64; 3],
}

/// A relight in progress: direct light computed, interreflection iterating.
pub struct Relight<'a> {
    model: &'a LightModel,
    /// Irradiance below which a side counts as dark (for relative convergence).
    floor: f64,
    direct: Vec<Channels>,
    reflectance: Vec<[f64; 3]>,
    indirect: Vec<[f64; 3]>,
    sensors: Vec<SensorDirect>,
    iterations: usize,
    residual: f64,
    converged: bool,
}

impl Relight<'_> {
    /// One Jacobi iteration, E_ind(i) = Σ_j w_ij ρ_j (E_direct(j) + E_ind(j)).
    /// Returns whether the solution has converged (or the iteration budget is spent).
    pub fn step(&mut self) -> bool {
        if self.converged {
            return true;
        }
        let model = self.model;
        let leaving = self.leaving(true);
        let next: Vec<[f64; 3]> = par_map(model.settings.threads, self.direct.len(), |i| {
            let mut sum = [0.0; 3];
            for &(j, w) in &model.side_gathers[i].sides {
                for c in 0..3 {
                    sum[c] += f64::from(w) * leaving[j as usize][c];
                }
            }
            sum
        });
        // The largest change relative to each side's own irradiance (dark
        // corners converge as well as sunlit floors).
        let change = next
            .iter()
            .zip(&self.indirect)
            .zip(&self.direct)
            .map(|((a, b), d)| {
                let level = (d.sun + d.sky + a.iter().copied().fold(0.0, f64::max)).max(self.floor);
                (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max) / level
            })
            .fold(0.0, f64::max);
        self.indirect = next;
        self.iterations += 1;
        self.residual = change;
        self.converged = change <= model.settings.tolerance || self.iterations >= model.settings.max_iterations;
        self.converged
    }

    pub fn is_converged(&self) -> bool {
        self.converged
    }

    /// Radiant exitance of each side (RGB), with or without its direct sun.
    /// Without the sun's beams (sensors take their first bounce where their
    /// rays land), the panels' diffuse sunlight still counts.
    fn leaving(&self, with_sun: bool) -> Vec<[f64; 3]> {
        (0..self.direct.len())
            .map(|j| {
                let sun = if with_sun { self.direct[j].sun } else { self.direct[j].sun_diffuse };
                let e = sun + self.direct[j].sky;
                [0, 1, 2].map(|c| self.reflectance[j][c] * (e + self.indirect[j][c]))
            })
            .collect()
    }

    /// The light as it stands.
    pub fn lighting(&self) -> Lighting {
        let model = self.model;
        let sides = self.direct.iter().zip(&self.indirect).map(|(d, i)| Channels { indirect: *i, ..*d }).collect();
        // Sensors take the sun's first bounce from where their rays land.
        let without_sun = self.leaving(false);
        let sensors = model
            .scene
            .sensors
            .iter()
            .zip(&model.sensors)
            .zip(&self.sensors)
            .map(|((sensor, geometry), direct)| {
                let mut rgb = direct.sun_bounce;
                for &(j, w) in &geometry.gather.sides {
                    for c in 0..3 {
                        rgb[c] += f64::from(w) * without_sun[j as usize][c];
                    }
                }
                let indirect = Channels { indirect: rgb, ..Default::default() }.indirect_luminous();
                let lux = |e: f64| e * LUMINOUS_EFFICACY;
                SensorReading {
                    name: sensor.name.clone(),
                    total: lux(direct.sun + direct.sky + indirect),
                    direct_sun: lux(direct.sun),
                    direct_sky: lux(direct.sky),
                    indirect: lux(indirect),
                }
            })
            .collect();
        Lighting { sides, sensors, iterations: self.iterations, residual: self.residual }
    }
}

/// Where a sensor measures: its position, or an n × n grid of cell centres
/// over its square, lifted off a surface it lies on.
fn place_sensor(tracer: &Tracer, sensor: &Sensor, n: usize) -> Vec<DVec3> {
    let normal = sensor.normal.as_dvec3();
    let [u, v] = sensor.axes.map(|a| a.as_dvec3());
    let mut centre = sensor.position.as_dvec3();
    // Lying on a surface (within the lift, facing away from it): lift it.
    // Probe beside the point too, in case a ray down a shared edge slips between triangles.
    let probes = [DVec3::ZERO, u * 1e-4, v * 1e-4, -(u + v) * 1e-4];
    let gap = probes
        .iter()
        .filter_map(|&o| tracer.closest(centre + o + normal * SENSOR_LIFT, -normal, 0.0))
        .map(|hit| hit.distance - SENSOR_LIFT)
        .fold(f64::INFINITY, f64::min);
    if gap <= SENSOR_LIFT * 0.01 {
        centre += normal * (SENSOR_LIFT - gap.max(-SENSOR_LIFT)).max(0.0);
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

impl LightModel {
    /// Each sensor's direct sky and ground light in lux, split by where it
    /// comes from: `(None, lux)` straight from outside, `(Some(k), lux)`
    /// through window `k` of [`Scene::windows`]. Sums to `direct_sky`.
    pub fn sky_through_windows(&self, sky: &Sky) -> Vec<Vec<(Option<u32>, f64)>> {
        let seen = self.key_radiance(sky);
        self.sensors
            .iter()
            .map(|geometry| {
                let mut by_window: Vec<(Option<u32>, f64)> = Vec::new();
                for &(k, w) in &geometry.gather.bins {
                    let key = SkyKey::unpack(k, self.bin_count());
                    let lux = PI * f64::from(w) * seen.of(k) * LUMINOUS_EFFICACY;
                    match by_window.last_mut() {
                        Some(last) if last.0 == key.window => last.1 += lux,
                        _ => by_window.push((key.window, lux)),
                    }
                }
                by_window
            })
            .collect()
    }

    /// The radiance behind each gather key under `sky`: a bin's own, or
    /// through a panel window what the panel makes of the sky and sun.
    fn key_radiance(&self, sky: &Sky) -> KeyRadiance {
        let mut bins = Vec::with_capacity(self.bin_count() as usize);
        self.bins.integrate_sphere_into(sky, &mut bins);
        let sun = sky.sun.filter(|s| s.direction.z > 0.0);
        let panels = self.panel_groups.iter().map(|g| g.radiance_through(&self.bins, &bins)).collect();
        let panel_sun = self.panel_groups.iter().map(|g| g.sun_diffuse_radiance(sun.as_ref())).collect();
        let window_panel = self.scene.windows.iter().map(|w| self.group_of_surface[w.surface as usize]).collect();
        KeyRadiance { bin_count: self.bin_count(), bins, panels, panel_sun, window_panel }
    }

    /// Sensors that seem to sit inside a solid: every ray from them meets a
    /// surface from its back, within a few metres. They still read what
    /// reaches them; the caller warns.
    pub fn sensors_inside_solids(&self) -> Vec<usize> {
        const RAYS: usize = 64;
        let patches = &self.scene.patches.patches;
        (0..self.scene.sensors.len())
            .filter(|&i| {
                let position = self.scene.sensors[i].position.as_dvec3();
                let mut rng = Rng::new(4, i as u64);
                let up = cosine_directions(DVec3::Z, RAYS / 2, &mut rng);
                up.iter().chain(cosine_directions(DVec3::NEG_Z, RAYS / 2, &mut rng).iter()).all(|&d| {
                    self.tracer
                        .closest(position, d, 1e-6)
                        .is_some_and(|hit| hit.distance < 5.0 && d.dot(patches[hit.patch as usize].normal.as_dvec3()) > 0.0)
                })
            })
            .collect()
    }
}

/// Every sensor's measuring points as [`LightModel`] places them (area
/// sensors: a 4 × 4 grid), for exporting them.
pub fn sensor_points(scene: &Scene) -> Vec<Vec<DVec3>> {
    let tracer = Tracer::new(&scene.patches);
    scene.sensors.iter().map(|s| place_sensor(&tracer, s, 4)).collect()
}

/// A uniformly distributed point on triangles given with cumulative areas.
fn sample_area(triangles: &[([DVec3; 3], f64)], rng: &mut Rng) -> DVec3 {
    let total = triangles.last().map_or(0.0, |t| t.1);
    let pick = rng.next_f64() * total;
    let index = triangles.partition_point(|t| t.1 < pick).min(triangles.len() - 1);
    point_on_triangle(&triangles[index].0, rng.next_f64(), rng.next_f64())
}
