//! Panel windows in the light engine. Each window group of a panel material
//! ([`super::windows`]: one material, facing one way) is a panel group with
//! a frame (its outward normal turned into the room, its `up`), whose
//! response to the sun is computed once.
//! Sunlight reaches the room through a panel only along its lobes: each
//! transmitted lobe is a beam of its own, a fake sun (thesis section 3.5).

use std::sync::{Arc, OnceLock};

use glam::DVec3;

use super::sampling::{Rng, sample_area, with_cumulative_areas};
use super::windows::WindowGroups;
use super::{LightModel, SURFACE_OFFSET};
use crate::panel::{Lobe, PanelModel};
use crate::scene::{MaterialKind, Scene};
use crate::sky::{LUMINOUS_EFFICACY, SkyPatches, SunSource};

/// A panel's frame in the model: z into the room, y its up, x = y × z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelFrame {
    /// y × z: across the panel.
    pub x: DVec3,
    /// The panel's up, in its plane.
    pub y: DVec3,
    /// The window's normal into the room.
    pub z: DVec3,
}

impl PanelFrame {
    /// The frame of a window whose normal into the room is `inward`, with
    /// `up` projected onto its plane (north for a horizontal window).
    pub fn new(inward: DVec3, up: Option<DVec3>) -> Self {
        let z = inward.normalize();
        let project = |v: DVec3| (v - z * v.dot(z)).try_normalize();
        let y = up.and_then(project).or_else(|| project(DVec3::Z)).or_else(|| project(DVec3::Y)).unwrap_or(DVec3::X);
        Self { x: y.cross(z), y, z }
    }

    /// A model direction in the panel's frame.
    pub fn to_panel(&self, d: DVec3) -> DVec3 {
        DVec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }

    /// A panel-frame direction in the model.
    pub fn to_world(&self, d: DVec3) -> DVec3 {
        self.x * d.x + self.y * d.y + self.z * d.z
    }
}

/// Windows of one panel material facing one way.
pub struct PanelGroup {
    /// The panel material (index into [`Scene::materials`]).
    pub material: u32,
    /// The material's built panel model.
    pub model: Arc<dyn PanelModel>,
    /// The frame shared by the group's windows.
    pub frame: PanelFrame,
    /// The model's [`PanelModel::back_reflectance`], clamped to 0-1: the
    /// windows' room side is a diffuse reflector of it.
    pub back_reflectance: f64,
    /// What the windows see outside ([`Outlook`]); everything until
    /// [`LightModel`] looks.
    pub outlook: Outlook,
    /// How sky and ground light pass it, made on first use.
    transfer: OnceLock<SkyTransfer>,
}

/// What a panel group's windows see outside: overhangs, fins and
/// neighbouring buildings hide part of the sky from them, and shade them
/// from the sun, as they do a plain window.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outlook {
    /// Seeded points on the windows, just outside them.
    pub points: Vec<DVec3>,
    /// Per sphere bin: the share of the points that see it (through any
    /// glass on the way, by its transmittance); ground bins count as seen
    /// (their light is the ground's, wherever it comes from). Empty: all
    /// seen.
    pub sky_seen: Vec<f64>,
}

/// Points per window an outlook is taken from.
const OUTLOOK_POINTS: usize = 16;

impl LightModel {
    /// Every panel group's [`Outlook`], by shadow rays from points on its
    /// windows toward each sky bin's middle.
    pub(super) fn look_out_of_panels(&mut self) {
        let bins = self.sky_bins.len();
        let outlooks: Vec<Outlook> = (0..self.panel_groups.len())
            .map(|g| {
                let outward = -self.panel_groups[g].frame.z;
                let mut rng = Rng::new(4, g as u64);
                let points: Vec<DVec3> = self
                    .scene
                    .windows
                    .iter()
                    .filter(|w| self.group_of_surface[w.surface as usize] == Some(g as u32))
                    .flat_map(|w| {
                        let triangles = with_cumulative_areas(self.scene.surface_triangles(w.surface).iter().map(|t| t.vertices));
                        (0..OUTLOOK_POINTS).map(|_| sample_area(&triangles, &mut rng) + outward * SURFACE_OFFSET).collect::<Vec<_>>()
                    })
                    .collect();
                let sky_seen = (0..2 * bins)
                    .map(|b| {
                        let direction = self.sky_bins.patches[b % bins].direction;
                        if b >= bins || direction.dot(outward) <= 0.0 { 1.0 } else { self.share_seeing(&points, direction) }
                    })
                    .collect();
                Outlook { points, sky_seen }
            })
            .collect();
        for (group, outlook) in self.panel_groups.iter_mut().zip(outlooks) {
            group.outlook = outlook;
        }
    }

