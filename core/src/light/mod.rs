//! The light engine: the light factored as the thesis does (chapter 3).
//!
//! How it works, in the order it runs:
//! 0. **Windows** ([`windows`]): grouped by material and outward facing,
//!    the one rule everything that groups windows uses.
//! 1. **Gather** ([`gather`], once per geometry, [`LightModel::precompute`]):
//!    from every side of every diffuse patch and from every sensor,
//!    cosine-weighted hemisphere rays are followed through glass
//!    (Radiance's `glass`, [`glass`]: transmitted and reflected) until they
//!    reach a diffuse patch side (a form factor) or leave the model (a
//!    daylight coefficient of a sky or ground bin, Reinhart MF:n above the
//!    horizon and its mirror below); patch sides also aim rays at the
//!    windows they see, for a steadier sky. Cached on disk
//!    ([`cache`]).
//! 2. **Direct light** per sun and sky ([`LightModel::relight`]): direct sun
//!    by shadow rays through windows and along panel lobes ([`sun`],
//!    [`panels`]), direct sky as the sparse product of daylight coefficients
//!    and bin radiances ([`daylight`]).
//!    Shadow rays are spared where the sun cannot come in ([`openings`]).
//! 3. **Interreflection** ([`solver`]): Jacobi iterations over the form
//!    factors, RGB, warm-started from a previous solution
//!    ([`Relight::step`]); sensors gather through their own rays, never
//!    from the nearest patch.
//! 4. **Many skies** ([`coefficients`], the annual study): each sensor's
//!    adjoint of step 3, solved once, folds the interreflection into
//!    coefficients per sky bin and per side's sun; a sky is then a product,
//!    not a solve.
//!
//! Results are deterministic: every receiver has its own seeded generator
//! ([`sampling`]). Knobs: [`LightSettings`]. Plain Rust, no Bevy types.

mod bvh;
pub mod cache;
pub mod coefficients;
pub mod daylight;
pub mod gather;
mod glass;
mod landings;
mod lobe_table;
mod measured;
mod openings;
pub mod panels;
mod sampling;
pub mod settings;
mod solids;
pub mod solver;
pub mod sun;
mod totals;
pub mod windows;

use std::sync::Arc;

use glam::DVec3;

pub use coefficients::{SensorCoefficients, SunPath};
pub use gather::{Gather, SkyKey, sensor_points};
pub use glass::Glass;
pub use lobe_table::{LOBE_STEP, LobeTable, Sunlit};
pub use measured::MeasuredSun;
pub use panels::{LobeLook, PanelFrame, PanelLook, SunBeam};
pub use settings::LightSettings;
pub use solver::{Interreflection, Relight, form_factor_product};
pub use totals::{HourLight, HourSky, KnownSky, SkyBesidePanels, TotalCoefficients};
pub use windows::{WindowGroup, WindowGroups};

/// A patch side: index `2·patch` for the side its normal points to, `2·patch + 1` for the other.
pub fn side_of(patch: u32, back: bool) -> u32 {
    2 * patch + u32::from(back)
}

use crate::parallel::par_map;
use crate::scene::{MaterialKind, Scene};
use crate::sky::{Sky, SkyPatches};
use bvh::Tracer;
use gather::SensorGeometry;
use sampling::{Rng, cosine_directions};

/// Offset of ray origins off their surface, metres.
const SURFACE_OFFSET: f64 = 1e-4;
/// Glass interactions followed along one ray: deep enough for a stack of
/// panes (a double-skin façade of double glazing; IfcOpenHouse's panes in
/// glazed linings). At 4 a room behind five panes read 15.8 lx where
/// Radiance, which follows a ray 32 deep, reads 237.1.
const MAX_GLASS_DEPTH: u32 = 16;
/// Branches carrying less than this share of a ray are dropped.
const MIN_WEIGHT: f64 = 1e-4;

/// What a material does to a ray that meets it.
#[derive(Debug, Clone, Copy)]
enum Surface {
    Diffuse([f64; 3]),
    Glass(Glass),
    /// A panel window of this group: a ray from the room ends there, keyed
    /// by its window and direction (the panel's light along it is made at
    /// relight from the sky the windows see, `PanelGroup::radiance_through`),
    /// and meets the room side, which reflects the room's light back (its
    /// group's `back_reflectance`); a ray from outside passes on. The sun
    /// passes only along its lobes.
    Panel(u32),
}

/// Precomputed light transport for one scene.
pub struct LightModel {
    /// The scene the transport was traced in.
    pub scene: Arc<Scene>,
    /// The settings it was traced with.
    pub settings: LightSettings,
    /// The sky and ground bins daylight coefficients refer to.
    pub sky_bins: SkyPatches,
    /// The patches' render triangles, hits naming their patch: built on
    /// first use, since a start from the cache traces none (a warm
    /// `sensors` run on AC20-Institute-Var-2 with one office's sensors
    /// spares 210 ms).
    tracer: std::sync::OnceLock<Arc<Tracer>>,
    /// The model's own triangles, hits naming their scene surface: fewer
    /// than the patches' render triangles, for shadow rays toward the sun.
    shadow_tracer: Arc<Tracer>,
    surfaces: Vec<Surface>,
    /// The windows by material and outward facing (the one grouping rule).
    pub windows: WindowGroups,
    /// Per scene surface: its index in [`Scene::windows`], if it is one.
    window_of_surface: Vec<Option<u32>>,
    /// Panel windows by material and orientation, and each surface's group.
    panel_groups: Vec<panels::PanelGroup>,
    group_of_surface: Vec<Option<u32>>,
    /// Per panel group, its windows' triangles.
    panel_windows: Vec<Vec<[DVec3; 3]>>,
    /// Per panel group, points on its windows (sensors' direct sun through
    /// measured panels, [`measured`]).
    panel_samples: Vec<measured::WindowSamples>,
    /// Where the sun can come in (spares shadow rays).
    openings: openings::Openings,
    /// Per patch, the box its sensors' landings are stored in.
    patch_boxes: Vec<landings::PatchBox>,
    /// Per patch, the share of its sides' rays and sun samples by where it
    /// lies ([`crate::scene::PatchSizing::ray_share`]).
    ray_shares: Vec<f64>,
    /// Per patch side (2 per patch; empty for glass, the outer side of
    /// panels and sides inside solids, `solids`), shared with a model this
    /// one refines where they are the same ([`cache::precompute_cached_beside`]).
    side_gathers: Vec<Arc<Gather>>,
    sensors: Arc<Vec<SensorGeometry>>,
    /// The [`cache::key`] of the model whose `sensors` these are, when they
    /// are shared with it (a picture's model beside the settings' own): its
    /// cache file names that model instead of holding them again.
    sensors_of: Option<u64>,
    /// Per patch side, whether the sun may reach it without crossing a
    /// window: its space has an opening to the open sky
    /// ([`openings::Spaces`]).
    open_sides: Vec<bool>,
    /// Per sensor, the same: it saw the open sky, or an open side with no
    /// window between.
    open_sensors: Vec<bool>,
    /// [`cache::key`] of `scene` and `settings`, found once: the cached
    /// tables made from the model key on it, and finding it hashes every
    /// triangle of the model and of its patches.
    cache_key: std::sync::OnceLock<u64>,
    /// Per patch side, how many of the sensors' rays land on it: found on
    /// first use (a pass over every landing), since a relight and every
    /// hour of a year ask.
    landings_on_sides: std::sync::OnceLock<Vec<u32>>,
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
        luminous(self.indirect)
    }
}

/// Radiance's weights of red, green and blue in luminous quantities.
pub const RGB_TO_LUMINOUS: [f64; 3] = [0.265, 0.670, 0.065];

/// The luminous part of an RGB quantity (Radiance's weights).
pub fn luminous(rgb: [f64; 3]) -> f64 {
    rgb.iter().zip(RGB_TO_LUMINOUS).map(|(c, w)| c * w).sum()
}

/// A sensor's reading in lux.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorReading {
    /// The sensor's name (grid sensors: `<grid>/<k>`).
    pub name: String,
    /// All light: the sum of the three parts, lux.
    pub total: f64,
    /// Direct sun, panels' redirected sunlight included, lux.
    pub direct_sun: f64,
    /// Direct sky and ground glow, lux.
    pub direct_sky: f64,
    /// Interreflected light, lux.
    pub indirect: f64,
}