    /// The share of panel group `group`'s windows the sun reaches.
    pub(super) fn panel_sunlit(&self, group: usize, sun: DVec3) -> f64 {
        self.share_seeing(&self.panel_groups[group].outlook.points, sun)
    }

    /// The mean of what reaches `points` from `direction` (through glass,
    /// by its transmittance); 1 without points.
    fn share_seeing(&self, points: &[DVec3], direction: DVec3) -> f64 {
        if points.is_empty() {
            return 1.0;
        }
        points.iter().map(|&p| self.sun_transmittance(p, direction)).sum::<f64>() / points.len() as f64
    }
}

/// How a panel group passes sky and ground light into the radiance seen
/// through it in each sphere bin.
pub enum SkyTransfer {
    /// By the model's response, per sphere bin the light comes from: the
    /// bins its lobes' beams ([`spread`]) leave along, as factors from the
    /// incoming bin's radiance to the radiance seen through the panel in
    /// the outgoing bin (share · cos θin · ωin / (cos θout · ωout)), and the
    /// factor to the radiance of its diffuse transmission (τd · cos θin ·
    /// ωin / π).
    Lobes {
        /// Per incoming bin: (outgoing bin, radiance factor) for each transmitted lobe.
        lobes: Vec<Vec<(u32, f64)>>,
        /// Per incoming bin: the factor to the diffusely transmitted radiance.
        diffuse: Vec<f64>,
    },
    /// By the model's measured transmission ([`PanelModel::measured`]),
    /// as Radiance's 3-phase method does: the light of the incoming bins
    /// summed per incoming patch of the data (a Klems basis), its
    /// irradiance then sent into every outgoing bin by the data's BTDF
    /// from that patch. No lobe fit between the data and the room: a
    /// diffusing panel's light goes where the data sends it, not evenly.
    Measured {
        /// Per incoming bin: its patch and the factor cos θin · ωin from its
        /// radiance to the patch's irradiance (patch `u32::MAX`: the bin
        /// lies on the room's side).
        incoming: Vec<(u32, f64)>,
        /// The bins the light leaves into the room along (the others see
        /// none of it).
        outgoing: Vec<u32>,
        /// The BTDF from each patch into each of those bins, `[bin][patch]`.
        btdf: Vec<f32>,
        /// The data's incoming patches.
        patches: usize,
    },
}

impl PanelGroup {
    /// The lobes the panel sends into the room under `sun`, with the
    /// irradiance its area receives (E · cos θin); none when the sun is
    /// behind it.
    fn transmitted_lobes(&self, sun: &SunSource) -> (f64, Vec<Lobe>) {
        let incoming = self.frame.to_panel(-sun.direction);
        if incoming.z <= 0.0 {
            return (0.0, Vec::new());
        }
        let lobes = self.model.response(incoming).lobes.into_iter().filter(|l| l.direction.z > 1e-6 && l.share > 0.0).collect();
        (sun.normal_irradiance() * incoming.z, lobes)
    }

    /// Another model for the group's windows; its sky transfer is made anew.
    pub fn set_model(&mut self, model: Arc<dyn PanelModel>) {
        self.back_reflectance = back_reflectance(model.as_ref());
        self.model = model;
        self.transfer = OnceLock::new();
    }

    /// The group's sky transfer over `bins`' sphere bins.
    pub fn sky_transfer(&self, bins: &SkyPatches) -> &SkyTransfer {
        self.transfer.get_or_init(|| {
            let count = 2 * bins.len();
            let direction = |b: usize| {
                let d = bins.patches[b % bins.len()].direction;
                if b < bins.len() { d } else { DVec3::new(d.x, d.y, -d.z) }
            };
            let solid_angle = |b: usize| bins.patches[b % bins.len()].solid_angle;
            if let Some(data) = self.model.measured() {
                let incoming = (0..count)
                    .map(|b| {
                        let travel = self.frame.to_panel(-direction(b));
                        if travel.z > 0.0 { (data.incoming_patch(travel) as u32, travel.z * solid_angle(b)) } else { (u32::MAX, 0.0) }
                    })
                    .collect();
                let patches = data.incoming_patches();
                let rows = super::par_map(None, patches, |p| data.patch_row(p));
                // Seen from the room along bin o, the light leaves against it.
                let leaving = |o: u32| self.frame.to_panel(-direction(o as usize));
                let outgoing: Vec<u32> = (0..count as u32).filter(|&o| leaving(o).z > 0.0).collect();
                let btdf = (outgoing.iter())
                    .flat_map(|&o| {
                        let cell = data.outgoing_cell(leaving(o));
                        rows.iter().map(move |row| row.get(cell).map_or(0.0, |&f| f as f32))
                    })
                    .collect();
                return SkyTransfer::Measured { incoming, outgoing, btdf, patches };
            }
            // Each bin on its own (panel responses can be costly): in parallel.
            let per_bin = super::par_map(None, count, |b| {
                // Light from bin b travels away from it.
                let incoming = self.frame.to_panel(-direction(b));
                if incoming.z <= 0.0 {
                    return (Vec::new(), 0.0);
                }
                let flux = incoming.z * solid_angle(b);
                let response = self.model.response(incoming);
                let lobes = response
                    .lobes
                    .iter()
                    .filter(|l| l.direction.z > 1e-6 && l.share > 0.0)
                    .flat_map(spread)
                    .map(|(direction, share)| {
                        // Seen from the room, looking back against the beam.
                        let out = bins.sphere_bin(-self.frame.to_world(direction));
                        (out as u32, share * flux / (direction.z * solid_angle(out)))
                    })
                    .collect();
                (lobes, response.diffuse_transmittance * flux / std::f64::consts::PI)
            });
            let (lobes, diffuse) = per_bin.into_iter().unzip();
            SkyTransfer::Lobes { lobes, diffuse }
        })
    }

    /// Radiance (W/sr/m²) of sky and ground light seen through the group's
    /// windows in every sphere bin, for bin radiances `sky` (each as much as
    /// the windows see of it: [`Outlook`]).
    pub fn radiance_through(&self, bins: &SkyPatches, sky: &[f64]) -> Vec<f64> {
        let seen = sky.iter().enumerate().map(|(b, &radiance)| radiance * self.outlook.sky_seen.get(b).copied().unwrap_or(1.0));
        match self.sky_transfer(bins) {
            SkyTransfer::Lobes { lobes, diffuse: diffuse_factors } => {
                let mut out = vec![0.0; sky.len()];
                let mut diffuse = 0.0;
                for (b, radiance) in seen.enumerate().filter(|(_, r)| *r > 0.0) {
                    for &(o, factor) in &lobes[b] {
                        out[o as usize] += factor * radiance;
                    }
                    diffuse += diffuse_factors[b] * radiance;
                }
                out.iter_mut().for_each(|r| *r += diffuse);
                out
            }
            SkyTransfer::Measured { incoming, outgoing, btdf, patches } => {
                let mut irradiance = vec![0.0; *patches];
                for ((patch, factor), radiance) in incoming.iter().zip(seen) {
                    if let Some(e) = irradiance.get_mut(*patch as usize) {
                        *e += factor * radiance;
                    }
                }
                let mut out = vec![0.0; sky.len()];
                for (&o, row) in outgoing.iter().zip(btdf.chunks_exact(*patches)) {
                    out[o as usize] = row.iter().zip(&irradiance).map(|(&f, e)| f64::from(f) * e).sum();
                }
                out
            }
        }
    }