impl SensorReading {
    /// A reading from its three parts (lux). A part that is an empty sum
    /// reads 0, not −0 (Rust sums floats from −0).
    pub fn new(name: String, direct_sun: f64, direct_sky: f64, indirect: f64) -> Self {
        let (direct_sun, direct_sky, indirect) = (direct_sun + 0.0, direct_sky + 0.0, indirect + 0.0);
        Self { name, total: direct_sun + direct_sky + indirect, direct_sun, direct_sky, indirect }
    }
}

/// A reading under this share of the sky's horizontal illuminance is no
/// daylight, as in a room no window or opening lights: a sealed room reads
/// nothing, or millionths where a ray slips through a seam. Revit's
/// Office_A under a clear morning sky: 19 sensors in its restrooms, lit
/// through their doors at most, read 0–0.6 lx; its inner rooms lit through
/// a corridor, 1–3.5 lx, and its lit offices 20 lx and more.
const NO_DAYLIGHT: f64 = 1e-5;

/// Per reading, whether `sky` gives it no daylight: under [`NO_DAYLIGHT`]
/// of the sky's horizontal illuminance. `None` where the sky sheds no
/// light (at night), which tells nothing.
pub fn without_daylight(readings: &[SensorReading], sky: &Sky) -> Option<Vec<bool>> {
    let outside = sky.global_horizontal() * crate::sky::LUMINOUS_EFFICACY;
    (outside > 0.0).then(|| readings.iter().map(|r| r.total < NO_DAYLIGHT * outside).collect())
}

/// The light for one sun and sky.
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    /// Per patch side (see [`side_of`]).
    pub sides: Vec<Channels>,
    /// Per sensor of the scene, in its order.
    pub sensors: Vec<SensorReading>,
    /// Jacobi iterations used.
    pub iterations: usize,
    /// The last iteration's largest change of a patch side's indirect light,
    /// relative to its irradiance (infinite before the first).
    pub residual: f64,
}

impl LightModel {
    /// The model with its tracer and materials but nothing gathered: enough
    /// for ray queries ([`Self::trace`], [`Self::sun_irradiance`]), not for
    /// lighting.
    pub fn unlit(scene: Arc<Scene>) -> Self {
        Self::empty(scene, LightSettings::default(), None, None).with_tracer()
    }

    /// This model with its patch tracer built now, not at the first ray
    /// query: for a model whose queries must not wait (the viewer's clicks
    /// and exposure metering run in a frame).
    pub fn with_tracer(self) -> Self {
        self.tracer();
        self
    }

    /// [`cache::key`] of the model's scene and settings.
    pub fn cache_key(&self) -> u64 {
        *self.cache_key.get_or_init(|| cache::key(&self.scene, &self.settings))
    }

    /// The first patch a ray meets and its distance.
    pub fn trace(&self, origin: DVec3, direction: DVec3) -> Option<(u32, f64)> {
        self.tracer().closest(origin, direction, 1e-6).map(|hit| (hit.patch, hit.distance))
    }

    fn tracer(&self) -> &Tracer {
        self.tracer.get_or_init(|| Arc::new(Tracer::new(&self.scene.patches)))
    }

    /// The triangles the shadow tracer is built over, each owned by its
    /// surface.
    fn shadow_casters(scene: &Scene) -> (Vec<[glam::Vec3; 3]>, Vec<u32>) {
        let triangles = scene.triangles.iter().map(|t| t.vertices).collect();
        let owner = scene.surfaces.iter().enumerate().flat_map(|(k, s)| std::iter::repeat_n(k as u32, s.triangles.len())).collect();
        (triangles, owner)
    }