    /// Radiance (W/sr/m²) of the sunlight the group's windows transmit
    /// diffusely (their lobes are beams of their own): sunlight redirected
    /// by the panel, so it counts as direct sun.
    pub fn sun_diffuse_radiance(&self, sun: Option<&SunSource>) -> f64 {
        let Some(sun) = sun.filter(|s| s.direction.z > 0.0) else { return 0.0 };
        let incoming = self.frame.to_panel(-sun.direction);
        if incoming.z <= 0.0 {
            return 0.0;
        }
        sun.normal_irradiance() * incoming.z * self.model.response(incoming).diffuse_transmittance / std::f64::consts::PI
    }
}

/// A beam of direct sunlight: the sun itself, or a panel lobe's fake sun.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunBeam {
    /// Unit vector toward the (fake) sun.
    pub to_light: DVec3,
    /// Irradiance normal to the beam, W/m² (for a lobe: after the panel).
    pub normal_irradiance: f64,
    /// The panel group the beam comes out of; `None` for the sun itself.
    pub panel_group: Option<u32>,
    /// For a lobe, the real sun's direction: how much of the lobe leaves
    /// by a point of its windows is how much sun reaches that point from
    /// outside. `None`: the windows taken as sunlit throughout (a unit lobe
    /// of a [`super::LobeTable`]). Unused for the sun itself.
    pub window_sun: Option<DVec3>,
}

/// How a panel's room side looks under a sky: the light it sends into the
/// room, as an eye there sees it on the panel.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelLook {
    /// The panel material (index into [`Scene::materials`]).
    pub material: u32,
    /// Its windows' normal into the room: the side it is seen like this from.
    pub inward: DVec3,
    /// The diffusely transmitted sun: its luminance the same from every
    /// direction, cd/m².
    pub diffuse: f64,
    /// Sky and ground as the panel passes them into the room, per sphere
    /// bin of the way the eye looks out through it, cd/m²
    /// ([`LightModel::panel_sky_luminance`]).
    pub sky: Vec<f64>,
    /// The transmitted lobes, each light filling a cone evenly.
    pub lobes: Vec<LobeLook>,
}

/// A lobe seen from the room: looking at the panel from within its cone,
/// against the way its light travels, the eye sees it at `luminance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeLook {
    /// The way its light travels into the room (unit).
    pub travel: DVec3,
    /// The cone's half angle, radians (at least [`LOBE_LOOK_HALF_ANGLE`]).
    pub half_angle: f64,
    /// cd/m².
    pub luminance: f64,
}

/// The narrowest cone a lobe is drawn in, radians: a lobe narrower than that
/// (a mirror's, 0°) would be a point; it shows as a small bright disc the
/// size of a sun of 2°.
pub const LOBE_LOOK_HALF_ANGLE: f64 = 0.0175;

impl LightModel {
    /// Each panel group's look under `sky`, from what the engine makes of
    /// it: the sky and ground its windows pass (the radiance behind their
    /// gather keys, [`super::daylight`]), its diffusely transmitted sun, and
    /// its lobes ([`PanelModel::response`]), each the irradiance the panel's
    /// area receives (E·cos θin, times the share of its windows the sun
    /// reaches) spread over its cone's solid angle.
    pub fn panel_looks(&self, sky: &crate::sky::Sky) -> Vec<PanelLook> {
        let behind_keys = self.key_radiance(sky);
        let sun = sky.sun_up();
        self.panel_groups
            .iter()
            .enumerate()
            .map(|(g, group)| {
                let (sky_through, sun_diffuse) = behind_keys.through_panel(g);
                let mut look = PanelLook {
                    material: group.material,
                    inward: group.frame.z,
                    diffuse: sun_diffuse * LUMINOUS_EFFICACY,
                    sky: sky_through.iter().map(|r| r * LUMINOUS_EFFICACY).collect(),
                    lobes: Vec::new(),
                };
                let Some(sun) = &sun else { return look };
                let (irradiance, lobes) = group.transmitted_lobes(sun);
                let irradiance = irradiance * self.panel_sunlit(g, sun.direction);
                for lobe in lobes.iter().filter(|_| irradiance > 0.0) {
                    let direction = lobe.direction.normalize();
                    // (A NaN width reads as narrow, as in `spread`.)
                    let width = if lobe.width.is_nan() { 0.0 } else { lobe.width };
                    let half_angle = (0.5 * width).to_radians().clamp(LOBE_LOOK_HALF_ANGLE, std::f64::consts::FRAC_PI_2);
                    let solid_angle = std::f64::consts::TAU * (1.0 - half_angle.cos());
                    // The flux on the panel's area, spread over the lobe's cross section.
                    let normal_irradiance = irradiance * lobe.share / direction.z;
                    look.lobes.push(LobeLook {
                        travel: group.frame.to_world(direction).normalize(),
                        half_angle,
                        luminance: normal_irradiance / solid_angle * LUMINOUS_EFFICACY,
                    });
                }
                look
            })
            .collect()
    }

    /// What an eye in the room sees of the sky and ground through a panel
    /// of `look`, looking out through it along `outward`, cd/m².
    pub fn panel_sky_luminance(&self, look: &PanelLook, outward: DVec3) -> f64 {
        look.sky.get(self.sky_bins.sphere_bin(outward)).copied().unwrap_or(0.0)
    }
}

/// The panel groups of a scene (one per window group of a panel material,
/// see [`super::windows`]) and each surface's group.
pub fn panel_groups(scene: &Scene, windows: &WindowGroups) -> (Vec<PanelGroup>, Vec<Option<u32>>) {
    let mut groups: Vec<PanelGroup> = Vec::new();
    let mut group_of_surface = vec![None; scene.surfaces.len()];
    for window_group in &windows.groups {
        let MaterialKind::Panel { model, up, .. } = &scene.materials[window_group.material as usize].kind else { continue };
        let frame = PanelFrame::new(-window_group.outward, up.map(|u| u.as_dvec3()));
        for &window in &window_group.windows {
            group_of_surface[scene.windows[window as usize].surface as usize] = Some(groups.len() as u32);
        }
        let back_reflectance = back_reflectance(model.0.as_ref());
        groups.push(PanelGroup {
            material: window_group.material,
            model: model.0.clone(),
            frame,
            back_reflectance,
            outlook: Outlook::default(),
            transfer: OnceLock::new(),
        });
    }
    (groups, group_of_surface)
}

/// A model's back reflectance, a finite share (a plugin's bad value reads 0).
fn back_reflectance(model: &dyn PanelModel) -> f64 {
    let rho = model.back_reflectance();
    if rho.is_finite() { rho.clamp(0.0, 1.0) } else { 0.0 }
}

/// Lobes at least this wide (full angle, degrees) are spread over their cone.
pub const SPREAD_WIDTH: f64 = 4.0;

/// Beams a wide lobe is spread into, on a ring around its direction.
const RING: usize = 3;

/// The directions (panel frame) and shares a lobe's light travels in: the
/// lobe itself when it is narrower than [`SPREAD_WIDTH`]; else three beams
/// on a ring around its direction at 1/√2 of the cone's half angle, a
/// third of the share each: their mean is the lobe's direction and their
/// spread (the mean squared angle from it, the same across every axis)
/// that of light filling the cone of the lobe's width evenly. Three, not
/// more, because each beam is a pass pair of the renderer's sun pass. The
/// ring starts toward the panel's x axis; beams that would leave below the
/// panel's plane are dropped and the others carry the lobe.
pub fn spread(lobe: &Lobe) -> Vec<(DVec3, f64)> {
    let centre = lobe.direction.normalize();
    // (A NaN width reads as narrow.)
    if lobe.width.is_nan() || lobe.width < SPREAD_WIDTH {
        return vec![(centre, lobe.share)];
    }
    let (sin, cos) = ((0.5 * lobe.width.min(180.0)).to_radians() * std::f64::consts::FRAC_1_SQRT_2).sin_cos();
    let across = (DVec3::X - centre * centre.x).try_normalize().unwrap_or_else(|| (DVec3::Y - centre * centre.y).normalize());
    let (u, v) = (across, centre.cross(across));
    let ring = (0..RING).map(|k| {
        let (s, c) = (std::f64::consts::TAU * k as f64 / RING as f64).sin_cos();
        centre * cos + (u * c + v * s) * sin
    });
    let directions: Vec<DVec3> = ring.filter(|d| d.z > 1e-6).collect();
    if directions.is_empty() {
        return vec![(centre, lobe.share)];
    }
    let share = lobe.share / directions.len() as f64;
    directions.into_iter().map(|d| (d, share)).collect()
}