    /// The model with its tracer and materials but nothing gathered yet;
    /// the shadow tracer `shadow_tracer` when given, else the tracers those
    /// of `beside` where it has them and the same scene.
    fn empty(scene: Arc<Scene>, settings: LightSettings, beside: Option<&LightModel>, shadow_tracer: Option<Arc<Tracer>>) -> Self {
        let beside = beside.filter(|b| Arc::ptr_eq(&b.scene, &scene));
        let shadow_tracer = shadow_tracer.or_else(|| beside.map(|b| b.shadow_tracer.clone())).unwrap_or_else(|| {
            let (triangles, owner) = Self::shadow_casters(&scene);
            Arc::new(Tracer::over(&triangles, owner))
        });
        let tracer = beside.and_then(|b| b.tracer.get()).cloned().map_or_else(std::sync::OnceLock::new, std::sync::OnceLock::from);
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
        let windows = WindowGroups::new(&scene, &shadow_tracer);
        let (panel_groups, group_of_surface) = panels::panel_groups(&scene, &windows);
        let mut panel_windows = vec![Vec::new(); panel_groups.len()];
        for window in &scene.windows {
            if let Some(group) = group_of_surface[window.surface as usize] {
                let triangles = scene.surface_triangles(window.surface).iter().map(|t| t.vertices.map(|v| v.as_dvec3()));
                panel_windows[group as usize].extend(triangles);
            }
        }
        let openings = openings::Openings::new(&scene, &group_of_surface);
        let mut window_of_surface = vec![None; scene.surfaces.len()];
        for (k, window) in scene.windows.iter().enumerate() {
            window_of_surface[window.surface as usize] = Some(k as u32);
        }
        let patch_boxes = scene
            .patches
            .patches
            .iter()
            .map(|patch| landings::PatchBox::around(&scene.patches.triangles[patch.triangle_indices()]))
            .collect();
        let ray_shares = scene.patch_sizing.ray_shares(&scene.patches.patches, settings.threads);
        let mut model = Self {
            sky_bins: SkyPatches::reinhart(settings.sky_subdivision),
            patch_boxes,
            ray_shares,
            windows,
            window_of_surface,
            panel_groups,
            group_of_surface,
            panel_windows,
            panel_samples: Vec::new(),
            openings,
            scene,
            settings,
            tracer,
            shadow_tracer,
            surfaces,
            side_gathers: Vec::new(),
            sensors: Arc::default(),
            sensors_of: None,
            open_sides: Vec::new(),
            open_sensors: Vec::new(),
            cache_key: std::sync::OnceLock::new(),
            landings_on_sides: std::sync::OnceLock::new(),
        };
        model.look_out_of_panels();
        model.panel_samples = (0..model.panel_groups.len()).map(|g| model.window_samples(g)).collect();
        model
    }

    fn surface_of_patch(&self, patch: u32) -> Surface {
        self.surface_kind(self.scene.patches.patches[patch as usize].surface)
    }

    /// What scene surface `surface` does to rays.
    fn surface_kind(&self, surface: u32) -> Surface {
        match self.group_of_surface[surface as usize] {
            Some(group) => Surface::Panel(group),
            None => self.surfaces[self.scene.surfaces[surface as usize].material as usize],
        }
    }

    fn patch_normal(&self, patch: u32) -> DVec3 {
        self.scene.patches.patches[patch as usize].normal.as_dvec3()
    }

    /// The outward normal of a patch side ([`side_of`]).
    fn side_normal(&self, side: u32) -> DVec3 {
        self.patch_normal(side / 2) * if side % 2 == 1 { -1.0 } else { 1.0 }
    }

    /// Whether the sun may reach the side without crossing a window: its
    /// space is open ([`openings::Spaces`]).
    fn side_is_open(&self, side: usize) -> bool {
        self.open_sides[side]
    }

    /// The opening (m²) through which side `side` saw the open sky (through
    /// no window, upward, whence the sun comes): its area times the share
    /// of its rays ([`openings::Spaces`]).
    fn sky_opening(&self, side: usize, gather: &Gather) -> f64 {
        let sky_bins = self.sky_bins.len() as u32;
        let share: f64 = (gather.daylight_coefficients.iter())
            .map(|&(k, w)| (SkyKey::unpack(k, self.bin_count()), w))
            .take_while(|(key, _)| key.window.is_none())
            .filter(|(key, _)| key.bin < sky_bins)
            .map(|(_, w)| f64::from(w))
            .sum();
        f64::from(self.scene.patches.patches[side / 2].area) * share
    }