/// The beams of direct sunlight for a sun: the sun, and for each panel
/// group its transmitted lobes, each as the beams it [`spread`]s into. A
/// beam carries the flux the panel's area receives (E · cos θin) times its
/// share, spread over the beam's cross section (÷ cos θout).
pub fn sun_beams(groups: &[PanelGroup], sun: &SunSource) -> Vec<SunBeam> {
    let mut beams =
        vec![SunBeam { to_light: sun.direction, normal_irradiance: sun.normal_irradiance(), panel_group: None, window_sun: None }];
    for (index, group) in groups.iter().enumerate() {
        let (irradiance, lobes) = group.transmitted_lobes(sun);
        for lobe in &lobes {
            for (direction, share) in spread(lobe) {
                beams.push(SunBeam {
                    to_light: -group.frame.to_world(direction).normalize(),
                    normal_irradiance: irradiance * share / direction.z,
                    panel_group: Some(index as u32),
                    window_sun: Some(sun.direction),
                });
            }
        }
    }
    beams
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    /// A wide lobe's beams carry its share, centred on it, spread as light
    /// filling its cone evenly (mean squared angle (w/2)²/2); a narrow lobe
    /// stays one beam; a lobe near the panel's plane keeps its share in the
    /// beams left above it.
    #[test]
    fn wide_lobes_spread_over_their_cone_and_keep_their_share() {
        let tilted = DVec3::new(0.3, -0.5, 0.81).normalize();
        for width in [4.0, 23.0, 40.0] {
            let beams = spread(&Lobe { direction: tilted, share: 0.42, width });
            assert_eq!(beams.len(), 3);
            assert!((beams.iter().map(|b| b.1).sum::<f64>() - 0.42).abs() < 1e-12);
            let mean: DVec3 = beams.iter().map(|b| b.0 * b.1).sum();
            assert!(mean.normalize().angle_between(tilted) < 1e-6, "{width}");
            let spread_sq = beams.iter().map(|b| b.0.angle_between(tilted).powi(2) * b.1).sum::<f64>() / 0.42;
            let half = (0.5 * width).to_radians();
            assert!((spread_sq / (0.5 * half * half) - 1.0).abs() < 0.01, "{width}: {spread_sq}");
        }
        assert_eq!(spread(&Lobe { direction: tilted, share: 0.42, width: 2.0 }), vec![(tilted, 0.42)]);
        let grazing = spread(&Lobe { direction: DVec3::new(0.0, 0.999, 0.045).normalize(), share: 0.3, width: 30.0 });
        assert!(grazing.len() < 3 && grazing.iter().all(|b| b.0.z > 0.0));
        assert!((grazing.iter().map(|b| b.1).sum::<f64>() - 0.3).abs() < 1e-12);
    }

    /// Measured transmission on the patches of a Tregenza sky laid on the
    /// panel (incoming patches and outgoing cells alike): a diffuser
    /// (BTDF τ/π everywhere) or clear glass at patch resolution (BTDF
    /// τ / projected solid angle from a patch into the same patch).
    #[derive(Debug)]
    struct OnPatches {
        patches: SkyPatches,
        diffuser: bool,
    }

    impl crate::panel::MeasuredTransmission for OnPatches {
        fn outgoing_cells(&self) -> usize {
            self.patches.len()
        }
        fn outgoing_cell(&self, outgoing: DVec3) -> usize {
            self.patches.patch_of(outgoing).unwrap_or(0)
        }
        fn row(&self, incoming: DVec3) -> Vec<f64> {
            self.patch_row(self.incoming_patch(incoming))
        }
        fn incoming_patches(&self) -> usize {
            self.patches.len()
        }
        fn incoming_patch(&self, incoming: DVec3) -> usize {
            self.patches.patch_of(incoming).unwrap_or(0)
        }
        fn patch_row(&self, patch: usize) -> Vec<f64> {
            let projected = self.patches.patches[patch].projected_solid_angle;
            (0..self.patches.len())
                .map(|o| {
                    if self.diffuser {
                        0.4 / PI
                    } else if o == patch {
                        0.4 / projected
                    } else {
                        0.0
                    }
                })
                .collect()
        }
    }

    impl PanelModel for OnPatches {
        fn response(&self, _: DVec3) -> crate::panel::PanelResponse {
            crate::panel::PanelResponse { diffuse_transmittance: 0.4, absorbed: 0.6, ..Default::default() }
        }
        fn measured(&self) -> Option<&dyn crate::panel::MeasuredTransmission> {
            Some(self)
        }
    }

    fn group(model: OnPatches) -> PanelGroup {
        PanelGroup {
            material: 0,
            model: Arc::new(model),
            // A south window: into the room is north.
            frame: PanelFrame::new(DVec3::Y, None),
            back_reflectance: 0.0,
            outlook: Outlook::default(),
            transfer: OnceLock::new(),
        }
    }

    /// Sky light passes a panel with measured data by the data: a diffuser
    /// of τ = 0.4 under an even sphere of radiance 1 shows 0.4 in every
    /// direction seen from the room; clear glass at patch resolution shows
    /// one bright sky bin where one looks toward it through the window, and
    /// nowhere else.
    #[test]
    fn sky_light_passes_a_measured_panel_by_its_data() {
        let bins = SkyPatches::reinhart(4);
        let panel = |diffuser| group(OnPatches { patches: SkyPatches::reinhart(1), diffuser });
        let room_side = |b: usize| {
            let d = bins.patches[b % bins.len()].direction;
            let d = if b < bins.len() { d } else { DVec3::new(d.x, d.y, -d.z) };
            (d.y < -0.05).then_some(d)
        };
        let seen = panel(true).radiance_through(&bins, &vec![1.0; 2 * bins.len()]);
        for (b, radiance) in seen.iter().enumerate().filter(|(b, _)| room_side(*b).is_some()) {
            assert!((radiance - 0.4).abs() < 0.004, "bin {b}: {radiance}");
        }
        let bright = bins.sphere_bin(DVec3::new(0.3, -0.8, 0.5).normalize());
        let mut sky = vec![0.0; 2 * bins.len()];
        sky[bright] = 1.0;
        let seen = panel(false).radiance_through(&bins, &sky);
        let brightest = (0..seen.len()).max_by(|&a, &b| seen[a].total_cmp(&seen[b])).unwrap();
        let patch = |b: usize| SkyPatches::reinhart(1).patch_of(PanelFrame::new(DVec3::Y, None).to_panel(-room_side(b).unwrap()));
        assert_eq!(patch(brightest), patch(bright), "seen in bin {brightest}, the bright bin is {bright}");
        assert!(seen[bright] > 0.0 && seen.iter().enumerate().all(|(b, &r)| r == 0.0 || patch(b) == patch(bright)));
    }

    #[test]
    fn frames_are_right_handed_with_up_in_the_plane() {
        // A south wall seen from the room: into the room is north (+y).
        let frame = PanelFrame::new(DVec3::Y, None);
        assert!((frame.y - DVec3::Z).length() < 1e-12);
        assert!((frame.x.cross(frame.y) - frame.z).length() < 1e-12);
        // A skylight: up is north.
        let frame = PanelFrame::new(-DVec3::Z, None);
        assert!((frame.y - DVec3::Y).length() < 1e-12);
        let d = DVec3::new(0.3, -0.4, 0.866).normalize();
        assert!((frame.to_world(frame.to_panel(d)) - d).length() < 1e-12);
    }
}