    /// Whether some ray of `gather` left straight to the open sky or ground
    /// (keys are sorted, windowless ones first).
    fn sees_open_sky(&self, gather: &Gather) -> bool {
        gather.daylight_coefficients.first().is_some_and(|&(k, _)| SkyKey::unpack(k, self.bin_count()).window.is_none())
    }

    /// The diffuse reflectance (RGB) of a patch side; `None` for glass, the
    /// outer side of panels and panels that reflect nothing back.
    fn side_reflectance(&self, side: usize) -> Option<[f64; 3]> {
        match self.surface_of_patch((side / 2) as u32) {
            Surface::Diffuse(rho) => Some(rho),
            Surface::Panel(group) if self.panel_room_side((side / 2) as u32, group) == Some(side as u32) => {
                let rho = self.panel_groups[group as usize].back_reflectance;
                (rho > 0.0).then_some([rho; 3])
            }
            _ => None,
        }
    }

    /// The side of a panel patch (of `group`) that faces the room.
    fn panel_room_side(&self, patch: u32, group: u32) -> Option<u32> {
        let inward = self.panel_groups.get(group as usize)?.frame.z;
        Some(side_of(patch, self.patch_normal(patch).dot(inward) < 0.0))
    }

    /// Bins of the sky sphere (sky above the horizon, ground below).
    fn bin_count(&self) -> u32 {
        2 * self.sky_bins.len() as u32
    }

    /// Puts `model` in the windows of panel material `material` (an index
    /// into [`Scene::materials`]): what the sky and sun send through them
    /// changes, the gathered transport does not (rays pass panels
    /// unweighted), so a sweep of panel keys keeps one precomputation.
    /// (Sensor coefficients also hold while the back reflectance stays:
    /// [`Self::panel_back_reflectance`].) `scene.materials` keeps the file's keys.
    pub fn set_panel_model(&mut self, material: u32, model: Arc<dyn crate::panel::PanelModel>) {
        for group in self.panel_groups.iter_mut().filter(|g| g.material == material) {
            group.set_model(model.clone());
        }
        // Which data cells the sensors see the windows in is the model's.
        Arc::make_mut(&mut self.sensors).iter_mut().for_each(|s| s.panel_views = std::sync::OnceLock::new());
    }

    /// The back reflectance of panel material `material`'s windows, as the
    /// model in them gives it; `None` when no window has that material.
    pub fn panel_back_reflectance(&self, material: u32) -> Option<f64> {
        self.panel_groups.iter().find(|g| g.material == material).map(|g| g.back_reflectance)
    }

    /// Which panel group a surface's windows belong to.
    pub fn panel_group_of_surface(&self, surface: u32) -> Option<u32> {
        self.group_of_surface[surface as usize]
    }

    /// What patch side `side` ([`side_of`]) gathered: for tools that follow
    /// the light (`examples/light_into_room.rs`).
    pub fn side_gather(&self, side: usize) -> &Gather {
        &self.side_gathers[side]
    }

    /// What sensor `sensor` gathered (its first `rays_per_sensor` rays and
    /// the sky rays after them).
    pub fn sensor_gather(&self, sensor: usize) -> &Gather {
        &self.sensors[sensor].gather
    }

    /// The light patch side `side` sends out in `lighting`, RGB W/m²: its
    /// reflectance times all its irradiance (none for glass).
    pub fn side_exitance(&self, lighting: &Lighting, side: usize) -> [f64; 3] {
        let Some(rho) = self.side_reflectance(side) else { return [0.0; 3] };
        let c = &lighting.sides[side];
        [0, 1, 2].map(|k| rho[k] * (c.sun + c.sky + c.indirect[k]))
    }

    /// Each sensor's share of its hemisphere (cosine-weighted) that sees the
    /// open sky or ground directly, through no window: near 0 in a room,
    /// 1 in the open. A sensor with much of it stands outside every room.
    pub fn open_sky_shares(&self) -> Vec<f64> {
        let bins = self.bin_count();
        self.sensors
            .iter()
            .map(|s| {
                s.gather
                    .daylight_coefficients
                    .iter()
                    .filter(|&&(k, _)| SkyKey::unpack(k, bins).window.is_none())
                    .map(|&(_, w)| f64::from(w))
                    .sum()
            })
            .collect()
    }

    /// Sensors with nothing under them: most rays down from them meet no
    /// surface and reach the ground below the
    /// model, as in a room whose floor the model lacks (an architect's
    /// export without its structural slabs: Revit's Office_A has two
    /// slabs, both stair landings, and its ground floor's ceilings read the
    /// ground's glow through the floor that is not there). They still read
    /// what reaches them; the caller warns.
    pub fn sensors_over_nothing(&self) -> Vec<usize> {
        const RAYS: usize = 32;
        (0..self.scene.sensors.len())
            .filter(|&i| {
                let sensor = &self.scene.sensors[i];
                let mut rng = Rng::new(6, i as u64);
                let down = cosine_directions(DVec3::NEG_Z, RAYS, &mut rng);
                // Off the floor a sensor may lie on, as it is placed to measure.
                let origin = sensor.position.as_dvec3() + sensor.normal.as_dvec3() * gather::SENSOR_LIFT;
                let open = down.iter().filter(|&&d| self.shadow_tracer.closest(origin, d, 1e-6).is_none()).count();
                2 * open > RAYS
            })
            .collect()
    }

    /// Sensors that seem to sit inside a solid: every ray from them meets a
    /// surface from its back, within a few metres. They still read what
    /// reaches them; the caller warns.
    pub fn sensors_inside_solids(&self) -> Vec<usize> {
        const RAYS: usize = 64;
        let surfaces = &self.scene.surfaces;
        (0..self.scene.sensors.len())
            .filter(|&i| {
                let position = self.scene.sensors[i].position.as_dvec3();
                let mut rng = Rng::new(4, i as u64);
                let up = cosine_directions(DVec3::Z, RAYS / 2, &mut rng);
                up.iter().chain(cosine_directions(DVec3::NEG_Z, RAYS / 2, &mut rng).iter()).all(|&d| {
                    self.shadow_tracer
                        .closest(position, d, 1e-6)
                        .is_some_and(|hit| hit.distance < 5.0 && d.dot(surfaces[hit.patch as usize].normal.as_dvec3()) > 0.0)
                })
            })
            .collect()
    }
}

/// Scenes the light engine's unit tests build from OBJ text.
#[cfg(test)]
mod test_scene {
    use crate::panel::PanelCatalog;
    use crate::scene::{Scene, load_scene};

    /// The scene of `obj` (materials `wall`, ρ 0.5, and `glass`) at 45° N,
    /// with `more` added to its scene file: written to a temporary folder
    /// named after `name` and read back.
    pub(super) fn scene_of(name: &str, obj: &str, more: &str) -> Scene {
        let dir = std::env::temp_dir().join(format!("heliodon-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("m.obj"), format!("mtllib m.mtl\n{obj}")).unwrap();
        std::fs::write(dir.join("m.mtl"), "newmtl wall\nKd 0.5 0.5 0.5\nnewmtl glass\nd 0.8\n").unwrap();
        let scene = format!("[site]\nlatitude = 45.0\nlongitude = 0.0\ntimezone = 0.0\n[model]\nobj = \"m.obj\"\n{more}");
        std::fs::write(dir.join("scene.toml"), scene).unwrap();
        let scene = load_scene(&dir.join("scene.toml"), &PanelCatalog::new()).unwrap().scene;
        std::fs::remove_dir_all(&dir).ok();
        scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sensor no sun or sky reaches says 0 lux of each, not −0 (an empty
    /// sum of floats is −0 in Rust).
    #[test]
    fn a_dark_sensor_reads_zero_not_minus_zero() {
        let nothing: f64 = std::iter::empty::<f64>().sum();
        assert!(nothing.is_sign_negative());
        let reading = SensorReading::new("dark".into(), nothing, nothing * crate::sky::LUMINOUS_EFFICACY, 0.0);
        let shown = format!("{:.1} {:.1} {:.1} {:.1}", reading.total, reading.direct_sun, reading.direct_sky, reading.indirect);
        assert_eq!(shown, "0.0 0.0 0.0 0.0");
    }
}
